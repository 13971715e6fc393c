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

/// Are all values finite? Without a branch per value (a bitwise and, not `&&`).
#[inline(always)]
pub fn all_finite<'a>(values: impl IntoIterator<Item = &'a f64>) -> bool {
    values.into_iter().fold(true, |all, v| all & v.is_finite())
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

/// Has m no out-of-plane shear (xz, yz, zx, zy all zero)? So are the
/// deformation gradients and stresses of plane strain and axisymmetry.
#[inline(always)]
pub fn is_plane(m: &Mat3) -> bool {
    m[(0, 2)] == 0.0 && m[(1, 2)] == 0.0 && m[(2, 0)] == 0.0 && m[(2, 1)] == 0.0
}

/// The product a b of two deformation gradients (`compose_plane` when neither
/// has out-of-plane shear).
#[inline(always)]
pub fn compose(a: &Mat3, b: &Mat3) -> Mat3 {
    match is_plane(a) && is_plane(b) {
        true => compose_plane(a, b),
        false => a * b,
    }
}

/// The product a b of two plane deformation gradients (`is_plane`: the plane
/// strain and axisymmetric ones), from the 2 × 2 block and zz. Equal to the
/// full product, term for term, but for the sign of the zero out-of-plane shear.
#[inline(always)]
pub fn compose_plane(a: &Mat3, b: &Mat3) -> Mat3 {
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

/// det m of a gradient without out-of-plane shear when `plane` (`is_plane`):
/// m_zz (m_xx m_yy − m_xy m_yx), the cofactor expansion without its zero
/// terms, the same value but for the sign of a zero determinant.
#[inline(always)]
pub fn determinant(m: &Mat3, plane: bool) -> f64 {
    match plane {
        true => m[(0, 0)] * (m[(1, 1)] * m[(2, 2)]) - m[(0, 1)] * (m[(1, 0)] * m[(2, 2)]),
        false => m.determinant(),
    }
}

/// The left Cauchy–Green tensor b = F Fᵀ; when `plane` (`is_plane`) from the
/// 2 × 2 block and zz, equal to the full product but for the sign of zero
/// entries.
#[inline(always)]
pub fn left_cauchy_green(f: &Mat3, plane: bool) -> Mat3 {
    if !plane {
        return f * f.transpose();
    }
    let e = |i: usize, j: usize| f[(i, 0)] * f[(j, 0)] + f[(i, 1)] * f[(j, 1)];
    let xy = e(0, 1);
    Mat3::new(
        e(0, 0),
        xy,
        0.0,
        xy,
        e(1, 1),
        0.0,
        0.0,
        0.0,
        f[(2, 2)] * f[(2, 2)],
    )
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

    #[test]
    fn all_finite_is_false_for_any_infinite_or_nan_value() {
        let finite = [
            0.0,
            -0.0,
            1.0,
            -3.5,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        assert!(all_finite(&finite));
        assert!(all_finite(&[]));
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            for at in 0..=finite.len() {
                let mut values = finite.to_vec();
                values.insert(at, bad);
                assert!(!all_finite(&values), "{bad} at {at}");
            }
        }
    }

    /// Plane gradients with irregular entries (not a short cycle of values).
    fn scattered_plane(k: u32) -> Mat3 {
        let r = |i: u32| (1.7 * k as f64 + 0.37 * i as f64).sin() * 0.6;
        let mut m = plane(k);
        for (i, (a, b)) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 2)]
            .into_iter()
            .enumerate()
        {
            m[(a, b)] += r(i as u32) * 1e-3 * (k % 7) as f64;
        }
        m
    }

    #[test]
    fn plane_determinant_and_left_cauchy_green_equal_the_full_forms() {
        for k in 0..200 {
            let f = scattered_plane(k);
            // Bit for bit: the full forms add only exact zeros.
            assert_eq!(
                determinant(&f, true).to_bits(),
                f.determinant().to_bits(),
                "plane {k}"
            );
            let (b, full) = (left_cauchy_green(&f, true), f * f.transpose());
            for (x, y) in b.iter().zip(full.iter()) {
                assert!(
                    x.to_bits() == y.to_bits() || (*x == 0.0 && *y == 0.0),
                    "plane {k}"
                );
            }
            let mut general = f;
            general[(2, 0)] = 0.05;
            assert_eq!(
                determinant(&general, false),
                general.determinant(),
                "general {k}"
            );
            let b = left_cauchy_green(&general, false);
            assert_eq!(b, general * general.transpose(), "general {k}");
        }
    }
}
