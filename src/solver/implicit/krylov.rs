//! Matrix-free Newton–Krylov corrections (thesis §2.2.2, first method).
//!
//! The Newton correction (2-38) J δu = −r is solved by GMRES or CG, which only
//! need products J v. Each is a one-sided difference of the residual (2-39),
//!
//!   J v ≈ (r(u + ε v) − r(u)) / ε,
//!
//! so no tangent is assembled and materials without an analytic tangent run
//! implicitly. The linear solve is inexact: it stops when
//! ‖r + J δu‖ ≤ η ‖r‖, with the forcing term η of Eisenstat & Walker (1996),
//! choice 2 (see [`Forcing`]).
//!
//! Choice of ε ([`difference_step`]). The residual depends on u through the
//! incremental deformation gradient ΔF = I + Σ u ⊗ ∇S, i.e. on u / h at cell size
//! h. Forming ΔF in floating point perturbs it by about ε_mach, which acts like a
//! displacement error ε_mach·h, or ε_mach·|u| once |u| exceeds h; the round-off
//! of the difference quotient relative to J v is therefore about
//! ε_mach (h + ‖u‖_∞) / (ε ‖v‖_∞). Its truncation error, ½ ε ‖v‖² |r''| relative to
//! ‖J v‖, is about ε ‖v‖_∞ / h (the residual bends on the scale of unit strain).
//! The two balance at
//!
//!   ε = √ε_mach (h + ‖u‖_∞) / ‖v‖_∞,
//!
//! where both errors are about √ε_mach ≈ 1.5e-8 of J v. Maximum norms make the
//! rule independent of the number of unknowns: the largest nodal perturbation is
//! √ε_mach (h + ‖u‖_∞). `tests::difference_product_error_against_step` checks the
//! error curve against the assembled tangent.
//!
//! Preconditioners are built from the particle tangents A_p = ∂P/∂ΔF at the
//! current iterate (the material's analytic derivative, or central differences
//! of its stress update when it has none): the diagonal or the nodal D×D
//! diagonal blocks of K summed particle by particle ([`diagonal_blocks`]), never
//! forming K; or K itself assembled and factorized with the direct solver and
//! kept while it works (lagged, see [`LAGGED_REFRESH_ITERATIONS`]).
//!
//! The multigrid preconditioner (`solver::linear::multigrid`, hierarchy from
//! `super::coarsening`) needs the assembled tangent K at the current iterate; K
//! is then also the Krylov operator (no difference products). Its hierarchy
//! (prolongations) is kept while the active nodes and unknowns are; each Newton
//! iteration refreshes the operators' values (Galerkin products, smoothers, the
//! coarse factorization). `lagged_multigrid` keeps the whole multigrid of an
//! earlier iteration's tangent (refreshed under the rule of `lagged_direct`)
//! and solves with the difference products, so a material without an analytic
//! tangent gets it from central differences once per refresh only.

use super::assembly::stiffness::{coupling, hoop_coupling, particle_tangents, ParticleTangents};
use super::assembly::Dofs;
use super::coarsening::hierarchy;
use super::failure::Failure;
use super::residual::{ordering, probe_residual, tangent};
use super::step::StepSystem;
use crate::dim::Vector;
use crate::model::Model;
use crate::scene::{LinearSolver, MassMatrix, PreconditionerKind, SolverConfig};
use crate::solver::linear::cg::cg;
use crate::solver::linear::direct::{DirectSolver, Structure};
use crate::solver::linear::gmres::gmres;
use crate::solver::linear::iterative::{norm, Identity, Outcome, Preconditioner, Settings};
use crate::solver::linear::multigrid::{Csr, Fine, Multigrid};
use crate::solver::linear::preconditioner::{BlockJacobi, Factorized, Jacobi};
use crate::solver::report::MultigridCounts;
use nalgebra::SMatrix;
use std::sync::Arc;

/// The lagged factorization is refreshed when a linear solve with it needed more
/// than this many iterations (or failed), and whenever the unknowns change.
pub const LAGGED_REFRESH_ITERATIONS: usize = 20;

/// ε = √ε_mach (h + ‖u‖_∞) / ‖v‖_∞ for the difference product (2-39); see the
/// module documentation.
pub fn difference_step(h: f64, u_max: f64, v_max: f64) -> f64 {
    f64::EPSILON.sqrt() * (h + u_max) / v_max
}

