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

/// The product a b of two deformation gradients, in the plane (a 2 × 2 block
/// and zz) when neither has out-of-plane shear: the plane strain and
/// axisymmetric gradients. Equal to the full product, term for term, but for
/// the sign of the zero out-of-plane shear.
#[inline(always)]
pub fn compose(a: &Mat3, b: &Mat3) -> Mat3 {
    let plane =
        |m: &Mat3| m[(0, 2)] == 0.0 && m[(1, 2)] == 0.0 && m[(2, 0)] == 0.0 && m[(2, 1)] == 0.0;
    if !(plane(a) && plane(b)) {
        return a * b;
    }
    let e = |i: usize, j: usize| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)];
    Mat3::new(
        e(0, 0),
        e(0, 1),
        0.0,
        e(1, 0),
        e(1, 1),
        0.0,
        0.0,
        0.0,
        a[(2, 2)] * b[(2, 2)],
    )
}

/// The rotation Q of the polar decomposition A = Q S (in 2D the in-plane
/// rotation of the upper-left block, closed form; in 3D from the SVD,
/// A = U Σ Vᵀ, Q = U Vᵀ with det Q = +1).
pub fn polar_rotation<const D: usize>(a: &Mat3) -> Mat3 {
    if D == 2 {
        let theta = (a[(1, 0)] - a[(0, 1)]).atan2(a[(0, 0)] + a[(1, 1)]);
        let (s, c) = theta.sin_cos();
        return Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    }
    let svd = a.svd(true, true);
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Mat3::identity();
    };
    if (u * v_t).determinant() < 0.0 {
        let last = u.column(2) * -1.0;
        u.set_column(2, &last);
    }
    u * v_t
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Gradients of a plane strain or axisymmetric step (no out-of-plane shear).
    pub fn plane(k: u32) -> Mat3 {
        let r = |i: u32| ((k * 7 + i * 13) % 17) as f64 / 17.0 - 0.5;
        Mat3::new(
            1.0 + r(0),
            r(1),
            0.0,
            r(2),
            1.0 + r(3),
            0.0,
            0.0,
            0.0,
            1.0 + r(4),
        )
    }

    #[test]
    fn compose_equals_the_full_product() {
        for k in 0..40 {
            let (a, b) = (plane(k), plane(k + 3));
            // Bit for bit: the full product adds only exact zeros to each term.
            assert_eq!(compose(&a, &b), a * b, "plane pair {k}");
            let mut general = b;
            general[(1, 2)] = 0.1;
            assert_eq!(compose(&a, &general), a * general, "general pair {k}");
            assert_eq!(compose(&general, &a), general * a, "general pair {k}");
        }
    }
}
