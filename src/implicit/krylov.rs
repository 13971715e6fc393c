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

use super::tangent::{Dofs, Pk1Derivative};
use super::{apply_correction, free_part, Failure, Implicit};
use crate::dim::Vector;
use crate::linear::cg::cg;
use crate::linear::direct::Structure;
use crate::linear::gmres::gmres;
use crate::linear::iterative::{Identity, Outcome, Preconditioner, Settings};
use crate::linear::preconditioner::{BlockJacobi, Factorized, Jacobi};
use crate::scene::{LinearSolver, MassMatrix, PreconditionerKind, SolverConfig};
use crate::setup::Model;
use crate::shape::Stencils;
use crate::transfer::NodeMap;
use nalgebra::SMatrix;

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
        let eta = eta.max(0.5 * stop / r_norm).min(self.fixed.unwrap_or(Self::ETA_MAX));
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
        })
    }

    /// "gmres/jacobi" and so on, for newton.csv.
    pub fn name(&self) -> &'static str {
        use LinearSolver::*;
        use PreconditionerKind::*;
        match (self.method, self.preconditioner) {
            (Cg, None) => "cg/none",
            (Cg, Jacobi) => "cg/jacobi",
            (Cg, BlockJacobi) => "cg/block_jacobi",
            (Cg, LaggedDirect) => "cg/lagged_direct",
            (_, None) => "gmres/none",
            (_, Jacobi) => "gmres/jacobi",
            (_, BlockJacobi) => "gmres/block_jacobi",
            (_, LaggedDirect) => "gmres/lagged_direct",
        }
    }
}

/// The Krylov solver's state across Newton iterations and steps.
#[derive(Clone, Debug)]
pub struct KrylovState {
    pub config: KrylovConfig,
    forcing: Forcing,
    /// Active nodes and unknown numbering the lagged factorization belongs to.
    lagged_for: Option<(Vec<u32>, Vec<u32>)>,
    refresh: bool,
    /// Lagged factorizations computed so far.
    pub factorizations: usize,
}

impl KrylovState {
    pub fn new(config: KrylovConfig) -> KrylovState {
        KrylovState {
            config,
            forcing: Forcing::new(config.fixed_tolerance),
            lagged_for: None,
            refresh: true,
            factorizations: 0,
        }
    }
}

/// One Newton correction and how it was obtained.
#[derive(Clone, Debug)]
pub struct Correction {
    pub du: Vec<f64>,
    pub method: &'static str,
    pub krylov_iterations: usize,
    /// η of an inexact solve (NaN for the direct solver).
    pub forcing: f64,
}

