//! The beam-based bond (seed `003`): a bond that resists stretch with an axial
//! micromodulus c1 and the rotation of its direction relative to its
//! neighbourhood with a tangential micromodulus c2, which lifts the bond-based
//! Poisson ratio limit: ν ∈ (−1, 1/3] in plane stress, (−1, 1/4] in plane
//! strain and 3D. The seed's equations are lost in its text; c1 and c2 are
//! derived here from strain-energy equivalence.
//!
//! **Bond measures.** For a bond ξ = x_j − x_i (n = ξ/|ξ|) deformed to
//! y = y_j − y_i: the stretch s = |y|/|ξ| − 1 (PMB) and the tangential strain
//! γ = (I − n⊗n) Rᵀ y / |ξ|, the deformed bond rotated back by the rotation R of
//! its ends' neighbourhood and projected off the bond's reference direction.
//! Under a rigid motion y = Q ξ the neighbourhood's rotation is R = Q, so γ = 0
//! (the measure does not resist a rigid rotation); under a small strain ε
//! without rotation γ = (I − n⊗n) ε n. R is the rotation of the polar
//! decomposition of each end's non-local deformation gradient F = N K⁻¹
//! (`physics::peridynamics`), and the bond uses the mean of its two ends',
//! ½(R_i γ_i + R_j γ_j) (equal and opposite on its ends).
//!
//! **Energy equivalence.** Bond energy w = ½ (c1 s² + c2 |γ|²) |ξ| per unit
//! volume squared (PMB's c s²|ξ|/2 when c2 = 0), strain energy density
//! W = ½ ∫_H w dV. Under a homogeneous small strain, with ∫ over the circle
//! (2D, thickness h) or the sphere (3D):
//! - 2D: ∫(n·εn)² dθ = π/4 (3ε11² + 3ε22² + 2ε11ε22 + 4ε12²),
//!   ∫|γ|² dθ = π/4 ((ε11 − ε22)² + 4ε12²), ∫₀^δ ξ² dξ = δ³/3, so
//!   W = A [c1 (3ε11² + 3ε22² + 2ε11ε22 + 4ε12²) + c2 ((ε11 − ε22)² + 4ε12²)],
//!   A = πhδ³/48. Against W = ½λ′(tr ε)² + μ ε:ε (λ′ = Eν/(1 − ν²) in plane
//!   stress, λ in plane strain): λ′ = 2A(c1 − c2), μ = 2A(c1 + c2), hence
//!   c1 = (λ′ + μ)/(4A), c2 = (μ − λ′)/(4A):
//!   plane stress c1 = 6E/(πhδ³(1 − ν)), c2 = 6E(1 − 3ν)/(πhδ³(1 − ν²));
//!   plane strain c1 = 6E/(πhδ³(1 + ν)(1 − 2ν)), c2 = 6E(1 − 4ν)/(πhδ³(1 + ν)(1 − 2ν)).
//! - 3D: ∫(n·εn)² dΩ = 4π/15 ((tr ε)² + 2ε:ε), ∫|γ|² dΩ = 4π/15 (3ε:ε − (tr ε)²),
//!   ∫₀^δ ξ³ dξ = δ⁴/4, so W = B [(c1 − c2)(tr ε)² + (2c1 + 3c2) ε:ε],
//!   B = πδ⁴/60: λ = 2B(c1 − c2), μ = B(2c1 + 3c2), hence
//!   c1 = 3K/(10B) = 18K/(πδ⁴) (whatever ν), c2 = (μ − λ)/(5B) = 12(μ − λ)/(πδ⁴).
//!
//! c2 = 0 gives PMB's constants back at its ν (1/3 plane stress, 1/4 plane
//! strain and 3D); c2 ≥ 0 bounds ν above there, and ν → −1 makes c1 and c2 grow
//! without bound in 2D (μ/λ′ → ∞). As for PMB, 2D works per unit thickness (h = 1).
//!
//! **Fracture.** A bond breaks for good when s > s0; s0 from G0 counts the
//! axial energy of the bonds a crack cuts (`super::critical_stretch` with c1):
//! the tangential energy of an opening crack's bonds is left out, a choice
//! stated, not derived.

use super::space::{critical_stretch, Space};
use crate::dim::{Tensor, Vector};
use std::f64::consts::PI;

/// A body's beam-bond constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beam {
    /// Horizon δ.
    pub horizon: f64,
    /// Axial micromodulus c1.
    pub axial: f64,
    /// Tangential micromodulus c2.
    pub tangential: f64,
    /// Critical stretch s0 (infinite: no fracture).
    pub critical_stretch: f64,
}

