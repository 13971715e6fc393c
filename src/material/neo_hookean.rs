//! Compressible neo-Hookean hyperelasticity.
//!
//! Stored energy per reference volume W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)², which
//! gives the Cauchy stress σ = (μ/J)(b − I) + (λ ln J / J) I with b = F Fᵀ, J = det F.
//! The stress depends only on F_new = ΔF F_old (no history, path independent).

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{lame, Increment, Material, StressDerivative};
use crate::dim::Mat3;

/// Compressible neo-Hookean solid with Lamé constants from (E, ν).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeoHookean {
    /// Reference mass density ρ0.
    pub density: f64,
    /// Young's modulus E (small-strain).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν (small-strain).
    pub poisson_ratio: f64,
    /// (λ, μ) from (E, ν), formed once: every stress update reads them.
    lame: (f64, f64),
}

impl NeoHookean {
    pub fn new(density: f64, youngs_modulus: f64, poisson_ratio: f64) -> Self {
        super::debug_check_elastic(density, youngs_modulus, poisson_ratio);
        Self {
            density,
            youngs_modulus,
            poisson_ratio,
            lame: lame(youngs_modulus, poisson_ratio),
        }
    }

    /// Lamé constants (λ, μ).
    pub fn lame(&self) -> (f64, f64) {
        self.lame
    }

    /// Cauchy stress at total deformation gradient `f`.
    pub fn cauchy(&self, f: &Mat3) -> Mat3 {
        let (lambda, mu) = self.lame();
        let j = f.determinant();
        debug_assert!(j > 0.0, "det F must be positive");
        let b = f * f.transpose();
        (b - Mat3::identity()) * (mu / j) + Mat3::identity() * (lambda * j.ln() / j)
    }
}

impl FromParameters for NeoHookean {
    const NAME: &'static str = "neo_hookean";
    const KEYS: &'static [&'static str] = &["youngs_modulus", "poisson_ratio"];
    const EXAMPLE: &'static str = "youngs_modulus = 1.0e6\npoisson_ratio = 0.3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        // E is checked before ν (arguments are evaluated in order).
        Ok(Self::new(density, p.youngs_modulus()?, p.poisson_ratio()?))
    }
}

impl Material for NeoHookean {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn update(&self, inc: &Increment, _history_new: &mut [f64]) -> Mat3 {
        self.cauchy(&inc.f)
    }

    fn p_wave_modulus(&self) -> f64 {
        let (lambda, mu) = self.lame();
        lambda + 2.0 * mu
    }

    /// W / J with W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)².
    fn strain_energy_density(&self, f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        let (lambda, mu) = self.lame();
        let j = f.determinant();
        let ln_j = j.ln();
        (0.5 * mu * (f.norm_squared() - 3.0) - mu * ln_j + 0.5 * lambda * ln_j * ln_j) / j
    }

    /// For dΔF = E_kl: dF = E_kl F_old, d ln J = tr(F⁻¹ dF), db = dF Fᵀ + F dFᵀ,
    /// dσ = (μ/J)(db − (b − I) d ln J) + λ (1 − ln J)/J d ln J I.
    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let (lambda, mu) = self.lame();
        let f = inc.f;
        let j = f.determinant();
        let ln_j = j.ln();
        let f_inv = f.try_inverse()?;
        let b_minus_i = f * f.transpose() - Mat3::identity();
        let mut d = StressDerivative::zeros();
        for k in 0..3 {
            for l in 0..3 {
                // dF = E_kl F_old: row k equals row l of F_old, other rows zero.
                let mut df = Mat3::zeros();
                df.set_row(k, &inc.f_old.row(l));
                let dlnj = (f_inv * df).trace();
                let dff = df * f.transpose();
                let db = dff + dff.transpose();
                let ds = (db - b_minus_i * dlnj) * (mu / j)
                    + Mat3::identity() * (lambda * (1.0 - ln_j) / j * dlnj);
                super::set_derivative_column(&mut d, k, l, &ds);
            }
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::testing::{general_f, prestressed, rel};

    fn model() -> NeoHookean {
        NeoHookean::new(1100.0, 3.0e6, 0.35)
    }

    #[test]
    fn zero_stress_at_identity() {
        let s = model().update(&prestressed(Mat3::identity(), Mat3::identity()), &mut []);
        assert!(s.norm() == 0.0, "σ(I) = 0 exactly");
    }

    #[test]
    fn small_strain_limit_is_hooke() {
        let m = model();
        let (lambda, mu) = m.lame();
        for (scale, tol) in [(1e-7, 1e-6), (1e-6, 1e-5)] {
            let h = Mat3::new(1.0, 0.4, -0.3, 0.4, -0.6, 0.2, -0.3, 0.2, 0.5) * scale;
            let s = m.update(
                &prestressed(Mat3::identity(), Mat3::identity() + h),
                &mut [],
            );
            let hooke = Mat3::identity() * (lambda * h.trace()) + h * (2.0 * mu);
            let e = rel(&s, &hooke);
            assert!(
                e < tol,
                "Hooke's law at strain {scale}: relative error {e:e} < {tol:e}"
            );
        }
    }

    #[test]
    fn stress_is_symmetric() {
        let s = model().update(&prestressed(general_f(), driver::rotation_z(0.3)), &mut []);
        assert!(
            (s - s.transpose()).norm() <= 1e-14 * s.norm(),
            "symmetric to 1e-14"
        );
    }

    #[test]
    fn stress_derivative_matches_finite_differences() {
        let m = model();
        let f_old = Mat3::new(1.1, 0.2, 0.0, 0.05, 0.95, 0.0, 0.0, 0.0, 1.02);
        let df = driver::rotation_z(0.15)
            * Mat3::new(1.02, 0.03, 0.01, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01);
        let i = prestressed(f_old, df);
        let exact = m.stress_derivative(&i).unwrap();
        let fd = driver::numerical_stress_derivative(&m, &i, 1e-5);
        let err = (exact - fd).norm() / exact.norm();
        assert!(
            err < 1e-6,
            "tangent vs central FD: relative error {err:e} must be < 1e-6"
        );
    }

    #[test]
    fn superposed_rotation_rotates_stress() {
        let m = model();
        let f_old = general_f();
        let df = Mat3::new(1.03, 0.02, 0.0, -0.01, 0.98, 0.01, 0.0, 0.0, 1.0);
        let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(0.3, -0.5, 0.8));
        let r = *nalgebra::Rotation3::from_axis_angle(&axis, 0.8).matrix();
        let s = m.update(&prestressed(f_old, df), &mut []);
        let sr = m.update(&prestressed(f_old, r * df), &mut []);
        assert!(
            rel(&sr, &(r * s * r.transpose())) < 1e-14,
            "σ(RF) = RσRᵀ to 1e-14"
        );
        // Through the driver: rotating a pre-stretched state.
        let u = Mat3::new(1.2, 0.1, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0, 1.0);
        let resp = driver::run(&m, &driver::rotation(&u, 1.3, 20), 1e-3);
        let r = driver::rotation_z(1.3);
        let s_u = resp.stress[20];
        assert!(
            rel(&resp.stress[40], &(r * s_u * r.transpose())) < 1e-13,
            "driver rotation to 1e-13"
        );
    }

