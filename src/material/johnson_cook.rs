//! Johnson–Cook viscoplasticity with an equation of state, adiabatic heating and
//! Johnson–Cook damage (metals under impact: the Taylor bar of review `002_…`).
//!
//! Stress split (thesis `000_…` Ch. 3): σ = s − p I, the pressure p from the EOS
//! (`eos.rs`) at μ = 1/J − 1 and the internal energy E per unit reference volume,
//! the deviator s from J2 plasticity on the isochoric Hencky kinematics: the
//! elastic deviatoric state is recovered from the stored stress,
//! ε̄_e,old = dev τ_old/(2G) with τ = J σ, b̄_e,old = exp(2 ε̄_e,old), the trial
//! b̄^tr = ΔF̄ b̄_e,old ΔF̄ᵀ with ΔF̄ = ΔJ^{−1/3} ΔF, ē_a = ½ ln β̄_a (made
//! traceless), s^tr_a = 2G ē_a (Kirchhoff), and a radial return in q = √(3/2)|s|:
//!
//!   σ_y = (A + B ε̄pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ)            (Johnson & Cook 1983)
//!   q^tr − 3G Δε̄p − σ_y(ε̄p,old + Δε̄p) = 0,  s = s^tr (1 − 3G Δε̄p / q^tr)
//!
//! ε̇* = ε̇/ε̇₀ with ε̇ = √(⅔ ė:ė) the equivalent deviatoric strain rate of the
//! increment (sym(ΔF − I)/Δt); the rate factor is 1 for ε̇* ≤ 1 (no softening
//! below the reference rate, LS-DYNA's and OpenRadioss' choice), and 1 for
//! quasi-static calls (Δt = 0). T* = (T − T_r)/(T_m − T_r), with T from the
//! plastic work (adiabatic, Taylor–Quinney χ): ΔT = χ σ_y Δε̄p/(ρ₀ c_p), the
//! temperature of the step start used in σ_y (explicit in T).
//!
//! Damage (Johnson & Cook 1985): D += Δε̄p/ε_f,
//! ε_f = [D1 + D2 exp(D3 σ*)][1 + D4 ln ε̇*][1 + D5 T*], σ* = −p/q the triaxiality
//! at the step start. At D = 1 the particle has failed: it carries no shear
//! (s = 0) and no tension (p ≥ 0), and no pressure at all while opened (J > 1:
//! rubble whose Grüneisen term would otherwise push it apart).
//!
//! Energy: E (per reference volume) follows dE = τ_dev : dε − p dJ by the
//! trapezoidal rule, with p_new from the EOS at E_new (closed form,
//! `eos::energy_update`), so an EOS with Γ ≠ 0 heats under compression; the
//! plastic work is part of E. Where the pressure is cut off, E takes the work of
//! the pressure carried (`eos::energy_and_pressure`). The model has no analytic tangent (implicit runs
//! use the matrix-free path).
//!
//! History: ε̄p, E, then T − T_r if the model is thermal, then D if it has damage.

use super::eos::{self, energy_and_pressure, Eos};
use super::erosion::{failed_jacobian, Erosion};
use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material};
use super::deviatoric::{deviator, equivalent_rate, strain_increment, TrialDeviator};
use crate::dim::Mat3;
use nalgebra::Vector3;

/// Adiabatic heating and thermal softening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thermal {
    pub room_temperature: f64,
    pub melting_temperature: f64,
    /// m in (1 − T*ᵐ).
    pub exponent: f64,
    /// c_p per unit mass.
    pub specific_heat: f64,
    /// χ, the fraction of plastic work turned into heat.
    pub taylor_quinney: f64,
}

impl Thermal {
    /// T* = (T − T_r)/(T_m − T_r) from the rise T − T_r.
    fn homologous(&self, rise: f64) -> f64 {
        rise / (self.melting_temperature - self.room_temperature)
    }

    /// 1 − T*ᵐ, 0 at and above melting, 1 below room temperature.
    fn softening(&self, rise: f64) -> f64 {
        let t = self.homologous(rise);
        if t <= 0.0 {
            1.0
        } else if t >= 1.0 {
            0.0
        } else {
            1.0 - t.powf(self.exponent)
        }
    }
}

