//! Shape functions behind one interface.
//!
//! Every family evaluates, for one particle, the list of nodes it touches with the
//! weight S_Ip and the gradient ∇S_Ip (thesis 2-53, 2-54; standard MPM is the
//! special case χ_p = V_p δ(x − x_p), 2-55). All families satisfy the partition of
//! unity Σ_I S_Ip = 1 and Σ_I ∇S_Ip = 0 and reproduce linear fields.

pub(crate) mod bspline;
pub(crate) mod cpdi;
pub(crate) mod gimp;
pub(crate) mod hoop;
pub(crate) mod linear;

pub use linear::{AxisFactors, MAX_PER_AXIS};

use crate::dim::{restrict, Mat3, Tensor, Vector};
use crate::model::grid::Grid;
use crate::model::tensors::Tensors;
pub use crate::scene::ShapeFunction;
use rayon::prelude::*;

/// Evaluate the nodes, weights and gradients of one particle. Writes at most
/// `max_support` entries into the output slices and returns how many it wrote.
/// `half_length0` is the reference half-size of the particle domain and `f` its
/// deformation gradient (used by cpGIMP and CPDI).
#[allow(clippy::too_many_arguments)]
pub fn evaluate<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    x: &Vector<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
    node: &mut [u32],
    w: &mut [f64],
    grad: &mut [Vector<D>],
) -> usize {
    match shape {
        ShapeFunction::Linear => linear::evaluate(grid, x, node, w, grad),
        ShapeFunction::Ugimp => gimp::evaluate(grid, x, half_length0, node, w, grad),
        ShapeFunction::Cpgimp => {
            let half = contiguous_half_length(grid, half_length0, f);
            gimp::evaluate(grid, x, &half, node, w, grad)
        }
        ShapeFunction::Cpbspline2 => {
            let half = contiguous_half_length(grid, half_length0, f);
            bspline::evaluate_domain(grid, x, &half, 2, node, w, grad)
        }
        ShapeFunction::Cpdi => {
            let r: Tensor<D> = restrict::<D>(f) * Tensor::<D>::from_diagonal(half_length0);
            cpdi::evaluate(grid, x, &r, node, w, grad)
        }
        ShapeFunction::Bspline2 => bspline::evaluate(grid, x, 2, node, w, grad),
        ShapeFunction::Bspline3 => bspline::evaluate(grid, x, 3, node, w, grad),
    }
}

/// The first moments M_kj = (1/|Ω|) ∫_Ω (y − x)_k ∂_j N_I of the gradients over
/// the particle domain about the particle, entry by entry in the order of
/// `evaluate` (`solver::implicit::stress_gradient`): for the families that integrate over
/// a box domain stretched with the material, `cpgimp` and `cpbspline2`; `None`
/// for the others.
pub fn gradient_moments<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    x: &Vector<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
    out: &mut [Tensor<D>],
) -> Option<usize> {
    let half = contiguous_half_length(grid, half_length0, f);
    match shape {
        ShapeFunction::Cpgimp => Some(gimp::moments(grid, x, &half, out)),
        ShapeFunction::Cpbspline2 => Some(bspline::domain_gradient_moments(grid, x, &half, 2, out)),
        _ => None,
    }
}

/// The mean of a nodal field (`value` of a grid node) at the 2^D corners of the
/// particle's box domain, by the point values of the grid basis the family
/// averages (hats for `cpgimp`, quadratic B-splines for `cpbspline2`); corners
/// outside the grid are taken on its faces. `None` for the other families.
pub fn domain_corner_mean<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    x: &Vector<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
    value: impl Fn(u32) -> Vector<D>,
) -> Option<Vector<D>> {
    let point = match shape {
        ShapeFunction::Cpgimp => ShapeFunction::Linear,
        ShapeFunction::Cpbspline2 => ShapeFunction::Bspline2,
        _ => return None,
    };
    let half = contiguous_half_length(grid, half_length0, f);
    let (mut node, mut w, mut grad) = ([0u32; 27], [0.0; 27], [Vector::<D>::zeros(); 27]);
    let mut sum = Vector::<D>::zeros();
    for corner in 0..1usize << D {
        let y = Vector::<D>::from_fn(|d, _| match corner >> d & 1 {
            1 => x[d] + half[d],
            _ => x[d] - half[d],
        });
        let y = y.sup(&grid.min).inf(&grid.max);
        let n = evaluate(
            point,
            grid,
            &y,
            half_length0,
            f,
            &mut node,
            &mut w,
            &mut grad,
        );
        for k in 0..n {
            sum += value(node[k]) * w[k];
        }
    }
    Some(sum / (1usize << D) as f64)
}

