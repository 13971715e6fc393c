//! The residual of one implicit step and its derivative, at the active nodes:
//!
//!   r(u) = M (u − ũ)/(βΔt²) + f_int(u) − f_ext − f_abs(u)   (thesis 2-37)
//!
//! with u the nodal displacement increments, M lumped or consistent (no inertia
//! when quasi-static), f_int the internal force of the relative first
//! Piola-Kirchhoff stress of the trial state at u on the step-start volumes (the
//! stresses always recomputed from the step-start state, `Trial`), f_ext the
//! external force at t + Δt and f_abs the dashpots and springs of absorbing faces
//! (2-63). At the prescribed components r is the reaction. The consistent
//! tangent K = ∂r/∂u (2-40) is assembled over the unknowns from the terms of
//! `assembly`.

use super::assembly::absorbing::add_absorbing;
use super::assembly::fbar::add_fbar_stiffness;
use super::assembly::linear_stress::add_linear_stress_stiffness;
use super::assembly::mass::{add_consistent_mass, add_lumped_mass};
use super::assembly::stiffness::{
    add_stiffness, hoop_symmetric, major_symmetric, particle_tangents, relative_pk1,
    ParticleTangents,
};
use super::assembly::{Pattern, Storage, Tangent};
use super::failure::Failure;
use super::step::StepSystem;
use crate::dim::Vector;
use crate::model::conditions::Constraint;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::transfer::{consistent_mass_product, internal_force};
use crate::scene::MassMatrix;
use crate::solver::linear::direct::Ordering;
use rayon::prelude::*;

/// r(u) at the active nodes; evaluates the particles' trial state at u.
pub fn residual<const D: usize>(
    m: &Model<D>,
    sys: &mut StepSystem<D>,
    u: &[Vector<D>],
) -> Result<Vec<Vector<D>>, Failure> {
    let p = &m.particles;
    let (st, map) = (&sys.stencils, &sys.map);
    if let Some(q) = sys.trial.evaluate(p, &m.materials, st, map, u, sys.dt) {
        return Err(Failure {
            particle: Some(q),
            message: "inverted (det F ≤ 0) in a Newton iterate".into(),
        });
    }
    let pk1: Vec<_> = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| relative_pk1(&sys.trial.df(st, map, q), &sys.trial.stress.get(q)))
        .collect();
    let mut f_int = internal_force(map, st, &p.volume, &pk1);
    // A stress linear within each particle domain (`solver::implicit::stress_gradient`).
    if let Some(linear) = &sys.linear_stress {
        let f_linear = linear.force(map, st, &p.volume, &pk1);
        f_int.iter_mut().zip(f_linear).for_each(|(f, g)| *f += g);
    }
    let w: Vec<Vector<D>> = u.iter().zip(&sys.u_tilde).map(|(a, b)| a - b).collect();
    let f_inertia = inertial_force(p, sys, &w);
    let mut r: Vec<Vector<D>> = (0..u.len())
        .map(|a| f_inertia[a] + f_int[a] - sys.f_ext[a])
        .collect();
    // Absorbing faces: − f_boundary(u), dashpots through v_{n+1}(u) (2-63).
    sys.absorbing.add_residual(map, st, p, u, &mut r);
    // Contact: r_I −= S_Ip f_p with rigid bodies, r_a −= c_a f between the
    // surfaces of deformable bodies (`super::contact`).
    if let Some(contact) = sys.contact.as_mut() {
        contact.evaluate(m, st, map, u);
        contact.add_residual(map, st, &mut r);
    }
    Ok(r)
}

/// M w / (βΔt²) at the active nodes (lumped or consistent M; zero when
/// quasi-static).
pub fn inertial_force<const D: usize>(
    p: &Particles<D>,
    sys: &StepSystem<D>,
    w: &[Vector<D>],
) -> Vec<Vector<D>> {
    let inertia = sys.inertia;
    if inertia == 0.0 {
        return vec![Vector::<D>::zeros(); sys.mass.len()];
    }
    match sys.mass_matrix {
        MassMatrix::Lumped => w
            .iter()
            .zip(&sys.mass)
            .map(|(w, m)| w * (m * inertia))
            .collect(),
        MassMatrix::Consistent => consistent_mass_product(&sys.map, &sys.stencils, p, w, inertia),
    }
}

