//! Tests of the direct solver: methods, reuse of the symbolic factorization,
//! singular and invalid input, determinism on any number of threads.

use super::*;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
};
use faer::{Par, Side};
use std::time::Instant;

type Trip = Vec<(usize, usize, f64)>;

/// `y = K x` straight from the triplets (full matrix, duplicates add up).
fn apply(n: usize, t: &[(usize, usize, f64)], x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; n];
    for &(i, j, v) in t {
        y[i] += v * x[j];
    }
    y
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|t| t * t).sum::<f64>().sqrt()
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(s, t)| s - t).collect();
    norm(&d) / norm(b)
}

/// Smooth-ish known solution.
fn x_star(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (0.37 * i as f64).sin() + 0.1 * (i % 5) as f64)
        .collect()
}

/// Factorize, solve against x*, return (method, relative error, relative residual).
fn check_solve(
    s: &mut DirectSolver,
    n: usize,
    t: &[(usize, usize, f64)],
    st: Structure,
) -> (Method, f64, f64) {
    let method = s.factorize_triplets(n, t, st).expect("factorize");
    let xs = x_star(n);
    let b = apply(n, t, &xs);
    let x = s.solve(&b).expect("solve");
    let res = rel_diff(&apply(n, t, &x), &b);
    (method, rel_diff(&x, &xs), res)
}

/// 1D Laplacian assembled from 2x2 element matrices, grounded at both ends (SPD).
fn laplace_1d(n: usize, ground: bool) -> Trip {
    let mut t = Vec::new();
    for e in 0..n - 1 {
        let (a, b) = (e, e + 1);
        t.extend([(a, a, 1.0), (a, b, -1.0), (b, a, -1.0), (b, b, 1.0)]);
    }
    if ground {
        t.extend([(0, 0, 1.0), (n - 1, n - 1, 1.0)]);
    }
    t
}

/// 2D 5-point Laplacian (Dirichlet), diagonal `4 * scale - shift`.
/// An SPD matrix shaped like a 3D elastic tangent: the 27-point stencil of
/// an m³ node grid (strictly diagonally dominant) ⊗ a 3×3 SPD block coupling
/// the components (1, 2, 1 tridiagonal), 3 unknowns per node.
fn elastic_like_3d(m: usize) -> Trip {
    let block = [[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]];
    let id = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
    let range = |i: usize| i.saturating_sub(1)..(i + 2).min(m);
    let mut t = Vec::new();
    for (i, j, k) in (0..m).flat_map(|i| (0..m).flat_map(move |j| (0..m).map(move |k| (i, j, k)))) {
        for (p, q, r) in
            range(i).flat_map(|p| range(j).flat_map(move |q| range(k).map(move |r| (p, q, r))))
        {
            let w = if (p, q, r) == (i, j, k) { 26.5 } else { -1.0 };
            for (a, row) in block.iter().enumerate() {
                for (b, &v) in row.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                    t.push((3 * id(i, j, k) + a, 3 * id(p, q, r) + b, w * v));
                }
            }
        }
    }
    t
}

fn laplace_2d(m: usize, scale: f64, shift: f64) -> Trip {
    let id = |i: usize, j: usize| i * m + j;
    let mut t = Vec::new();
    for i in 0..m {
        for j in 0..m {
            t.push((id(i, j), id(i, j), 4.0 * scale - shift));
            if i > 0 {
                t.push((id(i, j), id(i - 1, j), -1.0));
            }
            if i + 1 < m {
                t.push((id(i, j), id(i + 1, j), -1.0));
            }
            if j > 0 {
                t.push((id(i, j), id(i, j - 1), -1.0));
            }
            if j + 1 < m {
                t.push((id(i, j), id(i, j + 1), -1.0));
            }
        }
    }
    t
}

