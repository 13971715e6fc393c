//! B-splines of degree p on a clamped (open) uniform knot vector per direction
//! (Piegl & Tiller, The NURBS Book, eq. 2.5 and 2.7; B-spline MPM: Steffen, Kirby &
//! Berzins 2008). In cell units the knots are 0 (p+1 times), 1, …, n−1, n (p+1
//! times) for n cells, giving n + p basis functions per direction, one per grid node
//! (`grid.nodes = cells + degree`). The first and last functions interpolate the
//! faces, the basis is a partition of unity, and Σ N_I X_I = x with X_I the Greville
//! abscissae (`grid.node_position`), up to the faces included.

use super::linear::{
    cell_coordinate, cell_index, moment_product, per_axis, tensor_product, AxisFactors,
    MAX_PER_AXIS,
};
use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;

/// Knot `k` (cell units) of the clamped uniform knot vector of degree `p` on `cells` cells.
fn knot(k: usize, p: usize, cells: usize) -> f64 {
    (k as f64 - p as f64).clamp(0.0, cells as f64)
}

/// num / den with the B-spline convention 0/0 = 0 (repeated knots).
fn ratio(num: f64, den: f64) -> f64 {
    if den == 0.0 {
        0.0
    } else {
        num / den
    }
}

/// The p + 1 basis functions that are nonzero on the knot span of `xi` (cell units),
/// with their derivatives per cell; a point on the max face uses the last span.
/// Spans whose functions see only unrepeated knots take the uniform polynomials.
#[inline(always)]
fn basis(xi: f64, p: usize, cells: usize) -> AxisFactors {
    let first = cell_index(xi, cells);
    if p >= 2 && first >= p && first + p < cells {
        uniform_basis(xi - first as f64, first, p)
    } else {
        basis_in_span(xi, first, p, cells)
    }
}

/// The uniform (cardinal) B-splines of degree 2 or 3 that are nonzero on a span
/// at local coordinate t ∈ [0, 1], and their derivatives per cell (the pieces of
/// Cox–de Boor on equally spaced knots; e.g. Piegl & Tiller, ex. 2.2 for p = 2).
#[inline(always)]
fn uniform_basis(t: f64, first: usize, p: usize) -> AxisFactors {
    let s = 1.0 - t;
    let (weight, slope) = match p {
        2 => (
            [0.5 * s * s, 0.5 + t * s, 0.5 * t * t, 0.0],
            [-s, s - t, t, 0.0],
        ),
        _ => {
            debug_assert_eq!(p, 3);
            let (t2, s2) = (t * t, s * s);
            (
                [
                    s2 * s / 6.0,
                    (3.0 * t2 * t - 6.0 * t2 + 4.0) / 6.0,
                    (3.0 * s2 * s - 6.0 * s2 + 4.0) / 6.0,
                    t2 * t / 6.0,
                ],
                [
                    -0.5 * s2,
                    0.5 * t * (3.0 * t - 4.0),
                    -0.5 * s * (3.0 * s - 4.0),
                    0.5 * t2,
                ],
            )
        }
    };
    AxisFactors {
        first,
        count: p + 1,
        weight,
        slope,
    }
}