/// The contiguous particle domain's half-lengths (cpGIMP): the reference ones
/// stretched by F_dd, kept within (0, h/2] so the support stays within two cells per
/// axis (a domain stretched beyond a cell is capped at one cell).
pub(crate) fn contiguous_half_length<const D: usize>(
    grid: &Grid<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
) -> Vector<D> {
    Vector::<D>::from_fn(|d, _| {
        (half_length0[d] * f[(d, d)]).clamp(1e-3 * half_length0[d], 0.5 * grid.h[d])
    })
}

/// Where the factor of each axis of an entry with slot code `code` is in the
/// axis-factor arrays of particle p (`Values::Axes`).
#[inline(always)]
fn slots<const D: usize>(p: usize, per_axis: usize, code: u8) -> [usize; D] {
    let base = p * D * per_axis;
    std::array::from_fn(|d| base + d * per_axis + (code >> (2 * d) & 3) as usize)
}

/// The deformation gradient as `shape` reads it: the particle's (`f()`, which
/// may unpack it) for the families that follow the deformation, else I (unread).
#[inline(always)]
pub fn deformation_for(shape: ShapeFunction, f: impl FnOnce() -> Mat3) -> Mat3 {
    match shape.reads_deformation() {
        true => f(),
        false => Mat3::identity(),
    }
}

/// The per-axis factors of a particle for the separable families (all but
/// CPDI), as `evaluate` forms its tensor product from them.
#[inline(always)]
pub fn separable_axes<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    x: &Vector<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
) -> [linear::AxisFactors; D] {
    match shape {
        ShapeFunction::Linear => linear::axes(grid, x),
        ShapeFunction::Ugimp => gimp::axes(grid, x, half_length0),
        ShapeFunction::Cpgimp => {
            gimp::axes(grid, x, &contiguous_half_length(grid, half_length0, f))
        }
        ShapeFunction::Cpbspline2 => {
            bspline::domain_axes(grid, x, &contiguous_half_length(grid, half_length0, f), 2)
        }
        ShapeFunction::Bspline2 => bspline::axes(grid, x, 2),
        ShapeFunction::Bspline3 => bspline::axes(grid, x, 3),
        ShapeFunction::Cpdi => unreachable!("CPDI is not separable"),
    }
}

/// Shape-function values of all particles for one step, in fixed-stride storage:
/// particle p owns entries `p*stride .. p*stride + count[p]`, each with its node.
/// Read an entry's S_Ip and ∇S_Ip with `weight(e)` and `grad(e)`.
#[derive(Clone, Debug, Default)]
pub struct Stencils<const D: usize> {
    pub stride: usize,
    pub count: Vec<u32>,
    pub node: Vec<u32>,
    values: Values<D>,
    owner: Owner,
    /// Axisymmetric mode only (else empty): S_Ip / r_p per entry, the hoop
    /// gradient (`physics::shape::hoop`).
    pub hoop: Vec<f64>,
}

