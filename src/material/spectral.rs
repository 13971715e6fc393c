//! The spectral decomposition of a symmetric 3×3 tensor, A = Σ λ_a n_a ⊗ n_a,
//! as the spectral models (Hencky, the multiplicative return mappings) use it.
//!
//! In plane strain and axisymmetry the out-of-plane axis is a principal axis:
//! A_xz = A_yz = 0 and the in-plane 2×2 block is diagonalised by one Jacobi
//! rotation in closed form (Golub & Van Loan, Matrix Computations, §8.5.2,
//! the symmetric Schur decomposition), about a tenth of the cost of the
//! general iterative solver. Any other tensor goes to nalgebra's
//! `SymmetricEigen`. Both read the lower triangle only. The order of the
//! eigenvalues is not specified (callers pair each with its eigenvector).

use crate::dim::Mat3;
use nalgebra::{SymmetricEigen, Vector3};

/// Eigenvalues and eigenvectors (the columns of the matrix, orthonormal) of the
/// symmetric tensor `a` (its lower triangle).
pub fn symmetric_eigen(a: &Mat3) -> (Vector3<f64>, Mat3) {
    if a[(2, 0)] == 0.0 && a[(2, 1)] == 0.0 {
        let (c, s, l1, l2) = jacobi_rotation(a[(0, 0)], a[(1, 0)], a[(1, 1)]);
        let n = Mat3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0);
        return (Vector3::new(l1, l2, a[(2, 2)]), n);
    }
    let eig = SymmetricEigen::new(*a);
    (eig.eigenvalues, eig.eigenvectors)
}

/// The symmetric tensor Σ_a p_a n_a ⊗ n_a with principal values `principal` on
/// the eigenvectors `n` (its columns).
pub fn from_principal(n: &Mat3, principal: &Vector3<f64>) -> Mat3 {
    n * Mat3::from_diagonal(principal) * n.transpose()
}

/// The rotation (cos, sin) that diagonalises [[p, q], [q, r]] and the two
/// eigenvalues: the first with eigenvector (cos, −sin), the second with
/// (sin, cos). t = tan of the angle is the smaller root of t² + 2τt − 1 = 0,
/// τ = (r − p)/(2q) (Golub & Van Loan, Algorithm 8.5.1), so that λ₁ = p − t q
/// and λ₂ = r + t q lose no digits to cancellation.
fn jacobi_rotation(p: f64, q: f64, r: f64) -> (f64, f64, f64, f64) {
    if q == 0.0 {
        return (1.0, 0.0, p, r);
    }
    let tau = (r - p) / (2.0 * q);
    let t = 1.0_f64.copysign(tau) / (tau.abs() + sqrt_one_plus_square(tau));
    // |t| ≤ 1: 1 + t² cannot overflow.
    let c = 1.0 / (1.0 + t * t).sqrt();
    (c, t * c, p - t * q, r + t * q)
}

/// √(1 + x²) without `hypot`'s scaling (glibc's hypot was 3–4 % of a contact
/// run in perf); beyond |x| = 1e150, where x² would overflow, it is |x| to
/// round-off.
fn sqrt_one_plus_square(x: f64) -> f64 {
    match x.abs() < 1e150 {
        true => (1.0 + x * x).sqrt(),
        false => x.abs(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A v_a = λ_a v_a and VᵀV = I, to `tol` relative to the largest |A_ij|.
    fn assert_decomposes(a: &Mat3, tol: f64) {
        let (l, n) = symmetric_eigen(a);
        let scale = a.amax().max(f64::MIN_POSITIVE);
        for k in 0..3 {
            let v = n.column(k);
            let residual = (a * v - l[k] * v).amax() / scale;
            assert!(residual < tol, "A v − λ v = {residual:e} for {a}");
        }
        let orthogonality = (n.transpose() * n - Mat3::identity()).amax();
        assert!(orthogonality < 1e-15, "VᵀV − I = {orthogonality:e}");
    }

    /// Sorted eigenvalues.
    fn sorted(l: Vector3<f64>) -> [f64; 3] {
        let mut s = [l[0], l[1], l[2]];
        s.sort_by(f64::total_cmp);
        s
    }

    fn plane(p: f64, q: f64, r: f64, z: f64) -> Mat3 {
        Mat3::new(p, q, 0.0, q, r, 0.0, 0.0, 0.0, z)
    }

    #[test]
    fn plane_tensors_match_the_general_solver() {
        // A pseudo-random sequence of in-plane tensors over many scales, and the
        // hard cases: isotropic, diagonal, a tiny or a huge shear against the
        // difference of the diagonal, equal diagonal terms, negative entries.
        let mut x = 0.123_456_789_f64;
        let mut next = || {
            x = (x * 3.987_654_321 + 0.314_159).fract();
            2.0 * x - 1.0
        };
        let mut cases = vec![
            plane(0.0, 0.0, 0.0, 0.0),
            plane(1e-4, 0.0, 1e-4, 1e-4),
            plane(2.0, 0.0, -1.0, 0.5),
            plane(1.0, 1e-300, 2.0, 0.0),
            plane(1.0, 1e-12, 1.0 + 1e-12, 0.0),
            plane(1e-6, 1e3, -1e-6, 3.0),
            plane(0.3, 0.7, 0.3, -0.2),
            plane(-5.0, -2.0, -1.0, -4.0),
        ];
        for k in 0..2000 {
            let scale = 10f64.powi(k % 13 - 6);
            cases.push(plane(
                scale * next(),
                scale * next(),
                scale * next(),
                next(),
            ));
        }
        for a in &cases {
            assert_decomposes(a, 4.0 * f64::EPSILON);
            let general = SymmetricEigen::new(*a).eigenvalues;
            let (l, _) = symmetric_eigen(a);
            let scale = a.amax().max(f64::MIN_POSITIVE);
            for (x, y) in sorted(l).iter().zip(sorted(general)) {
                assert!(
                    (x - y).abs() <= 8.0 * f64::EPSILON * scale,
                    "{l} vs {general}"
                );
            }
        }
    }

    #[test]
    fn the_closed_form_keeps_small_eigenvalues_of_large_tensors() {
        // [[1, 1], [1, 1]] + δ I has eigenvalues δ and 2 + δ: λ₁ = p − t q (t = 1
        // here) keeps δ to the precision that 1 + δ carries (1e-16 / δ).
        let delta = 1e-9;
        let (l, _) = symmetric_eigen(&plane(1.0 + delta, 1.0, 1.0 + delta, 0.0));
        let small = sorted(l)[1];
        assert!(((small - delta) / delta).abs() < 1e-6, "{small}");
    }

    #[test]
    fn general_tensors_go_to_the_general_solver() {
        let a = Mat3::new(2.0, 0.5, 0.1, 0.5, 1.0, -0.3, 0.1, -0.3, 4.0);
        assert_decomposes(&a, 8.0 * f64::EPSILON);
        let (l, n) = symmetric_eigen(&a);
        let eig = SymmetricEigen::new(a);
        assert_eq!((l, n), (eig.eigenvalues, eig.eigenvectors));
    }
}
