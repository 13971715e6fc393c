//! Mohr–Coulomb as a second-order cone, and a small builder for the conic
//! programs handed to clarabel.
//!
//! Sign convention: tension positive (compression negative), stresses as
//! (σx, σy, τxy). The plane-strain Mohr–Coulomb criterion
//!
//! ```text
//! sqrt((σx − σy)² + (2 τxy)²) ≤ 2 c cos φ − (σx + σy) sin φ
//! ```
//!
//! is the cone (t, u, v) ∈ Q³, t ≥ ‖(u, v)‖, with t = 2c cos φ − (σx + σy) sin φ,
//! u = σx − σy, v = 2 τxy. Clarabel's form is A x + s = b with s in the cone, so
//! the rows below give s = b − A σ.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use std::fmt;

/// Clarabel's iteration limit unless the scene sets `solver.max_iterations`.
pub const MAX_ITERATIONS: u32 = 300;

/// Plane-strain Mohr–Coulomb strength: cohesion c ≥ 0, friction angle φ in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulomb {
    pub cohesion: f64,
    pub friction_angle: f64,
}

impl MohrCoulomb {
    /// Strength reduced by F in the strength-reduction sense: c/F, atan(tan φ / F).
    pub fn reduced(&self, factor: f64) -> MohrCoulomb {
        MohrCoulomb {
            cohesion: self.cohesion / factor,
            friction_angle: (self.friction_angle.tan() / factor).atan(),
        }
    }

    /// The three cone rows: coefficients on (σx, σy, τxy) and right-hand sides, so
    /// that s = b − A σ = (2c cos φ − (σx + σy) sin φ, σx − σy, 2τxy).
    pub fn cone_rows(&self) -> ([[f64; 3]; 3], [f64; 3]) {
        let (s, c) = self.friction_angle.sin_cos();
        (
            [[s, s, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, -2.0]],
            [2.0 * self.cohesion * c, 0.0, 0.0],
        )
    }

    /// t − ‖(u, v)‖: ≥ 0 inside the yield surface, 0 on it.
    pub fn margin(&self, sigma: [f64; 3]) -> f64 {
        let (s, c) = self.friction_angle.sin_cos();
        let [sx, sy, txy] = sigma;
        2.0 * self.cohesion * c - (sx + sy) * s - (sx - sy).hypot(2.0 * txy)
    }
}

/// One linear form: (variable, coefficient) pairs.
pub type Row = Vec<(usize, f64)>;

/// A conic program: minimise qᵀx subject to equality rows and Mohr–Coulomb cones
/// on triples of variables.
#[derive(Clone, Debug, Default)]
pub struct ConicProgram {
    pub variables: usize,
    pub objective: Vec<(usize, f64)>,
    equalities: Vec<(Row, f64)>,
    /// Factor each equality row was multiplied by (to undo it on the duals).
    row_scales: Vec<f64>,
    cones: Vec<([usize; 3], MohrCoulomb)>,
}

/// What clarabel returned.
#[derive(Clone, Debug)]
pub struct ConicSolution {
    pub x: Vec<f64>,
    /// Multipliers of the equality rows, in the order they were added.
    pub equality_duals: Vec<f64>,
    /// Primal objective (of a primal-feasible point).
    pub objective: f64,
    /// Dual objective: a bound on the optimum from below.
    pub dual_objective: f64,
    pub iterations: u32,
    pub seconds: f64,
    pub status: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SolverFailure {
    pub status: String,
    pub iterations: u32,
}

impl fmt::Display for SolverFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the conic solver (clarabel) stopped with status {} after {} iterations",
            self.status, self.iterations
        )
    }
}

impl std::error::Error for SolverFailure {}

impl ConicProgram {
    pub fn new(variables: usize) -> Self {
        ConicProgram {
            variables,
            ..Default::default()
        }
    }

    /// Σ coefficient · x = rhs. The row is scaled by its largest coefficient
    /// (which does not change the feasible set).
    pub fn equal(&mut self, row: Row, rhs: f64) -> usize {
        let scale = row.iter().fold(0.0f64, |m, &(_, a)| m.max(a.abs()));
        let scale = if scale > 0.0 { 1.0 / scale } else { 1.0 };
        let row = row.into_iter().map(|(j, a)| (j, a * scale)).collect();
        self.equalities.push((row, rhs * scale));
        self.row_scales.push(scale);
        self.equalities.len() - 1
    }

    /// (x[s], x[s+1], x[s+2]) = (σx, σy, τxy) lies inside `strength`.
    pub fn yield_cone(&mut self, stress: usize, strength: MohrCoulomb) {
        self.cones
            .push(([stress, stress + 1, stress + 2], strength));
    }

    /// Residual of every equality row (as scaled) at a point x.
    pub fn equality_residuals(&self, x: &[f64]) -> Vec<f64> {
        self.equalities
            .iter()
            .map(|(row, rhs)| row.iter().map(|&(j, a)| a * x[j]).sum::<f64>() - rhs)
            .collect()
    }

    pub fn equalities(&self) -> usize {
        self.equalities.len()
    }

    pub fn cones(&self) -> usize {
        self.cones.len()
    }