/// Eisenstat–Walker forcing terms, choice 2 (Eisenstat & Walker 1996, SIAM J.
/// Sci. Comput. 17:16–32): η_k = γ (‖r_k‖ / ‖r_{k−1}‖)^α with γ = 0.9, α = 2,
/// η_0 = 0.5. Safeguards: η_k ≥ γ η_{k−1}^α whenever γ η_{k−1}^α > 0.1 (a sudden
/// small η after a poor step would oversolve); η_k ≤ η_max = 0.9; and
/// η_k ≥ ½ τ / ‖r_k‖ with τ the Newton tolerance on ‖r‖ (a linear residual far
/// below what Newton will accept is wasted, Kelley 1995 §6.3). With a fixed
/// `krylov_tolerance` η is that constant (still subject to the last safeguard).
#[derive(Clone, Debug)]
pub struct Forcing {
    fixed: Option<f64>,
    /// (η, ‖r‖) of the previous Newton iteration of this step.
    previous: Option<(f64, f64)>,
}

impl Forcing {
    pub const GAMMA: f64 = 0.9;
    pub const ALPHA: f64 = 2.0;
    pub const ETA_0: f64 = 0.5;
    pub const ETA_MAX: f64 = 0.9;

    pub fn new(fixed: Option<f64>) -> Forcing {
        Forcing {
            fixed,
            previous: None,
        }
    }

    /// Forget the previous iteration (a new step or attempt).
    pub fn reset(&mut self) {
        self.previous = None;
    }

    /// η for the iteration with residual norm `r_norm`; `stop` is the Newton
    /// tolerance on the same norm.
    pub fn next(&mut self, r_norm: f64, stop: f64) -> f64 {
        let eta = match (self.fixed, self.previous) {
            (Some(eta), _) => eta,
            (None, None) => Self::ETA_0,
            (None, Some((eta_prev, r_prev))) => {
                let mut eta = Self::GAMMA * (r_norm / r_prev).powf(Self::ALPHA);
                let safeguard = Self::GAMMA * eta_prev.powf(Self::ALPHA);
                if safeguard > 0.1 {
                    eta = eta.max(safeguard);
                }
                eta.min(Self::ETA_MAX)
            }
        };
        let eta = eta
            .max(0.5 * stop / r_norm)
            .min(self.fixed.unwrap_or(Self::ETA_MAX));
        self.previous = Some((eta, r_norm));
        eta
    }
}

/// The Krylov settings of a stage.
#[derive(Clone, Copy, Debug)]
pub struct KrylovConfig {
    pub method: LinearSolver,
    pub preconditioner: PreconditionerKind,
    pub fixed_tolerance: Option<f64>,
    pub restart: usize,
    pub max_iterations: usize,
    /// Largest coarsest level of the multigrid preconditioner.
    pub coarse_unknowns: usize,
}

impl KrylovConfig {
    /// None for the direct solver.
    pub fn of(s: &SolverConfig) -> Option<KrylovConfig> {
        (s.linear_solver() != LinearSolver::Direct).then(|| KrylovConfig {
            method: s.linear_solver(),
            preconditioner: s.preconditioner(),
            fixed_tolerance: s.krylov_tolerance,
            restart: s.krylov_restart(),
            max_iterations: s.krylov_max_iterations(),
            coarse_unknowns: s.multigrid_coarse_unknowns(),
        })
    }

    /// "gmres/jacobi" and so on, for newton.csv.
    pub fn name(&self) -> String {
        format!("{}/{}", self.method.name(), self.preconditioner.name())
    }
}

/// The Krylov solver's state across Newton iterations and steps.
pub struct KrylovState {
    pub config: KrylovConfig,
    forcing: Forcing,
    /// The lagged_direct preconditioner's factorization, and the active nodes and
    /// unknown numbering it belongs to.
    pub lagged: DirectSolver,
    lagged_for: Option<(Vec<u32>, Vec<u32>)>,
    refresh: bool,
    /// The multigrid hierarchy and the active nodes and unknown numbering it
    /// belongs to.
    multigrid: Option<(Vec<u32>, Vec<u32>, Multigrid)>,
    /// Multigrid hierarchies built so far.
    pub hierarchies: usize,
    /// What the multigrid's refreshes did so far.
    pub multigrid_counts: MultigridCounts,
    /// Lagged factorizations computed so far.
    pub factorizations: usize,
    /// Krylov iterations over all Newton corrections.
    pub iterations: usize,
}

