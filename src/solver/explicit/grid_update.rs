//! The rules of the explicit grid update at one node, which every transfer
//! back-end applies (`solver::explicit::step`): the conditions on the
//! step-start velocity, local damping of the nodal force, no acceleration on
//! nodes too light to carry one, and the updated velocity with the friction
//! faces.

use crate::dim::Vector;
use crate::model::conditions::{Constraint, FrictionFace};
use crate::physics::boundary::conditions::friction_contact;

/// Nodes lighter than this fraction of the lightest particle get no acceleration:
/// f_I/m_I is ill-conditioned there (f_I need not vanish with m_I), while the
/// velocity p_I/m_I, a mass-weighted average of particle velocities, is always kept.
pub const TINY_MASS_FRACTION: f64 = 1e-9;

/// Local (non-viscous) damping of a nodal force: f − α |f| sign(v), component by
/// component, with sign(0) = 0.
pub fn local_damping<const D: usize>(f: &Vector<D>, v: &Vector<D>, alpha: f64) -> Vector<D> {
    let sign = |x: f64| {
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    Vector::<D>::from_fn(|d, _| f[d] - alpha * f[d].abs() * sign(v[d]))
}

/// A node's acceleration (2-23, 2-29): the force with local damping `alpha`
/// (the sign of the velocity `v`) over the mass, none on a node not heavier
/// than `tiny`; a prescribed component takes the acceleration that lands the
/// velocity `raw` = p/m on its value after `dt`.
#[allow(clippy::too_many_arguments)]
pub fn acceleration<const D: usize>(
    mass: f64,
    force: &Vector<D>,
    v: &Vector<D>,
    raw: &Vector<D>,
    constraint: &Constraint<D>,
    alpha: f64,
    tiny: f64,
    dt: f64,
) -> Vector<D> {
    let mut acc = if mass > tiny {
        local_damping(force, v, alpha) / mass
    } else {
        Vector::<D>::zeros()
    };
    for d in (0..D).filter(|&d| constraint.fixed[d]) {
        acc[d] = (constraint.value[d] - raw[d]) / dt;
    }
    acc
}

/// A node's velocity `raw` = p/m with its conditions: the prescribed
/// components, then the friction faces `on` (indices into `faces`) it lies on.
#[inline(always)]
pub fn with_conditions<const D: usize>(
    raw: &Vector<D>,
    constraint: &Constraint<D>,
    faces: &[FrictionFace<D>],
    on: &[u8],
) -> Vector<D> {
    let mut v = *raw;
    constraint.apply_velocity(&mut v);
    if !on.is_empty() {
        v = friction_contact(faces, on, constraint, &v);
    }
    v
}

/// A node's updated velocity v = v_raw + Δt a (2-29) and its acceleration:
/// the friction faces `on` act on the updated velocity, and the acceleration
/// follows from what they leave.
#[inline(always)]
pub fn updated_velocity<const D: usize>(
    raw: &Vector<D>,
    acc: &Vector<D>,
    constraint: &Constraint<D>,
    faces: &[FrictionFace<D>],
    on: &[u8],
    dt: f64,
) -> (Vector<D>, Vector<D>) {
    let v = raw + acc * dt;
    match on.is_empty() {
        true => (v, *acc),
        false => {
            let v = friction_contact(faces, on, constraint, &v);
            (v, (v - raw) / dt)
        }
    }
}
