//! Newton-Raphson on the increment u of one implicit step (thesis 2-37…2-40).
//!
//! From the predictor ũ with the prescribed components imposed, every iteration
//! 1. evaluates the residual r(u) from the step-start state (2-37, `residual`);
//! 2. stops when ‖r‖ is small against a reference force and the last correction
//!    was small against u;
//! 3. solves the correction K δu = −r (2-38), with the assembled consistent
//!    tangent (2-40) and the sparse direct solver, or matrix-free by GMRES or CG on
//!    difference products of the residual (2-39, `krylov`);
//! 4. with `line_search`, halves δu until ‖r‖ decreases (or takes the length
//!    that raised it least), keeping the residual it found for step 1;
//! 5. updates u ← u + s δu; tied nodes follow their masters.
//!
//! A non-finite residual, an inverted particle, a failed linear solve, a
//! residual that rose in `max_rising_iterations` consecutive iterations, one
//! that fell by less than `STALL_REDUCTION` over the last `stall_iterations`
//! iterations, or no convergence in `max_iterations` fails the attempt: the
//! caller cuts the step back. Every iteration is a row of newton.csv.

use super::assembly::{Storage, Tangent};
use super::export::{Export, Iterate};
use super::failure::Failure;
use super::krylov::{Correction, KrylovConfig, KrylovState};
use super::residual::{inertial_force, ordering, reactions, residual, step_pattern, tangent};
use super::step::StepSystem;
use crate::dim::Vector;
use crate::model::Model;
use crate::scene::SolverConfig;
use crate::solver::linear::direct::{DirectSolver, Method, Ordering, SolveError, Structure};
use crate::solver::linear::iterative::norm;
use crate::solver::report::NewtonRow;
use std::time::Instant;

/// The Newton settings of a stage and what the iteration keeps across steps.
pub struct Newton {
    pub residual_tolerance: f64,
    pub displacement_tolerance: f64,
    pub max_iterations: usize,
    /// The attempt fails once ‖r‖ has risen in this many consecutive
    /// iterations (`usize::MAX`: never).
    pub max_rising_iterations: usize,
    /// The attempt fails once ‖r‖ has fallen by less than `STALL_REDUCTION`
    /// over this many iterations (`usize::MAX`: never).
    pub stall_iterations: usize,
    pub line_search: bool,
    /// How the corrections are solved.
    pub linear: Linear,
    /// Iterations since the last time the solver's rows were taken (newton.csv).
    pub log: Vec<NewtonRow>,
    /// Corrections so far.
    pub iterations: usize,
    /// Matrix Market files of the linear systems (`[output] linear_systems`).
    pub export: Option<Export>,
}

/// The linear solver of the corrections K δu = −r (2-38).
#[allow(clippy::large_enum_variant)] // one per solver, not per iteration
pub enum Linear {
    /// The assembled tangent, factorized.
    Direct(DirectSolver),
    /// Matrix-free GMRES or CG on difference products (2-39).
    Krylov(KrylovState),
}

/// The converged increment of a step, and the reactions at its active nodes.
pub struct Converged<const D: usize> {
    pub u: Vec<Vector<D>>,
    pub reaction: Vec<Vector<D>>,
}

impl Newton {
    pub fn new(s: &SolverConfig) -> Newton {
        Newton {
            residual_tolerance: s.residual_tolerance(),
            displacement_tolerance: s.displacement_tolerance(),
            max_iterations: s.max_iterations(),
            max_rising_iterations: s.max_rising_iterations().unwrap_or(usize::MAX),
            stall_iterations: s.stall_iterations().unwrap_or(usize::MAX),
            line_search: s.line_search(),
            linear: match KrylovConfig::of(s) {
                Some(config) => Linear::Krylov(KrylovState::new(config)),
                None => Linear::Direct(DirectSolver::new()),
            },
            log: Vec::new(),
            iterations: 0,
            export: None,
        }
    }

    /// The Krylov solver, if the corrections are matrix-free.
    pub fn krylov(&self) -> Option<&KrylovState> {
        match &self.linear {
            Linear::Krylov(k) => Some(k),
            Linear::Direct(_) => None,
        }
    }

    /// Krylov iterations over all corrections (0 with the direct solver).
    pub fn krylov_iterations(&self) -> usize {
        self.krylov().map_or(0, |k| k.iterations)
    }