#[derive(Clone, Debug)]
pub struct JohnsonCook {
    pub density: f64,
    pub shear_modulus: f64,
    pub eos: Eos,
    /// A, B, n.
    pub yield_stress: f64,
    pub hardening_modulus: f64,
    pub hardening_exponent: f64,
    /// C and ε̇₀.
    pub rate_coefficient: f64,
    pub reference_strain_rate: f64,
    pub thermal: Option<Thermal>,
    /// D1 … D5.
    pub damage: Option<[f64; 5]>,
    /// When points leave the transfers (`erosion.rs`).
    pub erosion: Option<Erosion>,
}

/// History slots.
const PLASTIC_STRAIN: usize = 0;
const ENERGY: usize = 1;

impl JohnsonCook {
    fn temperature_slot(&self) -> Option<usize> {
        self.thermal.map(|_| 2)
    }

    fn damage_slot(&self) -> Option<usize> {
        self.damage.map(|_| 2 + usize::from(self.thermal.is_some()))
    }

    /// Static strength A + B ε̄pⁿ and its slope.
    fn hardening(&self, eps_p: f64) -> (f64, f64) {
        let (b, n) = (self.hardening_modulus, self.hardening_exponent);
        if b == 0.0 || eps_p <= 0.0 {
            let slope = if b == 0.0 || n > 1.0 {
                0.0
            } else if n == 1.0 {
                b
            } else {
                f64::INFINITY
            };
            return (self.yield_stress, slope);
        }
        let power = eps_p.powf(n);
        (self.yield_stress + b * power, b * n * power / eps_p)
    }

    /// 1 + C ln ε̇* for ε̇* > 1, else 1.
    fn rate_factor(&self, rate: f64) -> f64 {
        let r = rate / self.reference_strain_rate;
        if r > 1.0 {
            1.0 + self.rate_coefficient * r.ln()
        } else {
            1.0
        }
    }

    /// Δε̄p of the radial return from q^tr, with σ_y = k (A + B ε̄pⁿ): the root of
    /// g(Δ) = q^tr − 3GΔ − k h(ε̄p,old + Δ) in [0, (q^tr − k h_old)/3G], by Newton's
    /// method kept inside the bracket (bisection where a step leaves it).
    fn plastic_increment(&self, q_trial: f64, eps_p_old: f64, k: f64) -> f64 {
        let g3 = 3.0 * self.shear_modulus;
        let g = |d: f64| {
            let (h, slope) = self.hardening(eps_p_old + d);
            (q_trial - g3 * d - k * h, -g3 - k * slope)
        };
        let (mut lo, mut hi) = (0.0, (q_trial - k * self.hardening(eps_p_old).0) / g3);
        let mut d = hi;
        for _ in 0..100 {
            let (r, dr) = g(d);
            if r.abs() <= 1e-14 * q_trial {
                return d;
            }
            if r > 0.0 {
                lo = d;
            } else {
                hi = d;
            }
            let newton = d - r / dr;
            d = if newton > lo && newton < hi && dr.is_finite() {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 1e-15 * hi.max(f64::MIN_POSITIVE) {
                return d;
            }
        }
        d
    }

    /// Fracture strain ε_f at triaxiality σ*, rate ε̇ and temperature rise.
    fn fracture_strain(&self, d: &[f64; 5], triaxiality: f64, rate: f64, rise: f64) -> f64 {
        let r = (rate / self.reference_strain_rate).max(1.0);
        let t = self.thermal.map_or(0.0, |th| th.homologous(rise).max(0.0));
        (d[0] + d[1] * (d[2] * triaxiality).exp()) * (1.0 + d[3] * r.ln()) * (1.0 + d[4] * t)
    }
}

impl Material for JohnsonCook {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn n_history(&self) -> usize {
        2 + usize::from(self.thermal.is_some()) + usize::from(self.damage.is_some())
    }

