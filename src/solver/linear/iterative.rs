//! What the Krylov solvers (GMRES, CG) share: the preconditioner interface, the
//! settings and the outcome of one solve, and serial vector kernels (serial so that
//! the result does not depend on the number of threads; the operator products,
//! not these, dominate the cost).

/// z = M⁻¹ r for a preconditioner M ≈ A.
pub trait Preconditioner {
    fn apply(&self, r: &[f64], z: &mut [f64]);
}

/// M = I.
#[derive(Clone, Copy, Debug, Default)]
pub struct Identity;

impl Preconditioner for Identity {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
    }
}

/// Stopping rule of one linear solve.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Stop when ‖b − A x‖ ≤ tolerance · ‖b‖.
    pub tolerance: f64,
    /// Largest number of operator products (iterations) in total.
    pub max_iterations: usize,
    /// GMRES restart length m (ignored by CG).
    pub restart: usize,
}

/// How one linear solve ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// Iterations taken (one operator product each, not counting the products
    /// that form the initial and restart residuals).
    pub iterations: usize,
    /// Final ‖b − A x‖ / ‖b‖ (GMRES: the value its least-squares problem reports;
    /// CG: the recursively updated residual).
    pub relative_residual: f64,
    pub converged: bool,
    /// Why the iteration stopped early without converging (e.g. CG found a
    /// direction of non-positive curvature), if it did.
    pub breakdown: Option<&'static str>,
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// y += alpha x.
pub fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

#[cfg(test)]
pub(crate) mod test_matrices {
    //! Small dense test problems for the Krylov solvers.

    /// Dense row-major matrix-vector product y = A x.
    pub fn product(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
        for i in 0..n {
            y[i] = (0..n).map(|j| a[i * n + j] * x[j]).sum();
        }
    }

    /// The 1D Laplacian tridiag(−1, 2, −1) of order n (SPD, condition ~ 4n²/π²).
    pub fn laplacian(n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 2.0;
            if i > 0 {
                a[i * n + i - 1] = -1.0;
            }
            if i + 1 < n {
                a[i * n + i + 1] = -1.0;
            }
        }
        a
    }

    /// A nonsymmetric convection-diffusion matrix: tridiag(−1 − c, 2, −1 + c).
    pub fn convection_diffusion(n: usize, c: f64) -> Vec<f64> {
        let mut a = laplacian(n);
        for i in 0..n {
            if i > 0 {
                a[i * n + i - 1] -= c;
            }
            if i + 1 < n {
                a[i * n + i + 1] += c;
            }
        }
        a
    }

    /// Column-scale A: A D with d_j spanning four decades (badly scaled unknowns,
    /// which a right Jacobi preconditioner undoes exactly when diag(A) is constant).
    pub fn scale_columns(a: &mut [f64], n: usize) {
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] *= 10f64.powf(4.0 * j as f64 / n as f64);
            }
        }
    }

    /// Residual ‖b − A x‖ / ‖b‖.
    pub fn relative_residual(a: &[f64], n: usize, x: &[f64], b: &[f64]) -> f64 {
        let mut ax = vec![0.0; n];
        product(a, n, x, &mut ax);
        let r: f64 = ax.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum();
        (r / b.iter().map(|v| v * v).sum::<f64>()).sqrt()
    }
}
