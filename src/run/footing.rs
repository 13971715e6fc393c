//! footing.csv: the load–settlement curve of a rigid footing (a velocity condition
//! with a `footing_width`, `model::conditions::Footing`) after every step that
//! computes reactions (implicit steps), and its limit pressure for summary.json.

use crate::dim::Vector;
use crate::model::Model;
use crate::output::{CsvWriter, Field};
use crate::run::summary::FootingSummary;
use std::io;
use std::path::Path;

/// The load–settlement curve, written to footing.csv as it grows.
pub struct FootingCurve {
    /// (time, settlement, load, pressure).
    rows: Vec<[f64; 4]>,
    csv: CsvWriter,
    /// Settlement so far: the footing's speed into the body times the time.
    settlement: f64,
}

impl FootingCurve {
    /// footing.csv with its first point (0, 0, 0, 0).
    pub fn create(path: &Path) -> io::Result<Self> {
        let mut curve = FootingCurve {
            rows: Vec::new(),
            csv: CsvWriter::create(path, &["t", "settlement", "load", "pressure"])?,
            settlement: 0.0,
        };
        curve.push([0.0; 4])?;
        Ok(curve)
    }

    /// Write on after `text`, footing.csv as an earlier run had written it, with
    /// its points `rows` and `settlement` so far (from a checkpoint).
    pub fn resume(
        path: &Path,
        text: &str,
        rows: Vec<[f64; 4]>,
        settlement: f64,
    ) -> io::Result<Self> {
        let mut csv = CsvWriter::resume(path, text)?;
        csv.flush()?;
        Ok(FootingCurve {
            rows,
            csv,
            settlement,
        })
    }

    /// The points so far and the settlement (for a checkpoint).
    pub fn state(&self) -> (&[[f64; 4]], f64) {
        (&self.rows, self.settlement)
    }

    /// Add the point (t, settlement, load, pressure).
    fn push(&mut self, row: [f64; 4]) -> io::Result<()> {
        self.csv.row(row.map(Field::Number))?;
        self.csv.flush()?;
        self.rows.push(row);
        Ok(())
    }

    /// After a step of length dt ending at t: the settlement grows; a point is
    /// added when the step computed reactions.
    pub fn after_step<const D: usize>(
        &mut self,
        m: &Model<D>,
        t: f64,
        dt: f64,
        reaction: Option<&[(u32, Vector<D>)]>,
    ) -> io::Result<()> {
        let Some(f) = &m.footing else {
            return Ok(());
        };
        self.settlement += f.settlement_rate() * dt;
        match reaction {
            Some(r) => {
                let load = f.load(&m.grid, r);
                self.push([t, self.settlement, load, load / f.area()])
            }
            None => Ok(()),
        }
    }

    /// The limit pressure is the pressure at the end of the run (the plateau, if
    /// the run went far enough: `plateau_change` is the relative rise of the
    /// pressure over the last tenth of the settlement).
    pub fn summary(&self, cohesion: Option<f64>) -> Option<FootingSummary> {
        let last = self.rows.last()?;
        let limit = last[3];
        let peak = self
            .rows
            .iter()
            .map(|r| r[3])
            .fold(f64::NEG_INFINITY, f64::max);
        let at_90 = self
            .rows
            .iter()
            .rev()
            .find(|r| r[1] <= 0.9 * last[1])
            .map_or(f64::NAN, |r| r[3]);
        Some(FootingSummary {
            limit_pressure: limit,
            peak_pressure: peak,
            settlement: last[1],
            plateau_change: (limit - at_90) / limit,
            bearing_capacity_factor: cohesion.filter(|c| *c > 0.0).map(|c| limit / c),
        })
    }
}