    fn update(&self, inc: &Increment, h_new: &mut [f64]) -> Mat3 {
        let h_old = inc.history_old;
        let g = self.shear_modulus;
        let j_old = inc.f_old.determinant();
        let j = inc.df.determinant() * j_old;
        let rise_old = self.temperature_slot().map_or(0.0, |i| h_old[i]);
        let damage_old = self.damage_slot().map_or(0.0, |i| h_old[i]);
        let eps_p_old = h_old[PLASTIC_STRAIN];

        let strain_increment = strain_increment(&inc.df);
        let rate = equivalent_rate(&strain_increment, inc.dt);

        // Trial deviator and radial return.
        let tau_dev_old = deviator(&inc.stress_old) * j_old;
        let trial = TrialDeviator::of(&tau_dev_old, g, &inc.df);
        let s_trial = trial.strain * (2.0 * g);
        let q_trial = (1.5 * s_trial.norm_squared()).sqrt();
        let k = self.rate_factor(rate) * self.thermal.map_or(1.0, |t| t.softening(rise_old));
        let failed = damage_old >= 1.0;
        let (s, d_eps_p) = if failed {
            (Vector3::zeros(), 0.0)
        } else if q_trial > k * self.hardening(eps_p_old).0 {
            let d = self.plastic_increment(q_trial, eps_p_old, k);
            (s_trial * (1.0 - 3.0 * g * d / q_trial), d)
        } else {
            (s_trial, 0.0)
        };
        let tau_dev = trial.tensor(&s);
        let eps_p = eps_p_old + d_eps_p;
        h_new[PLASTIC_STRAIN] = eps_p;

        // Adiabatic heating by the plastic work σ_y Δε̄p.
        let q = (1.5 * s.norm_squared()).sqrt();
        if let (Some(i), Some(t)) = (self.temperature_slot(), self.thermal) {
            h_new[i] = rise_old + t.taylor_quinney * q * d_eps_p / (self.density * t.specific_heat);
        }

        // Damage at the step start's triaxiality.
        let p_old = -inc.stress_old.trace() / 3.0;
        let mut damage = damage_old;
        if let (Some(i), Some(d)) = (self.damage_slot(), &self.damage) {
            if d_eps_p > 0.0 {
                let q_old = (1.5 * tau_dev_old.norm_squared()).sqrt() / j_old;
                let triaxiality = if q_old > 0.0 { -p_old / q_old } else { 0.0 };
                let eps_f = self.fracture_strain(d, triaxiality, rate, rise_old);
                damage = (damage_old + d_eps_p / eps_f.max(f64::MIN_POSITIVE)).min(1.0);
            }
            h_new[i] = damage;
        }

        // Energy and pressure (trapezoidal, p_new from the EOS at E_new).
        let dw_dev = 0.5 * (tau_dev_old + tau_dev).component_mul(&strain_increment).sum();
        let affine = self.eos.affine(1.0 / j - 1.0);
        // Failed: no shear, no tension, and no pressure while opened (J > 1).
        let bounds = match (damage >= 1.0, j > 1.0) {
            (false, _) => (f64::NEG_INFINITY, f64::INFINITY),
            (true, false) => (0.0, f64::INFINITY),
            (true, true) => (0.0, 0.0),
        };
        let (energy, p) = energy_and_pressure(h_old[ENERGY], dw_dev, p_old, j - j_old, affine, bounds);
        h_new[ENERGY] = energy;
        if damage >= 1.0 {
            return -Mat3::identity() * p;
        }
        tau_dev / j - Mat3::identity() * p
    }

    fn p_wave_modulus(&self) -> f64 {
        self.eos.tangent(0.0) + 4.0 / 3.0 * self.shear_modulus
    }

    /// c² = (∂p/∂μ + 4GJ/3)/ρ₀ at μ = 1/J − 1: the EOS stiffens under compression;
    /// J ≤ 1 for a failed point (`failed_jacobian`).
    fn wave_speed(&self, j: f64, history: &[f64]) -> f64 {
        let bulk = self.eos.tangent(1.0 / j - 1.0).max(0.0);
        let damage = self.damage_slot().map_or(0.0, |i| history[i]);
        let j = failed_jacobian(j, damage);
        ((bulk + 4.0 / 3.0 * self.shear_modulus * j) / self.density).sqrt()
    }

    /// The internal energy (elastic, plastic and thermal) per unit current volume.
    fn strain_energy_density(&self, f: &Mat3, _stress: &Mat3, history: &[f64]) -> f64 {
        history[ENERGY] / f.determinant()
    }

    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    fn erodes(&self) -> bool {
        self.erosion.is_some()
    }

