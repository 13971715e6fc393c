//! Equations of state: the pressure of the high-rate models (Johnson–Cook today),
//! which split the Cauchy stress into a deviatoric part from a strength model and
//! a pressure from an EOS, σ = s − p I (thesis `000_…` Ch. 3, the split JH-2 and
//! HJC use; LS-DYNA's *EOS cards).
//!
//! Compression is positive: μ = ρ/ρ₀ − 1 = 1/J − 1, p = −tr σ / 3. Every EOS here
//! is affine in the internal energy E per unit reference volume,
//! p(μ, E) = a(μ) + b(μ) E, so a model can update E and p together in closed
//! form (`Eos::affine`).
//!
//! - `linear`: p = K μ, K the bulk modulus of the elastic constants (the linear EOS
//!   of the thesis' HJC element tests, p = 16e3 μ MPa).
//! - `polynomial`: p = K1 μ + K2 μ² + K3 μ³ in compression, K1 μ in tension (the
//!   JH-2 and HJC form, thesis 3-66).
//! - `mie_gruneisen`: the shock Hugoniot u_s = c₀ + S u_p with the Grüneisen
//!   parameter Γ₀ (first-order volume correction a), as LS-DYNA's *EOS_GRUNEISEN:
//!   in compression p = ρ₀c₀²μ[1 + (1 − Γ₀/2)μ − (a/2)μ²]/[1 − (S − 1)μ]² + (Γ₀ + aμ)E,
//!   in tension p = ρ₀c₀²μ + (Γ₀ + aμ)E. With E on the Hugoniot,
//!   E_H = ½ p_H μ/(1 + μ), it gives the Hugoniot pressure
//!   p_H = ρ₀c₀²μ(1 + μ)/[1 − (S − 1)μ]² (for a = 0; Meyers, Dynamic Behavior of
//!   Materials, §5.3).

use super::parameters::{KeyError, Parameters};

/// The keys of every equation of state (a model that takes an EOS takes these).
pub const KEYS: &[&str] = &[
    "eos",
    "k1",
    "k2",
    "k3",
    "sound_speed",
    "hugoniot_slope",
    "gruneisen_gamma",
    "volume_correction",
];

/// An equation of state p(μ, E).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Eos {
    /// p = K1 μ + K2 μ² + K3 μ³ (μ ≥ 0), K1 μ (μ < 0); `linear` is K2 = K3 = 0.
    Polynomial { k1: f64, k2: f64, k3: f64 },
    /// Shock Hugoniot u_s = c₀ + S u_p with Grüneisen Γ₀ and volume correction a.
    MieGruneisen {
        rho0_c0_squared: f64,
        slope: f64,
        gamma0: f64,
        a: f64,
    },
}