/// 3D 7-point Laplacian (Dirichlet).
fn laplace_3d(m: usize) -> Trip {
    let id = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
    let mut t = Vec::new();
    for i in 0..m {
        for j in 0..m {
            for k in 0..m {
                let p = id(i, j, k);
                t.push((p, p, 6.0));
                let nb = [
                    (i > 0, (i.wrapping_sub(1), j, k)),
                    (i + 1 < m, (i + 1, j, k)),
                    (j > 0, (i, j.wrapping_sub(1), k)),
                    (j + 1 < m, (i, j + 1, k)),
                    (k > 0, (i, j, k.wrapping_sub(1))),
                    (k + 1 < m, (i, j, k + 1)),
                ];
                for (ok, (a, b, c)) in nb {
                    if ok {
                        t.push((p, id(a, b, c), -1.0));
                    }
                }
            }
        }
    }
    t
}

#[test]
fn laplace_1d_with_duplicates_uses_llt() {
    let n = 1000;
    let t = laplace_1d(n, true);
    let mut s = DirectSolver::new();
    let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
    eprintln!("1D Laplacian n={n}: method {method:?}, rel error {err:.2e}, rel residual {res:.2e}");
    assert_eq!(method, Method::Llt);
    assert!(err < 1e-10, "relative error {err}");
    assert_eq!(s.symbolic_count(), 1);
}

#[test]
fn lower_triangle_only_gives_same_solution() {
    let n = 200;
    let full = laplace_1d(n, true);
    let lower: Trip = full.iter().copied().filter(|t| t.0 >= t.1).collect();
    let b = apply(n, &full, &x_star(n));
    let mut s = DirectSolver::new();
    s.factorize_triplets(n, &full, Structure::Symmetric)
        .unwrap();
    let x_full = s.solve(&b).unwrap();
    s.factorize_triplets(n, &lower, Structure::Symmetric)
        .unwrap();
    assert_eq!(x_full, s.solve(&b).unwrap());
    assert_eq!(s.symbolic_count(), 1, "same lower pattern");
}

#[test]
fn laplace_2d_symbolic_reuse() {
    let m = 100;
    let n = m * m;
    let mut s = DirectSolver::new();
    let t = laplace_2d(m, 1.0, 0.0);
    let t0 = Instant::now();
    let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
    let first = t0.elapsed();
    eprintln!("2D Laplacian n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, first factorize+solve {first:?}");
    assert_eq!(method, Method::Llt);
    assert!(err < 1e-10, "relative error {err}");
    assert_eq!(s.symbolic_count(), 1);

    let t2 = laplace_2d(m, 2.0, 0.0);
    let t0 = Instant::now();
    let (method, err, res) = check_solve(&mut s, n, &t2, Structure::Symmetric);
    let second = t0.elapsed();
    eprintln!("  values changed: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, refactorize+solve {second:?}");
    assert_eq!(method, Method::Llt);
    assert!(err < 1e-10, "relative error {err}");
    assert_eq!(
        s.symbolic_count(),
        1,
        "symbolic factorization must be reused"
    );

    let mut t3 = t2.clone();
    t3.extend([(0, n - 1, -0.5), (n - 1, 0, -0.5)]);
    let (method, err, _) = check_solve(&mut s, n, &t3, Structure::Symmetric);
    assert_eq!(method, Method::Llt);
    assert!(err < 1e-10, "relative error {err}");
    assert_eq!(s.symbolic_count(), 2, "pattern changed");
}

#[test]
fn timing_2d_100x100() {
    let m = 100;
    let n = m * m;
    let t = laplace_2d(m, 1.0, 0.0);
    let mut s = DirectSolver::new();
    let t0 = Instant::now();
    s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
    let first = t0.elapsed();
    let mut times = Vec::new();
    for _ in 0..5 {
        let t0 = Instant::now();
        s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
        times.push(t0.elapsed());
    }
    let b = vec![1.0; n];
    let t0 = Instant::now();
    let _ = s.solve(&b).unwrap();
    let solve = t0.elapsed();
    eprintln!("100x100: first factorize (symbolic+numeric+check) {first:?}, reuse {times:?}, solve {solve:?}");
    assert_eq!(s.symbolic_count(), 1);
}

