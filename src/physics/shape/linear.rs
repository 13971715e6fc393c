//! Standard MPM hat functions: the tensor product of the 1D hats N(ξ) = 1 − |ξ| on
//! the cell-corner nodes of a degree-1 grid (thesis 2-55).
//!
//! Also home of the tensor-product assembly shared by the separable families
//! (linear, GIMP, B-splines).

use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;

/// Most nodes a separable family touches per direction (cubic B-spline).
pub const MAX_PER_AXIS: usize = 4;

/// The 1D factors of a separable shape function along one axis: nodes
/// `first .. first + count`, their weights and derivatives (per physical length).
#[derive(Clone, Copy, Debug)]
pub struct AxisFactors {
    pub first: usize,
    pub count: usize,
    pub weight: [f64; MAX_PER_AXIS],
    pub slope: [f64; MAX_PER_AXIS],
}

impl AxisFactors {
    pub(super) const NONE: AxisFactors = AxisFactors {
        first: 0,
        count: 0,
        weight: [0.0; MAX_PER_AXIS],
        slope: [0.0; MAX_PER_AXIS],
    };
}

/// The factors of every axis, `axis(d)` for d = 0..D. (A loop instead of
/// `std::array::from_fn`, which the compiler left as a call per axis in the
/// particle loops: a fifth of the explicit step.)
#[inline(always)]
pub(super) fn per_axis<const D: usize>(axis: impl Fn(usize) -> AxisFactors) -> [AxisFactors; D] {
    let mut axes = [AxisFactors::NONE; D];
    for (d, a) in axes.iter_mut().enumerate() {
        *a = axis(d);
    }
    axes
}

/// Position of `x` along axis `d` in cell units, clamped to [0, cells] so that
/// round-off at the max face cannot push it outside.
#[inline(always)]
pub(crate) fn cell_coordinate<const D: usize>(grid: &Grid<D>, x: &Vector<D>, d: usize) -> f64 {
    ((x[d] - grid.min[d]) / grid.h[d]).clamp(0.0, grid.cells[d] as f64)
}

/// Cell containing cell coordinate `xi` ≥ 0; a point on the max face belongs to
/// the last cell. (The cast truncates, which is ⌊xi⌋ for xi ≥ 0, without a call
/// to libm's `floor`; NaN gives 0 either way. Through `u32`, whose saturating
/// cast takes half the instructions of `usize`'s: equal for grids of fewer than
/// 2³² cells per axis.)
#[inline(always)]
pub(crate) fn cell_index(xi: f64, cells: usize) -> usize {
    debug_assert!(xi >= 0.0 || xi.is_nan(), "cell coordinate {xi} < 0");
    (xi as u32 as usize).min(cells - 1)
}

/// The two hats of the cell containing `xi` along axis `d`.
#[inline(always)]
fn hat_factors<const D: usize>(grid: &Grid<D>, x: &Vector<D>, d: usize) -> AxisFactors {
    let xi = cell_coordinate(grid, x, d);
    let cell = cell_index(xi, grid.cells[d]);
    let t = xi - cell as f64;
    let slope = 1.0 / grid.h[d];
    let mut f = AxisFactors {
        first: cell,
        count: 2,
        weight: [0.0; MAX_PER_AXIS],
        slope: [0.0; MAX_PER_AXIS],
    };
    f.weight[..2].copy_from_slice(&[1.0 - t, t]);
    f.slope[..2].copy_from_slice(&[-slope, slope]);
    f
}

/// Tensor product S_I = Π_d S_d, ∂S_I/∂x_d = S'_d Π_{e≠d} S_e of per-axis factors.
/// Skips entries whose weight and gradient are exactly zero; returns the count.
/// Entries are written x fastest.
pub(super) fn tensor_product<const D: usize>(
    grid: &Grid<D>,
    axes: &[AxisFactors; D],
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    nonzero_entries(grid, axes, |n, index, _, weight, gradient| {
        node[n] = index;
        w[n] = weight;
        grad[n] = gradient;
    })
}

