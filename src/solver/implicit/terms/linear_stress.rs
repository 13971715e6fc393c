//! The linear domain stress in the implicit step (`[grid] domain_stress =
//! "linear"`, `super::super::stress_gradient`): a stress linear within each
//! particle domain adds Σ_p V_p Σ_k ∂_kP_p M_Ip,k to the internal force, with
//! the gradients the least-squares fit of the neighbours' stresses in the
//! step-start configuration; its tangent couples each particle to the nodes of
//! its neighbours' stencils (`assembly::linear_stress`), unsymmetric. The
//! particles then move with the mean of u at their domains' corners.

use super::{Couplings, StepStart, StepTerm, StepView};
use crate::dim::{Mat3, Vector};
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::{domain_corner_mean, ShapeFunction};
use crate::physics::transfer::interpolate;
use crate::solver::implicit::assembly::linear_stress::add_linear_stress_stiffness;
use crate::solver::implicit::assembly::stiffness::ParticleTangents;
use crate::solver::implicit::assembly::Tangent;
use crate::solver::implicit::stress_gradient::LinearStress;
use rayon::prelude::*;

/// The linear domain stress of the current step's start configuration.
#[derive(Clone, Debug)]
pub struct LinearDomainStress<const D: usize> {
    shape: ShapeFunction,
    linear: LinearStress<D>,
}

impl<const D: usize> LinearDomainStress<D> {
    /// The linear domain stress of model m, or None unless it asks for one.
    pub fn new(m: &Model<D>) -> Option<Self> {
        m.linear_domain_stress.then(|| LinearDomainStress {
            shape: ShapeFunction::Linear,
            linear: LinearStress::default(),
        })
    }
}

impl<const D: usize> StepTerm<D> for LinearDomainStress<D> {
    fn name(&self) -> &'static str {
        "linear domain stress"
    }

    fn cloned(&self) -> Box<dyn StepTerm<D>> {
        Box::new(self.clone())
    }

    /// The least-squares fit and the stencils' gradient moments at the step
    /// start.
    fn begin_step(&mut self, step: &StepView<'_, D>, start: &StepStart<'_, D>) {
        let m = step.m;
        self.shape = start.shape;
        self.linear = LinearStress::new(start.shape, &m.grid, &m.particles, step.stencils);
    }

    /// Each particle to the nodes of its neighbours' stencils.
    fn couplings(&self) -> Couplings<'_, D> {
        Couplings {
            node_pairs: Vec::new(),
            neighbours: Some(&self.linear.fit),
        }
    }

    /// f_I += Σ_p V_p Σ_k ∂_kP_p M_Ip,k.
    fn add_internal_force(&self, step: &StepView<'_, D>, pk1: &[Mat3], f_int: &mut [Vector<D>]) {
        let volume = &step.m.particles.volume;
        let f_linear = self.linear.force(step.map, step.stencils, volume, pk1);
        f_int.iter_mut().zip(f_linear).for_each(|(f, g)| *f += g);
    }

    /// Its residual is part of the internal force (`add_internal_force`).
    fn probe(&self, _step: &StepView<'_, D>, _u: &[Vector<D>], _r: &mut [Vector<D>]) {}

    fn add_tangent(&self, step: &StepView<'_, D>, a: &ParticleTangents<D>, k: &mut Tangent) {
        let (pattern, volume) = (k.pattern, &step.m.particles.volume);
        let (map, st, dofs) = (step.map, step.stencils, step.dofs);
        add_linear_stress_stiffness(k, pattern, map, st, dofs, volume, a, &self.linear);
    }

    /// Unsymmetric: a particle's stress gradient takes its neighbours' stresses.
    fn symmetric(&self) -> bool {
        false
    }

    /// The mean of u at the corners of the step-start domain, as CPDI moves
    /// its particles, so that the domains keep tiling the body (the domain
    /// average moves a domain's centre by δ²u''/24 off its corners' mean,
    /// which opens gaps and overlaps of O(h²) at the faces; docs/accuracy.md).
    /// A particle off the grid moves by Σ_I S_Ip u_I (zero).
    fn particle_displacements(
        &self,
        step: &StepView<'_, D>,
        u: &[Vector<D>],
    ) -> Option<Vec<Vector<D>>> {
        let (m, map, st) = (step.m, step.map, step.stencils);
        let p = &m.particles;
        let moved = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| match st.count[q] > 0 {
                false => interpolate(map, st, q, u),
                true => {
                    let value = |n: u32| u[map.local[n as usize] as usize];
                    let (x, half, f) = (&p.x[q], &p.half_length0[q], &p.f.get(q));
                    domain_corner_mean(self.shape, &m.grid, x, half, f, value)
                        .expect("a linear domain stress on a box domain")
                }
            })
            .collect();
        Some(moved)
    }
}