#[test]
fn laplace_minus_shift_is_indefinite() {
    let m = 30;
    let n = m * m;
    let t = laplace_2d(m, 1.0, 1.2345);
    let mut s = DirectSolver::new();
    let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
    eprintln!("shifted Laplacian n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}");
    assert_ne!(method, Method::Llt);
    assert!(res < 1e-8, "relative residual {res}");
}

#[test]
fn saddle_point_is_indefinite() {
    // [[A, Bᵀ], [B, 0]], A = 1D Laplacian (n_a), B sums pairs of consecutive unknowns.
    let (na, nb) = (400, 100);
    let n = na + nb;
    let mut t = laplace_1d(na, true);
    for k in 0..nb {
        for j in [4 * k, 4 * k + 1] {
            t.extend([(na + k, j, 1.0), (j, na + k, 1.0)]);
        }
    }
    let mut s = DirectSolver::new();
    let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
    eprintln!(
        "saddle point n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, symbolic {}",
        s.symbolic_count()
    );
    assert_ne!(method, Method::Llt);
    assert!(res < 1e-8, "relative residual {res}");
}

/// -eps u'' + c u' on a uniform grid, first-order upwinding (c > 0), Dirichlet ends.
fn convection_diffusion(n: usize, eps: f64, c: f64) -> Trip {
    let h = 1.0 / (n + 1) as f64;
    let (d, lo, up) = (
        2.0 * eps / (h * h) + c / h,
        -eps / (h * h) - c / h,
        -eps / (h * h),
    );
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, d));
        if i > 0 {
            t.push((i, i - 1, lo));
        }
        if i + 1 < n {
            t.push((i, i + 1, up));
        }
    }
    t
}

#[test]
fn nonsymmetric_uses_lu_and_reuses_symbolic() {
    let n = 1000;
    let t = convection_diffusion(n, 0.01, 1.0);
    let mut s = DirectSolver::new();
    let (method, err, res) = check_solve(&mut s, n, &t, Structure::General);
    eprintln!(
        "convection-diffusion n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}"
    );
    assert_eq!(method, Method::Lu);
    assert!(err < 1e-10, "relative error {err}");
    let t2 = convection_diffusion(n, 0.001, 2.0);
    let (method, err, _) = check_solve(&mut s, n, &t2, Structure::General);
    assert_eq!(method, Method::Lu);
    assert!(err < 1e-10, "relative error {err}");
    assert_eq!(s.symbolic_count(), 1);
}

#[test]
fn singular_matrices_give_errors() {
    let n = 300;
    let mut s = DirectSolver::new();
    // General: row k is all zeros (column k keeps its entries).
    let k = 150;
    let t: Trip = convection_diffusion(n, 0.01, 1.0)
        .into_iter()
        .filter(|e| e.0 != k)
        .collect();
    let r = s.factorize_triplets(n, &t, Structure::General);
    eprintln!("zero row (general): {r:?}");
    assert!(matches!(r, Err(SolveError::Singular(_))));
    assert!(matches!(
        s.solve(&vec![1.0; n]),
        Err(SolveError::NotFactorized)
    ));
    // General: row k holds an explicit 0 on the diagonal only.
    let mut t0 = t.clone();
    t0.retain(|e| e.1 != k);
    t0.push((k, k, 0.0));
    let r = s.factorize_triplets(n, &t0, Structure::General);
    eprintln!("zero row+column with explicit zero diagonal (general): {r:?}");
    assert!(matches!(r, Err(SolveError::Singular(_))));
    // Symmetric: zero row and column.
    let t: Trip = laplace_1d(n, true)
        .into_iter()
        .filter(|e| e.0 != k && e.1 != k)
        .collect();
    let r = s.factorize_triplets(n, &t, Structure::Symmetric);
    eprintln!("zero row and column (symmetric): {r:?}");
    assert!(matches!(r, Err(SolveError::Singular(_))));
    // Symmetric: pure-Neumann Laplacians, 1D and 2D.
    let r = s.factorize_triplets(n, &laplace_1d(n, false), Structure::Symmetric);
    eprintln!("pure Neumann 1D: {r:?}");
    assert!(matches!(r, Err(SolveError::Singular(_))));
    let m = 40;
    let mut t = laplace_2d(m, 1.0, 0.0);
    for (i, j, v) in t.iter_mut() {
        if i == j {
            let (a, b) = (*i / m, *i % m);
            *v = [a > 0, a + 1 < m, b > 0, b + 1 < m]
                .iter()
                .filter(|&&x| x)
                .count() as f64;
        }
    }
    let r = s.factorize_triplets(m * m, &t, Structure::Symmetric);
    eprintln!("pure Neumann 2D: {r:?}");
    assert!(matches!(r, Err(SolveError::Singular(_))));
}