/// One Newton correction and how it was obtained (by this solver or the direct
/// one).
#[derive(Clone, Debug)]
pub struct Correction {
    pub du: Vec<f64>,
    /// The linear solver, for newton.csv.
    pub method: String,
    pub krylov_iterations: usize,
    /// η of an inexact solve (NaN for the direct solver).
    pub forcing: f64,
}

/// The D×D diagonal blocks of the tangent at every active node, summed particle
/// by particle: K_(Ii)(Ik) = Σ_p V_p ∂S_Ip/∂X_j A_p,ijkl ∂S_Ip/∂X_l (2-41, 2-42)
/// plus the inertia M_II/(βΔt²) (2-40; lumped, or Σ_p m_p S_Ip² for the consistent
/// mass), with the hoop couplings in axisymmetric mode. Deterministic (a
/// gather). Components are not yet restricted to the free unknowns.
pub fn diagonal_blocks<const D: usize>(
    m: &Model<D>,
    sys: &StepSystem<D>,
    a: &ParticleTangents<D>,
) -> Vec<SMatrix<f64, D, D>> {
    let p = &m.particles;
    let (st, inertia) = (&sys.stencils, sys.inertia);
    let consistent = sys.mass_matrix == MassMatrix::Consistent;
    let mut blocks = sys
        .map
        .gather(st.stride, SMatrix::<f64, D, D>::zeros(), |q, e| {
            let g = &st.grad(e);
            let hoop = a.hoop_of(q);
            let mut b = SMatrix::<f64, D, D>::from_fn(|i, k| {
                let mut v = coupling(g, a.of(q), g, i, k);
                if !hoop.is_empty() {
                    v += hoop_coupling(g, st.hoop[e], hoop, g, st.hoop[e], i, k);
                }
                v * p.volume[q]
            });
            if consistent {
                let w = st.weight(e);
                b += SMatrix::<f64, D, D>::identity() * (p.mass[q] * w * w * inertia);
            }
            b
        });
    if !consistent {
        for (b, m) in blocks.iter_mut().zip(&sys.mass) {
            *b += SMatrix::<f64, D, D>::identity() * (m * inertia);
        }
    }
    blocks
}

/// The preconditioner of one linear solve.
enum Built {
    Identity,
    Jacobi(Jacobi),
    Blocks(BlockJacobi),
    /// Use the lagged factorization.
    Lagged,
    /// Use the multigrid hierarchy, whose fine operator is the Krylov operator.
    Multigrid,
    /// Use the kept multigrid hierarchy of an earlier tangent; the Krylov
    /// operator is the difference product.
    LaggedMultigrid,
}

impl KrylovState {
    pub fn new(config: KrylovConfig) -> KrylovState {
        KrylovState {
            config,
            forcing: Forcing::new(config.fixed_tolerance),
            lagged: DirectSolver::new(),
            lagged_for: None,
            refresh: true,
            multigrid: None,
            hierarchies: 0,
            multigrid_counts: MultigridCounts::default(),
            factorizations: 0,
            iterations: 0,
        }
    }