    /// Solve with clarabel (direct KKT factorisation, default tolerances 1e-8)
    /// in at most `max_iterations` interior-point iterations.
    pub fn solve(&self, max_iterations: u32) -> Result<ConicSolution, SolverFailure> {
        let n = self.variables;
        let (mut rows, mut cols, mut vals, mut b) = (vec![], vec![], vec![], vec![]);
        for (r, (row, rhs)) in self.equalities.iter().enumerate() {
            for &(j, a) in row {
                rows.push(r);
                cols.push(j);
                vals.push(a);
            }
            b.push(*rhs);
        }
        let m_eq = self.equalities.len();
        for (k, (vars, strength)) in self.cones.iter().enumerate() {
            let (a, rhs) = strength.cone_rows();
            for i in 0..3 {
                for (j, &v) in vars.iter().enumerate() {
                    if a[i][j] != 0.0 {
                        rows.push(m_eq + 3 * k + i);
                        cols.push(v);
                        vals.push(a[i][j]);
                    }
                }
                b.push(rhs[i]);
            }
        }
        let m = b.len();
        let a = CscMatrix::new_from_triplets(m, n, rows, cols, vals);
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        for &(j, c) in &self.objective {
            q[j] += c;
        }
        let mut cones = vec![SupportedConeT::ZeroConeT(m_eq)];
        cones.extend((0..self.cones.len()).map(|_| SupportedConeT::SecondOrderConeT(3)));
        // A static regularisation a little above clarabel's default (1e-8)
        // avoids the factorisation breakdowns seen on graded meshes of a few
        // thousand triangles.
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(max_iterations)
            .presolve_enable(false)
            .static_regularization_constant(1e-7)
            .build()
            .expect("valid clarabel settings");
        let failure = |status: String| SolverFailure {
            status,
            iterations: 0,
        };
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
            .map_err(|e| failure(format!("setup error: {e}")))?;
        solver.solve();
        let s = &solver.solution;
        let status = format!("{:?}", s.status);
        // A run that stalled numerically is still usable when it had converged
        // to a small duality gap with small residuals: the callers report the
        // primal (lower bound) or dual (upper bound) objective, which stay on the
        // safe side.
        let gap = (s.obj_val - s.obj_val_dual).abs() / s.obj_val.abs().max(1.0);
        let converged = gap < 1e-4 && s.r_prim < 1e-6 && s.r_dual < 1e-6;
        let stalled = matches!(
            s.status,
            SolverStatus::NumericalError
                | SolverStatus::InsufficientProgress
                | SolverStatus::MaxIterations
        );
        let solved = matches!(s.status, SolverStatus::Solved | SolverStatus::AlmostSolved);
        if !(solved || stalled && converged) {
            return Err(SolverFailure {
                status,
                iterations: s.iterations,
            });
        }
        Ok(ConicSolution {
            x: s.x.clone(),
            equality_duals: s.z[..m_eq]
                .iter()
                .zip(&self.row_scales)
                .map(|(z, k)| z * k)
                .collect(),
            objective: s.obj_val,
            dual_objective: s.obj_val_dual,
            iterations: s.iterations,
            seconds: s.solve_time,
            status,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cone rows reproduce the criterion: s = b − Aσ has t − ‖(u,v)‖ equal to
    /// the margin, and the margin vanishes on the Mohr–Coulomb envelope.
    #[test]
    fn cone_rows_are_the_mohr_coulomb_criterion() {
        let mc = MohrCoulomb {
            cohesion: 3.0,
            friction_angle: 25f64.to_radians(),
        };
        let (a, b) = mc.cone_rows();
        for sigma in [[-5.0, -1.0, 2.0], [1.0, 0.5, -0.3], [-20.0, -20.0, 0.0]] {
            let s: Vec<f64> = (0..3)
                .map(|i| b[i] - (0..3).map(|j| a[i][j] * sigma[j]).sum::<f64>())
                .collect();
            let cone = s[0] - s[1].hypot(s[2]);
            assert!((cone - mc.margin(sigma)).abs() < 1e-12);
        }
        // A state on the envelope: principal stresses σ1 = −1 (minor compression),
        // σ3 from σ1 − σ3 = 2c cos φ − (σ1 + σ3) sin φ, rotated by 30°.
        let (s, c) = mc.friction_angle.sin_cos();
        let s1 = -1.0;
        let s3 = (s1 * (1.0 + s) - 2.0 * 3.0 * c) / (1.0 - s);
        let (cr, sr) = (60f64.to_radians().cos(), 60f64.to_radians().sin());
        let (m, r) = (0.5 * (s1 + s3), 0.5 * (s1 - s3));
        let sigma = [m + r * cr, m - r * cr, r * sr];
        assert!(mc.margin(sigma).abs() < 1e-12, "{}", mc.margin(sigma));
        // Tension apex: hydrostatic σ = c cot φ is the only state with zero radius.
        let apex = mc.cohesion / mc.friction_angle.tan();
        assert!(mc.margin([apex, apex, 0.0]).abs() < 1e-12);
    }

    #[test]
    fn strength_reduction_divides_cohesion_and_tan_phi() {
        let mc = MohrCoulomb {
            cohesion: 10.0,
            friction_angle: 20f64.to_radians(),
        };
        let r = mc.reduced(1.5);
        assert!((r.cohesion - 10.0 / 1.5).abs() < 1e-14);
        assert!((r.friction_angle.tan() - 20f64.to_radians().tan() / 1.5).abs() < 1e-14);
    }

    /// A single point in pure shear: maximise τ subject to the Tresca cone gives c.
    #[test]
    fn solver_finds_the_shear_strength_of_one_point() {
        let mut p = ConicProgram::new(3);
        p.yield_cone(
            0,
            MohrCoulomb {
                cohesion: 2.0,
                friction_angle: 0.0,
            },
        );
        p.equal(vec![(0, 1.0), (1, 1.0)], 0.0);
        p.objective = vec![(2, -1.0)];
        let s = p.solve(MAX_ITERATIONS).unwrap();
        assert!((s.x[2] - 2.0).abs() < 1e-6, "{:?}", s.x);
    }
}
