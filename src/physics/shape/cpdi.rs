//! CPDI1 (Sadeghirad, Brannon & Burghardt 2011): the particle domain is the
//! parallelogram / parallelepiped x = x_p + Σ_i ξ_i r_i, ξ ∈ [−1, 1]^D, and the grid
//! hats are replaced by their multilinear interpolation from the 2^D corners
//! c_α = x_p + Σ_i s_αi r_i (signs s_α ∈ {−1, +1}^D).
//!
//! Weight: the domain average of that interpolant, S_I = (1/2^D) Σ_α N_I(c_α).
//! Gradient: its domain-averaged gradient, ∇S_I = (1/2^D) Σ_α N_I(c_α) J^{−T} s_α with
//! J = r (columns r_i). Derivation: with φ_α(ξ) = Π_i (1 + s_αi ξ_i)/2 and ∇_x = J^{−T}∇_ξ,
//! (1/V)∫ ∇_x φ_α dV = 2^{−D} J^{−T} ∫_{[−1,1]^D} ∇_ξ φ_α dξ and ∫ ∂φ_α/∂ξ_i dξ = s_αi.
//!
//! Boundary: a corner outside the grid box is clamped into the box before the hats
//! are evaluated. The partition of unity and Σ ∇S_I = 0 still hold; linear fields are
//! reproduced only while every corner is inside the box.
//!
//! A particle touches at most 2^D corners × 2^D hats = 4^D nodes, however large its
//! domain, so `max_support` cannot be exceeded.

use super::linear;
use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;

/// Add `weight`, `gradient` to the entry of `id`, or append a new entry; returns the count.
fn accumulate<const D: usize>(
    id: u32,
    weight: f64,
    gradient: Vector<D>,
    count: usize,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    if let Some(k) = node[..count].iter().position(|&n| n == id) {
        w[k] += weight;
        grad[k] += gradient;
        return count;
    }
    assert!(
        count < node.len(),
        "CPDI stencil overflows its {} entries",
        node.len()
    );
    node[count] = id;
    w[count] = weight;
    grad[count] = gradient;
    count + 1
}