impl Beam {
    /// The constants of Young's modulus `e`, Poisson ratio `nu` and horizon δ
    /// (module doc), for ν in the space's range (`Space::beam_poisson_range`).
    pub fn new(space: Space, e: f64, nu: f64, delta: f64) -> Beam {
        let (axial, tangential) = match space {
            Space::PlaneStress => {
                let a = 6.0 * e / (PI * delta.powi(3));
                (a / (1.0 - nu), a * (1.0 - 3.0 * nu) / (1.0 - nu * nu))
            }
            Space::PlaneStrain => {
                let a = 6.0 * e / (PI * delta.powi(3) * (1.0 + nu) * (1.0 - 2.0 * nu));
                (a, a * (1.0 - 4.0 * nu))
            }
            Space::ThreeD => {
                let (k, mu) = (e / (3.0 * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)));
                let lambda = k - 2.0 * mu / 3.0;
                (
                    18.0 * k / (PI * delta.powi(4)),
                    12.0 * (mu - lambda) / (PI * delta.powi(4)),
                )
            }
        };
        Beam {
            horizon: delta,
            axial,
            tangential,
            critical_stretch: f64::INFINITY,
        }
    }

    /// With the critical stretch of fracture energy G0 (module doc: from c1).
    pub fn with_fracture_energy(self, space: Space, g0: f64) -> Beam {
        self.with_critical_stretch(critical_stretch(space, self.axial, self.horizon, g0))
    }

    pub fn with_critical_stretch(self, s0: f64) -> Beam {
        Beam {
            critical_stretch: s0,
            ..self
        }
    }

    /// The stretch s and the tangential strain γ of the bond from y_i to y_j of
    /// reference vector ξ, seen through the rotation R (module doc).
    #[inline]
    pub fn measures<const D: usize>(
        yi: &Vector<D>,
        yj: &Vector<D>,
        xi: &Vector<D>,
        r: &Tensor<D>,
    ) -> (f64, Vector<D>) {
        let (y, length) = (yj - yi, xi.norm());
        let n = xi / length;
        let back = r.transpose() * y / length;
        (y.norm() / length - 1.0, back - n * n.dot(&back))
    }

    /// The force on j (per unit volume squared) of the bond from y_i to y_j of
    /// reference vector ξ, its ends' rotations R_i and R_j:
    /// f = c1 s ŷ + c2 ½(R_i γ_i + R_j γ_j), ∂w/∂y at fixed R (module doc).
    #[inline]
    pub fn pair_force<const D: usize>(
        &self,
        yi: &Vector<D>,
        yj: &Vector<D>,
        xi: &Vector<D>,
        ri: &Tensor<D>,
        rj: &Tensor<D>,
    ) -> Vector<D> {
        let y = yj - yi;
        let (s, gi) = Self::measures(yi, yj, xi, ri);
        let (_, gj) = Self::measures(yi, yj, xi, rj);
        y * (self.axial * s / y.norm()) + (ri * gi + rj * gj) * (0.5 * self.tangential)
    }

    /// Energy ½ (c1 s² + c2 |γ|²) |ξ| per unit volume squared.
    pub fn bond_energy<const D: usize>(&self, s: f64, gamma: &Vector<D>, length: f64) -> f64 {
        0.5 * (self.axial * s * s + self.tangential * gamma.norm_squared()) * length
    }

    /// The bond's spring constant times |ξ| for the stable step: the largest
    /// eigenvalue max(c1, c2) of c1 n⊗n + c2 (I − n⊗n).
    pub fn stiffness(&self) -> f64 {
        self.axial.max(self.tangential)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::bond::pmb::Pmb;

    const E: f64 = 70e9;

    #[test]
    fn no_tangential_modulus_gives_the_bond_based_constants_back() {
        let d = 3e-3;
        for space in [Space::PlaneStress, Space::PlaneStrain, Space::ThreeD] {
            let b = Beam::new(space, E, space.poisson_ratio(), d);
            let p = Pmb::new(space, E, d);
            println!(
                "{space:?}: c1/c − 1 = {:.1e}, c2/c1 = {:.1e}",
                b.axial / p.micromodulus - 1.0,
                b.tangential / b.axial
            );
            assert!((b.axial / p.micromodulus - 1.0).abs() < 1e-14, "{space:?}");
            assert!(b.tangential.abs() < 1e-14 * b.axial, "{space:?}");
        }
    }

    /// W = ½∫_H w dV under a homogeneous strain, by a fine quadrature of the
    /// horizon (not the lattice), against ½λ′(tr ε)² + μ ε:ε for several ν and
    /// a general strain: the constants' derivation, to quadrature error.
    #[test]
    fn the_micromoduli_give_the_continuum_strain_energy() {
        // Strains of 1e-6: s = n·εn + O(ε²), so the finite-strain measures differ
        // from the small-strain ones by ~1e-6 relative, below the quadrature's ~1e-5.
        let (d, eps) = (
            1.0,
            [
                [1.0e-6, 0.3e-6, -0.2e-6],
                [0.3e-6, -0.5e-6, 0.4e-6],
                [-0.2e-6, 0.4e-6, 0.7e-6],
            ],
        );
        for (space, nus) in [
            (Space::PlaneStress, vec![-0.9, -0.2, 0.0, 0.2, 1.0 / 3.0]),
            (Space::PlaneStrain, vec![-0.5, 0.0, 0.1, 0.25]),
            (Space::ThreeD, vec![-0.5, 0.0, 0.2, 0.25]),
        ] {
            for nu in nus {
                let b = Beam::new(space, E, nu, d);
                let (pd, continuum) = match space {
                    Space::ThreeD => {
                        let e = Tensor::<3>::from_fn(|i, j| eps[i][j]);
                        (
                            energy_3d(&b, &e),
                            continuum(space, nu, e.trace(), e.norm_squared()),
                        )
                    }
                    _ => {
                        let e = Tensor::<2>::from_fn(|i, j| eps[i][j]);
                        (
                            energy_2d(&b, &e),
                            continuum(space, nu, e.trace(), e.norm_squared()),
                        )
                    }
                };
                let error = pd / continuum - 1.0;
                println!("{space:?} ν = {nu:+.3}: W_PD/W − 1 = {error:+.2e}");
                assert!(error.abs() < 1e-4, "{space:?} ν = {nu}: {error}");
            }
        }
    }

    /// ½λ′(tr ε)² + μ ε:ε.
    fn continuum(space: Space, nu: f64, tr: f64, ee: f64) -> f64 {
        let mu = E / (2.0 * (1.0 + nu));
        let lambda = match space {
            Space::PlaneStress => E * nu / (1.0 - nu * nu),
            _ => E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        };
        0.5 * lambda * tr * tr + mu * ee
    }

    /// ½ ∫₀^δ ∫₀^{2π} w ξ dθ dξ (h = 1), midpoint rule.
    fn energy_2d(b: &Beam, e: &Tensor<2>) -> f64 {
        let (nr, nt) = (400, 720);
        let mut w = 0.0;
        for a in 0..nr {
            let r = (a as f64 + 0.5) / nr as f64 * b.horizon;
            for t in 0..nt {
                let th = (t as f64 + 0.5) / nt as f64 * 2.0 * PI;
                let xi = Vector::<2>::new(th.cos(), th.sin()) * r;
                let y = xi + e * xi;
                let (s, g) = Beam::measures(&Vector::zeros(), &y, &xi, &Tensor::identity());
                w += b.bond_energy(s, &g, r) * r * (b.horizon / nr as f64) * (2.0 * PI / nt as f64);
            }
        }
        0.5 * w
    }

    /// ½ ∫₀^δ ∫_{S²} w ξ² dΩ dξ, midpoint in ξ and cos φ, θ.
    fn energy_3d(b: &Beam, e: &Tensor<3>) -> f64 {
        let (nr, nz, nt) = (200, 200, 200);
        let mut w = 0.0;
        for a in 0..nr {
            let r = (a as f64 + 0.5) / nr as f64 * b.horizon;
            for z in 0..nz {
                let c = -1.0 + (z as f64 + 0.5) / nz as f64 * 2.0;
                let sn = (1.0 - c * c).sqrt();
                for t in 0..nt {
                    let th = (t as f64 + 0.5) / nt as f64 * 2.0 * PI;
                    let xi = Vector::<3>::new(sn * th.cos(), sn * th.sin(), c) * r;
                    let y = xi + e * xi;
                    let (s, g) = Beam::measures(&Vector::zeros(), &y, &xi, &Tensor::identity());
                    let dv = r
                        * r
                        * (b.horizon / nr as f64)
                        * (2.0 / nz as f64)
                        * (2.0 * PI / nt as f64);
                    w += b.bond_energy(s, &g, r) * dv;
                }
            }
        }
        0.5 * w
    }
}