/// The p + 1 basis functions of knot span `first` (cell `first`) at `xi`, which
/// lies in that span or on its ends (the polynomial pieces agree there).
#[inline(never)]
fn basis_in_span(xi: f64, first: usize, p: usize, cells: usize) -> AxisFactors {
    let u = |k: usize| knot(k, p, cells);
    // At degree q, value[r] = N_{first+p−q+r, q}(xi), r = 0..=q (Cox–de Boor, NURBS Book 2.5).
    let mut value = [1.0, 0.0, 0.0, 0.0];
    let mut lower = value;
    for q in 1..=p {
        lower = value;
        for r in 0..=q {
            let i = first + p - q + r;
            let rising = if r > 0 {
                ratio(xi - u(i), u(i + q) - u(i)) * lower[r - 1]
            } else {
                0.0
            };
            let falling = if r < q {
                ratio(u(i + q + 1) - xi, u(i + q + 1) - u(i + 1)) * lower[r]
            } else {
                0.0
            };
            value[r] = rising + falling;
        }
    }
    // N'_{i,p} = p N_{i,p−1}/(u_{i+p} − u_i) − p N_{i+1,p−1}/(u_{i+p+1} − u_{i+1}) (NURBS Book 2.7).
    let mut slope = [0.0; MAX_PER_AXIS];
    for (r, s) in slope.iter_mut().enumerate().take(p + 1) {
        let i = first + r;
        let from_left = if r > 0 {
            ratio(lower[r - 1], u(i + p) - u(i))
        } else {
            0.0
        };
        let from_right = if r < p {
            ratio(lower[r], u(i + p + 1) - u(i + 1))
        } else {
            0.0
        };
        *s = p as f64 * (from_left - from_right);
    }
    AxisFactors {
        first,
        count: p + 1,
        weight: value,
        slope,
    }
}

/// The B-splines along one axis averaged over the particle domain [a, b] (cell
/// units, clipped to the grid as for GIMP, `super::gimp`): S_I = (1/(b−a)) ∫_a^b N_I
/// and S'_I = (N_I(b) − N_I(a))/(b−a) per cell (Bardenhagen & Kober 2004's domain
/// average applied to B-splines; the integral by two-point Gauss–Legendre per knot
/// span, exact up to degree 3). At most p + 2 functions for b − a ≤ 1 cell.
fn domain_basis(xi: f64, half: f64, p: usize, cells: usize) -> AxisFactors {
    let Some(rule) = DomainRule::new(xi, half, cells) else {
        return basis(xi, p, cells);
    };
    let (a, b, first, last) = (rule.a, rule.b, rule.first, rule.last);
    let mut f = AxisFactors {
        first,
        count: last - first + p + 1,
        weight: [0.0; MAX_PER_AXIS],
        slope: [0.0; MAX_PER_AXIS],
    };
    assert!(
        f.count <= MAX_PER_AXIS,
        "particle domain wider than one cell"
    );
    for &(t, w) in rule.points() {
        let g = basis(t, p, cells);
        for r in 0..=p {
            f.weight[g.first - first + r] += w * g.weight[r];
        }
    }
    let (at_a, at_b) = (
        basis_in_span(a, first, p, cells),
        basis_in_span(b, last, p, cells),
    );
    let length = b - a;
    for r in 0..=p {
        f.slope[at_b.first - first + r] += at_b.weight[r] / length;
        f.slope[at_a.first - first + r] -= at_a.weight[r] / length;
    }
    f
}

/// The clipped particle domain [a, b] along one axis (cell units), the knot
/// spans it enters and their two-point Gauss–Legendre points with weights that
/// sum to 1 (exact for polynomials of degree 3 per span).
struct DomainRule {
    a: f64,
    b: f64,
    first: usize,
    last: usize,
    point: [(f64, f64); 6],
    count: usize,
}

impl DomainRule {
    /// For a particle at `xi` with half-width `half`; `None` when the clipped
    /// domain has no length.
    fn new(xi: f64, half: f64, cells: usize) -> Option<Self> {
        let (a, b) = ((xi - half).max(0.0), (xi + half).min(cells as f64));
        let length = b - a;
        if length <= 1e-12 {
            return None;
        }
        let first = cell_index(a, cells);
        // The last span that [a, b] enters with positive length.
        let last = ((b.ceil() as usize).max(1) - 1).clamp(first, cells - 1);
        let mut rule = DomainRule {
            a,
            b,
            first,
            last,
            point: [(0.0, 0.0); 6],
            count: 0,
        };
        let gauss = 0.5 / 3f64.sqrt();
        for span in first..=last {
            let (lo, hi) = (a.max(span as f64), b.min(span as f64 + 1.0));
            if hi <= lo {
                continue;
            }
            let (mid, w) = (0.5 * (lo + hi), 0.5 * (hi - lo) / length);
            for t in [mid - gauss * (hi - lo), mid + gauss * (hi - lo)] {
                rule.point[rule.count] = (t, w);
                rule.count += 1;
            }
        }
        Some(rule)
    }

