//! Drucker–Prager elastoplasticity at finite strain (thesis §3.2, 3-36…3-62),
//! perfectly plastic, on the Hencky kinematics of `return_mapping.rs`.
//!
//! Yield function and plastic potential on the Kirchhoff stress τ (tension
//! positive), with q = √(3/2 s:s) and σ_m = tr τ / 3:
//!
//!   f = q + 3α σ_m − σ_Y   (3-36),    g = q + 3β σ_m   (3-51).
//!
//! α, σ_Y and β follow from the Mohr–Coulomb c, φ, ψ by one of three fits:
//! - `Outer`: the compression cone through the outer (triaxial-compression)
//!   vertices of the Mohr–Coulomb pyramid, α = 2 sin φ/(3 − sin φ),
//!   σ_Y = 6c cos φ/(3 − sin φ) (3-37, 3-38), β = 2 sin ψ/(3 − sin ψ) (3-52);
//! - `Inner`: the extension cone through the inner (triaxial-extension) vertices,
//!   the same with 3 + sin (3-39, 3-40, 3-52);
//! - `PlaneStrain`: the cone whose plane-strain limit state (steady plastic flow
//!   with ε̇_zz = 0, where s_zz = −2βq/3) coincides with Mohr–Coulomb's for any ψ:
//!   β = √3 tan ψ/√(9 + 12 tan² ψ), α = sin φ/(√3 √(1 − β²) + β sin φ),
//!   σ_Y = √3 c cos φ (1 − αβ)/√(1 − β²). For ψ = φ this is the classical
//!   associated match (α = β), for ψ = 0 it is α = sin φ/√3, σ_Y = √3 c cos φ;
//!   the plane-strain dilatancy ε̇_v/(ε̇_1 − ε̇_3) = sin ψ is Mohr–Coulomb's too.
//!
//! # Return mapping (3-53…3-59, in principal Kirchhoff stresses)
//!
//! Trial: σ_m* = K tr ε^tr, s* = 2G dev ε^tr, q*. If f* > 0 the plastic
//! multiplier is Δλ = f*/(3G + 9αβK) (3-59), q = q* − 3GΔλ (3-56),
//! σ_m = σ_m* − 3βKΔλ (3-55) and s = (q/q*) s* (3-57, radial return); the
//! equivalent plastic strain grows by Δλ (3-60). If q* − 3GΔλ < 0 the return
//! passes the apex of the cone: the stress is the apex σ_m = σ_Y/(3α), s = 0, and
//! the equivalent plastic strain grows by √(2/3)|dev ε^tr| (all deviatoric elastic
//! strain becomes plastic). For φ = 0 (von Mises) the cone is a cylinder and has no
//! apex.
//!
//! The algorithmic tangent of the cone return differentiates these closed forms;
//! at the apex it is zero (the stress is fixed).
//!
//! History: one slot, the equivalent plastic strain ε̄p.
//!
//! Scene keys: youngs_modulus, poisson_ratio, cohesion, friction_angle,
//! dilation_angle (degrees) and mohr_coulomb_fit.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::return_mapping::{
    Elasticity, Frictional, Principal, PrincipalTangent, Return, ReturnMapping,
};
use super::{reduced_angle, Strength};
use crate::dim::Mat3;
use serde::Deserialize;

/// How the cone is matched to the Mohr–Coulomb parameters (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MohrCoulombFit {
    Outer,
    Inner,
    PlaneStrain,
}

/// The cone f = q + 3α σ_m − σ_Y with potential g = q + 3β σ_m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub alpha: f64,
    pub yield_stress: f64,
    pub beta: f64,
}

