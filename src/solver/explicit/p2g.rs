//! What a particle gives the nodes in the box scatter's P2G
//! (`solver::explicit::scatter`), formed once per particle: its mass m S_I
//! (2-24), momentum m v S_I (2-25) and force S_I (m g + s f) − V σ ∇S_I (2-51,
//! 2-52, `physics::transfer::force_at_node`, the rule the node map's
//! `physics::transfer::nodal_force` applies too), and in axisymmetric mode the
//! hoop part − V σ_θθ S_I / r_p of the radial force (`physics::shape::hoop`).

use crate::dim::{restrict, Tensor, Vector};
use crate::model::particles::Particles;
use crate::physics::transfer::force_at_node;

/// What particle q gives the nodes, formed once per P2G.
#[derive(Clone, Copy, Debug)]
pub struct Source<const D: usize> {
    pub mass: f64,
    /// m v.
    pub momentum: Vector<D>,
    /// m g + s f (`Step::applied`).
    pub applied: Vector<D>,
    /// V σ, the in-plane block of the total Cauchy stress σ′ − p I times the
    /// current volume.
    pub stress: Tensor<D>,
}

impl<const D: usize> Source<D> {
    /// Particle q's source, with the applied force `applied`.
    #[inline(always)]
    pub fn of(p: &Particles<D>, q: usize, applied: Vector<D>) -> Self {
        Source {
            mass: p.mass[q],
            momentum: p.v[q] * p.mass[q],
            applied,
            stress: restrict::<D>(&p.stored_total_stress(q)) * p.volume[q],
        }
    }

    /// The force on a node of weight S_I = `w` and gradient ∇S_I = `g`:
    /// S_I (m g + s f) − V σ ∇S_I (2-51, 2-52), V σ formed here once (so V = 1
    /// in the shared rule).
    #[inline(always)]
    pub fn force_at(&self, w: f64, g: &Vector<D>) -> Vector<D> {
        force_at_node(&self.applied, w, &self.stress, g, 1.0)
    }
}

/// Axisymmetric mode: V σ_θθ / r_p of particle q, whose product with S_I the
/// radial force of node I loses (the hoop term of the virtual work).
#[inline(always)]
pub fn hoop_stress<const D: usize>(p: &Particles<D>, q: usize) -> f64 {
    p.stored_total_stress(q)[(2, 2)] * p.volume[q] / p.x[q][0]
}
