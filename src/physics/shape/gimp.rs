//! GIMP (Bardenhagen & Kober 2004): the hat functions averaged over an axis-aligned
//! particle domain [x − half, x + half] (thesis 2-53, 2-54 with a box χ_p).
//!
//! Per direction S_I = (1/(b−a)) ∫_a^b N_I dx and S'_I = (N_I(b) − N_I(a))/(b−a), the
//! domain average of N_I', with the tensor product S_I = Π_d S_d and
//! ∂S_I/∂x_d = S'_d Π_{e≠d} S_e. Used by uGIMP (half = reference half-length) and
//! cpGIMP (half = reference half-length × F_dd).
//!
//! Boundary: [a, b] is the domain clipped to the grid box; the part outside the grid
//! is dropped. The partition of unity and Σ ∇S_I ⊗ X_I = I still hold, but
//! Σ S_I X_I is then the centre (a + b)/2 of the clipped domain, not x, and the
//! gradient is the clipped-domain average of ∇N_I, not ∂S_I/∂x_p.

use super::linear::{
    cell_coordinate, cell_index, moment_product, per_axis, tensor_product, AxisFactors,
    MomentFactors, MAX_PER_AXIS,
};
use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;

/// Unit hat φ(t) = max(0, 1 − |t|).
fn hat(t: f64) -> f64 {
    (1.0 - t.abs()).max(0.0)
}

/// Antiderivative Φ(t) = ∫_{−∞}^t φ of the unit hat (piecewise quadratic).
fn hat_integral(t: f64) -> f64 {
    if t <= -1.0 {
        0.0
    } else if t <= 0.0 {
        0.5 * (1.0 + t) * (1.0 + t)
    } else if t < 1.0 {
        1.0 - 0.5 * (1.0 - t) * (1.0 - t)
    } else {
        1.0
    }
}

/// The particle's cell coordinate xi along axis `d` and its domain [a, b]
/// clipped to the grid (cell units).
fn clipped_domain<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    d: usize,
) -> (f64, f64, f64) {
    let reach = half[d] / grid.h[d];
    assert!(
        reach > 0.0 && 2.0 * reach <= 1.0 + 1e-12,
        "GIMP domain half-width {} must be in (0, h/2] (h = {}) to touch at most 3 nodes per axis",
        half[d],
        grid.h[d]
    );
    let xi = cell_coordinate(grid, x, d);
    (
        xi,
        (xi - reach).max(0.0),
        (xi + reach).min(grid.cells[d] as f64),
    )
}

/// Averages of the hats along axis `d` over the clipped domain (in cell units).
fn domain_factors<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    d: usize,
) -> AxisFactors {
    let cells = grid.cells[d];
    let (_, a, b) = clipped_domain(grid, x, half, d);
    let first = cell_index(a, cells);
    let mut f = AxisFactors {
        first,
        count: (cells + 1 - first).min(3),
        weight: [0.0; MAX_PER_AXIS],
        slope: [0.0; MAX_PER_AXIS],
    };
    for k in 0..f.count {
        let node = (first + k) as f64;
        f.weight[k] = (hat_integral(b - node) - hat_integral(a - node)) / (b - a);
        f.slope[k] = (hat(b - node) - hat(a - node)) / ((b - a) * grid.h[d]);
    }
    f
}

/// GIMP weights and gradients of a particle at `x` with domain half-widths `half`
/// (at most 3^D entries; requires 0 < half ≤ h/2 per direction).
pub fn evaluate<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    tensor_product(grid, &axes(grid, x, half), node, w, grad)
}

/// The GIMP factors of a particle at `x` with domain half-lengths `half`, axis
/// by axis.
pub(super) fn axes<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
) -> [AxisFactors; D] {
    debug_assert_eq!(grid.degree, 1, "GIMP lives on a degree-1 grid");
    per_axis(|d| domain_factors(grid, x, half, d))
}

/// Ψ(t) = ∫_{−∞}^t s φ(s) ds, the first moment of the unit hat (piecewise cubic).
fn hat_first_moment(t: f64) -> f64 {
    if t <= -1.0 {
        0.0
    } else if t <= 0.0 {
        t * t / 2.0 + t * t * t / 3.0 - 1.0 / 6.0
    } else if t < 1.0 {
        -1.0 / 6.0 + t * t / 2.0 - t * t * t / 3.0
    } else {
        0.0
    }
}

