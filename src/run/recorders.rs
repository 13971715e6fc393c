//! What a run writes while it goes: history.csv rows and ParaView frames when
//! they are due, newton.csv after every implicit step, footing.csv when the scene
//! has a footing. Each file is flushed as it grows, so a run that stops early
//! keeps what it wrote.

use crate::dim::Vector;
use crate::model::Model;
use crate::output::{body_centres, CsvWriter, Field, FrameWriter, HistoryWriter};
use crate::physics::contact::totals::PairTotal;
use crate::run::contact::{ContactLog, ContactState};
use crate::run::energy::{kinetic_energy, strain_energy};
use crate::run::footing::FootingCurve;
use crate::run::particle_dumps::{DumpState, ParticleDumps};
use crate::run::schedule::Schedule;
use crate::run::summary::FootingSummary;
use crate::scene::{SceneConfig, SolverKind};
use crate::solver::report::NewtonRow;
use serde::{Deserialize, Serialize};
use std::io;
use std::path::{Path, PathBuf};

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
    /// The steps taken so far.
    pub step: usize,
    /// Work of gravity and applied loads since the start.
    pub external_work: f64,
}

/// Where the recorders are, for a checkpoint: the streamed files as written so
/// far and when the next row and frame are due, so that a restarted run writes
/// them on exactly as the uninterrupted run would.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RecorderState {
    pub history_csv: String,
    /// The next output time of history.csv not yet taken.
    pub next_history: f64,
    /// Time of the last history row (none before the first).
    pub last_history: Option<f64>,
    /// (time, file name) of every frame so far.
    pub frames: Vec<(f64, String)>,
    pub next_frame: f64,
    pub last_frame: Option<f64>,
    pub newton_csv: Option<String>,
    pub footing_csv: Option<String>,
    pub footing_rows: Vec<[f64; 4]>,
    pub footing_settlement: f64,
    /// contact.csv and the totals since its last rows, when the scene has contact.
    #[serde(default)]
    pub contact: Option<ContactState>,
    /// particles_NNNN.csv, when the scene asks for them.
    #[serde(default)]
    pub particle_dumps: Option<DumpState>,
}

/// The output files that grow during a run.
pub struct Recorders {
    out: PathBuf,
    history: HistoryWriter,
    history_times: Schedule,
    last_history: f64,
    /// particles_NNNN.csv at the scene's particle_times / particle_interval.
    dumps: Option<ParticleDumps>,
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
    /// contact.csv, when the scene has contact between bodies.
    contact: Option<ContactLog>,
}