/// The entries of `tensor_product` (same skips, same order) without their
/// values: the node of each and its slot on every axis, 2 bits per axis with x
/// lowest (`Stencils` forms the values from the axis factors when read).
pub(super) fn tensor_slots<const D: usize>(
    grid: &Grid<D>,
    axes: &[AxisFactors; D],
    node: &mut [u32],
    slot: &mut [u8],
) -> usize {
    nonzero_entries(grid, axes, |n, index, local, _, _| {
        node[n] = index;
        slot[n] = (0..D).map(|d| (local[d] as u8) << (2 * d)).sum();
    })
}

/// Calls `visit(n, node, local, S_I, ∇S_I)` for the n-th entry of the tensor
/// product whose weight or gradient is nonzero, x fastest; returns the count.
fn nonzero_entries<const D: usize>(
    grid: &Grid<D>,
    axes: &[AxisFactors; D],
    mut visit: impl FnMut(usize, u32, &[usize; D], f64, Vector<D>),
) -> usize {
    // Flat node index = Σ_d ijk_d · stride_d (`Grid::node_index`).
    let mut stride = [1usize; D];
    for d in 1..D {
        stride[d] = stride[d - 1] * grid.nodes[d - 1];
    }
    let count: [usize; D] = std::array::from_fn(|d| axes[d].count);
    if count.contains(&0) {
        return 0;
    }
    let mut local = [0usize; D];
    let mut n = 0;
    loop {
        let (weight, gradient) = weight_and_gradient(axes, &local);
        if weight != 0.0 || gradient.iter().any(|g| *g != 0.0) {
            let index: usize = (0..D).map(|d| (axes[d].first + local[d]) * stride[d]).sum();
            visit(n, index as u32, &local, weight, gradient);
            n += 1;
        }
        if !next_local(&mut local, &count) {
            return n;
        }
    }
}

/// S_I = Π_d S_d and ∂S_I/∂x_d = S'_d Π_{e≠d} S_e at the local multi-index `local`.
fn weight_and_gradient<const D: usize>(
    axes: &[AxisFactors; D],
    local: &[usize; D],
) -> (f64, Vector<D>) {
    let weight: f64 = (0..D).map(|d| axes[d].weight[local[d]]).product();
    let gradient = Vector::<D>::from_fn(|d, _| {
        (0..D)
            .map(|e| {
                if e == d {
                    axes[e].slope[local[e]]
                } else {
                    axes[e].weight[local[e]]
                }
            })
            .product()
    });
    (weight, gradient)
}

/// Advances `local` to the next multi-index below `count`, x fastest; false
/// after the last.
fn next_local<const D: usize>(local: &mut [usize; D], count: &[usize; D]) -> bool {
    for d in 0..D {
        local[d] += 1;
        if local[d] < count[d] {
            return true;
        }
        local[d] = 0;
    }
    false
}

/// Per-axis factors with the domain averages of (y − x) N' (dimensionless) and
/// (y − x) N (a length) of each function.
pub(super) type MomentFactors = (AxisFactors, [f64; MAX_PER_AXIS], [f64; MAX_PER_AXIS]);

/// The first moments M_kj = (1/|Ω|) ∫_Ω (y − x)_k ∂_j N_I of a separable
/// domain-averaged family: the factor of axis e is (y − x)N' for e = k = j,
/// (y − x)N for e = k ≠ j, N' for e = j ≠ k and N otherwise. Entries in the
/// order and with the skips of `tensor_product`; returns the count.
pub(super) fn moment_product<const D: usize>(
    axes: &[MomentFactors; D],
    out: &mut [Tensor<D>],
) -> usize {
    let factors: [AxisFactors; D] = std::array::from_fn(|d| axes[d].0);
    let count: [usize; D] = std::array::from_fn(|d| factors[d].count);
    if count.contains(&0) {
        return 0;
    }
    let mut local = [0usize; D];
    let mut n = 0;
    loop {
        let (weight, gradient) = weight_and_gradient(&factors, &local);
        if weight != 0.0 || gradient.iter().any(|g| *g != 0.0) {
            let f = |e: usize| &factors[e];
            out[n] = Tensor::<D>::from_fn(|k, j| {
                (0..D)
                    .map(|e| match (e == k, e == j) {
                        (true, true) => axes[e].1[local[e]],
                        (true, false) => axes[e].2[local[e]],
                        (false, true) => f(e).slope[local[e]],
                        (false, false) => f(e).weight[local[e]],
                    })
                    .product()
            });
            n += 1;
        }
        if !next_local(&mut local, &count) {
            return n;
        }
    }
}

