//! A run that stops early says what happened where: the step, the time and,
//! where there is one, the particle.

use crate::dim::{Mat3, Vector};
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

/// Stop on non-finite state, an inverted or collapsed particle (det F ≤ 0),
/// particles outside the grid or, axisymmetric, on or across the axis (first
/// offender).
pub fn check_state<const D: usize>(m: &Model<D>, step: usize, time: f64) -> Result<(), Divergence> {
    let p = &m.particles;
    let bad = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .find_first(|&q| {
            let inside = m.grid.contains(&p.x[q]) || m.remove_outside;
            let off_axis = !m.axisymmetric || p.x[q][0] > 0.0;
            !sound(
                &p.x[q],
                &p.v[q],
                &p.stress.get(q),
                p.f.get(q).determinant(),
                inside && off_axis,
            )
        });
    match bad {
        None => Ok(()),
        Some(q) => Err(unsound(m, q, step, time)),
    }
}

/// Particle q's deformation inverted in the stress update (det F ≤ 0).
pub fn inverted(q: usize, det: f64, step: usize, time: f64) -> Divergence {
    Divergence {
        step,
        time,
        particle: Some(q),
        message: format!("inverted: det F = {det:.3e} ≤ 0"),
    }
}

/// A particle state a run can go on from: finite, det F > 0, and `placed`
/// (in the grid, off the axis, as the mode requires).
#[inline(always)]
pub fn sound<const D: usize>(
    x: &Vector<D>,
    v: &Vector<D>,
    stress: &Mat3,
    det_f: f64,
    placed: bool,
) -> bool {
    x.iter().all(|v| v.is_finite())
        && v.iter().all(|v| v.is_finite())
        && stress.iter().all(|v| v.is_finite())
        && det_f > 0.0
        && placed
}

/// What went wrong with particle q, which is not `sound`.
pub fn unsound<const D: usize>(m: &Model<D>, q: usize, step: usize, time: f64) -> Divergence {
    let p = &m.particles;
    let finite = p.x[q]
        .iter()
        .chain(p.v[q].iter())
        .chain(p.stress.get(q).iter())
        .all(|v| v.is_finite());
    let det = p.f.get(q).determinant();
    let message = if finite && m.axisymmetric && p.x[q][0] <= 0.0 {
        format!(
            "(body {}) reached the axis: r = {:e} (axisymmetric mode)",
            p.body[q], p.x[q][0]
        )
    } else if finite && (det.is_nan() || det <= 0.0) {
        format!(
            "(body {}) is inverted or collapsed: det F = {det:e}",
            p.body[q]
        )
    } else if finite {
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
    Divergence {
        step,
        time,
        particle: Some(q),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::BLOCK;
    use crate::scene::Scene;

    #[test]
    fn a_collapsed_or_inverted_particle_stops_the_run() {
        let scene = Scene::parse("block.toml", BLOCK, &[]).unwrap();
        let mut m = Model::<2>::build(&scene).unwrap();
        assert!(check_state(&m, 0, 0.0).is_ok());
        for f in [
            Mat3::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
            -Mat3::identity(),
        ] {
            m.particles.f.set(2, &f);
            let d = check_state(&m, 5, 0.5).unwrap_err();
            assert_eq!((d.step, d.particle), (5, Some(2)));
            assert!(d.message.contains("inverted or collapsed"), "{d}");
        }
    }
}
