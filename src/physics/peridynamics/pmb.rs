//! The prototype microelastic brittle (PMB) bond of bond-based peridynamics
//! (Silling 2000; Silling & Askari 2005): pairwise force f = c s ŷ per unit
//! volume squared (constant influence), with s = (|y_j − y_i| − |ξ|)/|ξ| the
//! bond stretch and ŷ the unit vector from i to j in the current configuration;
//! the bond breaks for good when s > s0.
//!
//! Micromoduli from strain-energy equivalence (survey-peridynamics.md §2.1,
//! checked there against LAMMPS, Peridigm, PeriLab; digest Part 2 §2.2 for plane
//! stress), with h the thickness. In 2D this code works per unit thickness, as
//! every 2D quantity of the model (volumes are areas, masses per unit
//! thickness): h = 1, and since c V_j ∝ 1/h · h the thickness cancels from the
//! motion, so there is no thickness key (survey §6: Peridigm #381).
//!
//! | space        | c               | ν   | s0 from G0        |
//! |--------------|-----------------|-----|-------------------|
//! | 3D           | 18K/(πδ⁴)       | 1/4 | √(5G0/(9Kδ))      |
//! | plane stress | 9E/(πhδ³)       | 1/3 | √(4πG0/(9Eδ))     |
//! | plane strain | 48E/(5πhδ³)     | 1/4 | √(5πG0/(12Eδ))    |
//!
//! s0 from G0 = energy of the bonds cut by a crack per unit area, each bond
//! storing c s0² |ξ|/2 per unit volume squared: 3D G0 = πcs0²δ⁵/10; 2D
//! G0 = c h s0² δ⁴/4 (= 2∫₀^δ∫_z^δ∫₀^{acos(z/ξ)} (c s0² ξ/2) h ξ dθ dξ dz),
//! which with the c of each plane gives the 2D forms (survey §2.2, derived
//! there and again here).

use crate::dim::Vector;
use std::f64::consts::PI;

/// The space a PMB body is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    ThreeD,
    PlaneStress,
    PlaneStrain,
}

impl Space {
    /// The one Poisson ratio of the PMB bond in this space.
    pub fn poisson_ratio(self) -> f64 {
        match self {
            Space::ThreeD | Space::PlaneStrain => 0.25,
            Space::PlaneStress => 1.0 / 3.0,
        }
    }
}

/// A body's PMB constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pmb {
    /// Horizon δ.
    pub horizon: f64,
    /// Micromodulus c.
    pub micromodulus: f64,
    /// Critical stretch s0 (infinite: no fracture).
    pub critical_stretch: f64,
}

/// Safety factor on the Silling–Askari step (0.7–0.85 in Peridynamics.jl and
/// CabanaPD, survey §2.3).
pub const SAFETY: f64 = 0.8;

impl Pmb {
    /// The constants of Young's modulus `e` (ν the space's) and horizon δ.
    pub fn new(space: Space, e: f64, delta: f64) -> Pmb {
        let c = match space {
            // 18K/(πδ⁴), K = E/(3(1 − 2ν)) = 2E/3 at ν = 1/4.
            Space::ThreeD => 18.0 * bulk_modulus(e) / (PI * delta.powi(4)),
            Space::PlaneStress => 9.0 * e / (PI * delta.powi(3)),
            Space::PlaneStrain => 48.0 * e / (5.0 * PI * delta.powi(3)),
        };
        Pmb {
            horizon: delta,
            micromodulus: c,
            critical_stretch: f64::INFINITY,
        }
    }

    /// With the critical stretch of fracture energy G0 (module table).
    pub fn with_fracture_energy(self, space: Space, e: f64, g0: f64) -> Pmb {
        let d = self.horizon;
        let s0 = match space {
            Space::ThreeD => (5.0 * g0 / (9.0 * bulk_modulus(e) * d)).sqrt(),
            Space::PlaneStress => (4.0 * PI * g0 / (9.0 * e * d)).sqrt(),
            Space::PlaneStrain => (5.0 * PI * g0 / (12.0 * e * d)).sqrt(),
        };
        self.with_critical_stretch(s0)
    }

