//! Preconditioned conjugate gradients (Hestenes & Stiefel 1952; Saad, *Iterative
//! Methods for Sparse Linear Systems*, 2nd ed., Algorithm 9.1) for symmetric
//! positive definite A and M. Like GMRES it only applies A to vectors.
//!
//! A direction with pᵀA p ≤ 0 proves that A is not positive definite (or, for a
//! finite-difference product, too far from it); the solve then stops and reports
//! the breakdown instead of dividing by it.

use super::iterative::{axpy, dot, norm, Outcome, Preconditioner, Settings};

/// Solve A x = b starting from `x`. `apply(v, out)` writes A v into `out`; an
/// error from it aborts the solve and is returned.
pub fn cg<E>(
    mut apply: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    precond: &dyn Preconditioner,
    b: &[f64],
    x: &mut [f64],
    settings: &Settings,
) -> Result<Outcome, E> {
    let n = b.len();
    let b_norm = norm(b);
    let mut outcome = Outcome {
        iterations: 0,
        relative_residual: 0.0,
        converged: true,
        breakdown: None,
    };
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return Ok(outcome);
    }
    let target = settings.tolerance * b_norm;
    let mut q = vec![0.0; n];
    apply(x, &mut q)?;
    let mut r: Vec<f64> = b.iter().zip(&q).map(|(bi, qi)| bi - qi).collect();
    let mut z = vec![0.0; n];
    precond.apply(&r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    loop {
        let r_norm = norm(&r);
        outcome.relative_residual = r_norm / b_norm;
        if r_norm <= target {
            outcome.converged = true;
            return Ok(outcome);
        }
        if outcome.iterations >= settings.max_iterations {
            outcome.converged = false;
            return Ok(outcome);
        }
        // Written so that NaN also stops the iteration.
        if rz.is_nan() || rz <= 0.0 {
            outcome.converged = false;
            outcome.breakdown = Some("the preconditioner is not positive definite");
            return Ok(outcome);
        }
        apply(&p, &mut q)?;
        outcome.iterations += 1;
        let curvature = dot(&p, &q);
        if curvature.is_nan() || curvature <= 0.0 {
            outcome.converged = false;
            outcome.breakdown =
                Some("a search direction with pᵀA p ≤ 0: A is not positive definite");
            return Ok(outcome);
        }
        let alpha = rz / curvature;
        axpy(alpha, &p, x);
        axpy(-alpha, &q, &mut r);
        precond.apply(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for (pi, zi) in p.iter_mut().zip(&z) {
            *pi = zi + beta * *pi;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::iterative::test_matrices::*;
    use super::super::iterative::Identity;
    use super::super::preconditioner::Jacobi;
    use super::*;
    use std::convert::Infallible;

    fn solve(
        a: &[f64],
        n: usize,
        b: &[f64],
        precond: &dyn Preconditioner,
        max_iterations: usize,
    ) -> (Vec<f64>, Outcome) {
        let mut x = vec![0.0; n];
        let op = |v: &[f64], out: &mut [f64]| -> Result<(), Infallible> {
            product(a, n, v, out);
            Ok(())
        };
        let settings = Settings {
            tolerance: 1e-10,
            max_iterations,
            restart: 0,
        };
        let outcome = cg(op, precond, b, &mut x, &settings).unwrap();
        (x, outcome)
    }

    fn rhs(n: usize) -> Vec<f64> {
        (0..n).map(|i| ((i * 5 + 1) % 9) as f64 - 4.0).collect()
    }

    /// CG on an SPD matrix of order n: at most n iterations (exact arithmetic);
    /// the 1D Laplacian of order 30 needs close to n since its spectrum is spread.
    #[test]
    fn converges_in_at_most_n_iterations_on_spd() {
        let n = 30;
        let a = laplacian(n);
        let (x, out) = solve(&a, n, &rhs(n), &Identity, 10 * n);
        println!("laplacian({n}): {} iterations", out.iterations);
        assert!(out.converged && out.iterations <= n, "{out:?}");
        assert!(relative_residual(&a, n, &x, &rhs(n)) < 1e-9);
    }

    /// Symmetric scaling D A D with d over two decades: plain CG needs far more
    /// than n iterations in floating point; with Jacobi (M^{-1/2} A M^{-1/2} = A/2)
    /// it is back within n.
    #[test]
    fn jacobi_preconditioned_cg_on_a_badly_scaled_spd_matrix() {
        let n = 40;
        let base = laplacian(n);
        let d: Vec<f64> = (0..n)
            .map(|i| 10f64.powf(2.0 * i as f64 / n as f64))
            .collect();
        let a: Vec<f64> = (0..n * n).map(|k| d[k / n] * base[k] * d[k % n]).collect();
        let b = rhs(n);
        let (_, reference) = solve(&base, n, &b, &Identity, 10 * n);
        let (_, plain) = solve(&a, n, &b, &Identity, 10 * n);
        let jacobi = Jacobi::new((0..n).map(|i| a[i * n + i]).collect());
        let (x, pre) = solve(&a, n, &b, &jacobi, 10 * n);
        println!(
            "unscaled {} / scaled {} / scaled + Jacobi {}",
            reference.iterations, plain.iterations, pre.iterations
        );
        assert!(pre.converged && pre.iterations <= n);
        assert!(relative_residual(&a, n, &x, &b) < 1e-9);
        assert!(plain.iterations > 2 * pre.iterations);
    }

    /// An indefinite matrix: CG stops with a breakdown instead of a wrong answer.
    #[test]
    fn reports_indefinite_matrices() {
        let n = 6;
        let mut a = laplacian(n);
        a[0] = -3.0;
        let b = vec![1.0; n];
        let (_, out) = solve(&a, n, &b, &Identity, 100);
        assert!(!out.converged, "{out:?}");
        assert!(out.breakdown.is_some());
    }

    #[test]
    fn reports_the_iteration_cap() {
        let n = 50;
        let (_, out) = solve(&laplacian(n), n, &rhs(n), &Identity, 5);
        assert!(!out.converged && out.iterations == 5 && out.breakdown.is_none());
    }
}