    #[test]
    fn uniaxial_strain_closed_form() {
        let m = model();
        let (lambda, mu) = m.lame();
        let resp = driver::run(&m, &driver::uniaxial_strain(0, 0.5, 50), 1e-3);
        for (f, s) in resp.f.iter().zip(&resp.stress).skip(1) {
            let l1: f64 = f[(0, 0)];
            let s11 = mu / l1 * (l1 * l1 - 1.0) + lambda * l1.ln() / l1;
            let s22 = lambda * l1.ln() / l1;
            assert!(
                (s[(0, 0)] - s11).abs() < 1e-12 * s11.abs(),
                "σ11 closed form to 1e-12"
            );
            assert!(
                (s[(1, 1)] - s22).abs() < 1e-12 * s22.abs(),
                "σ22 closed form to 1e-12"
            );
            assert!(
                (s[(2, 2)] - s22).abs() < 1e-12 * s22.abs(),
                "σ33 = σ22 to 1e-12"
            );
            assert!(
                s[(0, 1)].abs() + s[(0, 2)].abs() + s[(1, 2)].abs() < 1e-12 * s11.abs(),
                "no shear"
            );
        }
    }

    #[test]
    fn simple_shear_closed_form() {
        let m = model();
        let (_, mu) = m.lame();
        let resp = driver::run(&m, &driver::simple_shear(1.5, 30), 1e-3);
        for (f, s) in resp.f.iter().zip(&resp.stress).skip(1) {
            let gamma = f[(0, 1)];
            let scale = mu * gamma;
            assert!(
                (s[(0, 1)] - mu * gamma).abs() < 1e-12 * scale,
                "σ12 = μγ to 1e-12"
            );
            assert!(
                (s[(0, 0)] - s[(1, 1)] - mu * gamma * gamma).abs() < 1e-12 * scale,
                "σ11 − σ22 = μγ² to 1e-12"
            );
            assert!(s[(1, 1)].abs() < 1e-12 * scale, "σ22 = 0 (J = 1) to 1e-12");
        }
    }

    #[test]
    fn energy_derivative_is_first_piola() {
        let m = model();
        let f = general_f();
        let h = 1e-6;
        let w = |f: &Mat3| f.determinant() * m.strain_energy_density(f, &Mat3::zeros(), &[]);
        let p_num = Mat3::from_fn(|k, l| {
            let mut fp = f;
            let mut fm = f;
            fp[(k, l)] += h;
            fm[(k, l)] -= h;
            (w(&fp) - w(&fm)) / (2.0 * h)
        });
        let p = m.cauchy(&f) * f.determinant() * f.try_inverse().unwrap().transpose();
        let e = rel(&p_num, &p);
        assert!(e < 1e-6, "∂W/∂F = Jσ F⁻ᵀ: relative error {e:e} < 1e-6");
        assert!(
            m.strain_energy_density(&Mat3::identity(), &Mat3::zeros(), &[]) == 0.0,
            "W(I) = 0"
        );
    }
}