    /// Solve r(u) = 0 for the step of `sys`; the rows of newton.csv carry the run's
    /// step number `step`, the cut-back level and the wall time since `started`.
    pub fn solve<const D: usize>(
        &mut self,
        m: &Model<D>,
        sys: &mut StepSystem<D>,
        step: usize,
        cutback: usize,
        started: Instant,
    ) -> Result<Converged<D>, Failure> {
        // Initial iterate: the predictor, with the prescribed components imposed.
        let mut u = sys.u_tilde.clone();
        for (ua, c) in u.iter_mut().zip(&sys.constraint) {
            for d in (0..D).filter(|&d| c.fixed[d]) {
                ua[d] = c.value[d] * sys.dt;
            }
        }
        sys.dofs.follow_ties(&mut u);
        let inertial = inertial_force(&m.particles, sys, &sys.u_tilde);
        let mut test = Convergence {
            residual_tolerance: self.residual_tolerance,
            displacement_tolerance: self.displacement_tolerance,
            applied: norm(&sys.dofs.reduce(&sys.f_ext)).max(norm(&sys.dofs.reduce(&inertial))),
            rising: 0,
            history: Vec::new(),
            last_increment: f64::NAN,
        };
        let mut method = "none".to_string();
        let mut known = None;
        for iteration in 0..=self.max_iterations {
            // Residual at the current iterate, from the step-start state (2-37),
            // unless the line search left it (and the trial state) there.
            let r = match known.take() {
                Some(r) => r,
                None => residual(m, sys, &u)?,
            };
            let r_free = sys.dofs.reduce(&r);
            let r_norm = norm(&r_free);
            let reaction = reactions(&sys.constraint, &r);
            let reference = test.reference(&reaction);
            if !r_norm.is_finite() {
                return Err(Failure {
                    particle: None,
                    message: format!("non-finite residual in Newton iteration {iteration}"),
                });
            }
            let mut row = NewtonRow {
                step: step + 1,
                time: sys.t + sys.dt,
                dt: sys.dt,
                cutback,
                iteration,
                residual: r_norm / reference,
                increment: f64::NAN,
                wall_seconds: started.elapsed().as_secs_f64(),
                linear_solver: method.clone(),
                krylov_iterations: 0,
                forcing: f64::NAN,
            };
            let floor = sys.residual_floor();
            if test.converged(iteration, r_norm, reference, floor) {
                self.log.push(row);
                return Ok(Converged { u, reaction });
            }
            let hopeless =
                test.hopeless(iteration, self.max_rising_iterations, self.stall_iterations);
            if let Some(message) = hopeless {
                self.log.push(row);
                return Err(Failure {
                    particle: None,
                    message,
                });
            }
            if iteration == self.max_iterations {
                self.log.push(row);
                break;
            }
            // Correction K δu = −r (2-38): the assembled tangent (2-40) and the direct
            // solver, or matrix-free Krylov (2-39) to the forcing term, both at u.
            debug_assert!(sys.iterate() == u.as_slice(), "the tangent is taken at u");
            let krylov_before = self.krylov_iterations();
            let correction = match &mut self.linear {
                Linear::Direct(solver) => {
                    let at = Iterate {
                        step: step + 1,
                        cutback,
                        iteration,
                    };
                    let export = self.export.as_ref().filter(|e| e.wants(iteration));
                    direct_correction(m, sys, solver, &r_free, export.map(|e| (e, at)))
                }
                Linear::Krylov(krylov) => {
                    let stop = (self.residual_tolerance * reference).max(ROUND_OFF_MARGIN * floor);
                    krylov.correction(m, sys, &u, &r_free, stop, iteration)
                }
            };
            let Correction {
                du,
                method: used,
                krylov_iterations,
                forcing,
            } = match correction {
                Ok(c) => c,
                Err(f) => {
                    // Keep the failing iteration in newton.csv.
                    row.wall_seconds = started.elapsed().as_secs_f64();
                    row.krylov_iterations = self.krylov_iterations() - krylov_before;
                    self.log.push(row);
                    return Err(f);
                }
            };
            method = used;
            // Update u ← u + s δu, s from the line search (or 1).
            let step_length = if self.line_search {
                let (length, r) = line_search(m, sys, &u, &du, r_norm);
                known = r;
                length
            } else {
                1.0
            };
            let u_norm = norm(&sys.dofs.values(&u));
            sys.dofs.apply_correction(&mut u, &du, step_length);
            test.last_increment = step_length * norm(&du)
                / norm(&sys.dofs.values(&u))
                    .max(u_norm)
                    .max(f64::MIN_POSITIVE);
            row.increment = test.last_increment;
            row.linear_solver = method.clone();
            row.krylov_iterations = krylov_iterations;
            row.forcing = forcing;
            row.wall_seconds = started.elapsed().as_secs_f64();
            self.log.push(row);
            self.iterations += 1;
        }
        Err(Failure {
            particle: None,
            message: format!(
                "Newton did not converge in {} iterations",
                self.max_iterations
            ),
        })
    }
}