/// The Newton path (`factorize_and_solve`: the right-hand side solved
/// with the probe as a second column) gives the solution of factorize +
/// solve to round-off, with the same method, for each method; a singular
/// matrix is refused as by `factorize`.
#[test]
fn factorize_and_solve_agrees_with_factorize_then_solve() {
    let cases: Vec<(usize, Trip, Structure, Method)> = vec![
        (
            10_000,
            laplace_2d(100, 1.0, 0.0),
            Structure::Symmetric,
            Method::Llt,
        ),
        (
            900,
            laplace_2d(30, 1.0, 1.2345),
            Structure::Symmetric,
            Method::Ldlt,
        ),
        (
            300,
            convection_diffusion(300, 0.01, 1.0),
            Structure::General,
            Method::Lu,
        ),
    ];
    for (n, t, structure, expected) in cases {
        let b = apply(n, &t, &x_star(n));
        let a = csc_from_triplets(n, &t, structure).unwrap();
        let mut plain = DirectSolver::new();
        let method = plain
            .factorize(a.as_ref(), structure, Ordering::Amd)
            .unwrap();
        let x = plain.solve(&b).unwrap();
        let mut fused = DirectSolver::new();
        let (method_fused, x_fused) = fused
            .factorize_and_solve(a.as_ref(), structure, Ordering::Amd, &b)
            .unwrap();
        assert_eq!(method, expected);
        assert_eq!(method_fused, expected);
        let d = rel_diff(&x_fused, &x);
        eprintln!("{expected:?}, n = {n}: fused against plain {d:.2e}");
        assert!(d < 1e-13, "{expected:?}: {d:.2e}");
        assert!(rel_diff(&x_fused, &x_star(n)) < 1e-8);
        // The fused solver can also solve again.
        assert!(rel_diff(&fused.solve(&b).unwrap(), &x) < 1e-13);
    }
    let m = 40;
    let t: Trip = laplace_1d(m, false);
    let a = csc_from_triplets(m, &t, Structure::Symmetric).unwrap();
    let mut s = DirectSolver::new();
    let r = s.factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &[1.0; 40]);
    assert!(matches!(r, Err(SolveError::Singular(_))), "{r:?}");
    assert!(matches!(
        s.solve(&[1.0; 40]),
        Err(SolveError::NotFactorized)
    ));
    let r = s.factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &[1.0; 3]);
    assert!(matches!(r, Err(SolveError::InvalidInput(_))), "{r:?}");
}

