//! A run that stops early says what happened where: the step, the time and,
//! where there is one, the particle.

use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use rayon::prelude::*;

/// Why a run stopped early.
#[derive(Clone, Debug)]
pub struct Divergence {
    pub step: usize,
    pub time: f64,
    /// The offending particle, when there is one (not for a Newton failure).
    pub particle: Option<usize>,
    pub message: String,
}

impl std::fmt::Display for Divergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "diverged at step {} (t = {:.6e}): ",
            self.step, self.time
        )?;
        if let Some(q) = self.particle {
            write!(f, "particle {q} ")?;
        }
        write!(f, "{}", self.message)
    }
}

/// Stop on non-finite state or particles outside the grid (first offender).
pub fn check_state<const D: usize>(m: &Model<D>, step: usize, time: f64) -> Result<(), Divergence> {
    let p = &m.particles;
    let bad = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .find_first(|&q| {
            !(p.x[q].iter().all(|v| v.is_finite())
                && p.v[q].iter().all(|v| v.is_finite())
                && p.stress[q].iter().all(|v| v.is_finite())
                && m.grid.contains(&p.x[q]))
        });
    match bad {
        None => Ok(()),
        Some(q) => {
            let finite = p.x[q]
                .iter()
                .chain(p.v[q].iter())
                .chain(p.stress[q].iter())
                .all(|v| v.is_finite());
            let message = if finite {
                format!(
                    "(body {}) left the grid: x = {:?}",
                    p.body[q],
                    p.x[q].as_slice()
                )
            } else {
                format!(
                    "(body {}) has a non-finite state: x = {:?}, v = {:?}",
                    p.body[q],
                    p.x[q].as_slice(),
                    p.v[q].as_slice()
                )
            };
            Err(Divergence {
                step,
                time,
                particle: Some(q),
                message,
            })
        }
    }
}
