//! Compressible Ogden hyperelasticity, with no analytic tangent: the implicit
//! solver runs it on the matrix-free Newton–Krylov path only (the direct solver
//! needs `stress_derivative`, which this model does not supply).
//!
//! Stored energy per reference volume, in the principal stretches λ_a of
//! F = ΔF F_old (Ogden 1972; the compressible form with a neo-Hookean volumetric
//! part, e.g. Simo & Hughes, *Computational Inelasticity*, §9.3):
//!
//!   W = Σ_p μ_p/α_p (λ_1^α_p + λ_2^α_p + λ_3^α_p − 3) − (Σ_p μ_p) ln J + ½ λ (ln J)²,
//!
//! (the ln J term makes the reference state stress-free) with the initial shear
//! modulus μ = ½ Σ_p μ_p α_p and λ = 2μν/(1 − 2ν). The principal Kirchhoff
//! stresses are τ_a = λ_a ∂W/∂λ_a = Σ_p μ_p (λ_a^α_p − 1) + λ ln J along the
//! eigenvectors n_a of b = F Fᵀ, and σ = τ / J. One term with α = 2 is the
//! neo-Hookean model of `neo_hookean.rs` (τ = μ (b − I) + λ ln J I).

use super::hencky::Spectral;
use super::parameters::{FromParameters, KeyError, Parameters};
use super::spectral::from_principal;
use super::{Increment, Material};
use crate::dim::Mat3;
use nalgebra::Vector3;

#[derive(Clone, Debug, PartialEq)]
pub struct Ogden {
    pub density: f64,
    /// μ_p of each term.
    pub mu: Vec<f64>,
    /// α_p of each term.
    pub alpha: Vec<f64>,
    /// Small-strain Poisson's ratio ν (sets λ).
    pub poisson_ratio: f64,
}

impl Ogden {
    pub fn new(density: f64, mu: Vec<f64>, alpha: Vec<f64>, poisson_ratio: f64) -> Self {
        debug_assert!(mu.len() == alpha.len() && !mu.is_empty());
        debug_assert!(mu.iter().zip(&alpha).all(|(m, a)| m * a > 0.0));
        Self {
            density,
            mu,
            alpha,
            poisson_ratio,
        }
    }

    /// (λ, μ): small-strain Lamé constants.
    pub fn lame(&self) -> (f64, f64) {
        let mu = 0.5
            * self
                .mu
                .iter()
                .zip(&self.alpha)
                .map(|(m, a)| m * a)
                .sum::<f64>();
        let nu = self.poisson_ratio;
        (2.0 * mu * nu / (1.0 - 2.0 * nu), mu)
    }

    /// Cauchy stress at total deformation gradient `f`.
    pub fn cauchy(&self, f: &Mat3) -> Mat3 {
        let (lambda, _) = self.lame();
        let j = f.determinant();
        let sp = Spectral::of(f);
        let ln_stretch = sp.principal_log_stretches();
        let tau: Vector3<f64> = ln_stretch.map(|l| {
            let deviatoric: f64 = self
                .mu
                .iter()
                .zip(&self.alpha)
                .map(|(m, a)| m * (a * l).exp_m1())
                .sum();
            deviatoric + lambda * j.ln()
        });
        from_principal(&sp.n, &tau) / j
    }
}

impl FromParameters for Ogden {
    const NAME: &'static str = "ogden";
    const KEYS: &'static [&'static str] = &["mu", "alpha", "poisson_ratio"];
    const EXAMPLE: &'static str = "mu = [1.0e5]\nalpha = [2.0]\npoisson_ratio = 0.3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let mu: Vec<f64> = p.required("mu")?;
        let alpha: Vec<f64> = p.required("alpha")?;
        p.ensure((1..=6).contains(&mu.len()), "mu", "needs 1 to 6 terms")?;
        p.ensure(
            alpha.len() == mu.len(),
            "alpha",
            format!("needs one entry per term of mu ({})", mu.len()),
        )?;
        p.ensure(
            mu.iter()
                .zip(&alpha)
                .all(|(m, a)| m * a > 0.0 && (m * a).is_finite()),
            "alpha",
            "every term needs mu_p * alpha_p > 0 (a positive shear modulus)",
        )?;
        Ok(Self::new(density, mu, alpha, p.poisson_ratio()?))
    }
}

impl Material for Ogden {
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

    /// W / J.
    fn strain_energy_density(&self, f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        let (lambda, _) = self.lame();
        let mu_sum: f64 = self.mu.iter().sum();
        let j = f.determinant();
        let ln_stretch = Spectral::of(f).principal_log_stretches();
        let w: f64 = self
            .mu
            .iter()
            .zip(&self.alpha)
            .map(|(m, a)| m / a * (ln_stretch.map(|l| (a * l).exp()).sum() - 3.0))
            .sum();
        (w - mu_sum * j.ln() + 0.5 * lambda * j.ln().powi(2)) / j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::neo_hookean::NeoHookean;
    use crate::material::testing::general_f;

    /// One term with α = 2 and μ_1 = μ is neo-Hookean, at finite strain.
    #[test]
    fn one_term_with_alpha_two_is_neo_hookean() {
        let (e, nu) = (3.0e6, 0.35);
        let mu = e / (2.0 * (1.0 + nu));
        let ogden = Ogden::new(1000.0, vec![mu], vec![2.0], nu);
        let neo = NeoHookean::new(1000.0, e, nu);
        for f in [
            general_f(),
            driver::rotation_z(0.7) * general_f(),
            Mat3::identity(),
        ] {
            let (a, b) = (ogden.cauchy(&f), neo.cauchy(&f));
            assert!((a - b).norm() <= 1e-9 * b.norm().max(1.0), "{a} vs {b}");
            let (wa, wb) = (
                ogden.strain_energy_density(&f, &a, &[]),
                neo.strain_energy_density(&f, &b, &[]),
            );
            assert!((wa - wb).abs() <= 1e-9 * wb.abs().max(1.0), "{wa} vs {wb}");
        }
        assert!(ogden
            .stress_derivative(&Increment::at_rest(general_f(), &[]))
            .is_none());
    }

    /// The stress is the derivative of the stored energy: for dF, J σ : (dF F⁻¹) =
    /// dW (central differences, three terms), and σ(I) = 0.
    #[test]
    fn stress_is_the_derivative_of_the_energy() {
        let m = Ogden::new(
            1000.0,
            vec![6.3e5, 1.2e3, -1.0e4],
            vec![1.3, 5.0, -2.0],
            0.3,
        );
        assert!(m.cauchy(&Mat3::identity()).norm() < 1e-9);
        let f = general_f();
        let sigma = m.cauchy(&f);
        let w = |f: &Mat3| m.strain_energy_density(f, &sigma, &[]) * f.determinant();
        let h = 1e-6;
        for k in 0..3 {
            for l in 0..3 {
                let mut df = Mat3::zeros();
                df[(k, l)] = 1.0;
                let dw = (w(&(f + df * h)) - w(&(f - df * h))) / (2.0 * h);
                let power =
                    f.determinant() * (sigma.component_mul(&(df * f.try_inverse().unwrap()))).sum();
                assert!(
                    (dw - power).abs() < 1e-6 * sigma.norm(),
                    "({k},{l}): dW = {dw}, J σ : dF F⁻¹ = {power}"
                );
            }
        }
    }
}