#[test]
fn invalid_input_is_reported() {
    let mut s = DirectSolver::new();
    assert!(matches!(s.solve(&[1.0]), Err(SolveError::NotFactorized)));
    let r = s.factorize_triplets(3, &[(0, 0, 1.0), (3, 0, 1.0)], Structure::General);
    assert!(matches!(r, Err(SolveError::InvalidInput(_))));
    let r = s.factorize_triplets(2, &[(0, 0, 1.0), (1, 1, f64::NAN)], Structure::General);
    assert!(matches!(r, Err(SolveError::InvalidInput(_))));
    let upper = [(0, 0, 2.0), (0, 1, -1.0), (1, 1, 2.0)];
    let r = s.factorize_triplets(2, &upper, Structure::Symmetric);
    assert!(matches!(r, Err(SolveError::InvalidInput(_))));
    s.factorize_triplets(2, &[(0, 0, 2.0), (1, 1, 4.0)], Structure::Symmetric)
        .unwrap();
    assert!(matches!(s.solve(&[1.0]), Err(SolveError::InvalidInput(_))));
    let x = s.solve(&[1.0, 1.0]).unwrap();
    assert!((x[0] - 0.5).abs() < 1e-15 && (x[1] - 0.25).abs() < 1e-15);
    for st in [Structure::Symmetric, Structure::General] {
        assert!(s.factorize_triplets(0, &[], st).is_ok());
        assert!(s.solve(&[]).unwrap().is_empty());
    }
}

#[test]
fn deterministic_results() {
    let cases: Vec<(usize, Trip, Structure)> = vec![
        (10_000, laplace_2d(100, 1.0, 0.0), Structure::Symmetric),
        (27_000, laplace_3d(30), Structure::Symmetric),
        (900, laplace_2d(30, 1.0, 1.2345), Structure::Symmetric),
        (27_000, laplace_3d(30), Structure::General),
    ];
    for (n, t, st) in cases {
        let b = apply(n, &t, &x_star(n));
        let mut s1 = DirectSolver::new();
        let m1 = s1.factorize_triplets(n, &t, st).unwrap();
        let x1 = s1.solve(&b).unwrap();
        let x1b = s1.solve(&b).unwrap();
        s1.factorize_triplets(n, &t, st).unwrap();
        let x1c = s1.solve(&b).unwrap();
        let mut s2 = DirectSolver::new();
        let m2 = s2.factorize_triplets(n, &t, st).unwrap();
        let x2 = s2.solve(&b).unwrap();
        eprintln!(
            "determinism n={n} {st:?}: {m1:?}, rel error {:.2e}",
            rel_diff(&x1, &x_star(n))
        );
        assert_eq!(m1, m2);
        assert_eq!(x1, x1b);
        assert_eq!(x1, x1c);
        assert_eq!(x1, x2);
    }
}

/// A solver that factored another matrix first (its factor buffer and
/// workspace are refilled, grown or not) gives bit for bit the solution
/// of a fresh one: simplicial (small) and supernodal factors.
#[test]
fn kept_buffers_give_the_same_factors() {
    let cases: Vec<(usize, Trip)> = vec![
        (900, laplace_2d(30, 1.0, 1.2345)),
        (10_000, laplace_2d(100, 1.0, 0.0)),
        (8_000, laplace_3d(20)),
    ];
    for (n, t) in &cases {
        let b = apply(*n, t, &x_star(*n));
        let mut fresh = DirectSolver::new();
        fresh
            .factorize_triplets(*n, t, Structure::Symmetric)
            .unwrap();
        let x = fresh.solve(&b).unwrap();
        for (m, other) in &cases {
            let mut reused = DirectSolver::new();
            reused
                .factorize_triplets(*m, other, Structure::Symmetric)
                .unwrap();
            reused
                .factorize_triplets(*n, t, Structure::Symmetric)
                .unwrap();
            assert_eq!(reused.solve(&b).unwrap(), x, "n = {n} after m = {m}");
        }
    }
}