impl Eos {
    /// The EOS of a material table: `eos = "linear"` (K from the elastic constants,
    /// `bulk_modulus`), `"polynomial"` (k1, k2, k3) or `"mie_gruneisen"`
    /// (sound_speed, hugoniot_slope, gruneisen_gamma, volume_correction).
    pub fn from_parameters(
        density: f64,
        bulk_modulus: f64,
        p: &Parameters,
    ) -> Result<Eos, KeyError> {
        let kind: String = p.get("eos")?.unwrap_or_else(|| "linear".into());
        let only_for = |keys: &[&str], kind: &str| -> Result<(), KeyError> {
            match KEYS[1..].iter().find(|k| p.given(k) && !keys.contains(k)) {
                Some(k) => Err((p.key(k), format!("does not apply to eos = \"{kind}\""))),
                None => Ok(()),
            }
        };
        match kind.as_str() {
            "linear" => {
                only_for(&[], "linear")?;
                Ok(Eos::Polynomial {
                    k1: bulk_modulus,
                    k2: 0.0,
                    k3: 0.0,
                })
            }
            "polynomial" => {
                only_for(&["k1", "k2", "k3"], "polynomial")?;
                let what = "eos = \"polynomial\"";
                let k1: f64 = p.required_for("k1", what)?;
                p.ensure(k1 > 0.0 && k1.is_finite(), "k1", "must be a positive number")?;
                let k2: f64 = p.get("k2")?.unwrap_or(0.0);
                let k3: f64 = p.get("k3")?.unwrap_or(0.0);
                let eos = Eos::Polynomial { k1, k2, k3 };
                // The compression branch must stiffen or soften without turning back
                // over the range a run reaches (μ ≤ 1).
                let monotone = (0..=100).all(|i| eos.tangent(i as f64 / 100.0) > 0.0);
                p.ensure(
                    monotone,
                    "k2",
                    "with these k1, k2, k3 the pressure falls with compression for some μ in [0, 1]",
                )?;
                Ok(eos)
            }
            "mie_gruneisen" => {
                only_for(
                    &["sound_speed", "hugoniot_slope", "gruneisen_gamma", "volume_correction"],
                    "mie_gruneisen",
                )?;
                let what = "eos = \"mie_gruneisen\"";
                let c0: f64 = p.required_for("sound_speed", what)?;
                p.ensure(c0 > 0.0 && c0.is_finite(), "sound_speed", "must be a positive number")?;
                let slope: f64 = p.required_for("hugoniot_slope", what)?;
                p.ensure(
                    (0.0..10.0).contains(&slope),
                    "hugoniot_slope",
                    format!("must lie in [0, 10) (u_s = c0 + S u_p); got {slope}"),
                )?;
                let gamma0: f64 = p.required_for("gruneisen_gamma", what)?;
                p.ensure(
                    (0.0..10.0).contains(&gamma0),
                    "gruneisen_gamma",
                    format!("must lie in [0, 10); got {gamma0}"),
                )?;
                let a: f64 = p.get("volume_correction")?.unwrap_or(0.0);
                p.ensure(a.is_finite(), "volume_correction", "must be a number")?;
                Ok(Eos::MieGruneisen {
                    rho0_c0_squared: density * c0 * c0,
                    slope,
                    gamma0,
                    a,
                })
            }
            other => Err((
                p.key("eos"),
                format!(
                    "unknown equation of state `{other}`; the choices are linear, polynomial, mie_gruneisen"
                ),
            )),
        }
    }

    /// (a, b) with p(μ, E) = a + b E.
    pub fn affine(&self, mu: f64) -> (f64, f64) {
        match *self {
            Eos::Polynomial { k1, k2, k3 } => {
                let p = if mu > 0.0 {
                    mu * (k1 + mu * (k2 + mu * k3))
                } else {
                    k1 * mu
                };
                (p, 0.0)
            }
            Eos::MieGruneisen {
                rho0_c0_squared,
                slope,
                gamma0,
                a,
            } => {
                let b = gamma0 + a * mu;
                if mu > 0.0 {
                    let den = 1.0 - (slope - 1.0) * mu;
                    let num = 1.0 + (1.0 - 0.5 * gamma0) * mu - 0.5 * a * mu * mu;
                    (rho0_c0_squared * mu * num / (den * den), b)
                } else {
                    (rho0_c0_squared * mu, b)
                }
            }
        }
    }

    /// p(μ, E).
    pub fn pressure(&self, mu: f64, energy: f64) -> f64 {
        let (a, b) = self.affine(mu);
        a + b * energy
    }

    /// ∂p/∂μ at E = 0 (the bulk stiffness that sets the wave speed), by a central
    /// difference of the closed forms.
    pub fn tangent(&self, mu: f64) -> f64 {
        let h = 1e-7 * (1.0 + mu.abs());
        (self.affine(mu + h).0 - self.affine(mu - h).0) / (2.0 * h)
    }

    /// Whether the pressure depends on the internal energy.
    pub fn needs_energy(&self) -> bool {
        matches!(self, Eos::MieGruneisen { gamma0, a, .. } if *gamma0 != 0.0 || *a != 0.0)
    }