    fn points(&self) -> &[(f64, f64)] {
        &self.point[..self.count]
    }
}

/// The domain averages of (y − x) N_I' (dimensionless) and of (y − x) N_I (per
/// cell) over the clipped domain of `domain_basis`, x the particle at `xi`, in
/// the order of its functions (two-point Gauss per span: exact for p ≤ 2).
fn domain_moments(
    xi: f64,
    half: f64,
    p: usize,
    cells: usize,
) -> ([f64; MAX_PER_AXIS], [f64; MAX_PER_AXIS]) {
    let (mut slope_moment, mut weight_moment) = ([0.0; MAX_PER_AXIS], [0.0; MAX_PER_AXIS]);
    let Some(rule) = DomainRule::new(xi, half, cells) else {
        return (slope_moment, weight_moment);
    };
    for &(t, w) in rule.points() {
        let g = basis(t, p, cells);
        for r in 0..=p {
            slope_moment[g.first - rule.first + r] += w * (t - xi) * g.slope[r];
            weight_moment[g.first - rule.first + r] += w * (t - xi) * g.weight[r];
        }
    }
    (slope_moment, weight_moment)
}

/// The first moments of the domain-averaged B-spline gradients about the
/// particle, M_kj = (1/|Ω|) ∫_Ω (y − x)_k ∂_j N_I, in the order of
/// `evaluate_domain` (`super::gimp::moments` for the hats; quadratic only).
pub fn domain_gradient_moments<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    degree: usize,
    out: &mut [Tensor<D>],
) -> usize {
    assert_eq!(
        degree, 2,
        "first moments of the domain-averaged B-splines: quadratic only"
    );
    let axes: [_; D] = std::array::from_fn(|d| {
        let xi = cell_coordinate(grid, x, d);
        let mut f = domain_basis(xi, half[d] / grid.h[d], degree, grid.cells[d]);
        f.slope.iter_mut().for_each(|s| *s /= grid.h[d]);
        let (t, mut u) = domain_moments(xi, half[d] / grid.h[d], degree, grid.cells[d]);
        u.iter_mut().for_each(|u| *u *= grid.h[d]);
        (f, t, u)
    });
    moment_product(&axes, out)
}

/// Quadratic or cubic B-splines averaged over the axis-aligned particle domain
/// [x − half, x + half] (`domain_basis`); `half` at most h/2 per axis.
pub fn evaluate_domain<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    degree: usize,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    tensor_product(grid, &domain_axes(grid, x, half, degree), node, w, grad)
}

/// The domain-averaged B-splines of a particle at `x` with domain half-lengths
/// `half`, axis by axis, derivatives per physical length.
pub(super) fn domain_axes<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    degree: usize,
) -> [AxisFactors; D] {
    debug_assert_eq!(
        grid.degree, degree,
        "the grid must be laid out for this degree"
    );
    per_axis(|d| {
        let xi = cell_coordinate(grid, x, d);
        let mut f = domain_basis(xi, half[d] / grid.h[d], degree, grid.cells[d]);
        f.slope.iter_mut().for_each(|s| *s /= grid.h[d]);
        f
    })
}

/// The basis functions of degree `p` on `cells` cells that are nonzero at `xi`
/// (cell units), as (function index, value): one grid direction of the basis,
/// for the multigrid's two-scale relations.
pub fn axis_values(xi: f64, p: usize, cells: usize) -> impl Iterator<Item = (usize, f64)> {
    let f = basis(xi, p, cells);
    (0..f.count).map(move |r| (f.first + r, f.weight[r]))
}

/// B-spline weights and gradients of degree `degree` (1 to 3) of a particle at `x`
/// (at most (degree + 1)^D entries).
pub fn evaluate<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    degree: usize,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    tensor_product(grid, &axes(grid, x, degree), node, w, grad)
}