/// Where the values of the entries are kept.
#[derive(Clone, Debug)]
enum Values<const D: usize> {
    /// Per entry: CPDI, whose functions are not products of 1D factors.
    Entries {
        weight: Vec<f64>,
        grad: Vec<Vector<D>>,
    },
    /// Per particle and axis, for the separable families (linear, GIMP,
    /// B-splines): factors S_d and S'_d at `per_axis` slots per axis, and each
    /// entry's slot on every axis (2 bits per axis); S_I = Π_d S_d and
    /// ∂S_I/∂x_d = S'_d Π_{e≠d} S_e are formed when read, with the arithmetic of
    /// `linear::tensor_product`. In 2D quadratic B-splines take 141 bytes per
    /// particle instead of 252, in 3D 279 instead of 972.
    Axes {
        per_axis: usize,
        slot: Vec<u8>,
        weight: Vec<f64>,
        slope: Vec<f64>,
    },
}

impl<const D: usize> Default for Values<D> {
    fn default() -> Self {
        Values::Entries {
            weight: Vec::new(),
            grad: Vec::new(),
        }
    }
}

impl<const D: usize> Stencils<D> {
    /// Evaluate the shape functions of every particle (in parallel; each particle
    /// writes only its own entries, so the result does not depend on threads).
    pub fn compute(
        &mut self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        x: &[Vector<D>],
        half_length0: &[Vector<D>],
        f: &Tensors,
    ) {
        let n = x.len();
        let stride = shape.max_support(D);
        self.stride = stride;
        self.owner = Owner::new(stride);
        self.count.resize(n, 0);
        self.node.resize(n * stride, 0);
        self.hoop.clear();
        match shape.per_axis() {
            Some(per_axis) => self.compute_axes(shape, per_axis, grid, x, half_length0, f),
            None => self.compute_entries(shape, grid, x, half_length0, f),
        }
    }

    /// `compute` for a family without per-axis factors: values per entry.
    fn compute_entries(
        &mut self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        x: &[Vector<D>],
        half_length0: &[Vector<D>],
        f: &Tensors,
    ) {
        let (n, stride) = (x.len(), self.stride);
        if !matches!(self.values, Values::Entries { .. }) {
            self.values = Values::default();
        }
        let Values::Entries { weight, grad } = &mut self.values else {
            unreachable!()
        };
        weight.resize(n * stride, 0.0);
        grad.resize(n * stride, Vector::<D>::zeros());
        self.count
            .par_iter_mut()
            .zip(self.node.par_chunks_mut(stride))
            .zip(weight.par_chunks_mut(stride))
            .zip(grad.par_chunks_mut(stride))
            .enumerate()
            .with_min_len(crate::parallel::MIN_PARALLEL_LEN)
            .for_each(|(p, (((c, nd), w), g))| {
                // A particle outside the grid (removed, `Model::removed`) has no nodes.
                *c = match grid.contains(&x[p]) {
                    true => evaluate(
                        shape,
                        grid,
                        &x[p],
                        &half_length0[p],
                        &deformation_for(shape, || f.get(p)),
                        nd,
                        w,
                        g,
                    ) as u32,
                    false => 0,
                };
            });
    }

    /// `compute` for a separable family: the axis factors of every particle and
    /// the slots of its entries.
    fn compute_axes(
        &mut self,
        shape: ShapeFunction,
        per_axis: usize,
        grid: &Grid<D>,
        x: &[Vector<D>],
        half_length0: &[Vector<D>],
        f: &Tensors,
    ) {
        let (n, stride) = (x.len(), self.stride);
        // The buffers of the last step are reused.
        let (mut slot, mut weight, mut slope) = match std::mem::take(&mut self.values) {
            Values::Axes {
                slot,
                weight,
                slope,
                ..
            } => (slot, weight, slope),
            Values::Entries { .. } => Default::default(),
        };
        slot.resize(n * stride, 0);
        weight.resize(n * D * per_axis, 0.0);
        slope.resize(n * D * per_axis, 0.0);
        self.count
            .par_iter_mut()
            .zip(self.node.par_chunks_mut(stride))
            .zip(slot.par_chunks_mut(stride))
            .zip(weight.par_chunks_mut(D * per_axis))
            .zip(slope.par_chunks_mut(D * per_axis))
            .enumerate()
            .with_min_len(crate::parallel::MIN_PARALLEL_LEN)
            .for_each(|(p, ((((c, nd), sl), w), s))| {
                // A particle outside the grid (removed, `Model::removed`) has no nodes.
                if !grid.contains(&x[p]) {
                    *c = 0;
                    return;
                }
                let f = deformation_for(shape, || f.get(p));
                let axes = separable_axes(shape, grid, &x[p], &half_length0[p], &f);
                for (d, a) in axes.iter().enumerate() {
                    w[d * per_axis..(d + 1) * per_axis].copy_from_slice(&a.weight[..per_axis]);
                    s[d * per_axis..(d + 1) * per_axis].copy_from_slice(&a.slope[..per_axis]);
                }
                *c = linear::tensor_slots(grid, &axes, nd, sl) as u32;
            });
        self.values = Values::Axes {
            per_axis,
            slot,
            weight,
            slope,
        };
    }