/// Hat-function weights and gradients of a particle at `x` (at most 2^D entries).
pub fn evaluate<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    tensor_product(grid, &axes(grid, x), node, w, grad)
}

/// The hats of a particle at `x`, axis by axis.
pub(super) fn axes<const D: usize>(grid: &Grid<D>, x: &Vector<D>) -> [AxisFactors; D] {
    debug_assert_eq!(grid.degree, 1, "hat functions live on a degree-1 grid");
    per_axis(|d| hat_factors(grid, x, d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shape::tests::*;

    fn eval<const D: usize>(g: &Grid<D>, x: &Vector<D>) -> Stencil<D> {
        Stencil::collect(1 << D, |n, w, gr| evaluate(g, x, n, w, gr))
    }

    fn sum_rules<const D: usize>() {
        let g = test_grid::<D>(1);
        for x in sample_points(&g, 300) {
            let s = eval(&g, &x);
            assert!(s.len() <= 1 << D);
            s.check_partition_of_unity(&g);
            s.check_linear_reproduction(&g, &x, 1e-12);
            s.check_gradient_reproduction(&g, 1e-10);
        }
    }

    #[test]
    fn sum_rules_2d() {
        sum_rules::<2>();
    }

    #[test]
    fn sum_rules_3d() {
        sum_rules::<3>();
    }

    /// Central differences of the weights, away from the node lines (kinks).
    fn finite_differences<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut checked = 0;
        for x in sample_points(&g, 300) {
            let step = 1e-5 * g.h_min();
            let kink = (0..D).any(|d| near_integer(cell_coordinate(&g, &x, d), 3e-5))
                || !g.contains(&(x.add_scalar(-2.0 * step)))
                || !g.contains(&(x.add_scalar(2.0 * step)));
            if kink {
                continue;
            }
            check_finite_differences(&g, &x, step, 1e-8, |y| eval(&g, y));
            checked += 1;
        }
        assert!(checked > 50, "only {checked} checked");
    }

    #[test]
    fn finite_differences_2d() {
        finite_differences::<2>();
    }

    #[test]
    fn finite_differences_3d() {
        finite_differences::<3>();
    }

    #[test]
    fn max_face_uses_last_cell() {
        let g = test_grid::<3>(1);
        let s = eval(&g, &g.max);
        let last = g.node_index(std::array::from_fn(|d| g.nodes[d] - 1));
        assert!((s.weight_of(last) - 1.0).abs() < 1e-12);
        // The corner node and its neighbours in the last cell, nothing outside the grid.
        assert!(s.nodes().iter().all(|&n| (n as usize) < g.node_count()));
        s.check_partition_of_unity(&g);
        s.check_gradient_reproduction(&g, 1e-10);
    }

    #[test]
    fn known_bilinear_values() {
        let g = test_grid::<2>(1);
        // A quarter of the way across cell (1, 2) in x, three quarters in y.
        let x = Vector::<2>::new(g.min[0] + 1.25 * g.h[0], g.min[1] + 2.75 * g.h[1]);
        let s = eval(&g, &x);
        let expect = [
            ([1, 2], 0.75 * 0.25),
            ([2, 2], 0.25 * 0.25),
            ([1, 3], 0.75 * 0.75),
            ([2, 3], 0.25 * 0.75),
        ];
        for (ijk, v) in expect {
            assert!((s.weight_of(g.node_index(ijk)) - v).abs() < 1e-14);
        }
        let gx = s.grad_of(g.node_index([1, 2]));
        assert!((gx[0] + 0.25 / g.h[0]).abs() < 1e-12 && (gx[1] + 0.75 / g.h[1]).abs() < 1e-12);
    }
}