    pub fn with_critical_stretch(self, s0: f64) -> Pmb {
        Pmb {
            critical_stretch: s0,
            ..self
        }
    }

    /// f = c s ŷ (per unit volume squared) of the bond from y_i to y_j of
    /// reference length |ξ|.
    #[inline]
    pub fn pair_force<const D: usize>(
        &self,
        yi: &Vector<D>,
        yj: &Vector<D>,
        length: f64,
    ) -> Vector<D> {
        let d = yj - yi;
        let l = d.norm();
        let s = (l - length) / length;
        d * (self.micromodulus * s / l)
    }

    /// Energy c s² |ξ| / 2 per unit volume squared of a bond at stretch s.
    pub fn bond_energy(&self, s: f64, length: f64) -> f64 {
        0.5 * self.micromodulus * s * s * length
    }

    /// SAFETY × √(2ρ / Σ_j V_j c/|ξ|) (Silling & Askari 2005, eq. 29), given
    /// `stiffness` = Σ_j V_j c/|ξ| over the particle's bonds.
    pub fn stable_dt(&self, rho: f64, stiffness: f64) -> f64 {
        SAFETY * (2.0 * rho / stiffness).sqrt()
    }
}

/// K = E/(3(1 − 2ν)) at the PMB ν = 1/4.
fn bulk_modulus(e: f64) -> f64 {
    e / (3.0 * (1.0 - 2.0 * 0.25))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::peridynamics::PdBody;

    const E: f64 = 70e9;

    /// A lattice of n^D points of spacing dx, each moved by `perturb` × dx
    /// times a deterministic pseudo-random number in [−1, 1).
    fn lattice<const D: usize>(n: usize, dx: f64, perturb: f64) -> Vec<Vector<D>> {
        let mut seed = 12345u64;
        let mut rand = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..n.pow(D as u32))
            .map(|q| {
                Vector::<D>::from_fn(|d, _| {
                    ((q / n.pow(d as u32)) % n) as f64 * dx + perturb * dx * rand()
                })
            })
            .collect()
    }

    fn body<const D: usize>(x: &[Vector<D>], dx: f64, space: Space) -> PdBody<D> {
        let v = vec![dx.powi(D as i32); x.len()];
        PdBody::new(
            0,
            (0..x.len()).collect(),
            x,
            v,
            Pmb::new(space, E, 3.0 * dx),
        )
    }

    fn max_norm<const D: usize>(f: &[Vector<D>]) -> f64 {
        f.iter().map(|v| v.norm()).fold(0.0, f64::max)
    }

    fn sum_of_forces_vanishes<const D: usize>(space: Space) {
        let dx = 1e-3;
        let x = lattice::<D>(if D == 2 { 20 } else { 8 }, dx, 0.2);
        let mut b = body(&x, dx, space);
        // A deformed state: each point moved by up to 1 % of dx at random.
        let n = if D == 2 { 20 } else { 8 };
        let jitter = lattice::<D>(n, dx, 0.01);
        let y: Vec<Vector<D>> = (x.iter().zip(&jitter))
            .map(|(p, l)| p + (l - lattice_point::<D>(l, dx)))
            .collect();
        let f = b.forces(&y);
        let total: Vector<D> = f.iter().sum();
        let scale: f64 = f.iter().map(|v| v.norm()).sum();
        println!(
            "{space:?}: |Σ F| = {:.3e}, Σ |F| = {scale:.3e}",
            total.norm()
        );
        assert!(scale > 0.0);
        assert!(total.norm() <= 1e-13 * scale, "{} vs {scale}", total.norm());
    }

    /// The lattice point nearest l.
    fn lattice_point<const D: usize>(l: &Vector<D>, dx: f64) -> Vector<D> {
        l.map(|c| (c / dx).round() * dx)
    }

    #[test]
    fn the_bond_forces_sum_to_zero_on_a_perturbed_lattice() {
        sum_of_forces_vanishes::<2>(Space::PlaneStress);
        sum_of_forces_vanishes::<3>(Space::ThreeD);
    }

    fn rotation<const D: usize>(angle: f64) -> crate::dim::Tensor<D> {
        let (c, s) = (angle.cos(), angle.sin());
        let mut r = crate::dim::Tensor::<D>::identity();
        (r[(0, 0)], r[(0, 1)], r[(1, 0)], r[(1, 1)]) = (c, -s, s, c);
        r
    }

    fn rigid_motion_gives_no_force<const D: usize>(space: Space) {
        let dx = 1e-3;
        let x = lattice::<D>(if D == 2 { 15 } else { 7 }, dx, 0.2);
        let mut b = body(&x, dx, space);
        // The force scale: the same lattice stretched by 1e-3.
        let stretched: Vec<Vector<D>> = x.iter().map(|p| p * 1.001).collect();
        let scale = max_norm(&b.forces(&stretched));
        let shift = Vector::<D>::from_element(0.37);
        let r = rotation::<D>(30f64.to_radians());
        let moved: Vec<Vector<D>> = x.iter().map(|p| r * p + shift).collect();
        let translated: Vec<Vector<D>> = x.iter().map(|p| p + shift).collect();
        let (ft, fr) = (
            max_norm(&b.forces(&translated)),
            max_norm(&b.forces(&moved)),
        );
        println!(
            "{space:?}: max |F| translated {ft:.2e}, rotated 30° {fr:.2e}, at s = 1e-3 {scale:.2e}"
        );
        assert!(ft <= 1e-9 * scale && fr <= 1e-9 * scale);
    }

    #[test]
    fn a_rigid_translation_and_a_30_degree_rotation_give_no_force() {
        rigid_motion_gives_no_force::<2>(Space::PlaneStress);
        rigid_motion_gives_no_force::<3>(Space::ThreeD);
    }

    #[test]
    fn a_single_bond_breaks_past_s0_and_never_heals() {
        let dx = 1e-3;
        let x = vec![Vector::<2>::zeros(), Vector::<2>::new(dx, 0.0)];
        let s0 = 1e-3;
        let pmb = Pmb::new(Space::PlaneStress, E, 1.5 * dx).with_critical_stretch(s0);
        let mut b = PdBody::new(0, vec![0, 1], &x, vec![dx * dx; 2], pmb);
        assert_eq!(b.bonds.len(), 1);
        let at = |s: f64| vec![x[0], Vector::<2>::new(dx * (1.0 + s), 0.0)];
        let f = b.forces(&at(0.999 * s0));
        let expected = pmb.micromodulus * 0.999 * s0 * dx.powi(4);
        assert!((f[0][0] - expected).abs() <= 1e-9 * expected && f[1][0] == -f[0][0]);
        assert!(b.bonds.intact[0]);
        b.forces(&at(1.001 * s0));
        assert!(!b.bonds.intact[0]);
        assert_eq!(b.damage(), vec![1.0, 1.0]);
        for s in [0.5 * s0, 0.0, -0.01] {
            let f = b.forces(&at(s));
            assert!(
                !b.bonds.intact[0] && f[0] == Vector::<2>::zeros() && f[1] == Vector::<2>::zeros()
            );
        }
    }

    #[test]
    fn the_2d_and_3d_critical_stretches_invert_their_fracture_energies() {
        let (g0, d) = (20e3, 3e-3);
        // G0 = c h s0² δ⁴/4 (2D, h = 1) and π c s0² δ⁵/10 (3D).
        for space in [Space::PlaneStress, Space::PlaneStrain] {
            let p = Pmb::new(space, E, d).with_fracture_energy(space, E, g0);
            let g = p.micromodulus * p.critical_stretch.powi(2) * d.powi(4) / 4.0;
            assert!((g / g0 - 1.0).abs() < 1e-12, "{space:?}");
        }
        let p = Pmb::new(Space::ThreeD, E, d).with_fracture_energy(Space::ThreeD, E, g0);
        let g = PI * p.micromodulus * p.critical_stretch.powi(2) * d.powi(5) / 10.0;
        assert!((g / g0 - 1.0).abs() < 1e-12);
        // 3D: 18K/(πδ⁴) = 12E/(πδ⁴) at ν = 1/4.
        let c = Pmb::new(Space::ThreeD, E, d).micromodulus;
        assert!((c / (12.0 * E / (PI * d.powi(4))) - 1.0).abs() < 1e-14);
    }

    /// The energy of the bonds cut by a straight crack (the line x = x_c
    /// between two lattice columns), per unit crack length, against G0: the
    /// lattice's quadrature of the G0 integral (no partial volumes, m = 3).
    #[test]
    fn the_bonds_cut_by_a_straight_crack_hold_g0_per_unit_area() {
        let (dx, g0) = (1e-3, 100.0);
        let n = 30;
        let x = lattice::<2>(n, dx, 0.0);
        let space = Space::PlaneStress;
        let b = body(&x, dx, space);
        let p = b.pmb.with_fracture_energy(space, E, g0);
        let xc = 14.5 * dx;
        let (y0, y1) = (10.0 * dx, 20.0 * dx);
        let energy: f64 = (0..b.bonds.len())
            .filter(|&k| {
                let [i, j] = b.bonds.ends[k].map(|e| x[e as usize]);
                let mid = 0.5 * (i[1] + j[1]);
                (i[0] - xc) * (j[0] - xc) < 0.0 && mid >= y0 && mid < y1
            })
            .map(|k| p.bond_energy(p.critical_stretch, b.bonds.length[k]) * dx.powi(4))
            .sum();
        let ratio = energy / (y1 - y0) / g0;
        println!("cut-bond energy / (G0 × length) = {ratio:.4}");
        assert!((ratio - 1.0).abs() < 0.06, "{ratio}");
    }

    /// The strain energy density of an interior particle under a homogeneous
    /// uniaxial-stress strain (ε, −νε) against ½Eε² (plane stress), and under
    /// an isotropic strain against 9Kε²/2 (3D): the lattice calibration error
    /// of m = 3 without partial volumes.
    #[test]
    fn interior_strain_energy_matches_the_classical_one_to_the_lattice_error() {
        let (dx, eps) = (1e-3, 1e-4);
        let x = lattice::<2>(13, dx, 0.0);
        let b = body(&x, dx, Space::PlaneStress);
        let y: Vec<Vector<2>> = x
            .iter()
            .map(|p| Vector::<2>::new(p[0] * (1.0 + eps), p[1] * (1.0 - eps / 3.0)))
            .collect();
        let w = interior_energy(&b, &y, 6 * 13 + 6, dx * dx);
        let ratio_2d = w / (0.5 * E * eps * eps);
        let x3 = lattice::<3>(9, dx, 0.0);
        let b3 = body(&x3, dx, Space::ThreeD);
        let y3: Vec<Vector<3>> = x3.iter().map(|p| p * (1.0 + eps)).collect();
        let w3 = interior_energy(&b3, &y3, 4 * 81 + 4 * 9 + 4, dx.powi(3));
        let ratio_3d = w3 / (4.5 * bulk_modulus(E) * eps * eps);
        println!("interior W_PD / W: plane stress {ratio_2d:.4}, 3D {ratio_3d:.4}");
        assert!((ratio_2d - 1.0).abs() < 0.15 && (ratio_3d - 1.0).abs() < 0.15);
    }

    /// W_i = ½ Σ_j (c s² |ξ|/2) V_j.
    fn interior_energy<const D: usize>(b: &PdBody<D>, y: &[Vector<D>], i: usize, v: f64) -> f64 {
        0.5 * b.bonds.gather_scalar(i, |k, _| {
            b.pmb.bond_energy(b.bonds.stretch(k, y), b.bonds.length[k]) * v
        })
    }
}
