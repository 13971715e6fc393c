//! The deviatoric kinematics shared by the models that take their pressure from
//! an equation of state (Johnson–Cook, JH-2): the elastic deviatoric state on the
//! isochoric Hencky kinematics, recovered from the stored stress, and the
//! equivalent strain rate of an increment.
//!
//! ε̄_e,old = dev τ_old/(2G) with τ = J σ, b̄_e,old = exp(2 ε̄_e,old), the trial
//! b̄^tr = ΔF̄ b̄_e,old ΔF̄ᵀ with ΔF̄ = ΔJ^{−1/3} ΔF, and the trial principal
//! deviatoric strains ē_a = ½ ln β̄_a (made traceless); the trial Kirchhoff
//! deviator is 2G ē_a along the eigenvectors (Simo & Hughes, Computational
//! Inelasticity, §9.2). A rigid rotation rotates the stress exactly.

use super::spectral::{from_principal, symmetric_eigen};
use crate::dim::Mat3;
use nalgebra::Vector3;

/// Deviatoric part of a tensor.
pub fn deviator(a: &Mat3) -> Mat3 {
    a - Mat3::identity() * (a.trace() / 3.0)
}

/// von Mises equivalent √(3/2 s:s) of a tensor's deviator.
pub fn equivalent(a: &Mat3) -> f64 {
    (1.5 * deviator(a).norm_squared()).sqrt()
}

/// The trial state of an increment: principal deviatoric elastic strains and
/// their eigenvectors (columns).
pub struct TrialDeviator {
    pub strain: Vector3<f64>,
    pub n: Mat3,
}

impl TrialDeviator {
    /// From the Kirchhoff deviator at the start of the increment and ΔF.
    pub fn of(tau_dev_old: &Mat3, shear_modulus: f64, df: &Mat3) -> Self {
        let (old, v) = symmetric_eigen(&(tau_dev_old / (2.0 * shear_modulus)));
        let be_old_minus_i = from_principal(&v, &old.map(|e| (2.0 * e).exp_m1()));
        let df_bar = df * df.determinant().cbrt().recip();
        // b̄^tr − I = ΔF̄ (b̄_e,old − I) ΔF̄ᵀ + (ΔF̄ ΔF̄ᵀ − I), without cancellation.
        let h = df_bar - Mat3::identity();
        let btr_minus_i =
            df_bar * be_old_minus_i * df_bar.transpose() + h + h.transpose() + h * h.transpose();
        let (m, n) = symmetric_eigen(&btr_minus_i);
        let e = m.map(|m| 0.5 * m.ln_1p());
        let mean = e.sum() / 3.0;
        TrialDeviator {
            strain: e.map(|x| x - mean),
            n,
        }
    }

    /// The tensor with principal values `principal` on these eigenvectors.
    pub fn tensor(&self, principal: &Vector3<f64>) -> Mat3 {
        from_principal(&self.n, principal)
    }
}

/// The trial state of the models whose strength is a Cauchy stress (JH-2, HJC,
/// RHT): the trial deviator from the step-start Kirchhoff deviator `tau_dev_old`
/// at shear modulus G, its principal Cauchy values 2G ē_a / J at the end
/// Jacobian J, and their equivalent stress q = √(3/2)|s|.
pub fn cauchy_trial(
    tau_dev_old: &Mat3,
    shear_modulus: f64,
    df: &Mat3,
    j: f64,
) -> (TrialDeviator, Vector3<f64>, f64) {
    let trial = TrialDeviator::of(tau_dev_old, shear_modulus, df);
    let s = trial.strain * (2.0 * shear_modulus / j);
    let q = (1.5 * s.norm_squared()).sqrt();
    (trial, s, q)
}

/// The deviatoric strain increment dev sym(ΔF − I) of an increment.
pub fn strain_increment(df: &Mat3) -> Mat3 {
    deviator(&(0.5 * (df + df.transpose())))
}

/// Equivalent strain rate √(⅔ ė:ė) of the increment (thesis 3-69); 0 for
/// quasi-static calls (Δt = 0).
pub fn equivalent_rate(strain_increment: &Mat3, dt: f64) -> f64 {
    if dt > 0.0 {
        (2.0 / 3.0 * strain_increment.norm_squared()).sqrt() / dt
    } else {
        0.0
    }
}