/// CPDI1 weights and gradients of a particle at `x` whose domain is spanned by the
/// columns of `r` (at most 4^D entries).
pub fn evaluate<const D: usize>(
    grid: &Grid<D>,
    x: &Vector<D>,
    r: &Tensor<D>,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    debug_assert_eq!(
        grid.degree, 1,
        "CPDI interpolates the hats of a degree-1 grid"
    );
    // A collapsed domain (dependent r_i, det F = 0) has no gradient; the divergence
    // check stops a run at the end of the step that collapses one (det F ≤ 0), so
    // this zero is only a guard against a panic.
    let inv_t = r.try_inverse().unwrap_or_else(Tensor::zeros).transpose();
    let corners = 1usize << D;
    let share = 1.0 / corners as f64;
    let mut count = 0;
    for alpha in 0..corners {
        let sign = Vector::<D>::from_fn(|i, _| if alpha >> i & 1 == 1 { 1.0 } else { -1.0 });
        let corner = (x + r * sign).sup(&grid.min).inf(&grid.max);
        let corner_grad = inv_t * sign * share;
        let (mut hat_node, mut hat_w, mut hat_grad) =
            ([0u32; 8], [0.0; 8], [Vector::<D>::zeros(); 8]);
        let hats = linear::evaluate(grid, &corner, &mut hat_node, &mut hat_w, &mut hat_grad);
        for k in (0..hats).filter(|&k| hat_w[k] != 0.0) {
            let weight = hat_w[k];
            count = accumulate(
                hat_node[k],
                weight * share,
                corner_grad * weight,
                count,
                node,
                w,
                grad,
            );
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shape::gimp;
    use crate::physics::shape::tests::*;

    fn eval<const D: usize>(g: &Grid<D>, x: &Vector<D>, r: &Tensor<D>) -> Stencil<D> {
        Stencil::collect(4usize.pow(D as u32), |n, w, gr| evaluate(g, x, r, n, w, gr))
    }

    /// A rotated, sheared, stretched domain whose corners reach exactly `reach` cell
    /// sizes from the particle along every axis (Σ_i |r_di| = reach h_d).
    fn random_domain<const D: usize>(g: &Grid<D>, rng: &mut Rng, reach: f64) -> Tensor<D> {
        loop {
            let mut r = Tensor::<D>::from_fn(|_, _| rng.range(-1.0, 1.0));
            for d in 0..D {
                let row_reach: f64 = (0..D).map(|i| r[(d, i)].abs()).sum();
                r.row_mut(d).scale_mut(reach * g.h[d] / row_reach);
            }
            let normalised = Tensor::<D>::from_fn(|i, j| r[(i, j)] / (reach * g.h[i]));
            // Well conditioned: no corner collapses onto another.
            if normalised
                .try_inverse()
                .is_some_and(|inv| inv.norm() < 20.0)
            {
                return r;
            }
        }
    }

    fn corners<const D: usize>(x: &Vector<D>, r: &Tensor<D>) -> Vec<Vector<D>> {
        (0..1 << D)
            .map(|alpha| {
                x + r * Vector::<D>::from_fn(|i, _| if alpha >> i & 1 == 1 { 1.0 } else { -1.0 })
            })
            .collect()
    }

    fn sum_rules<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(21);
        let mut interior = 0;
        for x in sample_points(&g, 400) {
            let reach = rng.range(0.02, 1.0);
            let r = random_domain(&g, &mut rng, reach);
            let s = eval(&g, &x, &r);
            s.check_partition_of_unity(&g);
            let c = corners(&x, &r);
            let clamped: Vector<D> = c
                .iter()
                .map(|c| c.sup(&g.min).inf(&g.max))
                .sum::<Vector<D>>()
                / c.len() as f64;
            s.check_linear_reproduction(&g, &clamped, 1e-12);
            if c.iter().all(|c| g.contains(c)) {
                s.check_linear_reproduction(&g, &x, 1e-12);
                s.check_gradient_reproduction(&g, 1e-10);
                interior += 1;
            }
        }
        assert!(interior > 50, "only {interior} interior particles");
    }

    /// Dependent domain vectors (a collapsed particle, det F = 0): the weights
    /// still sum to one and reproduce the corners' mean, the gradients are zero,
    /// and nothing panics.
    #[test]
    fn a_collapsed_domain_has_weights_and_no_gradient() {
        let g = test_grid::<2>(1);
        let x = Vector::<2>::from_fn(|d, _| g.min[d] + 0.43 * (g.max[d] - g.min[d]));
        let a = Vector::<2>::new(0.3 * g.h[0], 0.2 * g.h[1]);
        let r = Tensor::<2>::from_columns(&[a, 0.5 * a]);
        let s = eval(&g, &x, &r);
        let sum: f64 = s.w.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "Σ S = {sum}");
        assert!(s.grad.iter().all(|gr| *gr == Vector::<2>::zeros()));
        s.check_linear_reproduction(&g, &x, 1e-12);
    }

    #[test]
    fn sum_rules_2d() {
        sum_rules::<2>();
    }

    #[test]
    fn sum_rules_3d() {
        sum_rules::<3>();
    }

    /// The definition checked independently of the J^{−T} formula: the weights and
    /// gradients are the domain averages of u_I(y) = Σ_α N_I(ĉ_α) φ_α(ξ(y)), the
    /// multilinear interpolant of the (clamped) corner hats. The average is taken by
    /// 2-point Gauss quadrature in ξ (exact), the gradient of u_I by five-point central
    /// differences in physical space (exact for u_I, a polynomial of degree ≤ 3 along
    /// any line).
    fn domain_average_of_interpolant<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(22);
        for x in sample_points(&g, 100) {
            let reach = rng.range(0.05, 1.0);
            let r = random_domain(&g, &mut rng, reach);
            let inv = r.try_inverse().unwrap();
            let hats: Vec<Stencil<D>> = corners(&x, &r)
                .iter()
                .map(|c| {
                    let c = c.sup(&g.min).inf(&g.max);
                    Stencil::collect(1 << D, |n, w, gr| linear::evaluate(&g, &c, n, w, gr))
                })
                .collect();
            let interpolant = |n: usize, y: &Vector<D>| -> f64 {
                let xi = inv * (y - x);
                (0..1 << D)
                    .map(|alpha| {
                        let phi: f64 = (0..D)
                            .map(|i| (1.0 + if alpha >> i & 1 == 1 { xi[i] } else { -xi[i] }) / 2.0)
                            .product();
                        hats[alpha].weight_of(n) * phi
                    })
                    .sum()
            };
            let s = eval(&g, &x, &r);
            let gauss = 1.0 / 3f64.sqrt();
            let step = 1e-2 * g.h_min();
            for n in 0..g.node_count() {
                let (mut w, mut grad) = (0.0, Vector::<D>::zeros());
                for q in 0..1 << D {
                    let xi =
                        Vector::<D>::from_fn(|i, _| if q >> i & 1 == 1 { gauss } else { -gauss });
                    let y = x + r * xi;
                    w += interpolant(n, &y) / (1 << D) as f64;
                    for d in 0..D {
                        let mut e = Vector::<D>::zeros();
                        e[d] = step;
                        let at = |k: f64| interpolant(n, &(y + e * k));
                        let slope =
                            (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * step);
                        grad[d] += slope / (1 << D) as f64;
                    }
                }
                assert!(
                    (s.weight_of(n) - w).abs() < 1e-12,
                    "weight of {n}: {} vs {w}",
                    s.weight_of(n)
                );
                assert!(
                    (s.grad_of(n) - grad).norm() * g.h_min() < 1e-10,
                    "gradient of {n}: {} vs {grad}",
                    s.grad_of(n)
                );
            }
        }
    }

    #[test]
    fn domain_average_of_interpolant_2d() {
        domain_average_of_interpolant::<2>();
    }

    #[test]
    fn domain_average_of_interpolant_3d() {
        domain_average_of_interpolant::<3>();
    }

    /// 2D divergence theorem, with no Jacobian at all: ∇S_I = (1/A) ∮ u_I n ds, where
    /// u_I is linear along each edge between the corner values N_I(ĉ_α).
    #[test]
    fn divergence_theorem_2d() {
        let g = test_grid::<2>(1);
        let mut rng = Rng::new(23);
        for x in sample_points(&g, 300) {
            let reach = rng.range(0.05, 1.0);
            let r = random_domain(&g, &mut rng, reach);
            // Corners in order around the domain: ξ = (−1,−1), (1,−1), (1,1), (−1,1).
            let ring: Vec<Vector<2>> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(a, b)| x + r * Vector::<2>::new(a, b))
                .collect();
            let hats: Vec<Stencil<2>> = ring
                .iter()
                .map(|c| {
                    let c = c.sup(&g.min).inf(&g.max);
                    Stencil::collect(4, |n, w, gr| linear::evaluate(&g, &c, n, w, gr))
                })
                .collect();
            let signed_area = 4.0 * r.determinant();
            let s = eval(&g, &x, &r);
            for n in 0..g.node_count() {
                let mut flux = Vector::<2>::zeros();
                for k in 0..4 {
                    let (p, q) = (k, (k + 1) % 4);
                    let edge = ring[q] - ring[p];
                    let mean = (hats[p].weight_of(n) + hats[q].weight_of(n)) / 2.0;
                    flux += Vector::<2>::new(edge[1], -edge[0]) * mean;
                }
                let expect = flux / signed_area;
                assert!(
                    (s.grad_of(n) - expect).norm() * g.h_min() < 1e-10,
                    "node {n}: {} vs {expect}",
                    s.grad_of(n)
                );
            }
        }
    }

    /// An axis-aligned domain inside one cell: the hats are multilinear there, so
    /// CPDI, GIMP and the plain hats at x_p all agree exactly.
    fn axis_aligned_in_one_cell<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(24);
        for _ in 0..200 {
            let cell: [usize; D] = std::array::from_fn(|d| rng.below(g.cells[d]));
            let half = Vector::<D>::from_fn(|d, _| rng.range(0.01, 0.2) * g.h[d]);
            let x = Vector::<D>::from_fn(|d, _| {
                g.min[d] + g.h[d] * cell[d] as f64 + rng.range(half[d], g.h[d] - half[d])
            });
            let s = eval(&g, &x, &Tensor::<D>::from_diagonal(&half));
            let gimp = Stencil::collect(3usize.pow(D as u32), |n, w, gr| {
                gimp::evaluate(&g, &x, &half, n, w, gr)
            });
            let hats = Stencil::collect(1 << D, |n, w, gr| linear::evaluate(&g, &x, n, w, gr));
            for n in 0..g.node_count() {
                for other in [&gimp, &hats] {
                    assert!((s.weight_of(n) - other.weight_of(n)).abs() < 1e-12);
                    assert!((s.grad_of(n) - other.grad_of(n)).norm() * g.h_min() < 1e-10);
                }
            }
        }
    }

    #[test]
    fn axis_aligned_in_one_cell_2d() {
        axis_aligned_in_one_cell::<2>();
    }

    #[test]
    fn axis_aligned_in_one_cell_3d() {
        axis_aligned_in_one_cell::<3>();
    }

    /// A tiny rotated, sheared domain away from node lines: CPDI tends to the plain
    /// hats, whose gradients are the finite-difference-checked ∂N_I/∂x at x_p
    /// (the error is O(|r|²/h²)).
    fn tiny_domain_limit<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(25);
        let mut checked = 0;
        for x in sample_points(&g, 300) {
            let r = random_domain(&g, &mut rng, 1e-4);
            let away = (0..D).all(|d| !near_integer((x[d] - g.min[d]) / g.h[d], 1e-3));
            if !away {
                continue;
            }
            let s = eval(&g, &x, &r);
            let hats = Stencil::collect(1 << D, |n, w, gr| linear::evaluate(&g, &x, n, w, gr));
            for n in 0..g.node_count() {
                assert!((s.weight_of(n) - hats.weight_of(n)).abs() < 1e-7);
                assert!((s.grad_of(n) - hats.grad_of(n)).norm() * g.h_min() < 1e-7);
            }
            checked += 1;
        }
        assert!(checked > 50);
    }

    #[test]
    fn tiny_domain_limit_2d() {
        tiny_domain_limit::<2>();
    }

    #[test]
    fn tiny_domain_limit_3d() {
        tiny_domain_limit::<3>();
    }

    /// However large and distorted the domain, at most 4^D nodes are touched.
    fn huge_domains_fit<const D: usize>() {
        let g = test_grid::<D>(1);
        let mut rng = Rng::new(26);
        for x in sample_points(&g, 300) {
            let reach = rng.range(1.0, 4.0);
            let r = random_domain(&g, &mut rng, reach);
            eval(&g, &x, &r).check_partition_of_unity(&g);
        }
    }

    #[test]
    fn huge_domains_fit_2d() {
        huge_domains_fit::<2>();
    }

    #[test]
    fn huge_domains_fit_3d() {
        huge_domains_fit::<3>();
    }
}
