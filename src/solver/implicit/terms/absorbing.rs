//! Absorbing faces in the implicit step (thesis 2-63, docs/absorbing.md): the
//! dashpots and springs of the layer particles at each absorbing face,
//!
//!   r −= f_abs(u),   f_abs = −Σ_p S_Ip (C_p v_p(u) + K_p u_p(u)),
//!
//! plus an incoming wave's 2 C_p v_in at the end of the step (a compliant
//! base, constant in u), with the end-of-step velocity v(u) = v* + rate · u of Newmark (none when
//! quasi-static: the springs alone) and u_p the displacement at the end of the
//! step (`physics::boundary::absorbing::AbsorbingStep`); the tangent is
//! Σ_p S_Ip S_Jp (rate C_p + K_p) (`assembly::absorbing`), symmetric. Linear in
//! u: nothing is kept between residuals.

use super::{StepStart, StepTerm, StepView};
use crate::dim::Vector;
use crate::model::Model;
use crate::physics::boundary::absorbing::{self, AbsorbingStep};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::implicit::assembly::absorbing::add_absorbing;
use crate::solver::implicit::assembly::stiffness::ParticleTangents;
use crate::solver::implicit::assembly::Tangent;

/// The absorbing faces of a scene, and their layer in the current step.
#[derive(Clone, Debug, Default)]
pub struct AbsorbingFaces<const D: usize> {
    step: AbsorbingStep<D>,
}

impl<const D: usize> AbsorbingFaces<D> {
    /// The faces of model m, or None without any.
    pub fn new(m: &Model<D>) -> Option<Self> {
        (!m.absorbing.is_empty()).then(Self::default)
    }
}

impl<const D: usize> StepTerm<D> for AbsorbingFaces<D> {
    fn name(&self) -> &'static str {
        "absorbing faces"
    }

    fn cloned(&self) -> Box<dyn StepTerm<D>> {
        Box::new(self.clone())
    }

    /// The faces' forces at the initial velocities v and time t.
    fn add_initial_force(
        &self,
        m: &Model<D>,
        st: &Stencils<D>,
        map: &NodeMap,
        v: &[Vector<D>],
        t: f64,
        force: &mut [Vector<D>],
    ) {
        absorbing::add_force(&m.absorbing, &m.grid, &m.particles, map, st, v, t, force);
    }

    /// The layer particles at the step start, and their velocity as a function
    /// of u through Newmark (none when quasi-static).
    fn begin_step(&mut self, step: &StepView<'_, D>, start: &StepStart<'_, D>) {
        let m = step.m;
        // The incoming waves at the end of the step, as the applied loads.
        let t_end = step.t + step.dt;
        let layer = absorbing::layer(&m.absorbing, &m.grid, &m.particles, t_end);
        if layer.is_empty() {
            self.step = AbsorbingStep::default();
            return;
        }
        let n = start.a_n.len();
        let (velocity_offset, rate) = match start.newmark {
            Some(nm) => (
                (0..n)
                    .map(|a| {
                        let (u_tilde, a_n) = (&start.u_tilde[a], &start.a_n[a]);
                        nm.end_velocity(step.dt, &Vector::<D>::zeros(), u_tilde, a_n)
                    })
                    .collect(),
                nm.velocity_rate(step.dt),
            ),
            None => (vec![Vector::<D>::zeros(); n], 0.0),
        };
        self.step = AbsorbingStep {
            layer,
            velocity_offset,
            rate,
        };
    }

    /// − f_abs(u): dashpots through v(u), springs through u_p(u) (2-63).
    fn probe(&self, step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        let p = &step.m.particles;
        self.step.add_residual(step.map, step.stencils, p, u, r);
    }

    /// Σ_p S_Ip S_Jp (rate C_p + K_p), symmetric.
    fn add_tangent(&self, step: &StepView<'_, D>, _a: &ParticleTangents<D>, k: &mut Tangent) {
        add_absorbing(k, &self.step, step.map, step.stencils, step.dofs);
    }
}
