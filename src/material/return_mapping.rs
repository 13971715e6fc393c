//! Finite-strain elastoplasticity on the kinematics of the Hencky model
//! (multiplicative split F = Fe Fp, exponential-map return, isotropic).
//!
//! The elastic state is the elastic left Cauchy–Green tensor b_e = Fe Feᵀ, with the
//! elastic logarithmic strain ε_e = ½ ln b_e and the Kirchhoff stress
//! τ = λ tr(ε_e) I + 2μ ε_e (the Hencky law of `hencky.rs`). Because this law is
//! invertible, the elastic state at the start of an increment is recovered from the
//! stress itself: τ_old = det(F_old) σ_old, ε_e,old = ℂ⁻¹ τ_old,
//! b_e,old = exp(2 ε_e,old). A material therefore only stores its hardening
//! variables in the history, and a prescribed initial stress (e.g. geostatic) is a
//! consistent elastic state without further input.
//!
//! An increment ΔF gives the trial b_e^tr = ΔF b_e,old ΔFᵀ = Σ β_a n_a⊗n_a, trial
//! principal elastic strains ε_a = ½ ln β_a, and the principal Kirchhoff stresses
//! τ_a come from a return mapping in principal space that is exactly the
//! small-strain algorithm (the exponential map makes the plastic flow act on the
//! principal logarithmic strains). The eigenvectors do not change in the return,
//! so τ = Σ τ_a n_a⊗n_a and σ = τ / J with J = det ΔF det F_old.
//!
//! # Consistent tangent
//!
//! With the algorithmic principal tangent D_ab = ∂τ_a/∂ε_b of the return mapping,
//! the derivative of the isotropic tensor function τ(b^tr) in the direction db is,
//! in the eigenbasis N (d̂b = Nᵀ db N),
//!
//!   (Nᵀ dτ N)_aa = Σ_b D_ab d̂b_bb / (2 β_b),
//!   (Nᵀ dτ N)_ab = (τ_a − τ_b)/(β_a − β_b) d̂b_ab          (a ≠ b),
//!
//! the second written as Q_ab · ½ G_ab with G_ab the divided difference of ln
//! (`hencky::log_divided_difference`) and Q_ab = (τ_a − τ_b)/(ε_a − ε_b), which for
//! coincident strains tends to ½(D_aa − D_ab − D_ba + D_bb). For dΔF = E_kl:
//! db = E_kl b_e,old ΔFᵀ + (…)ᵀ and d ln J = (ΔF⁻¹)_lk, dσ = dτ / J − σ d ln J.
//!
//! # Frictional models
//!
//! Drucker–Prager and Mohr–Coulomb differ only in their return mapping, their
//! strength and how a factor reduces it (`Frictional`); their `Material`
//! implementation is the one at the end of this file.

use super::hencky::log_divided_difference;
use super::parameters::FromParameters;
use super::spectral::{from_principal, symmetric_eigen};
use super::{lame, Increment, Material, Strength, StressDerivative};
use crate::dim::Mat3;
use nalgebra::{Matrix3, Vector3};

/// Principal values (strains or stresses), in the order of the eigenvectors.
pub type Principal = Vector3<f64>;
/// ∂τ_a/∂ε_b, the algorithmic tangent of a principal return mapping.
pub type PrincipalTangent = Matrix3<f64>;

/// Isotropic linear elasticity between logarithmic strain and Kirchhoff stress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elasticity {
    pub lambda: f64,
    pub mu: f64,
}

impl Elasticity {
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Self {
        let (lambda, mu) = lame(youngs_modulus, poisson_ratio);
        Elasticity { lambda, mu }
    }

    /// Bulk modulus K = λ + 2μ/3.
    pub fn bulk(&self) -> f64 {
        self.lambda + 2.0 * self.mu / 3.0
    }

    /// τ_a = λ Σ ε + 2μ ε_a.
    pub fn stress(&self, eps: &Principal) -> Principal {
        Principal::repeat(self.lambda * eps.sum()) + eps * (2.0 * self.mu)
    }

    /// D^e_ab = λ + 2μ δ_ab.
    pub fn stiffness(&self) -> PrincipalTangent {
        PrincipalTangent::repeat(self.lambda) + PrincipalTangent::identity() * (2.0 * self.mu)
    }

