//! A particle file (`shape = "particles"`): CSV with a header row naming the
//! columns, one particle per row, as users bring from their own generators
//! (and as `particles_final.csv` is written, so a run's particles read back).
//!
//! | columns | needed | meaning |
//! |---|---|---|
//! | `x`, `y`[, `z`] | yes | position |
//! | `volume` | yes | volume (> 0): area × unit thickness in 2D, per radian in an axisymmetric model |
//! | `material` | no | the name of a `[[material]]` table (a material zone); empty: the body's |
//! | `body` | with `body_id` | the rows of this body are those whose `body` is the key's number |
//! | `vx`, `vy`[, `vz`] | no, all or none | initial velocity |
//! | `sxx`, `syy`, `szz`, `sxy`[, `syz`, `sxz`] | no, all or none | initial Cauchy stress, tension positive |
//!
//! Other columns are read past. Lines starting with `#` are comments; fields
//! are trimmed. Every error names the file, its line and the column.

use crate::dim::Mat3;
use crate::model::particle_set::{FileParticle, ParticleSet};
use std::path::Path;

/// What a particle file is read against: the model's dimension, the grid its
/// particles must lie in, the body's `body_id`, and how a `material` name
/// becomes a table index (or why it cannot).
pub struct Expect<'a> {
    pub dim: usize,
    pub per_radian: bool,
    pub grid: (&'a [f64], &'a [f64]),
    pub body_id: Option<u32>,
    pub material: &'a dyn Fn(&str) -> Result<u32, String>,
}

const AXES: [&str; 3] = ["x", "y", "z"];
const VELOCITY: [&str; 3] = ["vx", "vy", "vz"];
/// Stress columns: name, row, column of σ.
const STRESS: [(&str, usize, usize); 6] = [
    ("sxx", 0, 0),
    ("syy", 1, 1),
    ("szz", 2, 2),
    ("sxy", 0, 1),
    ("syz", 1, 2),
    ("sxz", 0, 2),
];

/// The indices of the columns the file has.
struct Layout {
    position: Vec<usize>,
    volume: usize,
    material: Option<usize>,
    body: Option<usize>,
    velocity: Option<Vec<usize>>,
    stress: Option<Vec<usize>>,
}

/// Read the particles of `path` (`shown` names it in messages).
pub fn read(path: &Path, shown: &str, e: &Expect) -> Result<ParticleSet, String> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|err| format!("cannot read the particle file {shown}: {err}"))?;
    let header = reader
        .headers()
        .map_err(|err| format!("{shown}: {err}"))?
        .clone();
    let layout = layout(&header, shown, e)?;
    let mut particles = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|err| format!("{shown}: {err}"))?;
        let line = record.position().map_or(0, |p| p.line());
        let row = Row {
            record: &record,
            header: &header,
            shown,
            line,
        };
        if let (Some(id), Some(k)) = (e.body_id, layout.body) {
            if row.integer(k)? != u64::from(id) {
                continue;
            }
        }
        particles.push(row.particle(&layout, e)?);
    }
    if particles.is_empty() {
        let which = e
            .body_id
            .map_or(String::new(), |id| format!(" with body = {id}"));
        return Err(format!("{shown}: the file holds no particle row{which}"));
    }
    Ok(ParticleSet {
        dim: e.dim,
        particles,
        per_radian: e.per_radian,
    })
}

/// Where the columns are; a missing one that is needed, or part of a group,
/// is named.
fn layout(header: &csv::StringRecord, shown: &str, e: &Expect) -> Result<Layout, String> {
    let find = |name: &str| header.iter().position(|h| h == name);
    let columns = || header.iter().collect::<Vec<_>>().join(", ");
    let need = |name: &str, why: &str| {
        find(name).ok_or_else(|| {
            format!(
                "{shown}:1: no column `{name}` ({why}); the header names: {}",
                columns()
            )
        })
    };
    let position = (AXES[..e.dim].iter())
        .map(|a| need(a, "the particles' positions"))
        .collect::<Result<_, _>>()?;
    let volume = need("volume", "the particles' volumes")?;
    let body = match e.body_id {
        Some(_) => Some(need("body", "the key `body_id` selects rows by it")?),
        None => None,
    };
    let stress_names: Vec<&str> = (STRESS.iter())
        .take(if e.dim == 3 { 6 } else { 4 })
        .map(|s| s.0)
        .collect();
    Ok(Layout {
        position,
        volume,
        material: find("material"),
        body,
        velocity: group(&VELOCITY[..e.dim], &find, &need, "velocity")?,
        stress: group(&stress_names, &find, &need, "stress")?,
    })
}