/// The residual at the prescribed components, r = f_int + inertia − f_ext: the
/// reactions, node by node (zero at free components).
pub fn reactions<const D: usize>(constraint: &[Constraint<D>], r: &[Vector<D>]) -> Vec<Vector<D>> {
    constraint
        .iter()
        .zip(r)
        .map(|(c, ra)| Vector::<D>::from_fn(|d, _| if c.fixed[d] { ra[d] } else { 0.0 }))
        .collect()
}

/// K = ∂r/∂u at the trial state over the unknowns (2-40): the stiffness of the
/// particles (2-41, 2-42; with F-bar if on), the absorbing faces' dashpots and
/// springs, and the inertia; and whether K is symmetric. `numerical` lets
/// materials without an analytic tangent use a numerical one (Krylov
/// preconditioners only).
pub fn tangent<'s, const D: usize>(
    m: &Model<D>,
    sys: &'s StepSystem<D>,
    numerical: bool,
) -> Result<Tangent<'s>, Failure> {
    let p = &m.particles;
    let (st, map, dofs) = (&sys.stencils, &sys.map, &sys.dofs);
    let a = particle_tangents(m, &sys.trial, &sys.stencils, &sys.map, numerical)?;
    let fbar = sys.trial.fbar.as_ref();
    let pattern = step_pattern(sys);
    // Symmetric unless F-bar or a non-associated material breaks it.
    let contact = sys.contact.as_ref();
    let symmetric = fbar.is_none()
        && sys.linear_stress.is_none()
        && contact.is_none_or(|c| c.symmetric())
        && (a.values)
            .par_chunks(ParticleTangents::<D>::LEN)
            .enumerate()
            .all(|(q, a_q)| {
                major_symmetric::<D>(a_q)
                    && (a.hoop.is_empty() || hoop_symmetric::<D>(a.hoop_of(q), a_q))
            });
    let storage = if symmetric {
        Storage::Lower
    } else {
        Storage::Full
    };
    let col_ptr = pattern.col_ptr(storage).map_err(|message| Failure {
        particle: None,
        message,
    })?;
    let mut k = Tangent {
        pattern,
        col_ptr,
        values: vec![0.0; col_ptr[col_ptr.len() - 1] as usize],
        storage,
    };
    match fbar {
        None => add_stiffness(&mut k, pattern, map, st, dofs, &p.volume, &a),
        Some(state) => add_fbar_stiffness(&mut k, pattern, map, st, dofs, &p.volume, state, &a),
    }
    // Absorbing faces: Σ S_I S_J (γ/(βΔt) C + K), symmetric.
    if let Some(linear) = &sys.linear_stress {
        add_linear_stress_stiffness(&mut k, pattern, map, st, dofs, &p.volume, &a, linear);
    }
    add_absorbing(&mut k, &sys.absorbing, pattern, map, st, dofs);
    if let Some(contact) = contact {
        contact.add_tangent(&mut k, pattern, map, st, dofs);
    }
    if sys.inertia > 0.0 {
        match sys.mass_matrix {
            MassMatrix::Lumped => add_lumped_mass::<D>(&mut k, dofs, &sys.mass, sys.inertia),
            MassMatrix::Consistent => {
                add_consistent_mass(&mut k, pattern, map, st, dofs, &p.mass, sys.inertia)
            }
        }
    }
    Ok(k)
}

/// The sparsity pattern of the step's tangent (built at the first call of the
/// step, or kept from the previous step).
pub fn step_pattern<const D: usize>(sys: &StepSystem<D>) -> &Pattern {
    let cells = sys.trial.fbar.as_ref().map(|f| &f.cells);
    let fit = sys.linear_stress.as_ref().map(|l| &l.fit);
    let coupled = (sys.contact.as_ref()).map_or_else(Vec::new, |c| c.coupled_nodes());
    (sys.pattern)
        .get_or_init(|| Pattern::new(&sys.map, &sys.stencils, &sys.dofs, cells, fit, &coupled))
}

/// The fill-reducing ordering for the factorization of the tangent `k` of
/// `sys`: the pattern's ordering of whole nodes when `k` is symmetric (LU
/// orders its columns itself).
pub fn ordering<'s, const D: usize>(sys: &'s StepSystem<D>, k: &Tangent) -> Ordering<'s> {
    match (k.symmetric(), sys.pattern.get()) {
        (true, Some(pattern)) => Ordering::Given(pattern.ordering::<D>(sys.direct_ordering)),
        _ => Ordering::Amd,
    }
}
