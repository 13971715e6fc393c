//! The non-local deformation gradient of a peridynamic particle over its
//! intact bonds (Silling et al. 2007, the correspondence model; digest Part 3):
//! shape tensor K_i = Σ_j ξ⊗ξ V_j, N_i = Σ_j (y_j − y_i)⊗ξ V_j, F_i = N_i K_i⁻¹,
//! with ξ = x_j − x_i and a constant influence function (`weighted_shapes`:
//! any, each bond weighted by ω in K and N). F_i equals an applied
//! affine map at every particle, surface included, since K and N run over the
//! same bonds. The beam bond takes the rotation of its polar decomposition
//! (`material::bond::beam`).

use crate::dim::{embed_deformation, polar_rotation, restrict, Tensor, Vector};
use crate::model::peridynamics::PdBody;
use crate::parallel::MIN_PARALLEL_LEN;
use rayon::prelude::*;

/// det K below this × (tr K / D)^D: the intact bonds do not span the space
/// (a particle cut off, or bonds along one line), no F.
const DEGENERATE: f64 = 1e-8;

/// F_i of each particle of `b` at positions `y` (local order); None where its
/// intact bonds do not span the space.
pub fn deformation_gradients<const D: usize>(
    b: &PdBody<D>,
    y: &[Vector<D>],
) -> Vec<Option<Tensor<D>>> {
    (shapes(b, y).into_iter())
        .map(|s| s.map(|(_, f)| f))
        .collect()
}

/// K_i⁻¹ and F_i of each particle of `b` at positions `y` (local order); None
/// where its intact bonds do not span the space.
pub fn shapes<const D: usize>(
    b: &PdBody<D>,
    y: &[Vector<D>],
) -> Vec<Option<(Tensor<D>, Tensor<D>)>> {
    weighted_shapes(b, y, |_| 1.0)
}

/// As [`shapes`], each bond k weighted by ω(k) in K and N (the influence
/// function; F stays exact for affine maps).
pub fn weighted_shapes<const D: usize>(
    b: &PdBody<D>,
    y: &[Vector<D>],
    omega: impl Fn(usize) -> f64 + Sync,
) -> Vec<Option<(Tensor<D>, Tensor<D>)>> {
    let (x, v, bonds) = (&b.reference, &b.volume, &b.bonds);
    (0..y.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|i| {
            let (mut k, mut n) = (Tensor::<D>::zeros(), Tensor::<D>::zeros());
            bonds.each_intact(i, |bond, j| {
                let (xi, w) = (x[j] - x[i], omega(bond) * v[j]);
                k += xi * xi.transpose() * w;
                n += (y[j] - y[i]) * xi.transpose() * w;
            });
            // In 3 × 3 (zz = 1 in 2D), where nalgebra has det and inverse.
            let k3 = embed_deformation(&k);
            let scale = (k.trace() / D as f64).powi(D as i32);
            let det = k3.determinant();
            if det.is_nan() || det <= DEGENERATE * scale {
                return None;
            }
            k3.try_inverse().map(|k_inv| {
                let k_inv = restrict::<D>(&k_inv);
                (k_inv, n * k_inv)
            })
        })
        .collect()
}

/// The rotation R_i of the polar decomposition of each particle's F_i; the
/// identity where it has none.
pub fn rotations<const D: usize>(b: &PdBody<D>, y: &[Vector<D>]) -> Vec<Tensor<D>> {
    (deformation_gradients(b, y).into_iter())
        .map(|f| {
            f.map_or(Tensor::identity(), |f| {
                restrict(&polar_rotation::<D>(&embed_deformation(&f)))
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::bond::{pmb::Pmb, BondLaw, Space};

    /// F_i under an affine map y = A x + c equals A at every particle of a
    /// perturbed lattice, surface and corners included (2D and 3D).
    fn affine<const D: usize>(n: usize) {
        let dx = 1e-3;
        let x: Vec<Vector<D>> = (0..n.pow(D as u32))
            .map(|q| {
                Vector::<D>::from_fn(|d, _| {
                    let k = (q / n.pow(d as u32)) % n;
                    (k as f64 + 0.1 * ((q * 7 + d * 3) % 5) as f64 / 5.0) * dx
                })
            })
            .collect();
        let law = BondLaw::Pmb(Pmb::new(Space::PlaneStress, 1e9, 3.0 * dx));
        let b = PdBody::new(
            0,
            (0..x.len()).collect(),
            &x,
            vec![dx.powi(D as i32); x.len()],
            law,
        );
        let a = Tensor::<D>::from_fn(|i, j| {
            if i == j {
                1.1
            } else {
                0.05 * (i + 2 * j) as f64
            }
        });
        let c = Vector::<D>::from_element(0.3);
        let y: Vec<Vector<D>> = x.iter().map(|p| a * p + c).collect();
        let worst = (deformation_gradients(&b, &y).into_iter())
            .map(|f| (f.expect("spanning bonds") - a).norm())
            .fold(0.0, f64::max);
        println!("{D}D: max |F_i − A| = {worst:.2e}");
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn the_non_local_deformation_gradient_is_exact_for_an_affine_map() {
        affine::<2>(12);
        affine::<3>(7);
    }
}