/// The columns of a group given all or none: none, or each one's index.
fn group(
    names: &[&str],
    find: &dyn Fn(&str) -> Option<usize>,
    need: &dyn Fn(&str, &str) -> Result<usize, String>,
    what: &str,
) -> Result<Option<Vec<usize>>, String> {
    if names.iter().all(|n| find(n).is_none()) {
        return Ok(None);
    }
    let why = format!("an initial {what} needs all of {}", names.join(", "));
    names
        .iter()
        .map(|n| need(n, &why))
        .collect::<Result<_, _>>()
        .map(Some)
}

/// One record, with what its messages name.
struct Row<'a> {
    record: &'a csv::StringRecord,
    header: &'a csv::StringRecord,
    shown: &'a str,
    line: u64,
}

impl Row<'_> {
    fn error(&self, k: usize, msg: impl std::fmt::Display) -> String {
        let name = self.header.get(k).unwrap_or("?");
        format!("{}:{}: column `{name}`: {msg}", self.shown, self.line)
    }

    fn text(&self, k: usize) -> Result<&str, String> {
        self.record
            .get(k)
            .ok_or_else(|| self.error(k, "the row has no such field"))
    }

    fn number(&self, k: usize) -> Result<f64, String> {
        let t = self.text(k)?;
        match t.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.error(k, format!("`{t}` is not a finite number"))),
        }
    }

    fn integer(&self, k: usize) -> Result<u64, String> {
        let t = self.text(k)?;
        t.parse::<u64>()
            .map_err(|_| self.error(k, format!("`{t}` is not a body number (0, 1, …)")))
    }

    fn particle(&self, l: &Layout, e: &Expect) -> Result<FileParticle, String> {
        let mut x = [0.0; 3];
        for (d, &k) in l.position.iter().enumerate() {
            x[d] = self.number(k)?;
            let (lo, hi) = (e.grid.0[d], e.grid.1[d]);
            if !(x[d] >= lo && x[d] < hi) {
                let msg = format!("{} lies outside the grid [{lo}, {hi})", x[d]);
                return Err(self.error(k, msg));
            }
        }
        if e.per_radian && x[0] <= 0.0 {
            return Err(self.error(l.position[0], "an axisymmetric particle needs r = x > 0"));
        }
        let volume = self.number(l.volume)?;
        if volume <= 0.0 {
            return Err(self.error(l.volume, format!("{volume} is not a positive volume")));
        }
        let material = match l.material.map(|k| (k, self.text(k))) {
            Some((k, name)) if !name.as_ref().is_ok_and(|n| n.is_empty()) => {
                Some((e.material)(name?).map_err(|m| self.error(k, m))?)
            }
            _ => None,
        };
        let velocity = match &l.velocity {
            Some(cols) => {
                let mut v = [0.0; 3];
                for (d, &k) in cols.iter().enumerate() {
                    v[d] = self.number(k)?;
                }
                Some(v)
            }
            None => None,
        };
        let stress = match &l.stress {
            Some(cols) => Some(self.stress(cols)?),
            None => None,
        };
        Ok(FileParticle {
            x,
            volume,
            material,
            stress,
            velocity,
            line: self.line,
        })
    }

    /// The symmetric stress of the stress columns (in `STRESS` order).
    fn stress(&self, cols: &[usize]) -> Result<Mat3, String> {
        let mut s = Mat3::zeros();
        for (&(_, r, c), &k) in STRESS.iter().zip(cols) {
            let value = self.number(k)?;
            s[(r, c)] = value;
            s[(c, r)] = value;
        }
        Ok(s)
    }
}