impl Cone {
    /// Fit to Mohr–Coulomb cohesion c, friction angle φ and dilation angle ψ
    /// (radians).
    pub fn fit(fit: MohrCoulombFit, c: f64, phi: f64, psi: f64) -> Cone {
        let (sp, cp, sq) = (phi.sin(), phi.cos(), psi.sin());
        match fit {
            // thesis (3-37), (3-38), (3-52)
            MohrCoulombFit::Outer => Cone {
                alpha: 2.0 * sp / (3.0 - sp),
                yield_stress: 6.0 * c * cp / (3.0 - sp),
                beta: 2.0 * sq / (3.0 - sq),
            },
            // thesis (3-39), (3-40), (3-52)
            MohrCoulombFit::Inner => Cone {
                alpha: 2.0 * sp / (3.0 + sp),
                yield_stress: 6.0 * c * cp / (3.0 + sp),
                beta: 2.0 * sq / (3.0 + sq),
            },
            MohrCoulombFit::PlaneStrain => {
                let tq = psi.tan();
                let beta = 3f64.sqrt() * tq / (9.0 + 12.0 * tq * tq).sqrt();
                let root = (1.0 - beta * beta).sqrt();
                let alpha = sp / (3f64.sqrt() * root + beta * sp);
                Cone {
                    alpha,
                    yield_stress: 3f64.sqrt() * c * cp * (1.0 - alpha * beta) / root,
                    beta,
                }
            }
        }
    }
}

/// Drucker–Prager solid: Hencky elasticity, perfectly plastic cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DruckerPrager {
    /// Reference mass density ρ0.
    pub density: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    /// Mohr–Coulomb cohesion c (≥ 0).
    pub cohesion: f64,
    /// Friction angle φ in radians, 0 ≤ φ < π/2.
    pub friction_angle: f64,
    /// Dilation angle ψ in radians, 0 ≤ ψ ≤ φ.
    pub dilation_angle: f64,
    pub fit: MohrCoulombFit,
}

impl DruckerPrager {
    pub fn cone(&self) -> Cone {
        Cone::fit(
            self.fit,
            self.cohesion,
            self.friction_angle,
            self.dilation_angle,
        )
    }

    fn elastic(&self) -> Elasticity {
        Elasticity::new(self.youngs_modulus, self.poisson_ratio)
    }
}

impl FromParameters for DruckerPrager {
    const NAME: &'static str = "drucker_prager";
    const KEYS: &'static [&'static str] = &[
        "youngs_modulus",
        "poisson_ratio",
        "cohesion",
        "friction_angle",
        "dilation_angle",
        "mohr_coulomb_fit",
    ];
    const EXAMPLE: &'static str = "youngs_modulus = 1.0e6\npoisson_ratio = 0.3\ncohesion = 1.0e3\nfriction_angle = 30.0\nmohr_coulomb_fit = \"outer\"";

    /// Angles in degrees in the scene, radians here.
    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let youngs_modulus = p.youngs_modulus()?;
        let poisson_ratio = p.poisson_ratio()?;
        let (cohesion, phi, psi) = p.mohr_coulomb_strength()?;
        let fit = p.required("mohr_coulomb_fit")?;
        Ok(DruckerPrager {
            density,
            youngs_modulus,
            poisson_ratio,
            cohesion,
            friction_angle: phi.to_radians(),
            dilation_angle: psi.to_radians(),
            fit,
        })
    }
}

/// q = √(3/2) |s| of a principal deviator.
fn equivalent(s: &Principal) -> f64 {
    (1.5 * s.norm_squared()).sqrt()
}

impl ReturnMapping for DruckerPrager {
    fn elastic_strain(&self, tau: &Mat3, _history: &[f64]) -> Mat3 {
        self.elastic().strain_of_stress(tau)
    }

