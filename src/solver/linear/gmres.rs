//! Restarted GMRES(m) with right preconditioning (Saad & Schultz 1986; Saad,
//! *Iterative Methods for Sparse Linear Systems*, 2nd ed., §6.5 and §9.3.2).
//!
//! The operator is only ever applied to vectors, so it may be a matrix-free
//! product (thesis 2-39). Right preconditioning, A M⁻¹ y = b with x = M⁻¹ y,
//! keeps the residual that GMRES minimises equal to the true residual b − A x,
//! which is what an inexact Newton method's forcing term bounds.
//!
//! One cycle: Arnoldi with modified Gram–Schmidt builds an orthonormal basis V of
//! the Krylov space of A M⁻¹ and the (j+1)×j Hessenberg matrix H; Givens rotations
//! reduce H to triangular form as it grows, so the least-squares residual
//! ‖β e₁ − H y‖ is known after every iteration without solving for y. At the end
//! of a cycle x ← x + M⁻¹ V y, and the next cycle restarts from the true residual.

use super::iterative::{axpy, dot, norm, Outcome, Preconditioner, Settings};

/// A plane rotation [c s; −s c] that maps (a, b) to (r, 0).
#[derive(Clone, Copy, Debug)]
struct Givens {
    c: f64,
    s: f64,
}

impl Givens {
    fn zeroing(a: f64, b: f64) -> Givens {
        if b == 0.0 {
            return Givens { c: 1.0, s: 0.0 };
        }
        let r = a.hypot(b);
        Givens { c: a / r, s: b / r }
    }

    fn apply(&self, a: &mut f64, b: &mut f64) {
        let (x, y) = (*a, *b);
        *a = self.c * x + self.s * y;
        *b = -self.s * x + self.c * y;
    }
}