/// How far above the estimated round-off floor of the residual Newton stops
/// (the estimate is a root sum of squares; the residuals it bounds scatter
/// about it by a factor of up to 1.3).
const ROUND_OFF_MARGIN: f64 = 4.0;

/// The convergence test of one attempt: ‖r‖ small against a reference force, and
/// the last correction small against u.
struct Convergence {
    residual_tolerance: f64,
    displacement_tolerance: f64,
    /// The larger of the applied and the predictor's inertial force, ‖f_ext‖ and
    /// ‖M ũ/(βΔt²)‖ over the unknowns.
    applied: f64,
    /// How many iterations in a row raised ‖r‖.
    rising: usize,
    /// ‖r‖ of every iteration so far.
    history: Vec<f64>,
    /// ‖δu‖ / ‖u‖ of the last correction (NaN before the first).
    last_increment: f64,
}

impl Convergence {
    /// The force ‖r‖ is measured against: the largest of the applied force, the
    /// inertial force and the reactions at the prescribed components (as FE codes
    /// do): a run driven only by prescribed displacements (weightless soil under a
    /// rigid footing) has no applied force.
    fn reference<const D: usize>(&self, reaction: &[Vector<D>]) -> f64 {
        let reaction_norm = reaction
            .iter()
            .map(|f| f.norm_squared())
            .sum::<f64>()
            .sqrt();
        self.applied.max(reaction_norm).max(f64::MIN_POSITIVE)
    }

    /// Has iteration `iteration`, whose residual norm is `r_norm`, converged?
    /// `floor` is the round-off the residual cannot go below (the step's
    /// terms', `StepSystem::residual_floor`: the penalty contact's): within
    /// `ROUND_OFF_MARGIN` of it the residual counts as converged.
    fn converged(&mut self, iteration: usize, r_norm: f64, reference: f64, floor: f64) -> bool {
        let tolerance = (self.residual_tolerance * reference).max(ROUND_OFF_MARGIN * floor);
        let residual_ok = r_norm <= tolerance || r_norm == 0.0;
        // Near rest (e.g. settled on absorbing faces) ‖u‖ → 0 and ‖δu‖/‖u‖ stalls
        // at round-off: a converged residual that a correction no longer halves
        // is at the round-off floor and accepted.
        let previous = self.history.last().copied().unwrap_or(f64::INFINITY);
        let stalled = iteration >= 2 && r_norm >= 0.5 * previous;
        self.rising = if r_norm > previous {
            self.rising + 1
        } else {
            0
        };
        self.history.push(r_norm);
        let increment_ok =
            iteration == 0 || self.last_increment <= self.displacement_tolerance || stalled;
        residual_ok && increment_ok
    }

    /// Has ‖r‖ fallen by less than `STALL_REDUCTION` over the last `n`
    /// iterations (‖r_i‖ > STALL_REDUCTION ‖r_{i−n}‖)? Newton that creeps like
    /// this is not converging within any useful number of iterations.
    fn stalled_over(&self, n: usize) -> bool {
        let h = &self.history;
        n < h.len() && h[h.len() - 1] > STALL_REDUCTION * h[h.len() - 1 - n]
    }

    /// Why this attempt will not converge, if its residual history up to
    /// `iteration` says so: ‖r‖ rose in `max_rising` consecutive iterations,
    /// or fell by less than `STALL_REDUCTION` over the last `stall`
    /// (`usize::MAX`: no such check).
    fn hopeless(&self, iteration: usize, max_rising: usize, stall: usize) -> Option<String> {
        if self.rising >= max_rising {
            return Some(format!(
                "the residual rose in {} consecutive Newton iterations, to iteration {iteration} (max_rising_iterations = {max_rising})",
                self.rising
            ));
        }
        self.stalled_over(stall).then(|| {
            format!(
                "the residual fell by less than {:.0} % over the last {stall} Newton iterations, to iteration {iteration} (stall_iterations)",
                100.0 * (1.0 - STALL_REDUCTION)
            )
        })
    }
}

/// A residual that has not fallen below this fraction of its value
/// `stall_iterations` iterations earlier has stalled (a fall of less than 10 %).
pub const STALL_REDUCTION: f64 = 0.9;

/// δu = −K⁻¹ r with the assembled consistent tangent (2-40), factorized by the
/// direct solver; with `export`, K and −r are written too.
fn direct_correction<const D: usize>(
    m: &Model<D>,
    sys: &StepSystem<D>,
    solver: &mut DirectSolver,
    r_free: &[f64],
    export: Option<(&Export, Iterate)>,
) -> Result<Correction, Failure> {
    let rhs: Vec<f64> = r_free.iter().map(|x| -x).collect();
    let (k, used, du) = factorized_tangent(m, sys, solver, &rhs)?;
    if let Some((e, at)) = export {
        e.write(m, sys, &k, &rhs, at)?;
    }
    Ok(Correction {
        du,
        method: used.name().to_string(),
        krylov_iterations: 0,
        forcing: f64::NAN,
    })
}