    /// S_Ip of entry e.
    #[inline(always)]
    pub fn weight(&self, e: usize) -> f64 {
        self.weight_at(self.owner.of(e as u32), e)
    }

    /// ∇S_Ip of entry e.
    #[inline(always)]
    pub fn grad(&self, e: usize) -> Vector<D> {
        self.grad_at(self.owner.of(e as u32), e)
    }

    /// S_Ip of entry e of particle p (the caller knows p).
    #[inline(always)]
    pub fn weight_at(&self, p: usize, e: usize) -> f64 {
        match &self.values {
            Values::Entries { weight, .. } => weight[e],
            Values::Axes {
                per_axis,
                slot,
                weight,
                ..
            } => {
                let at = slots::<D>(p, *per_axis, slot[e]);
                (0..D).map(|d| weight[at[d]]).product()
            }
        }
    }

    /// ∇S_Ip of entry e of particle p.
    #[inline(always)]
    pub fn grad_at(&self, p: usize, e: usize) -> Vector<D> {
        self.value_at(p, e).1
    }

    /// (S_Ip, ∇S_Ip) of entry e of particle p.
    #[inline(always)]
    pub fn value_at(&self, p: usize, e: usize) -> (f64, Vector<D>) {
        match &self.values {
            Values::Entries { weight, grad } => (weight[e], grad[e]),
            Values::Axes {
                per_axis,
                slot,
                weight,
                slope,
            } => {
                let at = slots::<D>(p, *per_axis, slot[e]);
                let w: [f64; D] = std::array::from_fn(|d| weight[at[d]]);
                let grad = Vector::<D>::from_fn(|d, _| {
                    (0..D)
                        .map(|k| match k == d {
                            true => slope[at[k]],
                            false => w[k],
                        })
                        .product()
                });
                (w.iter().product(), grad)
            }
        }
    }

    /// The number of entry slots (particles × stride).
    pub fn len(&self) -> usize {
        self.node.len()
    }

    pub fn is_empty(&self) -> bool {
        self.node.is_empty()
    }

    /// Entry range of particle p.
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        p * self.stride..p * self.stride + self.count[p] as usize
    }

    /// The particle of an entry, for loops over many entries.
    pub fn owner(&self) -> Owner {
        Owner::new(self.stride)
    }
}

/// The particle that owns stencil entry e, ⌊e / stride⌋, by one multiplication
/// instead of a division: ⌊e/d⌋ = ⌊c·e / 2⁶⁴⌋ with c = ⌈2⁶⁴/d⌉, exact for every
/// 32-bit e and 1 < d < 2³² (Lemire, Kaser & Kurz 2019, Softw. Pract. Exp. 49).
#[derive(Clone, Copy, Debug, Default)]
pub struct Owner {
    c: u64,
}

impl Owner {
    pub fn new(stride: usize) -> Self {
        assert!(
            (2..1 << 32).contains(&stride),
            "stencil stride {stride} outside 2..2³²"
        );
        Owner {
            c: u64::MAX / stride as u64 + 1,
        }
    }