/// Per axis, the domain averages of (y − x) N_I' (dimensionless) and of
/// (y − x) N_I (a length) over the clipped domain [a, b], x the particle.
fn moment_factors<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    d: usize,
) -> MomentFactors {
    let f = domain_factors(grid, x, half, d);
    let (xi, a, b) = clipped_domain(grid, x, half, d);
    let (mut slope_moment, mut weight_moment) = ([0.0; MAX_PER_AXIS], [0.0; MAX_PER_AXIS]);
    for k in 0..f.count {
        let node = (f.first + k) as f64;
        let (a, b, c) = (a - node, b - node, xi - node);
        // ∫ (y − x) N' dy = [(y − x) N]_a^b − ∫ N dy (by parts).
        slope_moment[k] = ((b - c) * hat(b) - (a - c) * hat(a)) / (b - a) - f.weight[k];
        weight_moment[k] = grid.h[d]
            * (hat_first_moment(b) - hat_first_moment(a) - c * (hat_integral(b) - hat_integral(a)))
            / (b - a);
    }
    (f, slope_moment, weight_moment)
}

/// The first moments of the GIMP gradients over the particle domain Ω about the
/// particle x, M_kj = (1/|Ω|) ∫_Ω (y − x)_k ∂_j N_I(y) dy, entry by entry in the
/// order of `evaluate`: with a stress linear within the domain,
/// (1/|Ω|) ∫_Ω σ ∇N_I = σ(x) ∇S_I + Σ_k ∂_kσ M_k·.
pub fn moments<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    half: &Vector<D>,
    out: &mut [Tensor<D>],
) -> usize {
    let axes: [_; D] = std::array::from_fn(|d| moment_factors(grid, x, half, d));
    moment_product(&axes, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shape::linear;
    use crate::physics::shape::tests::*;

    fn eval<const D: usize>(g: &Grid<D>, x: &Vector<D>, half: &Vector<D>) -> Stencil<D> {
        Stencil::collect(3usize.pow(D as u32), |n, w, gr| {
            evaluate(g, x, half, n, w, gr)
        })
    }

    /// Random half-widths in (0.05 h, 0.5 h], one in four exactly h/2 (one particle per cell).
    fn random_half<const D: usize>(g: &Grid<D>, rng: &mut Rng) -> Vector<D> {
        Vector::<D>::from_fn(|d, _| {
            g.h[d]
                * if rng.below(4) == 0 {
                    0.5
                } else {
                    rng.range(0.05, 0.5)
                }
        })
    }

    /// The clipped domain [a, b] along every axis.
    fn clipped<const D: usize>(
        g: &Grid<D>,
        x: &Vector<D>,
        half: &Vector<D>,
    ) -> (Vector<D>, Vector<D>) {
        ((x - half).sup(&g.min), (x + half).inf(&g.max))
    }

    fn sum_rules<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(11);
        let mut interior = 0;
        for x in sample_points(&g, 400) {
            let half = random_half(&g, &mut rng);
            let s = eval(&g, &x, &half);
            s.check_partition_of_unity(&g);
            s.check_gradient_reproduction(&g, 1e-10);
            // Linear fields: exact for unclipped domains; the clipped-domain centre otherwise.
            let (a, b) = clipped(&g, &x, &half);
            s.check_linear_reproduction(&g, &((a + b) / 2.0), 1e-12);
            if a == x - half && b == x + half {
                s.check_linear_reproduction(&g, &x, 1e-12);
                interior += 1;
            }
        }
        assert!(interior > 50);
    }

    #[test]
    fn sum_rules_2d() {
        sum_rules::<2>();
    }

    #[test]
    fn sum_rules_3d() {
        sum_rules::<3>();
    }

    /// Weights, gradients and the gradients' first moments about the particle equal
    /// the domain averages of the hat functions, their gradients and (y − x) ⊗ ∇N,
    /// integrated independently by Gauss quadrature of `linear::evaluate`;
    /// this covers the clipping at the faces.
    fn domain_average_of_hats<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(12);
        for x in sample_points(&g, 150) {
            let half = random_half(&g, &mut rng);
            let (a, b) = clipped(&g, &x, &half);
            let mut w = vec![0.0; g.node_count()];
            let mut grad = vec![Vector::<D>::zeros(); g.node_count()];
            let mut moment = vec![Tensor::<D>::zeros(); g.node_count()];
            for (y, q) in box_quadrature(&g, &a, &b) {
                let hats = Stencil::collect(1 << D, |n, w, gr| linear::evaluate(&g, &y, n, w, gr));
                for k in 0..hats.len() {
                    w[hats.node[k] as usize] += q * hats.w[k];
                    grad[hats.node[k] as usize] += hats.grad[k] * q;
                    moment[hats.node[k] as usize] += (y - x) * hats.grad[k].transpose() * q;
                }
            }
            let s = eval(&g, &x, &half);
            let mut m = vec![Tensor::<D>::repeat(f64::NAN); 3usize.pow(D as u32)];
            assert_eq!(moments(&g, &x, &half, &mut m), s.len());
            for (k, n) in s.nodes().iter().enumerate() {
                let error = (m[k] - moment[*n as usize]).norm();
                assert!(error < 1e-12, "first moment of {n} at {x}: {error:e}");
            }
            for n in 0..g.node_count() {
                assert!(
                    (s.weight_of(n) - w[n]).abs() < 1e-12,
                    "weight of {n} at {x}"
                );
                assert!(
                    (s.grad_of(n) - grad[n]).norm() * g.h_min() < 1e-10,
                    "gradient of {n} at {x}"
                );
            }
        }
    }

    #[test]
    fn domain_average_of_hats_2d() {
        domain_average_of_hats::<2>();
    }

    #[test]
    fn domain_average_of_hats_3d() {
        domain_average_of_hats::<3>();
    }

    /// For unclipped domains the gradient is ∂S/∂x_p: central differences away from
    /// the kinks (domain ends crossing node lines).
    fn finite_differences<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(13);
        let mut checked = 0;
        for x in sample_points(&g, 300) {
            let half = random_half(&g, &mut rng);
            let step = 1e-5 * g.h_min();
            let margin = half.add_scalar(3.0 * step);
            let inside = g.contains(&(x - margin)) && g.contains(&(x + margin));
            let kink = (0..D).any(|d| {
                let xi = cell_coordinate(&g, &x, d);
                let reach = half[d] / g.h[d];
                near_integer(xi - reach, 3e-5) || near_integer(xi + reach, 3e-5)
            });
            if inside && !kink {
                check_finite_differences(&g, &x, step, 1e-8, |y| eval(&g, y, &half));
                checked += 1;
            }
        }
        assert!(checked > 50, "only {checked} particles checked");
    }

    #[test]
    fn finite_differences_2d() {
        finite_differences::<2>();
    }

    #[test]
    fn finite_differences_3d() {
        finite_differences::<3>();
    }

    /// Closed-form 1D uGIMP weight and its derivative in d = x_p − x_I
    /// (Bardenhagen & Kober 2004), for lp ≤ h/2.
    fn closed_form(d: f64, h: f64, lp: f64) -> (f64, f64) {
        let (ad, sign) = (d.abs(), d.signum());
        if ad < lp {
            (1.0 - (d * d + lp * lp) / (2.0 * h * lp), -d / (h * lp))
        } else if ad <= h - lp {
            (1.0 - ad / h, -sign / h)
        } else if ad < h + lp {
            let gap = h + lp - ad;
            (gap * gap / (4.0 * h * lp), -sign * gap / (2.0 * h * lp))
        } else {
            (0.0, 0.0)
        }
    }

    /// On a strip one cell wide in every transverse direction, summing the weights
    /// over the transverse nodes leaves exactly the 1D weight along x (the transverse
    /// factors sum to one whatever the transverse clipping).
    fn closed_form_strip<const D: usize>() {
        let cells: [usize; D] = std::array::from_fn(|d| if d == 0 { 8 } else { 1 });
        let h = 0.4;
        let max = Vector::<D>::from_fn(|d, _| cells[d] as f64 * h);
        let g = Grid::new(Vector::<D>::zeros(), max, cells, 1);
        let mut rng = Rng::new(14);
        for lp in [0.5 * h, 0.25 * h, 0.1 * h, 0.37 * h] {
            for k in 0..200 {
                // Special offsets from node 3 first (the closed form's breakpoints), then random.
                let specials = [0.0, lp, h - lp, h + lp, -lp, lp - h, 0.5 * h];
                let xp = if k < specials.len() {
                    3.0 * h + specials[k]
                } else {
                    rng.range(lp, g.max[0] - lp)
                };
                let x = Vector::<D>::from_fn(|d, _| if d == 0 { xp } else { rng.range(0.0, h) });
                let half =
                    Vector::<D>::from_fn(|d, _| if d == 0 { lp } else { rng.range(0.05, 0.5) * h });
                let s = eval(&g, &x, &half);
                for i in 0..g.nodes[0] {
                    let column = (0..g.node_count()).filter(|&n| g.node_ijk(n)[0] == i);
                    let (w, dw) = column.fold((0.0, 0.0), |(w, dw), n| {
                        (w + s.weight_of(n), dw + s.grad_of(n)[0])
                    });
                    let (w_exact, dw_exact) = closed_form(xp - i as f64 * h, h, lp);
                    assert!(
                        (w - w_exact).abs() < 1e-12,
                        "lp {lp} x {xp} node {i}: {w} vs {w_exact}"
                    );
                    assert!(
                        (dw - dw_exact).abs() * h < 1e-10,
                        "lp {lp} x {xp} node {i}: {dw} vs {dw_exact}"
                    );
                }
            }
        }
    }

    #[test]
    fn closed_form_strip_2d() {
        closed_form_strip::<2>();
    }

    #[test]
    fn closed_form_strip_3d() {
        closed_form_strip::<3>();
    }

    #[test]
    #[should_panic(expected = "GIMP domain half-width")]
    fn domain_wider_than_a_cell_is_rejected() {
        let g = test_grid::<2>(1);
        let x = (g.min + g.max) / 2.0;
        eval(&g, &x, &(g.h * 0.6));
    }
}