/// history.csv's columns of a scene whose materials erode failed points or that
/// removes particles leaving the grid: the mass of the removed particles and
/// their kinetic + stored energy (both also inside `kinetic` and `strain`, which
/// sum over every particle).
const EROSION_COLUMNS: [&str; 2] = ["eroded_mass", "eroded_energy"];

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
            out: out.to_path_buf(),
            history: HistoryWriter::create(
                &out.join("history.csv"),
                D,
                n_bodies,
                if model.removes_particles() {
                    &EROSION_COLUMNS
                } else {
                    &[]
                },
            )?,
            history_times: Schedule::interval(cfg.output.history_interval),
            last_history: f64::NAN,
            dumps: ParticleDumps::create(out, &cfg.output, end_time)?,
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
            contact: match &model.contact {
                Some(_) => Some(ContactLog::create(&out.join("contact.csv"), D)?),
                None => None,
            },
        })
    }

    /// The recorders of a run resumed from a checkpoint's `saved` state, writing
    /// into `out`. Frames named in the state are copied from `from` (the
    /// checkpoint's directory) when `out` is another directory and they are there.
    pub fn resume<const D: usize>(
        out: &Path,
        from: &Path,
        cfg: &SceneConfig,
        model: &Model<D>,
        saved: RecorderState,
    ) -> io::Result<Self> {
        let mut r = Self::create(out, cfg, model)?;
        // The fresh files' headers reach the disk now, not when they are dropped
        // under the resumed writers.
        r.history.flush()?;
        if let Some(csv) = &mut r.newton {
            csv.flush()?;
        }
        let n_bodies = r.n_bodies;
        let extra = if model.removes_particles() {
            EROSION_COLUMNS.len()
        } else {
            0
        };
        r.history = HistoryWriter::resume(
            &out.join("history.csv"),
            D,
            n_bodies,
            extra,
            &saved.history_csv,
        )?;
        r.history_times.resume_at(saved.next_history);
        r.last_history = saved.last_history.unwrap_or(f64::NAN);
        r.next_frame = saved.next_frame;
        r.last_frame = saved.last_frame.unwrap_or(f64::NAN);
        if !same_directory(out, from) {
            for (_, name) in &saved.frames {
                let source = from.join(name);
                if source.exists() {
                    crate::output::atomic::replace(&out.join(name), |tmp| {
                        std::fs::copy(&source, tmp).map(|_| ())
                    })?;
                }
            }
        }
        r.frames = FrameWriter::resume(out, "particles", saved.frames)?;
        if let (Some(dumps), Some(state)) = (&mut r.dumps, &saved.particle_dumps) {
            dumps.resume(state, (!same_directory(out, from)).then_some(from))?;
        }
        if let (Some(_), Some(state)) = (&r.contact, &saved.contact) {
            r.contact = Some(ContactLog::resume(&out.join("contact.csv"), state)?);
        }
        if let (Some(_), Some(text)) = (&r.newton, &saved.newton_csv) {
            r.newton = Some(CsvWriter::resume(&out.join("newton.csv"), text)?);
        }
        if let (Some(_), Some(text)) = (&r.footing, &saved.footing_csv) {
            r.footing = Some(FootingCurve::resume(
                &out.join("footing.csv"),
                text,
                saved.footing_rows,
                saved.footing_settlement,
            )?);
        }
        Ok(r)
    }

    /// The state to save in a checkpoint (the streamed files are flushed and
    /// read back).
    pub fn saved(&mut self) -> io::Result<RecorderState> {
        self.history.flush()?;
        let read = |name: &str| std::fs::read_to_string(self.out.join(name));
        let newton_csv = match &mut self.newton {
            Some(csv) => {
                csv.flush()?;
                Some(read("newton.csv")?)
            }
            None => None,
        };
        let (footing_csv, footing_rows, footing_settlement) = match &self.footing {
            Some(curve) => {
                let (rows, settlement) = curve.state();
                (Some(read("footing.csv")?), rows.to_vec(), settlement)
            }
            None => (None, Vec::new(), 0.0),
        };
        let contact = match &mut self.contact {
            Some(log) => Some(log.saved(&self.out.join("contact.csv"))?),
            None => None,
        };
        let particle_dumps = match &mut self.dumps {
            Some(dumps) => Some(dumps.saved()?),
            None => None,
        };
        Ok(RecorderState {
            history_csv: read("history.csv")?,
            next_history: self.history_times.next_time().unwrap_or(0.0),
            last_history: Some(self.last_history).filter(|t| !t.is_nan()),
            frames: self.frames.frames().to_vec(),
            next_frame: self.next_frame,
            last_frame: Some(self.last_frame).filter(|t| !t.is_nan()),
            newton_csv,
            footing_csv,
            footing_rows,
            footing_settlement,
            contact,
            particle_dumps,
        })
    }

    /// The records of the state `now`, the next step taking `next_dt` (none at
    /// the run's start and end): a history row and a particle file when it is
    /// the state nearest one of their output times (`run::schedule`; a history
    /// row also when `force`d, at the start and the end), a frame at the first
    /// state at or after its time; never twice at the same time.
    pub fn state<const D: usize>(
        &mut self,
        now: &Moment<D>,
        next_dt: Option<f64>,
        force: bool,
    ) -> io::Result<()> {
        let (m, t) = (now.model, now.t);
        let tolerance = 1e-12 * self.end_time;
        let due = self.history_times.take(t, next_dt, tolerance);
        if (force || due) && t != self.last_history {
            self.last_history = t;
            let (com, vcom) = body_centres(&m.particles, self.n_bodies);
            let (kinetic, strain) = (kinetic_energy(m), strain_energy(m));
            let eroded = m.removes_particles().then(|| m.removed_mass_and_energy());
            let extra: Vec<f64> = eroded.map_or(vec![], |(mass, energy)| vec![mass, energy]);
            self.history
                .write_row(t, kinetic, strain, now.external_work, &extra, &com, &vcom)?;
            if let Some(log) = &mut self.contact {
                log.rows(t)?;
            }
        }
        if let Some(dumps) = &mut self.dumps {
            dumps.at(m, t, now.step, next_dt, tolerance)?;
        }
        let Some(interval) = self.frame_interval else {
            return Ok(());
        };
        if (force || t >= self.next_frame - tolerance) && t != self.last_frame {
            self.last_frame = t;
            let fields = m.point_fields();
            let extra: Vec<(&str, &[f64])> =
                (fields.iter()).map(|(n, v)| (*n, v.as_slice())).collect();
            self.frames.write_frame(t, &m.output_particles(), &extra)?;
            while self.next_frame <= t + tolerance {
                self.next_frame += interval;
            }
        }
        Ok(())
    }

    /// What contact did in the last step (rows follow with history.csv's).
    pub fn contact<const D: usize>(&mut self, totals: &[PairTotal<D>]) {
        if let Some(log) = &mut self.contact {
            log.after_step(totals);
        }
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

    /// The directory the files are written into.
    pub fn directory(&self) -> &Path {
        &self.out
    }

    /// The footing's limit pressure and its neighbours, for summary.json.
    pub fn footing_summary<const D: usize>(&self, m: &Model<D>) -> Option<FootingSummary> {
        let f = m.footing.as_ref()?;
        self.footing.as_ref()?.summary(f.cohesion)
    }
}

/// Whether two paths name the same directory.
fn same_directory(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}