    fn return_map(&self, eps: &Principal, h_old: &[f64], h_new: &mut [f64]) -> Return {
        let el = self.elastic();
        let (k, g) = (el.bulk(), el.mu);
        let Cone {
            alpha,
            yield_stress,
            beta,
        } = self.cone();
        let one = Principal::repeat(1.0);
        let dev_eps = eps - one * (eps.sum() / 3.0);
        let sm_trial = k * eps.sum();
        let s_trial = dev_eps * (2.0 * g);
        let q_trial = equivalent(&s_trial);
        let f_trial = q_trial + 3.0 * alpha * sm_trial - yield_stress;
        let tolerance = 1e-12 * (yield_stress + q_trial + (3.0 * alpha * sm_trial).abs());
        if f_trial <= tolerance {
            h_new[0] = h_old[0];
            return Return {
                tau: el.stress(eps),
                tangent: el.stiffness(),
            };
        }
        let denominator = 3.0 * g + 9.0 * alpha * beta * k;
        let dl = f_trial / denominator; // thesis (3-59)
        let q = q_trial - 3.0 * g * dl; // (3-56)
        if q < 0.0 {
            // Beyond the apex (exists for α > 0, because q < 0 needs σ_m > σ_Y/(3α)).
            h_new[0] = h_old[0] + (2.0 / 3.0f64).sqrt() * dev_eps.norm();
            return Return {
                tau: one * (yield_stress / (3.0 * alpha)),
                tangent: PrincipalTangent::zeros(),
            };
        }
        h_new[0] = h_old[0] + dl; // (3-60)
        let ratio = q / q_trial;
        let sm = sm_trial - 3.0 * beta * k * dl; // (3-55)
        let tau = s_trial * ratio + one * sm; // (3-57)
                                              // Tangent: differentiate Δλ, q/q* and σ_m with respect to ε^tr.
        let dq_trial = s_trial * (3.0 * g / q_trial);
        let d_dl = (dq_trial + one * (3.0 * alpha * k)) / denominator;
        let d_ratio = d_dl * (-3.0 * g / q_trial) + dq_trial * (3.0 * g * dl / (q_trial * q_trial));
        let deviatoric_projector =
            PrincipalTangent::identity() - PrincipalTangent::repeat(1.0 / 3.0);
        let d_sm = one * k - d_dl * (3.0 * beta * k);
        let tangent = s_trial * d_ratio.transpose()
            + deviatoric_projector * (2.0 * g * ratio)
            + one * d_sm.transpose();
        Return { tau, tangent }
    }
}

/// Its `Material` implementation is the one of `return_mapping::Frictional`.
impl Frictional for DruckerPrager {
    fn elasticity(&self) -> Elasticity {
        self.elastic()
    }

    fn reference_density(&self) -> f64 {
        self.density
    }

    fn peak_strength(&self) -> Strength {
        Strength {
            cohesion: self.cohesion,
            friction_angle: self.friction_angle,
            dilation_angle: self.dilation_angle,
        }
    }