/// Solve A x = b starting from `x`. `apply(v, out)` writes A v into `out`; an
/// error from it aborts the solve and is returned.
pub fn gmres<E>(
    mut apply: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    precond: &dyn Preconditioner,
    b: &[f64],
    x: &mut [f64],
    settings: &Settings,
) -> Result<Outcome, E> {
    let n = b.len();
    let m = settings.restart.max(1).min(n.max(1));
    let b_norm = norm(b);
    let target = settings.tolerance * b_norm;
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
    let mut r = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut z = vec![0.0; n];
    // Basis vectors V (m + 1 of them) and the rotated Hessenberg columns.
    let mut v: Vec<Vec<f64>> = Vec::with_capacity(m + 1);
    let mut h: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut rotations: Vec<Givens> = Vec::with_capacity(m);
    loop {
        // r = b − A x (true residual at the start of each cycle).
        apply(x, &mut w)?;
        for i in 0..n {
            r[i] = b[i] - w[i];
        }
        let beta = norm(&r);
        outcome.relative_residual = beta / b_norm;
        if beta <= target {
            outcome.converged = true;
            return Ok(outcome);
        }
        if outcome.iterations >= settings.max_iterations {
            outcome.converged = false;
            return Ok(outcome);
        }
        v.clear();
        h.clear();
        rotations.clear();
        v.push(r.iter().map(|ri| ri / beta).collect());
        // g = β e₁, rotated along with H.
        let mut g = vec![0.0; m + 1];
        g[0] = beta;
        let mut k = 0;
        while k < m && outcome.iterations < settings.max_iterations {
            // w = A M⁻¹ v_k.
            precond.apply(&v[k], &mut z);
            apply(&z, &mut w)?;
            outcome.iterations += 1;
            // Modified Gram–Schmidt against v_0 … v_k.
            let mut column = vec![0.0; k + 2];
            for (i, vi) in v.iter().enumerate() {
                column[i] = dot(&w, vi);
                axpy(-column[i], vi, &mut w);
            }
            let w_norm = norm(&w);
            column[k + 1] = w_norm;
            for (i, rot) in rotations.iter().enumerate() {
                let (lo, hi) = column.split_at_mut(i + 1);
                rot.apply(&mut lo[i], &mut hi[0]);
            }
            let rot = Givens::zeroing(column[k], column[k + 1]);
            {
                let (lo, hi) = column.split_at_mut(k + 1);
                rot.apply(&mut lo[k], &mut hi[0]);
            }
            {
                let (lo, hi) = g.split_at_mut(k + 1);
                rot.apply(&mut lo[k], &mut hi[0]);
            }
            rotations.push(rot);
            h.push(column);
            k += 1;
            outcome.relative_residual = g[k].abs() / b_norm;
            // A zero w_norm is a "lucky breakdown": the Krylov space is invariant
            // and the least-squares solution is exact.
            if g[k].abs() <= target || w_norm <= f64::EPSILON * beta {
                break;
            }
            v.push(w.iter().map(|wi| wi / w_norm).collect());
        }
        // y from the triangular system R y = g, then x += M⁻¹ V y.
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let s: f64 = (i + 1..k).map(|j| h[j][i] * y[j]).sum();
            y[i] = (g[i] - s) / h[i][i];
        }
        let mut vy = vec![0.0; n];
        for (j, yj) in y.iter().enumerate() {
            axpy(*yj, &v[j], &mut vy);
        }
        precond.apply(&vy, &mut z);
        axpy(1.0, &z, x);
        if g[k].abs() <= target {
            outcome.converged = true;
            return Ok(outcome);
        }
        if !y.iter().all(|v| v.is_finite()) {
            outcome.converged = false;
            outcome.breakdown = Some("non-finite least-squares solution");
            return Ok(outcome);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::iterative::test_matrices::*;
    use super::super::iterative::Identity;
    use super::*;
    use std::convert::Infallible;

    fn solve(
        a: &[f64],
        n: usize,
        b: &[f64],
        precond: &dyn Preconditioner,
        settings: Settings,
    ) -> (Vec<f64>, Outcome) {
        let mut x = vec![0.0; n];
        let op = |v: &[f64], out: &mut [f64]| -> Result<(), Infallible> {
            product(a, n, v, out);
            Ok(())
        };
        let outcome = gmres(op, precond, b, &mut x, &settings).unwrap();
        (x, outcome)
    }

    fn rhs(n: usize) -> Vec<f64> {
        (0..n).map(|i| ((i * 7 + 3) % 11) as f64 - 5.0).collect()
    }

    /// Full (unrestarted) GMRES solves an n×n system in at most n iterations, in
    /// exact arithmetic; here to 1e-10, for an SPD and a nonsymmetric matrix.
    #[test]
    fn converges_in_at_most_n_iterations() {
        let n = 40;
        for (name, a) in [
            ("laplacian", laplacian(n)),
            ("convection-diffusion", convection_diffusion(n, 0.6)),
        ] {
            let b = rhs(n);
            let settings = Settings {
                tolerance: 1e-10,
                max_iterations: 10 * n,
                restart: n,
            };
            let (x, out) = solve(&a, n, &b, &Identity, settings);
            let res = relative_residual(&a, n, &x, &b);
            println!("{name}: {} iterations, residual {res:.2e}", out.iterations);
            assert!(out.converged, "{name}: {out:?}");
            assert!(out.iterations <= n, "{name}: {} > n", out.iterations);
            assert!(res < 1e-9, "{name}: true residual {res:.2e}");
        }
    }

    /// With a diagonal matrix of k distinct eigenvalues, the minimal polynomial has
    /// degree k, so GMRES finishes in k iterations.
    #[test]
    fn finishes_in_as_many_iterations_as_distinct_eigenvalues() {
        let n = 30;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = [1.0, 3.0, 7.0, 20.0][i % 4];
        }
        let (x, out) = solve(
            &a,
            n,
            &rhs(n),
            &Identity,
            Settings {
                tolerance: 1e-12,
                max_iterations: 100,
                restart: 50,
            },
        );
        assert_eq!(out.iterations, 4, "{out:?}");
        assert!(relative_residual(&a, n, &x, &rhs(n)) < 1e-12);
    }

    /// Restarting: GMRES(m) still converges, with more iterations than full GMRES;
    /// the residual after each cycle never grows (GMRES minimises it over a space
    /// that contains the previous iterate); an iteration cap is reported as failure.
    #[test]
    fn restarted_gmres_converges_and_reports_the_cap() {
        let n = 60;
        let a = convection_diffusion(n, 0.3);
        let b = rhs(n);
        let full = |restart| {
            solve(
                &a,
                n,
                &b,
                &Identity,
                Settings {
                    tolerance: 1e-8,
                    max_iterations: 5000,
                    restart,
                },
            )
        };
        let (_, whole) = full(n);
        let (x, restarted) = full(8);
        println!(
            "full GMRES {} iterations, GMRES(8) {}",
            whole.iterations, restarted.iterations
        );
        assert!(whole.converged && restarted.converged);
        assert!(relative_residual(&a, n, &x, &b) < 1e-7);
        assert!(restarted.iterations > whole.iterations);
        // Monotone residual across cycles: cap the iterations at whole cycles.
        let mut last = f64::INFINITY;
        for cycles in 1..6 {
            let (x, out) = solve(
                &a,
                n,
                &b,
                &Identity,
                Settings {
                    tolerance: 1e-14,
                    max_iterations: 8 * cycles,
                    restart: 8,
                },
            );
            let res = relative_residual(&a, n, &x, &b);
            assert!(!out.converged && out.iterations == 8 * cycles, "{out:?}");
            assert!(
                res <= last * (1.0 + 1e-12),
                "cycle {cycles}: {res} > {last}"
            );
            assert!((res - out.relative_residual).abs() < 1e-8);
            last = res;
        }
    }

    /// Right Jacobi preconditioning of a matrix with columns scaled over four
    /// decades restores the iteration count of the unscaled matrix
    /// (A D (diag(A) D)⁻¹ = A / 2 here).
    #[test]
    fn jacobi_preconditioning_undoes_column_scaling() {
        use super::super::preconditioner::Jacobi;
        let n = 50;
        let plain = convection_diffusion(n, 0.2);
        let mut scaled = plain.clone();
        scale_columns(&mut scaled, n);
        let b = rhs(n);
        let settings = Settings {
            tolerance: 1e-8,
            max_iterations: 2000,
            restart: 20,
        };
        let (_, reference) = solve(&plain, n, &b, &Identity, settings);
        let (_, unpreconditioned) = solve(&scaled, n, &b, &Identity, settings);
        let jacobi = Jacobi::new((0..n).map(|i| scaled[i * n + i]).collect());
        let (x, preconditioned) = solve(&scaled, n, &b, &jacobi, settings);
        println!(
            "unscaled {} / scaled {} ({}) / scaled + Jacobi {}",
            reference.iterations,
            unpreconditioned.iterations,
            unpreconditioned.converged,
            preconditioned.iterations
        );
        assert!(preconditioned.converged);
        assert!(relative_residual(&scaled, n, &x, &b) < 1e-8);
        assert!(preconditioned.iterations <= reference.iterations + 2);
        assert!(unpreconditioned.iterations > 2 * preconditioned.iterations);
    }

    #[test]
    fn zero_right_hand_side_gives_zero() {
        let n = 5;
        let (x, out) = solve(
            &laplacian(n),
            n,
            &vec![0.0; n],
            &Identity,
            Settings {
                tolerance: 1e-8,
                max_iterations: 10,
                restart: 5,
            },
        );
        assert!(out.converged && out.iterations == 0 && x.iter().all(|v| *v == 0.0));
    }
}