/// The D×D diagonal blocks of the tangent at every active node, summed particle
/// by particle: K_(Ii)(Ik) = Σ_p V_p ∂S_Ip/∂X_j A_p,ijkl ∂S_Ip/∂X_l (2-41, 2-42)
/// plus the inertia M_II/(βΔt²) (2-40; lumped, or Σ_p m_p S_Ip² for the consistent
/// mass). Deterministic (a gather). Components are not yet restricted to the
/// free unknowns.
#[allow(clippy::too_many_arguments)]
pub fn diagonal_blocks<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    particle_mass: &[f64],
    a: &[Pk1Derivative],
    lumped_mass: &[f64],
    mass_matrix: MassMatrix,
    inertia: f64,
) -> Vec<SMatrix<f64, D, D>> {
    let consistent = mass_matrix == MassMatrix::Consistent;
    let mut blocks = map.gather(st.stride, SMatrix::<f64, D, D>::zeros(), |q, e| {
        let g = &st.grad[e];
        let mut b = SMatrix::<f64, D, D>::from_fn(|i, k| {
            let mut v = 0.0;
            for j in 0..D {
                for l in 0..D {
                    v += g[j] * a[q][(3 * i + j, 3 * k + l)] * g[l];
                }
            }
            v * volume[q]
        });
        if consistent {
            let w = st.weight[e];
            b += SMatrix::<f64, D, D>::identity() * (particle_mass[q] * w * w * inertia);
        }
        b
    });
    if !consistent {
        for (b, m) in blocks.iter_mut().zip(lumped_mass) {
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
    /// Use the direct solver's current factors.
    Lagged,
}

impl<const D: usize> Implicit<D> {
    /// δu with ‖r + J δu‖ ≤ η ‖r‖ by GMRES or CG on difference products at the
    /// iterate `u` (whose residual `r_free` the trial state holds). `stop` is the
    /// Newton tolerance on ‖r‖; `iteration` 0 starts a new forcing sequence.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn krylov_correction(
        &mut self,
        m: &Model<D>,
        dofs: &Dofs,
        u: &[Vector<D>],
        r_free: &[f64],
        stop: f64,
        iteration: usize,
        u_tilde: &[Vector<D>],
        mass: &[f64],
        f_ext: &[Vector<D>],
        inertia: f64,
        dt: f64,
    ) -> Result<Correction, Failure> {
        let state = self.krylov.as_mut().expect("a Krylov solver is configured");
        let config = state.config;
        if iteration == 0 {
            state.forcing.reset();
        }
        let r_norm = crate::linear::iterative::norm(r_free);
        let eta = state.forcing.next(r_norm, stop);
        let built = self.build_preconditioner(m, dofs, mass, inertia)?;

        let h = m.grid.h_min();
        let u_max = max_norm_free(u, dofs);
        let b: Vec<f64> = r_free.iter().map(|x| -x).collect();
        let mut du = vec![0.0; dofs.free];
        let settings = Settings {
            tolerance: eta,
            max_iterations: config.max_iterations,
            restart: config.restart,
        };
        // The direct solver leaves `self` for the solve: the difference products
        // need `self` mutably (trial states), the lagged preconditioner its factors.
        let solver = std::mem::take(&mut self.solver);
        let outcome = {
            let mut product = |v: &[f64], out: &mut [f64]| -> Result<(), Failure> {
                let v_max = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                if v_max == 0.0 {
                    out.iter_mut().for_each(|o| *o = 0.0);
                    return Ok(());
                }
                let eps = difference_step(h, u_max, v_max);
                let mut up = u.to_vec();
                apply_correction(&mut up, v, dofs, eps);
                let r = self
                    .residual(m, &up, u_tilde, mass, f_ext, inertia, dt)
                    .map_err(|f| Failure {
                        particle: f.particle,
                        message: format!("{} (in a finite-difference product, 2-39)", f.message),
                    })?;
                for (o, (rp, r0)) in out.iter_mut().zip(free_part(&r, dofs).iter().zip(r_free)) {
                    *o = (rp - r0) / eps;
                }
                Ok(())
            };
            let factors = Factorized(&solver);
            let pre: &dyn Preconditioner = match &built {
                Built::Identity => &Identity,
                Built::Jacobi(j) => j,
                Built::Blocks(b) => b,
                Built::Lagged => &factors,
            };
            match config.method {
                LinearSolver::Cg => cg(&mut product, pre, &b, &mut du, &settings),
                _ => gmres(&mut product, pre, &b, &mut du, &settings),
            }
        };
        self.solver = solver;
        let outcome: Outcome = outcome?;
        self.krylov_iterations += outcome.iterations;
        let state = self.krylov.as_mut().unwrap();
        if !outcome.converged || outcome.iterations > LAGGED_REFRESH_ITERATIONS {
            state.refresh = true;
        }
        if !outcome.converged {
            let name = match config.method {
                LinearSolver::Cg => "CG",
                _ => "GMRES",
            };
            let why = outcome
                .breakdown
                .map(|b| format!("stopped: {b}"))
                .unwrap_or_else(|| format!("hit krylov_max_iterations = {}", config.max_iterations));
            return Err(Failure {
                particle: None,
                message: format!(
                    "{name} ({} preconditioner) did not reach the forcing tolerance η = {eta:.2e} \
                     in Newton iteration {iteration}: relative linear residual {:.2e} after {} \
                     iterations, {why}",
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
    fn build_preconditioner(
        &mut self,
        m: &Model<D>,
        dofs: &Dofs,
        mass: &[f64],
        inertia: f64,
    ) -> Result<Built, Failure> {
        let kind = self.krylov.as_ref().unwrap().config.preconditioner;
        let blocks = |this: &Self| -> Result<Vec<SMatrix<f64, D, D>>, Failure> {
            let a = this.particle_tangents(m, true)?;
            let p = &m.particles;
            Ok(diagonal_blocks(
                &this.map,
                &this.stencils,
                &p.volume,
                &p.mass,
                &a,
                mass,
                this.mass_matrix,
                inertia,
            ))
        };
        Ok(match kind {
            PreconditionerKind::None => Built::Identity,
            PreconditionerKind::Jacobi => {
                let blocks = blocks(self)?;
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
                let blocks = blocks(self)?;
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
                self.refresh_lagged(m, dofs, mass, inertia)?;
                Built::Lagged
            }
        })
    }

    /// Assemble and factorize the tangent at the current iterate if the kept
    /// factorization is missing, belongs to other unknowns, or has stopped
    /// working (see [`LAGGED_REFRESH_ITERATIONS`]).
    fn refresh_lagged(
        &mut self,
        m: &Model<D>,
        dofs: &Dofs,
        mass: &[f64],
        inertia: f64,
    ) -> Result<(), Failure> {
        let state = self.krylov.as_ref().unwrap();
        let same_unknowns = state
            .lagged_for
            .as_ref()
            .is_some_and(|(active, index)| *active == self.map.active && *index == dofs.index);
        if same_unknowns && !state.refresh {
            return Ok(());
        }
        let (triplets, symmetric) = self.tangent(m, dofs, mass, inertia)?;
        let structure = if symmetric {
            Structure::Symmetric
        } else {
            Structure::General
        };
        self.solver
            .factorize(dofs.free, &triplets, structure)
            .map_err(|e| Failure {
                particle: None,
                message: format!("lagged_direct preconditioner: factorization failed: {e}"),
            })?;
        let active = self.map.active.clone();
        let state = self.krylov.as_mut().unwrap();
        state.lagged_for = Some((active, dofs.index.clone()));
        state.refresh = false;
        state.factorizations += 1;
        Ok(())
    }
}

/// max |u_i| over the free components.
fn max_norm_free<const D: usize>(u: &[Vector<D>], dofs: &Dofs) -> f64 {
    free_part(u, dofs)
        .iter()
        .fold(0.0f64, |a, x| a.max(x.abs()))
}