    /// δu with ‖r + J δu‖ ≤ η ‖r‖ by GMRES or CG on difference products at the
    /// step's iterate `u` (whose residual is `r_free`; the products leave the
    /// iterate's state as it is). `stop` is the Newton tolerance on ‖r‖;
    /// `iteration` 0 starts a new forcing sequence.
    pub fn correction<const D: usize>(
        &mut self,
        m: &Model<D>,
        sys: &StepSystem<D>,
        u: &[Vector<D>],
        r_free: &[f64],
        stop: f64,
        iteration: usize,
    ) -> Result<Correction, Failure> {
        let config = self.config;
        if iteration == 0 {
            self.forcing.reset();
        }
        let eta = self.forcing.next(norm(r_free), stop);
        let built = self.build_preconditioner(m, sys)?;

        let h = m.grid.h_min();
        let u_max = max_norm_free(u, &sys.dofs);
        let b: Vec<f64> = r_free.iter().map(|x| -x).collect();
        let mut du = vec![0.0; sys.dofs.free];
        let settings = Settings {
            tolerance: eta,
            max_iterations: config.max_iterations,
            restart: config.restart,
        };
        let assembled = match (&built, &self.multigrid) {
            (Built::Multigrid, Some((_, _, mg))) => Some(mg),
            _ => None,
        };
        let product = |v: &[f64], out: &mut [f64]| -> Result<(), Failure> {
            if let Some(mg) = assembled {
                mg.fine_operator().apply(v, out);
                return Ok(());
            }
            let v_max = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if v_max == 0.0 {
                out.iter_mut().for_each(|o| *o = 0.0);
                return Ok(());
            }
            let eps = difference_step(h, u_max, v_max);
            out.copy_from_slice(&difference_product(m, sys, u, r_free, v, eps)?);
            Ok(())
        };
        let factors = Factorized(&self.lagged);
        let pre: &dyn Preconditioner = match &built {
            Built::Identity => &Identity,
            Built::Jacobi(j) => j,
            Built::Blocks(b) => b,
            Built::Lagged => &factors,
            Built::Multigrid => assembled.expect("refreshed by build_preconditioner"),
            Built::LaggedMultigrid => match &self.multigrid {
                Some((_, _, mg)) => mg,
                None => unreachable!("refreshed by build_preconditioner"),
            },
        };
        let outcome: Outcome = match config.method {
            LinearSolver::Cg => cg(product, pre, &b, &mut du, &settings),
            LinearSolver::Gmres => gmres(product, pre, &b, &mut du, &settings),
            LinearSolver::Direct => unreachable!("KrylovConfig::of is None for the direct solver"),
        }?;
        // A multigrid refreshed at every iteration is not used again before the
        // next refresh: its operators, the fine tangent among them, are not held
        // through the residuals of the line search and the next iterate.
        if let (Built::Multigrid, Some((_, _, mg))) = (&built, self.multigrid.as_mut()) {
            mg.release();
        }
        self.iterations += outcome.iterations;
        if !outcome.converged || outcome.iterations > LAGGED_REFRESH_ITERATIONS {
            self.refresh = true;
        }
        if !outcome.converged {
            let why = outcome
                .breakdown
                .map(|b| format!("stopped: {b}"))
                .unwrap_or_else(|| {
                    format!("hit krylov_max_iterations = {}", config.max_iterations)
                });
            return Err(Failure {
                particle: None,
                message: format!(
                    "{} ({} preconditioner) did not reach the forcing tolerance η = {eta:.2e} \
                     in Newton iteration {iteration}: relative linear residual {:.2e} after {} \
                     iterations, {why}",
                    config.method.name().to_uppercase(),
                    config.preconditioner.name(),
                    outcome.relative_residual,
                    outcome.iterations
                ),
            });
        }
        Ok(Correction {
            du,
            method: config.name(),
            krylov_iterations: outcome.iterations,
            forcing: eta,
        })
    }

    /// The preconditioner at the current iterate (the trial state).
    fn build_preconditioner<const D: usize>(
        &mut self,
        m: &Model<D>,
        sys: &StepSystem<D>,
    ) -> Result<Built, Failure> {
        let dofs = &sys.dofs;
        let blocks = || -> Result<Vec<SMatrix<f64, D, D>>, Failure> {
            let a = particle_tangents(m, &sys.trial, &sys.stencils, &sys.map, true)?;
            Ok(diagonal_blocks(m, sys, &a))
        };
        Ok(match self.config.preconditioner {
            PreconditionerKind::None => Built::Identity,
            PreconditionerKind::Jacobi => {
                let blocks = blocks()?;
                let mut diagonal = vec![0.0; dofs.free];
                for (a, block) in blocks.iter().enumerate() {
                    for d in 0..D {
                        if let Some(i) = dofs.of(a, d, D) {
                            diagonal[i] = block[(d, d)];
                        }
                    }
                }
                Built::Jacobi(Jacobi::new(diagonal))
            }
            PreconditionerKind::BlockJacobi => {
                let blocks = blocks()?;
                let mut unknowns: Vec<Vec<usize>> = Vec::with_capacity(blocks.len());
                let mut values: Vec<Vec<f64>> = Vec::with_capacity(blocks.len());
                for (a, block) in blocks.iter().enumerate() {
                    let free: Vec<(usize, usize)> = (0..D)
                        .filter_map(|d| dofs.of(a, d, D).map(|i| (d, i)))
                        .collect();
                    values.push(
                        free.iter()
                            .flat_map(|&(d, _)| free.iter().map(move |&(e, _)| block[(d, e)]))
                            .collect(),
                    );
                    unknowns.push(free.iter().map(|&(_, i)| i).collect());
                }
                Built::Blocks(BlockJacobi::new(
                    unknowns
                        .iter()
                        .zip(&values)
                        .map(|(u, v)| (u.as_slice(), v.as_slice())),
                ))
            }
            PreconditionerKind::LaggedDirect => {
                self.refresh_lagged(m, sys)?;
                Built::Lagged
            }
            PreconditionerKind::Multigrid => {
                self.refresh_multigrid(m, sys)?;
                Built::Multigrid
            }
            PreconditionerKind::LaggedMultigrid => {
                if !self.multigrid_fits(sys) || self.refresh {
                    self.refresh_multigrid(m, sys)?;
                    self.refresh = false;
                }
                Built::LaggedMultigrid
            }
        })
    }