    pub fn of(&self, e: u32) -> usize {
        ((self.c as u128 * e as u128) >> 64) as usize
    }
}

#[cfg(test)]
pub(crate) mod tests {
    //! Helpers shared by the shape-function tests of every family, and checks across
    //! families through the `ShapeFunction` dispatch.

    use super::*;
    use crate::model::tensors::Layout;
    use strum::IntoEnumIterator;

    /// Small deterministic generator (SplitMix64), so tests need no extra crate.
    pub(crate) struct Rng(u64);

    impl Rng {
        pub(crate) fn new(seed: u64) -> Self {
            Rng(seed)
        }

        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }

        /// Uniform in [0, 1).
        pub(crate) fn unit(&mut self) -> f64 {
            (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
        }

        /// Uniform in [lo, hi).
        pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.unit()
        }

        pub(crate) fn below(&mut self, n: usize) -> usize {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// A grid with unequal cell sizes, an offset origin and few cells, for `degree`.
    pub(crate) fn test_grid<const D: usize>(degree: usize) -> Grid<D> {
        let min = Vector::<D>::from_fn(|d, _| [-1.0, 0.5, 2.0][d]);
        let cells: [usize; D] = std::array::from_fn(|d| [6, 5, 4][d]);
        let h = [0.3, 0.45, 0.25];
        let max = Vector::<D>::from_fn(|d, _| min[d] + cells[d] as f64 * h[d]);
        Grid::new(min, max, cells, degree)
    }

    /// One coordinate along axis d: random interior, exactly on a face, on a node
    /// line, just inside a face, or just either side of a cell boundary.
    pub(crate) fn sample_coordinate<const D: usize>(g: &Grid<D>, d: usize, rng: &mut Rng) -> f64 {
        let (lo, hi, h) = (g.min[d], g.max[d], g.h[d]);
        let line = lo + h * rng.below(g.cells[d] + 1) as f64;
        let x = match rng.below(16) {
            0 => lo,
            1 => hi,
            2 => line,
            3 => lo + 1e-9 * h,
            4 => hi - 1e-9 * h,
            5 => line + 1e-7 * h * (rng.unit() - 0.5),
            _ => rng.range(lo, hi),
        };
        x.clamp(lo, hi)
    }

    /// Deterministic particle positions over the closed grid box.
    pub(crate) fn sample_points<const D: usize>(g: &Grid<D>, n: usize) -> Vec<Vector<D>> {
        let mut rng = Rng::new(0x5EED + D as u64);
        (0..n)
            .map(|_| Vector::<D>::from_fn(|d, _| sample_coordinate(g, d, &mut rng)))
            .collect()
    }

    /// Gauss points and weights (summing to 1) of the clipped domain along axis d,
    /// split at the cell faces (the hats' kinks, the B-splines' knots): two-point
    /// Gauss per piece, exact for polynomials of degree 3 on every piece.
    pub(crate) fn axis_quadrature<const D: usize>(
        g: &Grid<D>,
        a: f64,
        b: f64,
        d: usize,
    ) -> Vec<(f64, f64)> {
        let mut cuts = vec![a];
        cuts.extend(
            (0..=g.cells[d])
                .map(|i| g.min[d] + i as f64 * g.h[d])
                .filter(|&y| y > a && y < b),
        );
        cuts.push(b);
        let gauss = 0.5 / 3f64.sqrt();
        let mut points = Vec::new();
        for piece in cuts.windows(2) {
            let (mid, len) = ((piece[0] + piece[1]) / 2.0, piece[1] - piece[0]);
            for s in [-gauss, gauss] {
                points.push((mid + s * len, 0.5 * len / (b - a)));
            }
        }
        points
    }

    /// Gauss points and weights (summing to 1) of the box [a, b]: the tensor
    /// product of `axis_quadrature` along every axis.
    pub(crate) fn box_quadrature<const D: usize>(
        g: &Grid<D>,
        a: &Vector<D>,
        b: &Vector<D>,
    ) -> Vec<(Vector<D>, f64)> {
        let rules: [Vec<(f64, f64)>; D] =
            std::array::from_fn(|d| axis_quadrature(g, a[d], b[d], d));
        let total: usize = rules.iter().map(|r| r.len()).product();
        (0..total)
            .map(|flat| {
                let mut rest = flat;
                let (mut y, mut q) = (Vector::<D>::zeros(), 1.0);
                for d in 0..D {
                    let (yd, qd) = rules[d][rest % rules[d].len()];
                    rest /= rules[d].len();
                    y[d] = yd;
                    q *= qd;
                }
                (y, q)
            })
            .collect()
    }

    /// Is `t` within `tol` of an integer?
    pub(crate) fn near_integer(t: f64, tol: f64) -> bool {
        (t - t.round()).abs() < tol
    }

    /// The entries one particle's evaluation wrote.
    #[derive(Clone, Debug)]
    pub(crate) struct Stencil<const D: usize> {
        pub node: Vec<u32>,
        pub w: Vec<f64>,
        pub grad: Vec<Vector<D>>,
    }

    impl<const D: usize> Stencil<D> {
        /// Run `eval` on output slices of exactly `capacity` entries (an overflow panics).
        pub(crate) fn collect(
            capacity: usize,
            eval: impl FnOnce(&mut [u32], &mut [f64], &mut [Vector<D>]) -> usize,
        ) -> Self {
            let mut node = vec![u32::MAX; capacity];
            let mut w = vec![f64::NAN; capacity];
            let mut grad = vec![Vector::<D>::repeat(f64::NAN); capacity];
            let n = eval(&mut node, &mut w, &mut grad);
            assert!(n <= capacity, "wrote {n} entries into {capacity}");
            node.truncate(n);
            w.truncate(n);
            grad.truncate(n);
            Stencil { node, w, grad }
        }

        pub(crate) fn len(&self) -> usize {
            self.node.len()
        }

        pub(crate) fn nodes(&self) -> &[u32] {
            &self.node
        }

        pub(crate) fn weight_of(&self, n: usize) -> f64 {
            self.node
                .iter()
                .zip(&self.w)
                .filter(|(k, _)| **k as usize == n)
                .map(|(_, w)| *w)
                .sum()
        }

        pub(crate) fn grad_of(&self, n: usize) -> Vector<D> {
            self.node
                .iter()
                .zip(&self.grad)
                .filter(|(k, _)| **k as usize == n)
                .map(|(_, g)| *g)
                .sum()
        }

        /// Σ S_I = 1 (1e-12) and Σ ∇S_I = 0 (1e-10 / h); also checks the entries are
        /// finite, inside the grid, non-trivial and on distinct nodes.
        pub(crate) fn check_partition_of_unity(&self, g: &Grid<D>) {
            self.check_entries(g);
            let sum: f64 = self.w.iter().sum();
            assert!((sum - 1.0).abs() < 1e-12, "Σ S = {sum}");
            let grad: Vector<D> = self.grad.iter().sum();
            assert!(grad.norm() * g.h_min() < 1e-10, "Σ ∇S = {grad}");
        }

        pub(crate) fn check_entries(&self, g: &Grid<D>) {
            let mut seen = self.node.clone();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), self.len(), "duplicate nodes {:?}", self.node);
            assert!(self.node.iter().all(|&n| (n as usize) < g.node_count()));
            for (w, gr) in self.w.iter().zip(&self.grad) {
                assert!(w.is_finite() && gr.iter().all(|c| c.is_finite()));
                assert!(*w != 0.0 || gr.iter().any(|c| *c != 0.0), "all-zero entry");
            }
        }