    /// The strain of a Kirchhoff stress: ε = (τ − λ tr ε I)/(2μ), tr ε = tr τ/(3λ + 2μ).
    pub fn strain_of_stress(&self, tau: &Mat3) -> Mat3 {
        let tr_eps = tau.trace() / (3.0 * self.lambda + 2.0 * self.mu);
        (tau - Mat3::identity() * (self.lambda * tr_eps)) / (2.0 * self.mu)
    }
}

/// Principal stresses and algorithmic tangent from a return mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Return {
    pub tau: Principal,
    pub tangent: PrincipalTangent,
}

/// A return mapping in principal logarithmic strains / Kirchhoff stresses.
pub trait ReturnMapping {
    /// The elastic logarithmic strain of a Kirchhoff stress (the inverse of the
    /// elastic law) with the history at the start of the increment: how the
    /// elastic state is recovered from the stored stress.
    fn elastic_strain(&self, tau: &Mat3, history: &[f64]) -> Mat3;

    /// Principal Kirchhoff stresses for the trial principal elastic strains
    /// `eps_trial` (any order), with ∂τ_a/∂ε_b; writes the new history.
    fn return_map(
        &self,
        eps_trial: &Principal,
        history_old: &[f64],
        history_new: &mut [f64],
    ) -> Return;

    /// The principal stresses of [`ReturnMapping::return_map`] alone, for
    /// callers that do not need the tangent (explicit steps).
    fn return_stress(
        &self,
        eps_trial: &Principal,
        history_old: &[f64],
        history_new: &mut [f64],
    ) -> Principal {
        self.return_map(eps_trial, history_old, history_new).tau
    }
}

/// The trial elastic state of an increment.
struct Trial {
    /// Eigenvectors of b_e^tr (columns).
    n: Mat3,
    /// Eigenvalues of b_e^tr − I (β_a = 1 + m_a).
    m: Principal,
    /// Trial principal elastic strains ε_a = ½ ln β_a.
    eps: Principal,
    /// b_e,old.
    be_old: Mat3,
    /// J = det ΔF det F_old.
    j: f64,
}

impl Trial {
    fn of<R: ReturnMapping + ?Sized>(r: &R, inc: &Increment) -> Trial {
        let j_old = inc.f_old.determinant();
        // b_e,old − I = exp(2 ε_e,old) − I, exact at zero stress.
        let eps_e_old = r.elastic_strain(&(inc.stress_old * j_old), inc.history_old);
        let (eps_old, v) = symmetric_eigen(&eps_e_old);
        let be_old_minus_i = from_principal(&v, &eps_old.map(|e| (2.0 * e).exp_m1()));
        // b_e^tr − I = ΔF (b_e,old − I) ΔFᵀ + (ΔF ΔFᵀ − I), without cancellation.
        let h = inc.df - Mat3::identity();
        let btr_minus_i =
            inc.df * be_old_minus_i * inc.df.transpose() + h + h.transpose() + h * h.transpose();
        let (m, n) = symmetric_eigen(&btr_minus_i);
        Trial {
            n,
            m,
            eps: m.map(|m| 0.5 * m.ln_1p()),
            be_old: be_old_minus_i + Mat3::identity(),
            j: inc.df.determinant() * j_old,
        }
    }

    fn rotate(&self, principal: &Principal) -> Mat3 {
        from_principal(&self.n, principal)
    }
}

/// Cauchy stress at the end of the increment; writes the new history.
pub fn update<R: ReturnMapping + ?Sized>(r: &R, inc: &Increment, history_new: &mut [f64]) -> Mat3 {
    let trial = Trial::of(r, inc);
    let tau = r.return_stress(&trial.eps, inc.history_old, history_new);
    trial.rotate(&tau) / trial.j
}

/// Below this difference of principal strains the quotient (τ_a − τ_b)/(ε_a − ε_b)
/// is replaced by its limit from the principal tangent.
const COINCIDENT_STRAINS: f64 = 1e-9;