/// K at the current iterate (2-40), assembled and factorized by `solver`, and
/// the solution x of K x = b (solved with the factorization's check). A new
/// pattern's ordering and symbolic factorization (sequential) run beside the
/// assembly of K's values (parallel) when K is expected to be symmetric: no
/// F-bar and the last K was (a material whose tangent turns unsymmetric wastes
/// one analysis; LU analyses its own pattern).
pub fn factorized_tangent<'s, const D: usize>(
    m: &Model<D>,
    sys: &'s StepSystem<D>,
    solver: &mut DirectSolver,
    b: &[f64],
) -> Result<(Tangent<'s>, Method, Vec<f64>), Failure> {
    let pattern = step_pattern(sys);
    let symmetric = sys.trial.fbar.is_none() && solver.structure() != Some(Structure::General);
    let (k, _) = rayon::join(
        || tangent(m, sys, false),
        || {
            if symmetric {
                // An error here comes back from the assembly or the
                // factorization below.
                if let Ok(lower) = pattern.csc(Storage::Lower) {
                    let order = Ordering::Given(pattern.ordering::<D>(sys.direct_ordering));
                    let _ = solver.analyse(lower, order);
                }
            }
        },
    );
    let k = k?;
    let structure = Structure::of(k.symmetric());
    let (used, x) = solver
        .factorize_and_solve(k.matrix(), structure, ordering(sys, &k), b)
        .map_err(linear_failure)?;
    Ok((k, used, x))
}

fn linear_failure(e: SolveError) -> Failure {
    Failure {
        particle: None,
        message: format!("linear solve failed: {e}"),
    }
}

/// Backtracking on ‖r‖: halve the step length until the residual decreases
/// (at most 6 halvings; if none decreases it, the length with the smallest
/// residual). Returns the length, and the residual there if it was the last
/// evaluated (the trial state is then that of the new iterate).
fn line_search<const D: usize>(
    m: &Model<D>,
    sys: &mut StepSystem<D>,
    u: &[Vector<D>],
    du: &[f64],
    r_norm: f64,
) -> (f64, Option<Vec<Vector<D>>>) {
    const SHORTEST: f64 = 1.0 / 64.0;
    let (mut length, mut best) = (1.0, (f64::INFINITY, SHORTEST));
    let mut last = None;
    while length >= SHORTEST {
        let mut trial_u = u.to_vec();
        sys.dofs.apply_correction(&mut trial_u, du, length);
        last = residual(m, sys, &trial_u).ok();
        if let Some(r) = &last {
            let trial = norm(&sys.dofs.reduce(r));
            if trial < r_norm {
                return (length, last);
            }
            if trial < best.0 {
                best = (trial, length);
            }
        }
        length *= 0.5;
    }
    // No length lowered ‖r‖: the one that raised it least. Its residual (and
    // the trial state) is the last evaluated only if it is the shortest.
    (best.1, last.filter(|_| best.1 == SHORTEST))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn after(residuals: &[f64]) -> Convergence {
        let mut c = Convergence {
            residual_tolerance: 1e-6,
            displacement_tolerance: 1e-6,
            applied: 1.0,
            rising: 0,
            history: Vec::new(),
            last_increment: f64::NAN,
        };
        for (i, r) in residuals.iter().enumerate() {
            assert!(!c.converged(i, *r, 1.0, 0.0));
        }
        c
    }

    #[test]
    fn a_residual_creeping_down_by_less_than_ten_percent_over_the_window_has_stalled() {
        // Falling 2 % per iteration: 0.98^5 = 0.904 > 0.9 over five iterations.
        let creep: Vec<f64> = (0..8).map(|i| 1e-2 * 0.98f64.powi(i)).collect();
        assert!(after(&creep).stalled_over(5));
        // Not before the window is full, and not with a longer window.
        assert!(!after(&creep[..5]).stalled_over(5));
        assert!(!after(&creep).stalled_over(8));
        // Falling 3 % per iteration: 0.97^5 = 0.859, still converging.
        let falling: Vec<f64> = (0..8).map(|i| 1e-2 * 0.97f64.powi(i)).collect();
        assert!(!after(&falling).stalled_over(5));
        // A plateau broken by a fast fall within the window is not a stall.
        let plateau = [1e-2, 9.9e-3, 9.8e-3, 9.7e-3, 9.6e-3, 1e-3];
        assert!(!after(&plateau).stalled_over(5));
    }
}