/// The B-splines of a particle at `x`, axis by axis, derivatives per physical
/// length.
#[inline(always)]
pub(super) fn axes<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    degree: usize,
) -> [AxisFactors; D] {
    assert!(
        (1..MAX_PER_AXIS).contains(&degree),
        "B-spline degree {degree} not in 1..=3"
    );
    debug_assert_eq!(
        grid.degree, degree,
        "the grid must be laid out for this degree"
    );
    // A loop, not `std::array::from_fn`, which the compiler left as a call per
    // axis in the explicit particle loops (a quarter of the step).
    let mut axes = [AxisFactors::NONE; D];
    for (d, f) in axes.iter_mut().enumerate() {
        *f = basis(cell_coordinate(grid, x, d), degree, grid.cells[d]);
        // Derivatives from cell units to physical units.
        let per_length = 1.0 / grid.h[d];
        f.slope[..=degree].iter_mut().for_each(|s| *s *= per_length);
    }
    axes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shape::linear;
    use crate::physics::shape::tests::*;

    fn eval<const D: usize>(g: &Grid<D>, x: &Vector<D>, p: usize) -> Stencil<D> {
        Stencil::collect((p + 1).pow(D as u32), |n, w, gr| {
            evaluate(g, x, p, n, w, gr)
        })
    }

    fn sum_rules<const D: usize>(p: usize) {
        let g = test_grid::<D>(p);
        for x in sample_points(&g, 400) {
            let s = eval(&g, &x, p);
            s.check_partition_of_unity(&g);
            // Greville abscissae reproduce linear fields everywhere, faces included.
            s.check_linear_reproduction(&g, &x, 1e-12);
            s.check_gradient_reproduction(&g, 1e-10);
        }
    }

    #[test]
    fn sum_rules_2d() {
        (1..=3).for_each(sum_rules::<2>);
    }

    #[test]
    fn sum_rules_3d() {
        (1..=3).for_each(sum_rules::<3>);
    }

    /// Naive recursive Cox–de Boor N_{i,q}(ξ) over the whole knot vector, the last
    /// nonempty span closed at ξ = n; an independent check of `basis`.
    fn naive(i: usize, q: usize, xi: f64, p: usize, n: usize) -> f64 {
        let u = |k: usize| knot(k, p, n);
        if q == 0 {
            let inside = u(i) <= xi && xi < u(i + 1);
            let at_end = xi == n as f64 && u(i) < u(i + 1) && u(i + 1) == n as f64;
            return if inside || at_end { 1.0 } else { 0.0 };
        }
        ratio(xi - u(i), u(i + q) - u(i)) * naive(i, q - 1, xi, p, n)
            + ratio(u(i + q + 1) - xi, u(i + q + 1) - u(i + 1)) * naive(i + 1, q - 1, xi, p, n)
    }

    fn naive_slope(i: usize, xi: f64, p: usize, n: usize) -> f64 {
        let u = |k: usize| knot(k, p, n);
        p as f64
            * (ratio(naive(i, p - 1, xi, p, n), u(i + p) - u(i))
                - ratio(naive(i + 1, p - 1, xi, p, n), u(i + p + 1) - u(i + 1)))
    }

    fn matches_naive_recursion<const D: usize>(p: usize) {
        let g = test_grid::<D>(p);
        for x in sample_points(&g, 200) {
            let s = eval(&g, &x, p);
            for n in 0..g.node_count() {
                let ijk = g.node_ijk(n);
                let xi: [f64; D] = std::array::from_fn(|d| cell_coordinate(&g, &x, d));
                let factor = |d: usize| naive(ijk[d], p, xi[d], p, g.cells[d]);
                let w: f64 = (0..D).map(factor).product();
                let grad = Vector::<D>::from_fn(|d, _| {
                    let slope = naive_slope(ijk[d], xi[d], p, g.cells[d]) / g.h[d];
                    (0..D)
                        .map(|e| if e == d { slope } else { factor(e) })
                        .product()
                });
                assert!((s.weight_of(n) - w).abs() < 1e-12, "p {p} node {n} at {x}");
                assert!(
                    (s.grad_of(n) - grad).norm() * g.h_min() < 1e-10,
                    "p {p} node {n} at {x}"
                );
            }
        }
    }

    #[test]
    fn matches_naive_recursion_2d() {
        (1..=3).for_each(matches_naive_recursion::<2>);
    }

    #[test]
    fn matches_naive_recursion_3d() {
        (1..=3).for_each(matches_naive_recursion::<3>);
    }

    /// The uniform pieces agree with Cox–de Boor on every span where they are
    /// used (to round-off), and the clamped spans next to the faces still go
    /// through Cox–de Boor (their values differ from the uniform pieces).
    #[test]
    fn uniform_pieces_match_cox_de_boor() {
        let cells = 12;
        for p in 2..=3 {
            let mut uniform_spans = 0;
            for span in 0..cells {
                for k in 0..=64 {
                    let xi = span as f64 + k as f64 / 64.0;
                    let (fast, general) = (
                        basis(xi, p, cells),
                        basis_in_span(xi, cell_index(xi, cells), p, cells),
                    );
                    assert_eq!((fast.first, fast.count), (general.first, general.count));
                    for r in 0..=p {
                        assert!(
                            (fast.weight[r] - general.weight[r]).abs() < 4e-16,
                            "p {p} ξ {xi} r {r}"
                        );
                        assert!(
                            (fast.slope[r] - general.slope[r]).abs() < 1e-15,
                            "p {p} ξ {xi} r {r}"
                        );
                    }
                }
                let t = 0.3;
                let clamped = basis_in_span(span as f64 + t, span, p, cells);
                let cardinal = uniform_basis(t, span, p);
                let same = (0..=p).all(|r| (clamped.weight[r] - cardinal.weight[r]).abs() < 1e-12);
                uniform_spans += same as usize;
                // The spans at the faces see the repeated knots.
                assert!(!same || (span > 0 && span + 1 < cells), "p {p} span {span}");
            }
            // At least spans p .. cells − p − 1, where the fast path is taken.
            assert!(uniform_spans >= cells - 2 * p, "p {p}");
        }
    }

    /// Central differences away from the knots (where the p-th derivative jumps).
    fn finite_differences<const D: usize>(p: usize) {
        let g = test_grid::<D>(p);
        let mut checked = 0;
        for x in sample_points(&g, 300) {
            let step = 1e-5 * g.h_min();
            let inside =
                g.contains(&x.add_scalar(-2.0 * step)) && g.contains(&x.add_scalar(2.0 * step));
            let knot_near = (0..D).any(|d| near_integer(cell_coordinate(&g, &x, d), 3e-5));
            if inside && !knot_near {
                check_finite_differences(&g, &x, step, 1e-8, |y| eval(&g, y, p));
                checked += 1;
            }
        }
        assert!(checked > 50, "only {checked} checked");
    }

    #[test]
    fn finite_differences_2d() {
        (1..=3).for_each(finite_differences::<2>);
    }

    #[test]
    fn finite_differences_3d() {
        (1..=3).for_each(finite_differences::<3>);
    }

    fn eval_domain<const D: usize>(g: &Grid<D>, x: &Vector<D>, half: &Vector<D>) -> Stencil<D> {
        Stencil::collect(4usize.pow(D as u32), |n, w, gr| {
            evaluate_domain(g, x, half, 2, n, w, gr)
        })
    }

    /// Domain averages: partition of unity and Σ ∇S ⊗ X = I everywhere, Σ S X = x
    /// for domains inside the grid, finite differences in x (fixed domain), and
    /// the weights against a brute-force average of the naive recursion.
    fn domain_averages<const D: usize>() {
        let g = test_grid::<D>(2);
        let mut rng = Rng::new(5);
        let mut inside = 0;
        for x in sample_points(&g, 300) {
            let half = Vector::<D>::from_fn(|d, _| g.h[d] * rng.range(0.01, 0.5));
            let s = eval_domain(&g, &x, &half);
            s.check_partition_of_unity(&g);
            s.check_gradient_reproduction(&g, 1e-10);
            if g.contains(&(x - half)) && g.contains(&(x + half)) {
                inside += 1;
                s.check_linear_reproduction(&g, &x, 1e-12);
                let step = 1e-6 * g.h_min();
                if g.contains(&(x - half).add_scalar(-2.0 * step))
                    && g.contains(&(x + half).add_scalar(2.0 * step))
                {
                    check_finite_differences(&g, &x, step, 1e-6, |y| eval_domain(&g, y, &half));
                }
                for n in s.nodes() {
                    let ijk = g.node_ijk(*n as usize);
                    let k = 4000;
                    let avg = |d: usize| {
                        let (lo, hi) = (
                            cell_coordinate(&g, &x, d) - half[d] / g.h[d],
                            cell_coordinate(&g, &x, d) + half[d] / g.h[d],
                        );
                        (0..k)
                            .map(|i| {
                                naive(
                                    ijk[d],
                                    2,
                                    lo + (i as f64 + 0.5) * (hi - lo) / k as f64,
                                    2,
                                    g.cells[d],
                                )
                            })
                            .sum::<f64>()
                            / k as f64
                    };
                    let w: f64 = (0..D).map(avg).product();
                    assert!(
                        (s.weight_of(*n as usize) - w).abs() < 1e-6,
                        "node {n} at {x}"
                    );
                }
            }
        }
        assert!(inside > 50, "only {inside} domains inside the grid");
    }

    /// The first moments of the domain-averaged gradients about the particle
    /// (`domain_gradient_moments`) against Gauss quadrature of (y − x) ⊗ ∇N_I
    /// with the point-sampled basis over the clipped domain (`axis_quadrature`),
    /// in the order of `evaluate_domain`.
    fn domain_gradient_moments_match_quadrature<const D: usize>() {
        let g = test_grid::<D>(2);
        let mut rng = Rng::new(6);
        for x in sample_points(&g, 120) {
            let half = Vector::<D>::from_fn(|d, _| g.h[d] * rng.range(0.01, 0.5));
            let (a, b) = ((x - half).sup(&g.min), (x + half).inf(&g.max));
            let mut moment = vec![Tensor::<D>::zeros(); g.node_count()];
            for (y, q) in box_quadrature(&g, &a, &b) {
                let point = eval(&g, &y, 2);
                for k in 0..point.len() {
                    moment[point.node[k] as usize] += (y - x) * point.grad[k].transpose() * q;
                }
            }
            let s = eval_domain(&g, &x, &half);
            let mut m = vec![Tensor::<D>::repeat(f64::NAN); 4usize.pow(D as u32)];
            assert_eq!(domain_gradient_moments(&g, &x, &half, 2, &mut m), s.len());
            for (k, n) in s.nodes().iter().enumerate() {
                let error = (m[k] - moment[*n as usize]).norm();
                assert!(error < 1e-12, "first moment of {n} at {x}: {error:e}");
            }
        }
    }

    #[test]
    fn domain_gradient_moments_match_quadrature_2d() {
        domain_gradient_moments_match_quadrature::<2>();
    }

    #[test]
    fn domain_gradient_moments_match_quadrature_3d() {
        domain_gradient_moments_match_quadrature::<3>();
    }

    #[test]
    fn domain_averages_2d() {
        domain_averages::<2>();
    }

    #[test]
    fn domain_averages_3d() {
        domain_averages::<3>();
    }

    #[test]
    fn degree_one_is_the_hat_basis() {
        let g = test_grid::<3>(1);
        for x in sample_points(&g, 200) {
            let s = eval(&g, &x, 1);
            let hats = Stencil::collect(8, |n, w, gr| linear::evaluate(&g, &x, n, w, gr));
            for n in 0..g.node_count() {
                assert!((s.weight_of(n) - hats.weight_of(n)).abs() < 1e-14);
                assert!((s.grad_of(n) - hats.grad_of(n)).norm() * g.h_min() < 1e-12);
            }
        }
    }

    /// Known interior values on a uniform stretch of knots: tensor products of the
    /// 1D values `w` and per-cell derivatives `dw` on nodes `first..`, at cell
    /// coordinate `xi` along every axis.
    fn known_values<const D: usize>(p: usize, xi: f64, first: usize, w: &[f64], dw: &[f64]) {
        let h = Vector::<D>::from_fn(|d, _| [0.5, 0.25, 2.0][d]);
        let cells = [9; D];
        let g = Grid::new(Vector::<D>::zeros(), h * 9.0, cells, p);
        let x = h * xi;
        let s = eval(&g, &x, p);
        let local_count = w.len().pow(D as u32);
        for flat in 0..local_count {
            let local: [usize; D] = std::array::from_fn(|d| flat / w.len().pow(d as u32) % w.len());
            let n = g.node_index(std::array::from_fn(|d| first + local[d]));
            let weight: f64 = local.iter().map(|&k| w[k]).product();
            let grad = Vector::<D>::from_fn(|d, _| {
                (0..D)
                    .map(|e| {
                        if e == d {
                            dw[local[e]] / h[e]
                        } else {
                            w[local[e]]
                        }
                    })
                    .product()
            });
            assert!((s.weight_of(n) - weight).abs() < 1e-14, "p {p} node {n}");
            assert!((s.grad_of(n) - grad).norm() < 1e-12, "p {p} node {n}");
        }
        let listed: f64 = s.w.iter().sum();
        assert!((listed - 1.0).abs() < 1e-14);
    }

    #[test]
    fn quadratic_at_span_centre() {
        // Span [4, 5]: functions 4, 5, 6 have knots 2..5, 3..6, 4..7 (all simple).
        known_values::<2>(2, 4.5, 4, &[0.125, 0.75, 0.125], &[-0.5, 0.0, 0.5]);
        known_values::<3>(2, 4.5, 4, &[0.125, 0.75, 0.125], &[-0.5, 0.0, 0.5]);
    }

    #[test]
    fn cubic_at_knot() {
        // Knot 4 (span [4, 5]): functions 4, 5, 6 are centred at 3, 4, 5; function 7 starts there.
        known_values::<2>(
            3,
            4.0,
            4,
            &[1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0],
            &[-0.5, 0.0, 0.5, 0.0],
        );
        known_values::<3>(
            3,
            4.0,
            4,
            &[1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0],
            &[-0.5, 0.0, 0.5, 0.0],
        );
    }

    /// The first and last control points interpolate the faces: on the face x_d = min
    /// only nodes with i_d = 0 carry weight (and all of it at the corner).
    fn faces_interpolate<const D: usize>(p: usize) {
        let g = test_grid::<D>(p);
        for (corner, node) in [(g.min, [0; D]), (g.max, g.nodes.map(|n| n - 1))] {
            let s = eval(&g, &corner, p);
            assert!(
                (s.weight_of(g.node_index(node)) - 1.0).abs() < 1e-14,
                "p {p} corner {corner}"
            );
        }
        let mut rng = Rng::new(31);
        for _ in 0..100 {
            let axis = rng.below(D);
            let upper = rng.below(2) == 1;
            let mut x = Vector::<D>::from_fn(|d, _| rng.range(g.min[d], g.max[d]));
            x[axis] = if upper { g.max[axis] } else { g.min[axis] };
            let s = eval(&g, &x, p);
            let face_layer = if upper { g.nodes[axis] - 1 } else { 0 };
            let on_face: f64 = (0..s.len())
                .filter(|&k| g.node_ijk(s.node[k] as usize)[axis] == face_layer)
                .map(|k| s.w[k])
                .sum();
            assert!(
                (on_face - 1.0).abs() < 1e-14,
                "p {p}: {on_face} on the face at {x}"
            );
        }
    }

    #[test]
    fn faces_interpolate_2d() {
        (1..=3).for_each(faces_interpolate::<2>);
    }

    #[test]
    fn faces_interpolate_3d() {
        (1..=3).for_each(faces_interpolate::<3>);
    }
}
