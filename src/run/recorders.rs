//! What a run writes while it goes: history.csv rows and ParaView frames when
//! they are due, newton.csv after every implicit step, footing.csv when the scene
//! has a footing. Each file is flushed as it grows, so a run that stops early
//! keeps what it wrote.

use crate::dim::Vector;
use crate::model::Model;
use crate::output::{body_centres, CsvWriter, Field, FrameWriter, HistoryWriter};
use crate::run::energy::{kinetic_energy, strain_energy};
use crate::run::footing::FootingCurve;
use crate::run::summary::FootingSummary;
use crate::scene::{SceneConfig, SolverKind};
use crate::solver::report::NewtonRow;
use std::io;
use std::path::Path;

/// The columns of newton.csv.
pub const NEWTON_COLUMNS: [&str; 11] = [
    "step",
    "time",
    "dt",
    "cutback",
    "iteration",
    "residual",
    "increment",
    "wall_seconds",
    "krylov_iterations",
    "forcing",
    "linear_solver",
];

/// The state of the run after a step (or at its start or end).
pub struct Moment<'a, const D: usize> {
    pub model: &'a Model<D>,
    pub t: f64,
    /// Work of gravity and applied loads since the start.
    pub external_work: f64,
}

/// The output files that grow during a run.
pub struct Recorders {
    history: HistoryWriter,
    history_interval: f64,
    next_history: f64,
    last_history: f64,
    frames: FrameWriter,
    /// Time between frames (None: no frames at all).
    frame_interval: Option<f64>,
    next_frame: f64,
    last_frame: f64,
    end_time: f64,
    n_bodies: usize,
    /// newton.csv, when the run has an implicit stage.
    newton: Option<CsvWriter>,
    /// footing.csv, when the scene has a footing.
    footing: Option<FootingCurve>,
}

impl Recorders {
    /// Create the files of a run of `cfg` on `model` in `out`.
    pub fn create<const D: usize>(
        out: &Path,
        cfg: &SceneConfig,
        model: &Model<D>,
    ) -> io::Result<Self> {
        let n_bodies = model.n_bodies();
        let end_time = cfg.total_time();
        let implicit = cfg.stages().iter().any(|s| s.kind == SolverKind::Implicit);
        Ok(Recorders {
            history: HistoryWriter::create(&out.join("history.csv"), D, n_bodies)?,
            history_interval: cfg.output.history_interval,
            next_history: 0.0,
            last_history: f64::NAN,
            frames: FrameWriter::new(out, "particles")?,
            frame_interval: (cfg.output.frames > 0).then(|| end_time / cfg.output.frames as f64),
            next_frame: 0.0,
            last_frame: f64::NAN,
            end_time,
            n_bodies,
            newton: match implicit {
                true => Some(CsvWriter::create(&out.join("newton.csv"), &NEWTON_COLUMNS)?),
                false => None,
            },
            footing: match &model.footing {
                Some(_) => Some(FootingCurve::create(&out.join("footing.csv"))?),
                None => None,
            },
        })
    }

    /// A history row and a frame when they are due (or `force`d, at the start
    /// and the end), never twice at the same time.
    pub fn state<const D: usize>(&mut self, now: &Moment<D>, force: bool) -> io::Result<()> {
        let (m, t) = (now.model, now.t);
        if (force || t >= self.next_history) && t != self.last_history {
            self.last_history = t;
            let (com, vcom) = body_centres(&m.particles, self.n_bodies);
            let (kinetic, strain) = (kinetic_energy(m), strain_energy(m));
            self.history
                .write_row(t, kinetic, strain, now.external_work, &com, &vcom)?;
            self.next_history = t + self.history_interval;
        }
        let Some(interval) = self.frame_interval else {
            return Ok(());
        };
        let tolerance = 1e-12 * self.end_time;
        if (force || t >= self.next_frame - tolerance) && t != self.last_frame {
            self.last_frame = t;
            let eps_p = m.plastic_strain();
            let extra: Vec<(&str, &[f64])> =
                eps_p.iter().map(|e| ("eps_p", e.as_slice())).collect();
            self.frames.write_frame(t, &m.particles, &extra)?;
            while self.next_frame <= t + tolerance {
                self.next_frame += interval;
            }
        }
        Ok(())
    }

    /// The Newton iterations of the last step, into newton.csv.
    pub fn newton(&mut self, rows: &[NewtonRow]) -> io::Result<()> {
        let Some(csv) = &mut self.newton else {
            return Ok(());
        };
        for r in rows {
            csv.row([
                Field::from(r.step),
                r.time.into(),
                r.dt.into(),
                r.cutback.into(),
                r.iteration.into(),
                r.residual.into(),
                r.increment.into(),
                r.wall_seconds.into(),
                r.krylov_iterations.into(),
                r.forcing.into(),
                Field::from(&r.linear_solver),
            ])?;
        }
        csv.flush()
    }

    /// After a step of length dt ending at t: the footing's load–settlement curve.
    pub fn footing<const D: usize>(
        &mut self,
        m: &Model<D>,
        t: f64,
        dt: f64,
        reaction: Option<&[(u32, Vector<D>)]>,
    ) -> io::Result<()> {
        match &mut self.footing {
            Some(curve) => curve.after_step(m, t, dt, reaction),
            None => Ok(()),
        }
    }

    /// The footing's limit pressure and its neighbours, for summary.json.
    pub fn footing_summary<const D: usize>(&self, m: &Model<D>) -> Option<FootingSummary> {
        let f = m.footing.as_ref()?;
        self.footing.as_ref()?.summary(f.cohesion)
    }
}