/// Exact ∂σ/∂ΔF of [`update`] (module documentation).
pub fn stress_derivative<R: ReturnMapping + ?Sized>(
    r: &R,
    inc: &Increment,
) -> Option<StressDerivative> {
    let trial = Trial::of(r, inc);
    let mut scratch = vec![0.0; inc.history_old.len()];
    let ret = r.return_map(&trial.eps, inc.history_old, &mut scratch);
    let df_inv = inc.df.try_inverse()?;
    let sigma = trial.rotate(&ret.tau) / trial.j;
    let d = &ret.tangent;
    let beta = trial.m.map(|m| 1.0 + m);
    // Off-diagonal factors (τ_a − τ_b)/(β_a − β_b).
    let off = Mat3::from_fn(|a, b| {
        if a == b {
            return 0.0;
        }
        let half_g = 0.5 * log_divided_difference(trial.m[a], trial.m[b]);
        let deps = (trial.m[a] - trial.m[b]) * half_g;
        let q = if deps.abs() > COINCIDENT_STRAINS {
            (ret.tau[a] - ret.tau[b]) / deps
        } else {
            0.5 * (d[(a, a)] - d[(a, b)] - d[(b, a)] + d[(b, b)])
        };
        q * half_g
    });
    let n = trial.n;
    let a = trial.be_old * inc.df.transpose();
    let mut out = StressDerivative::zeros();
    for k in 0..3 {
        for l in 0..3 {
            // dΔF b_e,old ΔFᵀ with dΔF = E_kl: row k equals row l of b_e,old ΔFᵀ.
            let mut m = Mat3::zeros();
            m.set_row(k, &a.row(l));
            let db_hat = n.transpose() * (m + m.transpose()) * n;
            let deps = Principal::from_fn(|b, _| 0.5 * db_hat[(b, b)] / beta[b]);
            let dtau_principal = d * deps;
            let mut dtau_hat = off.component_mul(&db_hat);
            dtau_hat.set_diagonal(&dtau_principal);
            let dtau = n * dtau_hat * n.transpose();
            let ds = dtau / trial.j - sigma * df_inv[(l, k)];
            super::set_derivative_column(&mut out, k, l, &ds);
        }
    }
    Some(out)
}

/// Stored elastic energy per unit current volume, ½ τ:ε_e / J = ½ σ:ε_e.
pub fn stored_energy_density(el: &Elasticity, f: &Mat3, stress: &Mat3) -> f64 {
    let eps = el.strain_of_stress(&(stress * f.determinant()));
    0.5 * stress.component_mul(&eps).sum()
}

/// A frictional elastoplastic model on these kinematics, with one history value,
/// the equivalent plastic strain ε̄p.
pub trait Frictional:
    ReturnMapping + FromParameters + Clone + std::fmt::Debug + Send + Sync + 'static
{
    /// The (constant) Hencky elasticity of the model.
    fn elasticity(&self) -> Elasticity;

    /// Reference mass density ρ0.
    fn reference_density(&self) -> f64;

    /// Peak cohesion, friction and dilation angles (radians).
    fn peak_strength(&self) -> Strength;

    /// The model with c/F, tan φ/F and tan ψ/F (strength reduction, Griffiths &
    /// Lane 1999).
    fn reduced(&self, factor: f64) -> Self;
}