    /// The Hugoniot u_s = c₀ + S u_p as a pressure: p_H = ρ₀c₀²μ(1 + μ)/[1 − (S − 1)μ]²
    /// (Mie–Grüneisen only).
    pub fn hugoniot_pressure(&self, mu: f64) -> Option<f64> {
        match *self {
            Eos::MieGruneisen {
                rho0_c0_squared,
                slope,
                ..
            } => {
                let den = 1.0 - (slope - 1.0) * mu;
                Some(rho0_c0_squared * mu * (1.0 + mu) / (den * den))
            }
            Eos::Polynomial { .. } => None,
        }
    }
}

/// E_new of the energy equation dE = dW_dev − p dJ (per reference volume) with
/// the trapezoidal rule and p_new = a + b E_new, solved in closed form:
/// E_new = (E_old + ΔW_dev − ½(p_old + a) ΔJ) / (1 + ½ b ΔJ) (Wilkins' scheme).
pub fn energy_update(e_old: f64, dw_dev: f64, p_old: f64, dj: f64, (a, b): (f64, f64)) -> f64 {
    (e_old + dw_dev - 0.5 * (p_old + a) * dj) / (1.0 + 0.5 * b * dj)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// OFHC copper (MPM3D-F90's Taylor input): ρ₀ 8930 kg/m³, c₀ 3940 m/s, S 1.49, Γ₀ 1.96.
    fn copper() -> Eos {
        Eos::MieGruneisen {
            rho0_c0_squared: 8930.0 * 3940.0 * 3940.0,
            slope: 1.49,
            gamma0: 1.96,
            a: 0.0,
        }
    }

    #[test]
    fn mie_gruneisen_gives_the_hugoniot_pressure_on_the_hugoniot() {
        let eos = copper();
        for mu in [1e-4, 0.01, 0.05, 0.1, 0.2, 0.3] {
            let p_h = eos.hugoniot_pressure(mu).unwrap();
            let e_h = 0.5 * p_h * mu / (1.0 + mu);
            let p = eos.pressure(mu, e_h);
            assert!((p - p_h).abs() <= 1e-12 * p_h, "μ {mu}: p {p} vs p_H {p_h}");
        }
    }

    #[test]
    fn mie_gruneisen_hugoniot_matches_shock_and_particle_velocities() {
        // Rankine–Hugoniot: p = ρ₀ u_s u_p, μ = u_p/(u_s − u_p), u_s = c₀ + S u_p.
        let eos = copper();
        for up in [10.0, 100.0, 500.0, 1000.0] {
            let us = 3940.0 + 1.49 * up;
            let mu = up / (us - up);
            let p = eos.hugoniot_pressure(mu).unwrap();
            let expected = 8930.0 * us * up;
            assert!(
                (p / expected - 1.0).abs() < 1e-12,
                "u_p {up}: {p} vs {expected}"
            );
        }
    }

    #[test]
    fn small_compression_has_the_bulk_sound_speed() {
        let eos = copper();
        let k = eos.tangent(0.0);
        assert!((k / (8930.0 * 3940.0 * 3940.0) - 1.0).abs() < 1e-6, "{k}");
        let poly = Eos::Polynomial {
            k1: 201e9,
            k2: 260e9,
            k3: 0.0,
        };
        assert!((poly.tangent(0.1) - (201e9 + 2.0 * 260e9 * 0.1)).abs() < 1e-3 * 201e9);
        assert_eq!(poly.pressure(-0.01, 5.0), -201e9 * 0.01);
    }

    #[test]
    fn the_energy_update_is_the_trapezoidal_rule_at_the_new_pressure() {
        let eos = copper();
        let (e_old, dw, p_old, dj) = (1.0e6, 2.0e4, 3.0e8, -0.01);
        let mu_new = 0.05;
        let ab = eos.affine(mu_new);
        let e_new = energy_update(e_old, dw, p_old, dj, ab);
        let p_new = eos.pressure(mu_new, e_new);
        let expected = e_old + dw - 0.5 * (p_old + p_new) * dj;
        assert!((e_new - expected).abs() < 1e-9 * e_new.abs());
    }
}
