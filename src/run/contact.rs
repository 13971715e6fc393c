//! contact.csv: what contact between bodies did (`crate::solver::explicit::contact`), one
//! row per pair of velocity fields at every history.csv row: the mean contact force
//! on the pair's first field since the previous row (impulse over elapsed time), the
//! nodes in contact in the last step, and the energy friction has dissipated since
//! the start.

use crate::output::{CsvWriter, Field};
use crate::physics::contact::totals::PairTotal;
use serde::{Deserialize, Serialize};
use std::io;
use std::path::Path;

/// The columns of contact.csv in dimension `dim`.
pub fn columns(dim: usize) -> Vec<String> {
    let mut c: Vec<String> = ["t", "first", "second", "nodes"].map(String::from).into();
    c.extend(["fx", "fy", "fz"][..dim].iter().map(|s| s.to_string()));
    c.push("dissipation".into());
    c
}

/// One pair of fields between rows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PairSince {
    pub bodies: [u32; 2],
    /// Impulse on the first field since the last row.
    pub impulse: Vec<f64>,
    /// Energy friction dissipated since the start.
    pub dissipation: f64,
    /// Nodes in contact in the last step.
    pub nodes: usize,
}

/// contact.csv as written and the pairs since its last rows, for a checkpoint.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ContactState {
    pub csv: String,
    pub pairs: Vec<PairSince>,
    pub since: f64,
}

/// contact.csv as it grows.
pub struct ContactLog {
    csv: CsvWriter,
    pairs: Vec<PairSince>,
    /// Time of the last row.
    since: f64,
}

impl ContactLog {
    pub fn create(path: &Path, dim: usize) -> io::Result<Self> {
        Ok(ContactLog {
            csv: CsvWriter::create(path, &columns(dim))?,
            pairs: Vec::new(),
            since: 0.0,
        })
    }

    /// Add what contact did in a step.
    pub fn after_step<const D: usize>(&mut self, totals: &[PairTotal<D>]) {
        if self.pairs.is_empty() {
            self.pairs = totals
                .iter()
                .map(|t| PairSince {
                    bodies: t.bodies,
                    impulse: vec![0.0; D],
                    dissipation: 0.0,
                    nodes: 0,
                })
                .collect();
        }
        for (pair, t) in self.pairs.iter_mut().zip(totals) {
            for d in 0..D {
                pair.impulse[d] += t.impulse[d];
            }
            pair.dissipation += t.dissipation;
            pair.nodes = t.nodes;
        }
    }

    /// The rows at time t (none at the start, when no time has passed, nor when
    /// only round-off has: a run's last step may end at 0.9999999999999999 and
    /// its final row come at 1, with no impulse between them).
    pub fn rows(&mut self, t: f64) -> io::Result<()> {
        let elapsed = t - self.since;
        if elapsed <= 1e-12 * t.abs() {
            return Ok(());
        }
        for pair in &mut self.pairs {
            let mut row: Vec<Field> = vec![
                t.into(),
                pair.bodies[0].into(),
                pair.bodies[1].into(),
                pair.nodes.into(),
            ];
            row.extend(pair.impulse.iter().map(|i| Field::from(i / elapsed)));
            row.push(pair.dissipation.into());
            self.csv.row(row)?;
            pair.impulse.iter_mut().for_each(|i| *i = 0.0);
        }
        self.since = t;
        self.csv.flush()
    }

    /// The state for a checkpoint (the file as written, read back from `path`).
    pub fn saved(&mut self, path: &Path) -> io::Result<ContactState> {
        self.csv.flush()?;
        Ok(ContactState {
            csv: std::fs::read_to_string(path)?,
            pairs: self.pairs.clone(),
            since: self.since,
        })
    }

    /// contact.csv of a checkpoint, written on.
    pub fn resume(path: &Path, saved: &ContactState) -> io::Result<Self> {
        let mut csv = CsvWriter::resume(path, &saved.csv)?;
        csv.flush()?;
        Ok(ContactLog {
            csv,
            pairs: saved.pairs.clone(),
            since: saved.since,
        })
    }
}
