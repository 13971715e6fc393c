//! A rigid footing: a velocity condition on a region of a grid face with a
//! `footing_width`. Its load is the reaction on the nodes it drives; the pressure
//! is that load over the width (unit thickness in 2D). The run writes the
//! load–settlement curve to footing.csv and the limit pressure to summary.json.

use serde_json::json;
use std::io::Write;

/// The load–settlement curve, written to footing.csv as it grows.
pub struct FootingCurve {
    /// (time, settlement, load, pressure).
    rows: Vec<[f64; 4]>,
    csv: std::io::BufWriter<std::fs::File>,
}

pub const FOOTING_CSV_HEADER: &str = "t,settlement,load,pressure";

impl FootingCurve {
    pub fn create(path: &std::path::Path) -> std::io::Result<Self> {
        let mut csv = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(csv, "{FOOTING_CSV_HEADER}")?;
        Ok(FootingCurve {
            rows: Vec::new(),
            csv,
        })
    }

    pub fn push(&mut self, t: f64, settlement: f64, load: f64, width: f64) -> std::io::Result<()> {
        let row = [t, settlement, load, load / width];
        writeln!(self.csv, "{},{},{},{}", row[0], row[1], row[2], row[3])?;
        self.csv.flush()?;
        self.rows.push(row);
        Ok(())
    }

    /// summary.json fields: the limit pressure is the pressure at the end of the
    /// run (the plateau, if the run went far enough: `plateau_change` is the
    /// relative rise of the pressure over the last tenth of the settlement).
    pub fn summary(&self, cohesion: Option<f64>) -> serde_json::Value {
        let Some(last) = self.rows.last() else {
            return json!({});
        };
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
        let mut s = json!({
            "limit_pressure": limit,
            "peak_pressure": peak,
            "settlement": last[1],
            "plateau_change": (limit - at_90) / limit,
        });
        if let Some(c) = cohesion.filter(|c| *c > 0.0) {
            s["bearing_capacity_factor"] = json!(limit / c);
        }
        s
    }
}
