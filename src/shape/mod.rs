//! Shape functions behind one interface.
//!
//! Every family evaluates, for one particle, the list of nodes it touches with the
//! weight S_Ip and the gradient ∇S_Ip (thesis 2-53, 2-54; standard MPM is the
//! special case χ_p = V_p δ(x − x_p), 2-55). All families satisfy the partition of
//! unity Σ_I S_Ip = 1 and Σ_I ∇S_Ip = 0 and reproduce linear fields.

pub mod bspline;
pub mod cpdi;
pub mod gimp;
pub mod linear;

use crate::dim::{restrict, Mat3, Tensor, Vector};
use crate::grid::Grid;
use rayon::prelude::*;
use serde::Deserialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeFunction {
    /// Standard MPM: piecewise-linear (bilinear, trilinear) hat functions.
    Linear,
    /// Uniform GIMP: fixed axis-aligned particle domain.
    Ugimp,
    /// Contiguous-particle GIMP: axis-aligned domain stretched by the diagonal of F.
    Cpgimp,
    /// Convected particle domain interpolation (CPDI1): parallelogram/parallelepiped
    /// spanned by r_i = F r_i⁰, weights from the corners.
    Cpdi,
    /// Quadratic B-spline on a clamped uniform knot vector.
    Bspline2,
    /// Cubic B-spline on a clamped uniform knot vector.
    Bspline3,
}

impl ShapeFunction {
    pub fn name(&self) -> &'static str {
        match self {
            ShapeFunction::Linear => "linear",
            ShapeFunction::Ugimp => "ugimp",
            ShapeFunction::Cpgimp => "cpgimp",
            ShapeFunction::Cpdi => "cpdi",
            ShapeFunction::Bspline2 => "bspline2",
            ShapeFunction::Bspline3 => "bspline3",
        }
    }

    /// Polynomial degree of the underlying grid basis (sets the node layout).
    pub fn degree(&self) -> usize {
        match self {
            ShapeFunction::Bspline2 => 2,
            ShapeFunction::Bspline3 => 3,
            _ => 1,
        }
    }

    /// Largest number of nodes one particle can touch.
    pub fn max_support(&self, dim: usize) -> usize {
        let per_dir: usize = match self {
            ShapeFunction::Linear => 2,
            ShapeFunction::Ugimp | ShapeFunction::Cpgimp => 3,
            ShapeFunction::Cpdi => 4,
            ShapeFunction::Bspline2 => 3,
            ShapeFunction::Bspline3 => 4,
        };
        per_dir.pow(dim as u32)
    }

    /// Evaluate the nodes, weights and gradients of one particle. Writes at most
    /// `max_support` entries into the output slices and returns how many it wrote.
    /// `half_length0` is the reference half-size of the particle domain and `f` its
    /// deformation gradient (used by cpGIMP and CPDI).
    pub fn evaluate<const D: usize>(
        &self,
        grid: &Grid<D>,
        x: &Vector<D>,
        half_length0: &Vector<D>,
        f: &Mat3,
        node: &mut [u32],
        w: &mut [f64],
        grad: &mut [Vector<D>],
    ) -> usize {
        match self {
            ShapeFunction::Linear => linear::evaluate(grid, x, node, w, grad),
            ShapeFunction::Ugimp => gimp::evaluate(grid, x, half_length0, node, w, grad),
            ShapeFunction::Cpgimp => {
                let half = Vector::<D>::from_fn(|d, _| half_length0[d] * f[(d, d)]);
                gimp::evaluate(grid, x, &half, node, w, grad)
            }
            ShapeFunction::Cpdi => {
                let r: Tensor<D> = restrict::<D>(f) * Tensor::<D>::from_diagonal(half_length0);
                cpdi::evaluate(grid, x, &r, node, w, grad)
            }
            ShapeFunction::Bspline2 => bspline::evaluate(grid, x, 2, node, w, grad),
            ShapeFunction::Bspline3 => bspline::evaluate(grid, x, 3, node, w, grad),
        }
    }
}

/// Shape-function values of all particles for one step, in fixed-stride storage:
/// particle p owns entries `p*stride .. p*stride + count[p]`.
#[derive(Clone, Debug, Default)]
pub struct Stencils<const D: usize> {
    pub stride: usize,
    pub count: Vec<u32>,
    pub node: Vec<u32>,
    pub weight: Vec<f64>,
    pub grad: Vec<Vector<D>>,
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
        f: &[Mat3],
    ) {
        let n = x.len();
        let stride = shape.max_support(D);
        self.stride = stride;
        self.count.resize(n, 0);
        self.node.resize(n * stride, 0);
        self.weight.resize(n * stride, 0.0);
        self.grad.resize(n * stride, Vector::<D>::zeros());
        self.count
            .par_iter_mut()
            .zip(self.node.par_chunks_mut(stride))
            .zip(self.weight.par_chunks_mut(stride))
            .zip(self.grad.par_chunks_mut(stride))
            .enumerate()
            .for_each(|(p, (((c, nd), w), g))| {
                *c = shape.evaluate(grid, &x[p], &half_length0[p], &f[p], nd, w, g) as u32;
            });
    }

    /// Entry range of particle p.
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        p * self.stride..p * self.stride + self.count[p] as usize
    }
}
