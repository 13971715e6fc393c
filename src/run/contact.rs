//! contact.csv: what contact between bodies did (`crate::physics::contact`), one
//! row per pair of velocity fields at every history.csv row: the mean contact force
//! on the pair's first field since the previous row (impulse over elapsed time), the
//! nodes in contact in the last step, and the energy friction has dissipated since
//! the start.

use crate::output::{CsvWriter, Field};
use crate::physics::contact::PairTotal;
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

/// The totals gathered since the last row, for a checkpoint.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ContactState {
    pub csv: String,
    /// Per pair: impulse components, then the dissipation since the start.
    pub pending: Vec<Vec<f64>>,
    pub nodes: Vec<usize>,
    pub since: f64,
}

/// contact.csv as it grows.
pub struct ContactLog {
    csv: CsvWriter,
    /// Per pair: its bodies, the impulse since the last row, the dissipation so far
    /// and the nodes in contact in the last step.
    pairs: Vec<([u32; 2], Vec<f64>, f64, usize)>,
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
                .map(|t| (t.bodies, vec![0.0; D], 0.0, 0))
                .collect();
        }
        for (pair, t) in self.pairs.iter_mut().zip(totals) {
            for d in 0..D {
                pair.1[d] += t.impulse[d];
            }
            pair.2 += t.dissipation;
            pair.3 = t.nodes;
        }
    }

    /// The rows at time t (none at the start, when no time has passed).
    pub fn rows(&mut self, t: f64) -> io::Result<()> {
        let elapsed = t - self.since;
        if elapsed <= 0.0 {
            return Ok(());
        }
        for (bodies, impulse, dissipation, nodes) in &mut self.pairs {
            let mut row: Vec<Field> = vec![
                t.into(),
                bodies[0].into(),
                bodies[1].into(),
                (*nodes).into(),
            ];
            row.extend(impulse.iter().map(|i| Field::from(i / elapsed)));
            row.push((*dissipation).into());
            self.csv.row(row)?;
            impulse.iter_mut().for_each(|i| *i = 0.0);
        }
        self.since = t;
        self.csv.flush()
    }

    /// The state for a checkpoint (the file as written, read back from `path`).
    pub fn saved(&mut self, path: &Path) -> io::Result<ContactState> {
        self.csv.flush()?;
        Ok(ContactState {
            csv: std::fs::read_to_string(path)?,
            pending: (self.pairs.iter())
                .map(|(b, i, d, _)| {
                    let mut v = vec![b[0] as f64, b[1] as f64];
                    v.extend(i);
                    v.push(*d);
                    v
                })
                .collect(),
            nodes: self.pairs.iter().map(|p| p.3).collect(),
            since: self.since,
        })
    }

    /// contact.csv of a checkpoint, written on.
    pub fn resume(path: &Path, dim: usize, saved: &ContactState) -> io::Result<Self> {
        let mut csv = CsvWriter::resume(path, &saved.csv)?;
        csv.flush()?;
        let pairs = (saved.pending.iter().zip(&saved.nodes))
            .map(|(v, &n)| {
                (
                    [v[0] as u32, v[1] as u32],
                    v[2..2 + dim].to_vec(),
                    v[2 + dim],
                    n,
                )
            })
            .collect();
        Ok(ContactLog {
            csv,
            pairs,
            since: saved.since,
        })
    }
}