impl<M: Frictional> Material for M {
    fn model(&self) -> &'static str {
        M::NAME
    }

    fn density(&self) -> f64 {
        self.reference_density()
    }

    fn n_history(&self) -> usize {
        1
    }

    fn update(&self, inc: &Increment, history_new: &mut [f64]) -> Mat3 {
        update(self, inc, history_new)
    }

    fn p_wave_modulus(&self) -> f64 {
        let el = self.elasticity();
        el.lambda + 2.0 * el.mu
    }

    fn strain_energy_density(&self, f: &Mat3, stress: &Mat3, _history: &[f64]) -> f64 {
        stored_energy_density(&self.elasticity(), f, stress)
    }

    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        stress_derivative(self, inc)
    }

    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    fn frictional_strength(&self) -> Option<Strength> {
        Some(self.peak_strength())
    }

    fn with_reduced_strength(&self, factor: f64) -> Option<Box<dyn Material>> {
        Some(Box::new(self.reduced(factor)))
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        history.first().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::hencky::Hencky;
    use crate::material::testing::{general_f, increment};
    use crate::material::{driver, Material};

    /// The purely elastic return: the framework must reproduce the Hencky model.
    #[derive(Clone, Debug)]
    struct Elastic(Elasticity, Hencky);

    impl ReturnMapping for Elastic {
        fn elastic_strain(&self, tau: &Mat3, _: &[f64]) -> Mat3 {
            self.0.strain_of_stress(tau)
        }
        fn return_map(&self, eps: &Principal, _: &[f64], _: &mut [f64]) -> Return {
            Return {
                tau: self.0.stress(eps),
                tangent: self.0.stiffness(),
            }
        }
    }

    impl Material for Elastic {
        fn model(&self) -> &'static str {
            "elastic return"
        }
        fn density(&self) -> f64 {
            1.0
        }
        fn update(&self, inc: &Increment, h: &mut [f64]) -> Mat3 {
            update(self, inc, h)
        }
        fn p_wave_modulus(&self) -> f64 {
            self.0.lambda + 2.0 * self.0.mu
        }
        fn strain_energy_density(&self, f: &Mat3, s: &Mat3, _: &[f64]) -> f64 {
            stored_energy_density(&self.0, f, s)
        }
        fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
            stress_derivative(self, inc)
        }
    }

    fn elastic() -> Elastic {
        Elastic(Elasticity::new(3.0e6, 0.3), Hencky::new(1.0, 3.0e6, 0.3))
    }

    #[test]
    fn elastic_return_reproduces_hencky_along_a_path() {
        let m = elastic();
        let path = driver::from_fn(30, |t| {
            driver::rotation_z(0.7 * t)
                * Mat3::new(
                    1.0 + 0.3 * t,
                    0.2 * t,
                    0.0,
                    -0.1 * t,
                    1.0 - 0.2 * t,
                    0.05 * t,
                    0.0,
                    0.0,
                    1.0 + 0.1 * t,
                )
        });
        let resp = driver::run(&m, &path, 0.0);
        for (f, s) in resp.f.iter().zip(&resp.stress) {
            let h = m.1.cauchy(f);
            let e = (s - h).norm() / h.norm().max(1.0);
            assert!(
                e < 1e-10,
                "stress from the carried elastic state = Hencky σ(F) to 1e-10: {e:e}"
            );
        }
        let f = resp.f.last().unwrap();
        let s = resp.stress.last().unwrap();
        let e_plastic = m.strain_energy_density(f, s, &[]);
        let e_hencky = m.1.strain_energy_density(f, s, &[]);
        assert!(
            (e_plastic - e_hencky).abs() < 1e-10 * e_hencky,
            "stored energy = Hencky W/J"
        );
    }

    #[test]
    fn elastic_return_tangent_matches_hencky_and_finite_differences() {
        let m = elastic();
        let f_old = general_f();
        let s_old = m.1.cauchy(&f_old);
        let r = driver::rotation_z(0.2);
        let cases = [
            (
                "generic",
                f_old,
                s_old,
                r * Mat3::new(1.02, 0.03, 0.01, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01),
            ),
            ("ΔF = I", f_old, s_old, Mat3::identity()),
            (
                "unstressed, ΔF = I",
                Mat3::identity(),
                Mat3::zeros(),
                Mat3::identity(),
            ),
            (
                "hydrostatic",
                Mat3::identity() * 1.1,
                m.1.cauchy(&(Mat3::identity() * 1.1)),
                Mat3::identity() * 0.95,
            ),
        ];
        for (name, f, s, df) in cases {
            let i = increment(f, df, s, &[]);
            let exact = m.stress_derivative(&i).unwrap();
            let hencky = m.1.stress_derivative(&increment(f, df, s, &[])).unwrap();
            let e_h = (exact - hencky).norm() / hencky.norm();
            let fd = driver::numerical_stress_derivative(&m, &i, 1e-6);
            let e_fd = (exact - fd).norm() / exact.norm();
            eprintln!("elastic return tangent, {name}: vs Hencky {e_h:e}, vs FD {e_fd:e}");
            assert!(e_h < 1e-9, "{name}: tangent = Hencky's to 1e-9 ({e_h:e})");
            assert!(
                e_fd < 1e-6,
                "{name}: tangent vs central FD to 1e-6 ({e_fd:e})"
            );
        }
    }
}