    /// Does the kept multigrid hierarchy belong to the step system's active nodes
    /// and unknowns?
    fn multigrid_fits<const D: usize>(&self, sys: &StepSystem<D>) -> bool {
        self.multigrid
            .as_ref()
            .is_some_and(|(active, index, _)| *active == sys.map.active && *index == sys.dofs.index)
    }

    /// The multigrid for the tangent at the current iterate: the hierarchy
    /// kept while the active nodes and unknowns are, the operators refreshed.
    fn refresh_multigrid<const D: usize>(
        &mut self,
        m: &Model<D>,
        sys: &StepSystem<D>,
    ) -> Result<(), Failure> {
        if !self.multigrid_fits(sys) {
            let h = hierarchy(
                &m.grid,
                &sys.map.active,
                &sys.dofs,
                self.config.coarse_unknowns,
            );
            let mg = Multigrid::new(h.transfers);
            self.multigrid = Some((sys.map.active.clone(), sys.dofs.index.clone(), mg));
            self.hierarchies += 1;
        }
        // The old operators are not needed to assemble the new ones (at 32³
        // cells in 3D they are 0.5 GB of a 1.4 GB peak).
        if let Some((_, _, mg)) = self.multigrid.as_mut() {
            mg.release();
        }
        // Materials without an analytic tangent use a numerical one.
        let k = tangent(m, sys, true)?;
        // A symmetric tangent serves as it is (its lower triangle, read by
        // rows); an unsymmetric one is copied into rows, and its columns dropped.
        let symmetric = k.symmetric();
        let a = if symmetric {
            Fine::Lower(
                Arc::clone(k.col_ptr),
                k.values,
                Arc::clone(k.pattern.lists()),
            )
        } else {
            let rows = Csr::from_csc(k.matrix());
            drop(k);
            Fine::Rows(rows)
        };
        let (_, _, mg) = self.multigrid.as_mut().expect("built above");
        let shape = mg.refresh(a, symmetric).map_err(|e| Failure {
            particle: None,
            message: format!("multigrid preconditioner: {e}"),
        })?;
        let counts = &mut self.multigrid_counts;
        counts.refreshes += 1;
        counts.shifted += usize::from(shape.coarse_shift > 0.0);
        counts.truncated += usize::from(shape.unknowns.len() < mg.built_levels());
        let coarse = *shape.unknowns.last().expect("a level");
        counts.largest_coarse_unknowns = counts.largest_coarse_unknowns.max(coarse);
        Ok(())
    }

    /// Assemble and factorize the tangent at the current iterate if the kept
    /// factorization is missing, belongs to other unknowns, or has stopped
    /// working (see [`LAGGED_REFRESH_ITERATIONS`]).
    fn refresh_lagged<const D: usize>(
        &mut self,
        m: &Model<D>,
        sys: &StepSystem<D>,
    ) -> Result<(), Failure> {
        let same_unknowns = self
            .lagged_for
            .as_ref()
            .is_some_and(|(active, index)| *active == sys.map.active && *index == sys.dofs.index);
        if same_unknowns && !self.refresh {
            return Ok(());
        }
        // The lagged preconditioner accepts a numerical tangent.
        let k = tangent(m, sys, true)?;
        let structure = Structure::of(k.symmetric());
        self.lagged
            .factorize(k.matrix(), structure, ordering(sys, &k))
            .map_err(|e| Failure {
                particle: None,
                message: format!("lagged_direct preconditioner: factorization failed: {e}"),
            })?;
        self.lagged_for = Some((sys.map.active.clone(), sys.dofs.index.clone()));
        self.refresh = false;
        self.factorizations += 1;
        Ok(())
    }
}

