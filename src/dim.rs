//! Small-tensor types shared by every module, and the embedding of `D`-dimensional
//! quantities into 3×3 tensors (plane strain: the out-of-plane row and column of the
//! velocity gradient are zero, so F_zz stays 1 and σ_zz follows from the material).

use nalgebra::{Matrix3, SMatrix, SVector};

pub type Vector<const D: usize> = SVector<f64, D>;
pub type Tensor<const D: usize> = SMatrix<f64, D, D>;
pub type Mat3 = Matrix3<f64>;

/// The upper-left D×D block of a 3×3 tensor.
pub fn restrict<const D: usize>(m: &Mat3) -> Tensor<D> {
    Tensor::<D>::from_fn(|i, j| m[(i, j)])
}

/// The six components of a symmetric tensor in Voigt order: xx, yy, zz, xy, yz, xz.
pub fn voigt(m: &Mat3) -> [f64; 6] {
    [
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        m[(0, 1)],
        m[(1, 2)],
        m[(0, 2)],
    ]
}

/// Embed a D×D increment of a deformation gradient: identity in the missing directions.
pub fn embed_deformation<const D: usize>(a: &Tensor<D>) -> Mat3 {
    let mut m = Mat3::identity();
    for i in 0..D {
        for j in 0..D {
            m[(i, j)] = a[(i, j)];
        }
    }
    m
}