    fn eroded(&self, history: &[f64]) -> bool {
        let damage = self.damage_slot().map_or(0.0, |i| history[i]);
        self.erosion
            .is_some_and(|e| e.applies(damage, history[PLASTIC_STRAIN]))
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        Some(history[PLASTIC_STRAIN])
    }
}

/// Keys of the thermal part (all or none of the three without defaults).
const THERMAL_KEYS: [&str; 3] = ["melting_temperature", "thermal_exponent", "specific_heat"];
const DAMAGE_KEYS: [&str; 5] = ["damage_d1", "damage_d2", "damage_d3", "damage_d4", "damage_d5"];

impl FromParameters for JohnsonCook {
    const NAME: &'static str = "johnson_cook";
    const KEYS: &'static [&'static str] = &[
        "youngs_modulus",
        "poisson_ratio",
        "yield_stress",
        "hardening_modulus",
        "hardening_exponent",
        "rate_coefficient",
        "reference_strain_rate",
        "room_temperature",
        "melting_temperature",
        "thermal_exponent",
        "specific_heat",
        "taylor_quinney",
        "damage_d1",
        "damage_d2",
        "damage_d3",
        "damage_d4",
        "damage_d5",
        "erosion",
        "erosion_plastic_strain",
        "eos",
        "k1",
        "k2",
        "k3",
        "sound_speed",
        "hugoniot_slope",
        "gruneisen_gamma",
        "volume_correction",
    ];
    const EXAMPLE: &'static str = "youngs_modulus = 117.0e9\npoisson_ratio = 0.35\nyield_stress = 90.0e6\nhardening_modulus = 292.0e6\nhardening_exponent = 0.31\nrate_coefficient = 0.025\nreference_strain_rate = 1.0\nroom_temperature = 293.0\nmelting_temperature = 1356.0\nthermal_exponent = 1.09\nspecific_heat = 383.0\ndamage_d1 = 0.54\ndamage_d2 = 4.89\ndamage_d3 = -3.03\neos = \"mie_gruneisen\"\nsound_speed = 3940.0\nhugoniot_slope = 1.49\ngruneisen_gamma = 1.96";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        debug_assert!(eos::KEYS.iter().all(|k| Self::KEYS.contains(k)));
        let e = p.youngs_modulus()?;
        let nu = p.poisson_ratio()?;
        let (lambda, g) = super::lame(e, nu);
        let eos = Eos::from_parameters(density, lambda + 2.0 * g / 3.0, p)?;
        let non_negative = |k: &str, default: Option<f64>| -> Result<f64, KeyError> {
            let v: f64 = match default {
                Some(d) => p.get(k)?.unwrap_or(d),
                None => p.required(k)?,
            };
            p.ensure(v >= 0.0 && v.is_finite(), k, format!("must be a number ≥ 0; got {v}"))?;
            Ok(v)
        };
        let yield_stress = non_negative("yield_stress", None)?;
        p.ensure(yield_stress > 0.0, "yield_stress", "must be positive (A > 0)")?;
        let hardening_modulus = non_negative("hardening_modulus", Some(0.0))?;
        let hardening_exponent = non_negative("hardening_exponent", Some(1.0))?;
        p.ensure(hardening_exponent > 0.0, "hardening_exponent", "must be positive (n > 0)")?;
        let rate_coefficient = non_negative("rate_coefficient", Some(0.0))?;
        let reference_strain_rate = non_negative("reference_strain_rate", Some(1.0))?;
        p.ensure(
            reference_strain_rate > 0.0,
            "reference_strain_rate",
            "must be positive (ε̇₀ > 0, per second)",
        )?;
        let thermal = if THERMAL_KEYS.iter().any(|k| p.given(k)) {
            let what = "thermal softening (melting_temperature, thermal_exponent, specific_heat)";
            let room: f64 = p.get("room_temperature")?.unwrap_or(293.15);
            let melt: f64 = p.required_for("melting_temperature", what)?;
            p.ensure(
                melt > room,
                "melting_temperature",
                format!("must exceed room_temperature = {room}; got {melt}"),
            )?;
            let exponent: f64 = p.required_for("thermal_exponent", what)?;
            p.ensure(exponent > 0.0, "thermal_exponent", "must be positive (m > 0)")?;
            let specific_heat: f64 = p.required_for("specific_heat", what)?;
            p.ensure(specific_heat > 0.0, "specific_heat", "must be positive")?;
            let chi = non_negative("taylor_quinney", Some(0.9))?;
            p.ensure(chi <= 1.0, "taylor_quinney", "must lie in [0, 1]")?;
            Some(Thermal {
                room_temperature: room,
                melting_temperature: melt,
                exponent,
                specific_heat,
                taylor_quinney: chi,
            })
        } else {
            for k in ["room_temperature", "taylor_quinney"] {
                p.ensure(
                    !p.given(k),
                    k,
                    "applies only with melting_temperature, thermal_exponent and specific_heat",
                )?;
            }
            None
        };
        let damage = if DAMAGE_KEYS.iter().any(|k| p.given(k)) {
            let what = "Johnson–Cook damage (damage_d1, damage_d2, damage_d3)";
            let mut d = [0.0f64; 5];
            for (i, k) in DAMAGE_KEYS.iter().enumerate() {
                d[i] = if i < 3 {
                    p.required_for(k, what)?
                } else {
                    p.get(k)?.unwrap_or(0.0)
                };
                p.ensure(d[i].is_finite(), k, "must be a number")?;
            }
            p.ensure(
                d[0] + d[1] > 0.0 || d[0] > 0.0,
                "damage_d1",
                "damage_d1 + damage_d2 must be positive (the fracture strain at zero triaxiality)",
            )?;
            Some(d)
        } else {
            None
        };
        let erosion = Erosion::from_parameters(p)?;
        p.ensure(
            !erosion.is_some_and(|e| e.at_failure) || damage.is_some(),
            "erosion",
            "needs Johnson–Cook damage (damage_d1, damage_d2, damage_d3): nothing fails without it",
        )?;
        Ok(JohnsonCook {
            erosion,
            density,
            shear_modulus: g,
            eos,
            yield_stress,
            hardening_modulus,
            hardening_exponent,
            rate_coefficient,
            reference_strain_rate,
            thermal,
            damage,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver::{self, hydrostatic, uniaxial_strain};

    /// Copper-like constants in SI units, linear EOS.
    fn copper(b: f64, n: f64) -> JohnsonCook {
        let (lambda, g) = super::super::lame(117e9, 0.35);
        JohnsonCook {
            density: 8930.0,
            shear_modulus: g,
            eos: Eos::Polynomial {
                k1: lambda + 2.0 * g / 3.0,
                k2: 0.0,
                k3: 0.0,
            },
            yield_stress: 90e6,
            hardening_modulus: b,
            hardening_exponent: n,
            rate_coefficient: 0.0,
            reference_strain_rate: 1.0,
            thermal: None,
            damage: None,
            erosion: None,
        }
    }

    /// q = √(3/2)|dev σ| (Cauchy) times J: the Kirchhoff equivalent stress.
    fn kirchhoff_q(stress: &Mat3, f: &Mat3) -> f64 {
        (1.5 * deviator(stress).norm_squared()).sqrt() * f.determinant()
    }

    #[test]
    fn uniaxial_strain_follows_the_hardening_curve() {
        let m = copper(292e6, 0.31);
        let path = uniaxial_strain(0, -0.3, 300);
        let r = driver::run(&m, &path, 0.0);
        let mut plastic = 0;
        for k in 1..path.len() {
            let eps_p = r.history[k][PLASTIC_STRAIN];
            if eps_p > 0.0 {
                plastic += 1;
                let q = kirchhoff_q(&r.stress[k], &r.f[k]);
                let expected = 90e6 + 292e6 * eps_p.powf(0.31);
                assert!((q / expected - 1.0).abs() < 1e-9, "step {k}: q {q} vs {expected}");
            }
        }
        assert!(plastic > 250, "only {plastic} plastic steps");
        // ε̄p of uniaxial strain: total deviatoric log strain minus the elastic part.
        let eps = (0.7f64).ln().abs();
        let last = r.history.last().unwrap()[PLASTIC_STRAIN];
        let q = kirchhoff_q(r.stress.last().unwrap(), r.f.last().unwrap());
        let expected = 2.0 / 3.0 * eps - q / (3.0 * m.shear_modulus);
        assert!((last / expected - 1.0).abs() < 1e-9, "{last} vs {expected}");
    }

    #[test]
    fn strain_rate_raises_the_yield_stress_by_one_plus_c_ln_rate() {
        let mut m = copper(0.0, 1.0);
        m.rate_coefficient = 0.025;
        let steps = 200;
        let strain = 0.1;
        let total_time = 1e-4;
        let path = uniaxial_strain(0, strain, steps);
        let r = driver::run(&m, &path, total_time / steps as f64);
        let last = path.len() - 1;
        // Equivalent deviatoric rate of uniaxial strain: (2/3)|Δε|/Δt, Δε = λ_k/λ_{k-1} − 1.
        let stretch = path[last][(0, 0)] / path[last - 1][(0, 0)] - 1.0;
        let rate = 2.0 / 3.0 * stretch / (total_time / steps as f64);
        let expected = 90e6 * (1.0 + 0.025 * rate.ln());
        let q = kirchhoff_q(&r.stress[last], &r.f[last]);
        assert!((q / expected - 1.0).abs() < 1e-9, "q {q} vs {expected} (rate {rate})");
        // Quasi-static calls (Δt = 0) and rates below ε̇₀ see A.
        let r0 = driver::run(&m, &path, 0.0);
        let q0 = kirchhoff_q(&r0.stress[last], &r0.f[last]);
        assert!((q0 / 90e6 - 1.0).abs() < 1e-9);
        let slow = driver::run(&m, &path, 1e3);
        let q_slow = kirchhoff_q(&slow.stress[last], &slow.f[last]);
        assert!((q_slow / 90e6 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn adiabatic_softening_follows_the_closed_form_of_the_heat_equation() {
        // B = 0, m = 1: dT/dε̄p = χ A (1 − T*)/(ρ c_p) gives
        // T* = 1 − exp(−χ A ε̄p / (ρ c_p (T_m − T_r))) and σ_y = A (1 − T*).
        let mut m = copper(0.0, 1.0);
        m.yield_stress = 400e6;
        let thermal = Thermal {
            room_temperature: 293.0,
            melting_temperature: 1356.0,
            exponent: 1.0,
            specific_heat: 383.0,
            taylor_quinney: 0.9,
        };
        m.thermal = Some(thermal);
        let path = uniaxial_strain(0, -0.5, 4000);
        let r = driver::run(&m, &path, 0.0);
        let h = r.history.last().unwrap();
        let eps_p = h[PLASTIC_STRAIN];
        let scale = 0.9 * 400e6 / (8930.0 * 383.0 * (1356.0 - 293.0));
        let t_star = 1.0 - (-scale * eps_p).exp();
        let t_seen = h[2] / (1356.0 - 293.0);
        assert!(eps_p > 0.4, "{eps_p}");
        assert!((t_seen / t_star - 1.0).abs() < 2e-3, "T* {t_seen} vs {t_star}");
        let q = kirchhoff_q(r.stress.last().unwrap(), r.f.last().unwrap());
        assert!((q / (400e6 * (1.0 - t_star)) - 1.0).abs() < 2e-3, "q {q}");
    }

    #[test]
    fn yield_stress_by_hand_at_given_strain_rate_and_temperature() {
        // OFHC copper (Johnson & Cook 1983 as quoted): A 90, B 292 MPa, n 0.31,
        // C 0.025, m 1.09, T_r 293 K, T_m 1356 K. At ε̄p = 0.5, ε̇ = 1e4 /s and
        // T = 500 K by hand: (90 + 292·0.5^0.31)(1 + 0.025 ln 1e4)(1 − 0.19473^1.09)
        // = 325.539 × 1.230259 × 0.831931 = 333.187 MPa.
        let mut m = copper(292e6, 0.31);
        m.rate_coefficient = 0.025;
        m.thermal = Some(Thermal {
            room_temperature: 293.0,
            melting_temperature: 1356.0,
            exponent: 1.09,
            specific_heat: 383.0,
            taylor_quinney: 0.9,
        });
        let static_part = 90e6 + 292e6 * 0.5f64.powf(0.31);
        let rate = m.rate_factor(1e4);
        let heat = m.thermal.unwrap().softening(500.0 - 293.0);
        assert!((static_part / 325.539e6 - 1.0).abs() < 2e-6, "{static_part}");
        assert!((rate - 1.230259).abs() < 1e-6, "{rate}");
        assert!((heat - 0.831931).abs() < 1e-6, "{heat}");
        assert!((static_part * rate * heat / 333.187e6 - 1.0).abs() < 2e-6);
        // The return reaches exactly that stress: a trial far outside it with
        // ε̄p,old = 0.5, at that rate and temperature, comes back to
        // k (A + B (0.5 + Δε̄p)ⁿ) with Δε̄p = (q^tr − σ_y)/3G.
        let k = rate * heat;
        let q_trial = 2.0 * static_part * k;
        let d = m.plastic_increment(q_trial, 0.5, k);
        let sigma_y = k * m.hardening(0.5 + d).0;
        assert!((q_trial - 3.0 * m.shear_modulus * d - sigma_y).abs() < 1e-6);
        assert!(sigma_y > 333.187e6 && sigma_y < 1.01 * 333.187e6, "{sigma_y}");
    }

    #[test]
    fn mie_gruneisen_energy_is_the_work_of_the_pressure() {
        let mut m = copper(0.0, 1.0);
        m.eos = Eos::MieGruneisen {
            rho0_c0_squared: 8930.0 * 3940.0 * 3940.0,
            slope: 1.49,
            gamma0: 1.96,
            a: 0.0,
        };
        // Hydrostatic compression: no deviator, dE = −p dJ.
        let steps = 2000;
        let path = hydrostatic(0.93, steps);
        let r = driver::run(&m, &path, 0.0);
        let mut work = 0.0;
        for k in 1..path.len() {
            let p = |i: usize| -r.stress[i].trace() / 3.0;
            let dj = path[k].determinant() - path[k - 1].determinant();
            work -= 0.5 * (p(k) + p(k - 1)) * dj;
        }
        let e = r.history.last().unwrap()[ENERGY];
        assert!((e / work - 1.0).abs() < 1e-12, "E {e} vs ∫p dV {work}");
        // The isentrope lies below the Hugoniot and above the cold curve (Γ > 0).
        let mu = 1.0 / path.last().unwrap().determinant() - 1.0;
        let p = -r.stress.last().unwrap().trace() / 3.0;
        let cold = m.eos.pressure(mu, 0.0);
        let hugoniot = m.eos.hugoniot_pressure(mu).unwrap();
        assert!(cold < p && p < hugoniot, "{cold} < {p} < {hugoniot}");
        assert!(deviator(r.stress.last().unwrap()).norm() < 1e-6 * p);
    }

    #[test]
    fn damage_fails_the_point_at_the_fracture_strain_and_removes_shear_and_tension() {
        let mut m = copper(0.0, 1.0);
        m.damage = Some([0.1, 0.0, 0.0, 0.0, 0.0]);
        // Simple shear to γ = 0.5: ε̄p passes ε_f = D1 = 0.1.
        let path = driver::simple_shear(0.5, 500);
        let r = driver::run(&m, &path, 0.0);
        let slot = m.damage_slot().unwrap();
        let fail = (0..path.len())
            .find(|&k| r.history[k][slot] >= 1.0)
            .expect("the point never failed");
        let eps_p_at_failure = r.history[fail][PLASTIC_STRAIN];
        let eps_p_before = r.history[fail - 1][PLASTIC_STRAIN];
        assert!(eps_p_before < 0.1 && eps_p_at_failure >= 0.1 - 1e-12);
        for k in fail..path.len() {
            assert!(deviator(&r.stress[k]).norm() == 0.0, "shear after failure at {k}");
        }
        // Then stretched hydrostatically: no tension.
        let stretched: Vec<Mat3> = hydrostatic(1.05, 20)
            .iter()
            .map(|s| s * path.last().unwrap())
            .collect();
        let r2 = driver::run_from(
            &m,
            &stretched,
            0.0,
            *r.stress.last().unwrap(),
            r.history.last().unwrap().clone(),
        );
        assert!(r2.stress.iter().all(|s| s.trace() <= 0.0 && deviator(s).norm() == 0.0));
    }

    #[test]
    fn stress_rotates_with_the_body() {
        let m = copper(292e6, 0.31);
        // Plastic uniaxial strain, then a rigid rotation of 90°.
        let path = uniaxial_strain(0, -0.05, 50);
        let r = driver::run(&m, &path, 0.0);
        let s0 = *r.stress.last().unwrap();
        let f0 = *path.last().unwrap();
        let turn: Vec<Mat3> = (0..=90)
            .map(|k| driver::rotation_z(k as f64 / 90.0 * std::f64::consts::FRAC_PI_2) * f0)
            .collect();
        let r2 = driver::run_from(&m, &turn, 0.0, s0, r.history.last().unwrap().clone());
        let q = driver::rotation_z(std::f64::consts::FRAC_PI_2);
        let expected = q * s0 * q.transpose();
        let err = (r2.stress.last().unwrap() - expected).norm() / s0.norm();
        assert!(err < 1e-9, "rotated stress off by {err}");
        let (after, before) = (
            r2.history.last().unwrap()[PLASTIC_STRAIN],
            r.history.last().unwrap()[PLASTIC_STRAIN],
        );
        assert!((after / before - 1.0).abs() < 1e-12, "ε̄p {before} → {after}");
    }
}