/// (r(u + ε v) − r(u)) / ε over the free unknowns (2-39); `r_free` is r(u).
/// r(u + ε v) is a probe: the step's iterate stays where it is.
pub fn difference_product<const D: usize>(
    m: &Model<D>,
    sys: &StepSystem<D>,
    u: &[Vector<D>],
    r_free: &[f64],
    v: &[f64],
    eps: f64,
) -> Result<Vec<f64>, Failure> {
    let mut up = u.to_vec();
    sys.dofs.apply_correction(&mut up, v, eps);
    let r = probe_residual(m, sys, &up).map_err(|f| Failure {
        particle: f.particle,
        message: format!("{} (in a finite-difference product, 2-39)", f.message),
    })?;
    Ok(sys
        .dofs
        .reduce(&r)
        .iter()
        .zip(r_free)
        .map(|(rp, r0)| (rp - r0) / eps)
        .collect())
}

/// max |u_i| over the free components.
fn max_norm_free<const D: usize>(u: &[Vector<D>], dofs: &Dofs) -> f64 {
    dofs.values(u).iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use crate::solver::implicit::residual::residual;
    use crate::solver::implicit::tests::BLOCK;
    use crate::solver::implicit::Implicit;

    /// The block of the implicit tests (`super::super::tests::BLOCK`) scaled to
    /// cell size h = `length`, uGIMP, quasi-static in one load step.
    fn block(length: f64) -> String {
        let l = |x: f64| x * length;
        let text =
            crate::scene::overrides::unset("block.toml", BLOCK, &["solver.dt".into()]).unwrap();
        let overrides = [
            format!("grid.max=[{},{}]", l(4.0), l(4.0)),
            "grid.shape_function=ugimp".to_string(),
            format!("body.0.min=[{},0.0]", l(0.5)),
            format!("body.0.max=[{},{}]", l(3.0), l(2.5)),
            format!("load.0.region_min=[{},{}]", l(2.5), l(2.0)),
            format!("load.0.region_max=[{},{}]", l(3.0), l(2.5)),
            "solver.integrator=quasi_static".to_string(),
            "solver.load_steps=1".to_string(),
        ];
        crate::scene::overrides::apply("block.toml", &text, &overrides).unwrap()
    }

    /// Relative error ‖J_fd v − K v‖ / ‖K v‖ of the difference product against the
    /// assembled tangent at a finite-strain iterate, for each step in `steps`, and
    /// the step the documented rule chooses.
    fn product_errors(length: f64, steps: &[f64]) -> (Vec<f64>, f64) {
        let scene = Scene::parse("block.toml", &block(length), &[]).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let mut solver = Implicit::<2>::new(
            scene.config.grid.shape_function,
            scene.config.stages()[0],
            0.0,
        );
        solver.prepare(&m, 0.0, 1.0);
        let sys = &mut solver.system;
        let nodes: Vec<usize> = sys.map.active.iter().map(|&g| g as usize).collect();
        // Strains of a few per cent: displacements scale with the length.
        let u: Vec<Vector<2>> = nodes
            .iter()
            .zip(&sys.constraint)
            .map(|(&g, c)| {
                let x = m.grid.node_position(m.grid.node_ijk(g)) / length;
                let mut v = Vector::<2>::new(
                    0.03 * (0.7 * x[1]).sin() + 0.01 * x[0],
                    -0.02 * x[0] * x[1] / 4.0,
                ) * length;
                for d in 0..2 {
                    if c.fixed[d] {
                        v[d] = 0.0;
                    }
                }
                v
            })
            .collect();
        let dofs = sys.dofs.clone();
        let r0 = dofs.reduce(&residual(&m, sys, &u).unwrap());
        // A smooth direction with ‖v‖_∞ = 1.
        let n = dofs.free;
        let v: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin()).collect();
        let v_max = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let v: Vec<f64> = v.iter().map(|x| x / v_max).collect();
        let kv = tangent(&m, sys, false).unwrap().apply(&v);
        let kv_norm = norm(&kv);
        let errors = steps
            .iter()
            .map(|&eps| {
                let jv = difference_product(&m, sys, &u, &r0, &v, eps).unwrap();
                let diff: Vec<f64> = jv.iter().zip(&kv).map(|(a, b)| a - b).collect();
                norm(&diff) / kv_norm
            })
            .collect();
        let chosen = difference_step(m.grid.h_min(), max_norm_free(&u, &dofs), 1.0);
        (errors, chosen)
    }

    /// The difference product against the assembled tangent (thesis 2-39 vs 2-40)
    /// over ε = 1e-1 … 1e-13 · length: the error falls ∝ ε (truncation) for large ε
    /// and grows ∝ 1/ε (round-off) for small ε; the minimum lies within a decade of
    /// the documented ε = √ε_mach (h + ‖u‖_∞)/‖v‖_∞, where the error is below 1e-6
    /// (the balance predicts a few √ε_mach ≈ 1.5e-8). The same problem in units a
    /// hundred times larger moves the whole curve, and the chosen ε, by 100.
    #[test]
    fn difference_product_error_against_step() {
        for length in [1.0, 100.0] {
            let exponents: Vec<i32> = (1..=13).collect();
            let steps: Vec<f64> = exponents.iter().map(|&k| length * 10f64.powi(-k)).collect();
            let (errors, chosen) = product_errors(length, &steps);
            let (_, at_chosen) = {
                let (e, _) = product_errors(length, &[chosen]);
                (chosen, e[0])
            };
            println!("length scale {length}: ε, relative error of J v");
            for (s, e) in steps.iter().zip(&errors) {
                println!("  {s:9.1e}  {e:9.2e}");
            }
            println!("  chosen ε = {chosen:.2e}: {at_chosen:.2e}");
            // Truncation: one decade of ε is one decade of error (slope 1) at ε ≥ 1e-4 L.
            for k in 1..3 {
                let slope = (errors[k - 1] / errors[k]).log10();
                assert!(
                    (0.8..1.2).contains(&slope),
                    "truncation slope {slope:.2} at ε = {:.0e}",
                    steps[k]
                );
            }
            // Round-off: the error grows as ε shrinks below 1e-10 L, about 1/ε
            // (noisy: the slope over two decades lies in 0.6 … 1.4).
            let slope = (errors[12] / errors[10]).log10() / 2.0;
            assert!(
                (0.6..1.4).contains(&slope),
                "round-off slope {slope:.2} between ε = 1e-11 L and 1e-13 L"
            );
            let best = (0..errors.len())
                .min_by(|&a, &b| errors[a].total_cmp(&errors[b]))
                .unwrap();
            let decades = (steps[best] / chosen).log10().abs();
            assert!(
                decades <= 1.0,
                "minimum at ε = {:.1e}, {decades:.1} decades from the chosen {chosen:.1e}",
                steps[best]
            );
            assert!(
                at_chosen < 1e-6 && at_chosen < 3.0 * errors[best],
                "error {at_chosen:.2e} at the chosen ε (best {:.2e})",
                errors[best]
            );
        }
    }

    /// Choice 2 of Eisenstat–Walker with its safeguards.
    #[test]
    fn forcing_terms() {
        let mut f = Forcing::new(None);
        let stop = 1e-12;
        assert_eq!(f.next(1.0, stop), Forcing::ETA_0);
        // Quadratic-like decrease: η = 0.9 (0.1)² = 9e-3, safeguard 0.9·0.5² = 0.225 > 0.1 wins.
        assert!((f.next(0.1, stop) - 0.225).abs() < 1e-15);
        // Next: 0.9 (1e-3 / 0.1)² = 9e-5; safeguard 0.9·0.225² = 0.0456 < 0.1 is off.
        assert!((f.next(1e-3, stop) - 9e-5).abs() < 1e-18);
        // A poor step (residual grows) is capped at η_max.
        assert_eq!(f.next(1.0, stop), Forcing::ETA_MAX);
        // Near the Newton tolerance η ≥ ½ τ / ‖r‖.
        f.reset();
        f.next(1.0, 0.5);
        assert!((f.next(2e-1, 0.5) - 0.9f64.min(0.5 * 0.5 / 0.2)).abs() < 1e-15);
        // A fixed tolerance stays fixed.
        let mut c = Forcing::new(Some(1e-4));
        assert_eq!(c.next(1.0, 0.0), 1e-4);
        assert_eq!(c.next(1e-3, 0.0), 1e-4);
    }
}