/// An analysis done ahead is the one the factorization uses: one symbolic
/// factorization, the same solution bits, the old factors' buffer kept.
#[test]
fn an_analysis_ahead_serves_the_factorization() {
    let (n, t) = (2_500, laplace_2d(50, 1.0, 0.0));
    let b = apply(n, &t, &x_star(n));
    let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
    let mut plain = DirectSolver::new();
    plain
        .factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
        .unwrap();
    let x = plain.solve(&b).unwrap();
    let mut ahead = DirectSolver::new();
    // A factorization of another pattern first, whose buffer is then kept.
    ahead
        .factorize_triplets(900, &laplace_2d(30, 1.0, 0.0), Structure::Symmetric)
        .unwrap();
    let shared = Arc::new(a.symbolic().to_owned().unwrap());
    ahead.analyse(&shared, Ordering::Amd).unwrap();
    assert_eq!(ahead.symbolic_count(), 2);
    assert!(
        ahead.solve(&b).is_err(),
        "no factors of the new pattern yet"
    );
    ahead
        .factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
        .unwrap();
    assert_eq!(ahead.symbolic_count(), 2, "the analysis was not repeated");
    assert_eq!(ahead.solve(&b).unwrap(), x);
    // A matrix on the shared arrays themselves (the Newton path) is known
    // to have the analysed pattern: no new analysis, the same solution.
    let on_shared = SparseColMatRef::new((*shared).as_ref(), a.val());
    let (_, x_shared) = ahead
        .factorize_and_solve(on_shared, Structure::Symmetric, Ordering::Amd, &b)
        .unwrap();
    assert_eq!(ahead.symbolic_count(), 2);
    assert_eq!(x_shared, x);
}

/// A given ordering is used (the solution agrees with AMD's to round-off)
/// and kept with the symbolic factorization while it does not change.
#[test]
fn a_given_ordering_is_used_and_kept() {
    let n = 10_000;
    let t = laplace_2d(100, 1.0, 0.0);
    let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
    let b = apply(n, &t, &x_star(n));
    let reversed: Vec<usize> = (0..n).rev().collect();
    let mut s = DirectSolver::new();
    s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&reversed))
        .unwrap();
    let x = s.solve(&b).unwrap();
    assert!(rel_diff(&x, &x_star(n)) < 1e-10);
    s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&reversed))
        .unwrap();
    assert_eq!(s.symbolic_count(), 1);
    s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
        .unwrap();
    assert_eq!(s.symbolic_count(), 2, "another ordering, another analysis");
    let short = vec![0; n - 1];
    assert!(matches!(
        s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&short)),
        Err(SolveError::InvalidInput(_))
    ));
}

/// A supernodal factorization large enough to run in parallel gives the
/// same solution, bit for bit, on one thread and on two.
#[test]
fn factors_do_not_depend_on_the_number_of_threads() {
    let m = 16;
    let elastic_like = elastic_like_3d(m);
    let n3 = 3 * m * m * m;
    // The elasticity-like block is dense enough for two faer tasks, the
    // Laplacians are factorized sequentially: both paths are checked.
    let sym = |n: usize, t: &Trip| {
        let a = csc_from_triplets(n, t, Structure::Symmetric).unwrap();
        let params = CholeskySymbolicParams::default();
        factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Amd, params)
            .unwrap()
    };
    let two_tasks = sym(n3, &elastic_like);
    let mean = two_tasks.len_val() / n3;
    assert!(
        matches!(cholesky_parallelism(&two_tasks), Par::Rayon(_)),
        "mean column count {mean} should take two tasks"
    );
    assert!(matches!(
        cholesky_parallelism(&sym(27_000, &laplace_3d(30))),
        Par::Seq
    ));
    for (n, t) in [
        (n3, elastic_like),
        (27_000, laplace_3d(30)),
        (40_000, laplace_2d(200, 1.0, 0.0)),
    ] {
        let b = apply(n, &t, &x_star(n));
        let solve = |threads: usize| {
            crate::parallel::on_threads(threads, || {
                let mut s = DirectSolver::new();
                s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
                let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
                let mut fused = DirectSolver::new();
                let (_, x) = fused
                    .factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &b)
                    .unwrap();
                (s.solve(&b).unwrap(), x)
            })
        };
        let one = solve(1);
        assert!(one == solve(2), "n = {n}: 1 and 2 threads differ");
        assert!(one == solve(3), "n = {n}: 1 and 3 threads differ");
    }
}