    fn reduced(&self, factor: f64) -> Self {
        DruckerPrager {
            cohesion: self.cohesion / factor,
            friction_angle: reduced_angle(self.friction_angle, factor),
            dilation_angle: reduced_angle(self.dilation_angle, factor),
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Mat3;
    use crate::material::testing::{increment, rotated};
    use crate::material::{driver, Increment, Material};
    use nalgebra::Vector3;

    const C: f64 = 1.0e4;

    fn model(fit: MohrCoulombFit, phi_deg: f64, psi_deg: f64) -> DruckerPrager {
        DruckerPrager {
            density: 2000.0,
            youngs_modulus: 2.0e7,
            poisson_ratio: 0.3,
            cohesion: C,
            friction_angle: phi_deg.to_radians(),
            dilation_angle: psi_deg.to_radians(),
            fit,
        }
    }

    /// f of a principal Kirchhoff stress.
    fn yield_value(m: &DruckerPrager, tau: &Principal) -> f64 {
        let cone = m.cone();
        let mean = tau.sum() / 3.0;
        equivalent(&(tau - Principal::repeat(mean))) + 3.0 * cone.alpha * mean - cone.yield_stress
    }

    /// Mohr–Coulomb failure states (tension positive) at confinement p: triaxial
    /// compression (σ1 = σ2 = −p, σ3 = −p − q_c) and extension (σ1 = −p + … ).
    fn mc_triaxial(phi: f64, p: f64) -> (Principal, Principal) {
        let s = phi.sin();
        let q_c = 2.0 * (C * phi.cos() + p * s) / (1.0 - s);
        let compression = Vector3::new(-p, -p, -p - q_c);
        // Extension: σ2 = σ3 = −p, σ1 = −p + q_e with σ1 − σ3 + (σ1 + σ3) sin φ = 2c cos φ.
        let q_e = 2.0 * (C * phi.cos() + p * s) / (1.0 + s);
        let extension = Vector3::new(-p + q_e, -p, -p);
        (compression, extension)
    }

    #[test]
    fn cones_touch_the_mohr_coulomb_vertices_they_are_fitted_to() {
        for phi_deg in [0.0, 10.0, 20.0, 35.0] {
            let phi = f64::to_radians(phi_deg);
            for p in [0.0, 5.0e4, 2.0e5] {
                let (comp, ext) = mc_triaxial(phi, p);
                let outer = model(MohrCoulombFit::Outer, phi_deg, 0.0);
                let inner = model(MohrCoulombFit::Inner, phi_deg, 0.0);
                let fo = yield_value(&outer, &comp) / C;
                let fi = yield_value(&inner, &ext) / C;
                assert!(
                    fo.abs() < 1e-12,
                    "outer cone through the compression vertex (φ = {phi_deg}°): {fo:e}"
                );
                assert!(
                    fi.abs() < 1e-12,
                    "inner cone through the extension vertex (φ = {phi_deg}°): {fi:e}"
                );
                // The outer cone contains the extension vertex, the inner one lies inside the compression vertex.
                if phi_deg > 0.0 {
                    assert!(yield_value(&outer, &ext) < 0.0 && yield_value(&inner, &comp) > 0.0);
                }
            }
        }
    }

    #[test]
    fn plane_strain_fit_reduces_to_the_classical_matches() {
        for phi_deg in [5.0, 20.0, 30.0, 40.0] {
            let phi = f64::to_radians(phi_deg);
            let t = phi.tan();
            let assoc = Cone::fit(MohrCoulombFit::PlaneStrain, C, phi, phi);
            let root = (9.0 + 12.0 * t * t).sqrt();
            // √J2 + α' I1 = k with α' = tan φ/√(9 + 12 tan² φ), k = 3c/√(…): α = √3 α', σ_Y = √3 k.
            let alpha = 3f64.sqrt() * t / root;
            let sy = 3f64.sqrt() * 3.0 * C / root;
            assert!((assoc.alpha - alpha).abs() < 1e-14 && (assoc.beta - alpha).abs() < 1e-14);
            assert!((assoc.yield_stress - sy).abs() < 1e-10 * sy);
            let nonassoc = Cone::fit(MohrCoulombFit::PlaneStrain, C, phi, 0.0);
            assert!((nonassoc.alpha - phi.sin() / 3f64.sqrt()).abs() < 1e-14);
            assert!((nonassoc.yield_stress - 3f64.sqrt() * C * phi.cos()).abs() < 1e-10 * C);
            assert_eq!(nonassoc.beta, 0.0);
        }
    }

    /// The start state: a rotated, stretched F_old with a stress inside the cone.
    fn start() -> (Mat3, Mat3) {
        let r = driver::rotation_z(0.4);
        let f_old = r * Mat3::new(1.01, 0.002, 0.0, 0.0, 0.995, 0.001, 0.0, 0.0, 0.998);
        let s = Mat3::new(
            -1.2e5, 8.0e3, 1.0e3, 8.0e3, -0.9e5, -2.0e3, 1.0e3, -2.0e3, -1.0e5,
        );
        (f_old, s)
    }

    /// Which part of the surface the update ended on: elastic, cone or apex.
    fn state(m: &DruckerPrager, i: &Increment) -> &'static str {
        let mut h = [0.0];
        let s = m.update(i, &mut h) * i.f.determinant();
        let eig = nalgebra::SymmetricEigen::new(s).eigenvalues;
        if h[0] == i.history_old[0] {
            "elastic"
        } else if (eig.max() - eig.min()).abs() < 1e-9 * eig.amax() {
            "apex"
        } else {
            assert!(
                yield_value(m, &eig).abs() < 1e-8 * C,
                "on the cone after the return"
            );
            "cone"
        }
    }

    #[test]
    fn tangent_matches_finite_differences_in_every_state() {
        let (f_old, s_old) = start();
        let cases = [
            ("elastic", [1.0 + 2e-5, 1.0 - 1e-5, 1.0]),
            ("cone", [1.0 + 1.5e-2, 1.0 - 1e-2, 1.0 - 1.5e-2]),
            ("cone", [1.0 - 3e-2, 1.0 + 2e-2, 1.0 + 1e-2]),
            ("apex", [1.03, 1.02, 1.025]),
        ];
        let history = [0.01];
        for fit in [
            MohrCoulombFit::Outer,
            MohrCoulombFit::Inner,
            MohrCoulombFit::PlaneStrain,
        ] {
            for (phi, psi) in [(30.0, 30.0), (30.0, 0.0), (25.0, 10.0), (0.0, 0.0)] {
                let mut m = model(fit, phi, psi);
                if phi == 0.0 {
                    m.cohesion = 5.0 * C; // the start state lies inside
                }
                for (expect, d) in cases {
                    let i = increment(f_old, rotated(d), s_old, &history);
                    let got = state(&m, &i);
                    if phi == 0.0 && expect == "apex" {
                        assert_eq!(got, "cone", "von Mises has no apex");
                    } else {
                        assert_eq!(got, expect, "{fit:?} φ = {phi}, ψ = {psi}, ΔF = {d:?}");
                    }
                    let e = driver::tangent_error(&m, &i, 1e-7);
                    eprintln!(
                        "DP {fit:?} φ = {phi:>4} ψ = {psi:>4} {got:>7}: tangent vs FD {e:.2e}"
                    );
                    assert!(
                        e < 1e-6,
                        "{fit:?} φ = {phi} ψ = {psi} {got}: tangent vs central FD {e:e} < 1e-6"
                    );
                }
            }
        }
    }

    #[test]
    fn radial_return_closed_form() {
        // Unstressed start, one large deviatoric + volumetric increment: the return
        // (3-55…3-59) in closed form on the principal trial strains.
        let m = model(MohrCoulombFit::Outer, 30.0, 10.0);
        let el = m.elastic();
        let eps = Vector3::new(-0.004, 0.001, 0.0015);
        let mut h = [0.0];
        let ret = m.return_map(&eps, &[0.0], &mut h);
        let cone = m.cone();
        let (k, g) = (el.bulk(), el.mu);
        let sm_t = k * eps.sum();
        let s_t = (eps - Principal::repeat(eps.sum() / 3.0)) * 2.0 * g;
        let q_t = equivalent(&s_t);
        let dl = (q_t + 3.0 * cone.alpha * sm_t - cone.yield_stress)
            / (3.0 * g + 9.0 * cone.alpha * cone.beta * k);
        let expect =
            s_t * ((q_t - 3.0 * g * dl) / q_t) + Principal::repeat(sm_t - 3.0 * cone.beta * k * dl);
        assert!(
            (ret.tau - expect).norm() < 1e-9 * expect.norm(),
            "τ from (3-55)…(3-59)"
        );
        assert!((h[0] - dl).abs() < 1e-15, "Δε̄p = Δλ (3-60)");
        assert!(
            yield_value(&m, &ret.tau).abs() < 1e-8 * C,
            "f = 0 after the return"
        );
    }
}