        /// Σ S_I X_I = x.
        pub(crate) fn check_linear_reproduction(&self, g: &Grid<D>, x: &Vector<D>, tol: f64) {
            let xr: Vector<D> = self
                .node
                .iter()
                .zip(&self.w)
                .map(|(n, w)| g.node_position(g.node_ijk(*n as usize)) * *w)
                .sum();
            assert!(
                (xr - x).norm() < tol * g.max.abs().max().max(1.0),
                "Σ S X = {xr} ≠ {x}"
            );
        }

        /// Σ ∇S_I ⊗ X_I = I.
        pub(crate) fn check_gradient_reproduction(&self, g: &Grid<D>, tol: f64) {
            let m: Tensor<D> = self
                .node
                .iter()
                .zip(&self.grad)
                .map(|(n, gr)| gr * g.node_position(g.node_ijk(*n as usize)).transpose())
                .sum();
            assert!((m - Tensor::<D>::identity()).norm() < tol, "Σ ∇S ⊗ X = {m}");
        }
    }

    /// Central differences of the weights against the gradients at `x`:
    /// |ΔS/Δx_d − ∂S/∂x_d| < tol / h_min for every node touched at x or x ± step e_d.
    pub(crate) fn check_finite_differences<const D: usize>(
        g: &Grid<D>,
        x: &Vector<D>,
        step: f64,
        tol: f64,
        eval: impl Fn(&Vector<D>) -> Stencil<D>,
    ) {
        let here = eval(x);
        for d in 0..D {
            let (mut xp, mut xm) = (*x, *x);
            xp[d] += step;
            xm[d] -= step;
            let (plus, minus) = (eval(&xp), eval(&xm));
            let nodes = here.nodes().iter().chain(plus.nodes()).chain(minus.nodes());
            for &n in nodes {
                let n = n as usize;
                let fd = (plus.weight_of(n) - minus.weight_of(n)) / (2.0 * step);
                let exact = here.grad_of(n)[d];
                assert!(
                    (fd - exact).abs() * g.h_min() < tol,
                    "node {n} axis {d}: fd {fd} vs {exact} at {x}"
                );
            }
        }
    }

    /// A deformation gradient with rotation, shear and stretch, scaled so that the
    /// CPDI domain r = F diag(h/4) reaches at most `reach` cell sizes from the
    /// particle along each axis (Σ_i |r_di| ≤ reach h_d).
    fn random_deformation<const D: usize>(rng: &mut Rng, h: &Vector<D>, reach: f64) -> Mat3 {
        let mut f = Mat3::identity();
        for i in 0..D {
            for j in 0..D {
                f[(i, j)] = if i == j {
                    rng.range(0.3, 4.0)
                } else {
                    rng.range(-3.0, 3.0)
                };
            }
        }
        let half0 = h / 4.0;
        let r: Tensor<D> = restrict::<D>(&f) * Tensor::<D>::from_diagonal(&half0);
        let worst = (0..D)
            .map(|d| (0..D).map(|i| r[(d, i)].abs()).sum::<f64>() / h[d])
            .fold(0.0, f64::max);
        let scale = reach / worst;
        for i in 0..D {
            for j in 0..D {
                f[(i, j)] *= scale;
            }
        }
        f
    }

    #[test]
    fn owner_is_the_integer_quotient() {
        let mut rng = Rng::new(3);
        for stride in (2..=130).chain([343, 1000, 4096, 65_537]) {
            let owner = Owner::new(stride);
            let near_max = (0..64).map(|k| u32::MAX - k);
            let multiples = (0..64u32).flat_map(|k| {
                let m = (k as u64 * stride as u64).min(u32::MAX as u64) as u32;
                [m.saturating_sub(1), m, m.saturating_add(1)]
            });
            let random = (0..2000).map(|_| rng.next_u64() as u32);
            for e in near_max.chain(multiples).chain(random) {
                assert_eq!(owner.of(e), e as usize / stride, "{e} / {stride}");
            }
        }
    }

    /// Every family, through the dispatch, never writes more than `max_support`
    /// entries and keeps the partition of unity; CPDI with sheared, rotated domains
    /// stretched until they reach one cell size from the particle.
    fn all_families_respect_max_support<const D: usize>() {
        let mut rng = Rng::new(77);
        for shape in ShapeFunction::iter() {
            let g = test_grid::<D>(shape.degree());
            let cap = shape.max_support(D);
            for x in sample_points(&g, 400) {
                let reach = if rng.below(4) == 0 {
                    1.0
                } else {
                    rng.range(0.05, 1.0)
                };
                let mut f = random_deformation::<D>(&mut rng, &g.h, reach);
                if matches!(shape, ShapeFunction::Cpgimp | ShapeFunction::Cpbspline2) {
                    // cpGIMP needs 2·half ≤ h, i.e. F_dd ≤ 2 for half0 = h/4.
                    let widest = (0..D).map(|d| f[(d, d)]).fold(0.0, f64::max);
                    f *= 2.0 * reach / widest;
                }
                let half0 = g.h / 4.0;
                let s = Stencil::collect(cap, |n, w, gr| {
                    evaluate(shape, &g, &x, &half0, &f, n, w, gr)
                });
                s.check_partition_of_unity(&g);
            }
        }
    }

    #[test]
    fn all_families_respect_max_support_2d() {
        all_families_respect_max_support::<2>();
    }

    #[test]
    fn all_families_respect_max_support_3d() {
        all_families_respect_max_support::<3>();
    }

    /// The stencils read back, entry by entry, exactly what `evaluate` writes:
    /// the same nodes, counts and bits, for every family (per-axis factors for
    /// the separable ones), deformed particles, points on nodes and faces (zero
    /// entries skipped) and a particle outside the grid.
    fn stencils_read_back_evaluate<const D: usize>() {
        let mut rng = Rng::new(5);
        for shape in ShapeFunction::iter() {
            let g = test_grid::<D>(shape.degree());
            let mut x = sample_points(&g, 300);
            x.push(g.min);
            x.push(g.max);
            x.push(g.min + g.h);
            x.push(g.max + g.h);
            let f: Vec<Mat3> = (0..x.len())
                .map(|_| {
                    let mut f = random_deformation::<D>(&mut rng, &g.h, 0.4);
                    let widest = (0..D).map(|d| f[(d, d)]).fold(0.0, f64::max);
                    f *= 0.8 / widest.max(0.8);
                    f
                })
                .collect();
            let half0 = vec![g.h / 4.0; x.len()];
            let mut st = Stencils::<D>::default();
            let packed = Tensors::from_matrices(Layout::gradient(D), f.iter().copied());
            st.compute(shape, &g, &x, &half0, &packed);
            let cap = shape.max_support(D);
            for (p, xp) in x.iter().enumerate() {
                let (mut node, mut w, mut grad) = (
                    vec![0; cap],
                    vec![0.0; cap],
                    vec![Vector::<D>::zeros(); cap],
                );
                let n = match g.contains(xp) {
                    true => evaluate(
                        shape, &g, xp, &half0[p], &f[p], &mut node, &mut w, &mut grad,
                    ),
                    false => 0,
                };
                assert_eq!(st.count[p] as usize, n, "{shape:?} particle {p}");
                for (k, e) in st.range(p).enumerate() {
                    assert_eq!(st.node[e], node[k], "{shape:?} particle {p} entry {k}");
                    assert_eq!(st.weight(e).to_bits(), w[k].to_bits(), "{shape:?} {p} {k}");
                    assert_eq!(st.weight_at(p, e).to_bits(), w[k].to_bits());
                    let bits = |v: Vector<D>| v.map(f64::to_bits);
                    assert_eq!(bits(st.grad(e)), bits(grad[k]), "{shape:?} {p} {k}");
                    assert_eq!(bits(st.value_at(p, e).1), bits(grad[k]));
                }
            }
        }
    }

    #[test]
    fn stencils_read_back_evaluate_2d() {
        stencils_read_back_evaluate::<2>();
    }

    #[test]
    fn stencils_read_back_evaluate_3d() {
        stencils_read_back_evaluate::<3>();
    }
}
