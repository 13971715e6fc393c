//! The residual of one implicit step and its derivative, at the active nodes:
//!
//!   r(u) = M (u − ũ)/(βΔt²) + f_int(u) − f_ext + Σ_terms r_term(u)   (thesis 2-37)
//!
//! with u the nodal displacement increments, M lumped or consistent (no inertia
//! when quasi-static), f_int the internal force of the relative first
//! Piola-Kirchhoff stress of the trial state's total stress σ′ − p I at u
//! (`model::water`: p fixed over the step) on the step-start volumes (the
//! stresses always recomputed from the step-start state, `Trial`), f_ext the
//! external force at t + Δt, and the optional terms of the step
//! (`super::terms`: the absorbing faces' dashpots and springs −f_abs(u) (2-63),
//! contact; a linear domain stress is part of f_int). At the prescribed
//! components r is the reaction. The consistent tangent K = ∂r/∂u (2-40) is
//! assembled over the unknowns from the terms of `assembly` and the step's
//! terms.
//!
//! [`residual`] makes u the step's iterate (the trial state and the terms'
//! states are kept there, for the tangent and the commit); [`probe_residual`]
//! evaluates r elsewhere (a difference product) and changes nothing.

use super::assembly::fbar::add_fbar_stiffness;
use super::assembly::mass::{add_consistent_mass, add_lumped_mass};
use super::assembly::stiffness::{
    add_stiffness, hoop_symmetric, major_symmetric, particle_tangents, relative_pk1,
    ParticleTangents,
};
use super::assembly::{Pattern, Storage, Tangent};
use super::failure::Failure;
use super::step::StepSystem;
use crate::dim::{Mat3, Vector};
use crate::model::conditions::Constraint;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::transfer::{consistent_mass_product, internal_force};
use crate::scene::MassMatrix;
use crate::solver::linear::direct::Ordering;
use rayon::prelude::*;

/// r(u) at the active nodes, u made the step's iterate: the particles' trial
/// state and every term's state are evaluated at u and kept.
pub fn residual<const D: usize>(
    m: &Model<D>,
    sys: &mut StepSystem<D>,
    u: &[Vector<D>],
) -> Result<Vec<Vector<D>>, Failure> {
    let p = &m.particles;
    let (st, map) = (&sys.stencils, &sys.map);
    if let Some(q) = sys.trial.evaluate(p, &m.materials, st, map, u, sys.dt) {
        return Err(inverted(q));
    }
    let pk1: Vec<_> = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            let total = p.total_stress(q, &sys.trial.stress.get(q));
            relative_pk1(&sys.trial.df(st, map, q), &total)
        })
        .collect();
    let mut r = material_residual(m, sys, u, &pk1);
    sys.for_each_term(m, |step, t| t.evaluate(step, u, &mut r));
    Ok(r)
}

/// r(u) at a u that is not the iterate (a difference product, 2-39): the
/// trial state and the terms' states stay at the iterate.
pub fn probe_residual<const D: usize>(
    m: &Model<D>,
    sys: &StepSystem<D>,
    u: &[Vector<D>],
) -> Result<Vec<Vector<D>>, Failure> {
    let p = &m.particles;
    let (st, map) = (&sys.stencils, &sys.map);
    let pk1 = (sys.trial)
        .probe(p, &m.materials, st, map, u, sys.dt, |q, df, sigma| {
            relative_pk1(df, &p.total_stress(q, sigma))
        })
        .map_err(inverted)?;
    let mut r = material_residual(m, sys, u, &pk1);
    let step = sys.view(m);
    for t in &sys.terms {
        t.probe(&step, u, &mut r);
    }
    Ok(r)
}

/// The failure of an iterate at which particle q inverts.
fn inverted(q: usize) -> Failure {
    Failure {
        particle: Some(q),
        message: "inverted (det F ≤ 0) in a Newton iterate".into(),
    }
}

/// M (u − ũ)/(βΔt²) + f_int − f_ext from the particles' stress measure `pk1`
/// at u: the residual but the terms' parts outside the internal force.
fn material_residual<const D: usize>(
    m: &Model<D>,
    sys: &StepSystem<D>,
    u: &[Vector<D>],
    pk1: &[Mat3],
) -> Vec<Vector<D>> {
    let p = &m.particles;
    let (st, map) = (&sys.stencils, &sys.map);
    let mut f_int = internal_force(map, st, &p.volume, pk1);
    let step = sys.view(m);
    for t in &sys.terms {
        t.add_internal_force(&step, pk1, &mut f_int);
    }
    let w: Vec<Vector<D>> = u.iter().zip(&sys.u_tilde).map(|(a, b)| a - b).collect();
    let f_inertia = inertial_force(p, sys, &w);
    (0..u.len())
        .map(|a| f_inertia[a] + f_int[a] - sys.f_ext[a])
        .collect()
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

/// K = ∂r/∂u at the step's iterate over the unknowns (2-40): the stiffness of
/// the particles at the trial state (2-41, 2-42; with F-bar if on), the step's
/// terms at their states (`super::terms`), and the inertia; and whether K is
/// symmetric. `numerical` lets materials without an analytic tangent use a
/// numerical one (Krylov preconditioners only).
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
    // Symmetric unless F-bar, a non-associated material or a term breaks it.
    let symmetric = fbar.is_none()
        && sys.terms.iter().all(|t| t.symmetric())
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
        None => add_stiffness(&mut k, map, st, dofs, &p.volume, &a),
        Some(state) => add_fbar_stiffness(&mut k, map, st, dofs, &p.volume, state, &a),
    }
    // The step's terms (absorbing faces, contact, a linear domain stress).
    let step = sys.view(m);
    for t in &sys.terms {
        t.add_tangent(&step, &a, &mut k);
    }
    if sys.inertia > 0.0 {
        match sys.mass_matrix {
            MassMatrix::Lumped => add_lumped_mass::<D>(&mut k, dofs, &sys.mass, sys.inertia),
            MassMatrix::Consistent => {
                add_consistent_mass(&mut k, map, st, dofs, &p.mass, sys.inertia)
            }
        }
    }
    Ok(k)
}

/// The sparsity pattern of the step's tangent (built at the first call of the
/// step, or kept from the previous step).
pub fn step_pattern<const D: usize>(sys: &StepSystem<D>) -> &Pattern {
    let cells = sys.trial.fbar.as_ref().map(|f| &f.cells);
    (sys.pattern).get_or_init(|| {
        let c = sys.couplings();
        let (map, st, dofs) = (&sys.map, &sys.stencils, &sys.dofs);
        Pattern::new(map, st, dofs, cells, c.neighbours, &c.node_pairs)
    })
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
