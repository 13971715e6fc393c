//! RHT, the Riedel–Hiermaier–Thoma concrete model, with the P-α equation of
//! state (thesis `000_…` §4.2, eqs. 4-17…4-49; digest A3–A4).
//!
//! Three surfaces in the meridian of the equivalent stress σ̄ (Cauchy) against the
//! pressure p (compression positive), all with the Lode-angle factor R3(θ):
//! - failure (4-17): σ_fail = f_c σ*_TXC(p_s) R3(θ) F_rate, p_s = p/F_rate (4-22);
//!   the compressive meridian σ*_TXC passes through the quasi-static tension,
//!   shear and compression points (4-23…4-26) and is A (p_s* − HTL*)ᴺ above f_c/3,
//!   HTL* = 1/3 − A^{−1/N} for continuity there (4-30, lost in the OCR,
//!   reconstructed);
//! - elastic limit (4-31): f_c σ*_TXC(p_s/F_el) R3 F_rate F_el F_cap, with F_el
//!   between R_t and R_c (4-32) and the cap F_cap = √(1 − ((p − p_u)/(p_0 − p_u))²)
//!   between p_u = f_c R_c/3 and the current crush pressure p_0 of the P-α curve
//!   (4-34 is lost in the OCR; this is the AUTODYN form, digest A3);
//! - residual (4-35): f_c B p*ᴹ ≤ f_c S_max, 0 in tension.
//!
//! R3 is the Willam–Warnke form (4-19) with Q2 = Q20 + BQ p* in [0.5, 1] (4-20),
//! θ from cos 3θ = 27 J3/(2 σ̄³) (θ = 0 in uniaxial tension, π/3 in compression).
//! F_rate (4-18): (ε̇/ε̇₀ᶜ)^α in compression (p ≥ f_c/3), (ε̇/ε̇₀ᵗ)^δ in tension
//! (p ≤ −f_t/3), linear in p between, at least 1; ε̇₀ᶜ = 30e-6 ε̇₀, ε̇₀ᵗ = 3e-6 ε̇₀.
//!
//! Beyond the elastic limit the strength hardens linearly, σ_el + (3G/PREFACT) ε_p
//! (4-36), up to the failure surface; there damage grows, D += Δε_p/ε_p^f with
//! ε_p^f = max(D1 (p* + (1 − D) T*)^{D2}, ε_f,min), T* = T_s F_rate/f_c (4-38,
//! 4-39), and the strength is (1 − D) σ_fail + D σ_res (4-37). The shear modulus
//! falls with damage, G_D = (1 − D) G + D SHRATD G (4-40…4-42). Tension cut-off
//! p ≥ −(1 − D) T_s F_rate (4-29). A failed point (D = 1) whose matrix is in
//! tension (μ_s < 0) is rubble and carries no pressure (our addition: with
//! T1 μ + B0 E it would push itself apart by its internal energy, and that
//! energy grows without bound as the rubble is recompacted); the energy takes the
//! work of the pressure carried (`eos::energy_and_pressure`).
//!
//! P-α (Herrmann; 4-43…4-49): the distension α = ρ_s/ρ follows the crush curve
//! α = 1 + (α₀ − 1)((P_lock − p)/(P_lock − P_crush))ⁿ for P_crush < p < P_lock on
//! loading and never grows again; the pressure is the matrix polynomial at the
//! matrix compression μ_s = αρ/ρ_s0 − 1 (4-45, as written: the thesis does not
//! divide by α, Kratos' implementation does), A1 μ + A2 μ² + A3 μ³ + (B0 + B1 μ)E
//! in compression, T1 μ + T2 μ² + B0 E in tension, with E the internal energy per
//! unit reference volume. α and p are found together by bisection on α; E by the
//! trapezoidal rule with two passes. The update follows the thesis' order
//! (digest A3): pressure, cut-off, rate, surfaces, radial return (Cauchy
//! deviator, `deviatoric.rs` kinematics), damage, shear modulus.
//! History: ε̄p, D, α, E.

use super::deviatoric::{cauchy_trial, deviator, equivalent, equivalent_rate, strain_increment};
use super::eos::{energy_and_pressure, energy_update};
use super::erosion::{failed_jacobian, Erosion};
use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material};
use crate::dim::Mat3;
use std::f64::consts::PI;

/// The matrix (solid) polynomial of the P-α EOS (4-48).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrix {
    pub a1: f64,
    pub a2: f64,
    pub a3: f64,
    pub b0: f64,
    pub b1: f64,
    pub t1: f64,
    pub t2: f64,
}

impl Matrix {
    /// (a, b) with p = a + b E at matrix compression μ.
    fn affine(&self, mu: f64) -> (f64, f64) {
        if mu >= 0.0 {
            (mu * (self.a1 + mu * (self.a2 + mu * self.a3)), self.b0 + self.b1 * mu)
        } else {
            (mu * (self.t1 + mu * self.t2), self.b0)
        }
    }
}

/// The P-α crush curve and the matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PAlpha {
    pub crush_pressure: f64,
    pub lock_pressure: f64,
    pub exponent: f64,
    /// α₀ = ρ_s0/ρ₀.
    pub alpha0: f64,
    pub matrix: Matrix,
}

impl PAlpha {
    /// α on the crush curve at pressure p (4-46).
    pub fn crush_curve(&self, p: f64) -> f64 {
        if p <= self.crush_pressure {
            self.alpha0
        } else if p >= self.lock_pressure {
            1.0
        } else {
            let x = (self.lock_pressure - p) / (self.lock_pressure - self.crush_pressure);
            1.0 + (self.alpha0 - 1.0) * x.powf(self.exponent)
        }
    }

    /// The pressure at which the crush curve gives α: the current crush pressure.
    pub fn crush_pressure_at(&self, alpha: f64) -> f64 {
        if alpha >= self.alpha0 {
            return self.crush_pressure;
        }
        let x = ((alpha - 1.0) / (self.alpha0 - 1.0)).max(0.0).powf(1.0 / self.exponent);
        self.lock_pressure - (self.lock_pressure - self.crush_pressure) * x
    }

    /// Matrix compression μ_s = αρ/ρ_s0 − 1 = α/(α₀ J) − 1.
    fn matrix_strain(&self, alpha: f64, j: f64) -> f64 {
        alpha / (self.alpha0 * j) - 1.0
    }

    /// (a, b) of p = a + b E at distension α and Jacobian J.
    pub fn affine(&self, alpha: f64, j: f64) -> (f64, f64) {
        self.matrix.affine(self.matrix_strain(alpha, j))
    }

    /// α at J and internal energy E from α_old: α = min(α_old, curve(p(α))),
    /// by bisection (the right side falls as α grows).
    pub fn distension(&self, alpha_old: f64, j: f64, energy: f64) -> f64 {
        let g = |alpha: f64| {
            let (a, b) = self.affine(alpha, j);
            alpha - alpha_old.min(self.crush_curve(a + b * energy))
        };
        if g(alpha_old) <= 0.0 {
            return alpha_old;
        }
        let (mut lo, mut hi) = (1.0, alpha_old);
        if g(lo) >= 0.0 {
            return lo;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo <= 1e-15 {
                break;
            }
        }
        0.5 * (lo + hi)
    }

    /// ∂p/∂μ of the matrix at zero (the bulk stiffness for the wave speed).
    fn stiffness(&self) -> f64 {
        self.matrix.a1.max(self.matrix.t1)
    }

    /// ∂p/∂μ of the porous material at distension α and Jacobian J (α fixed):
    /// the matrix tangent at μ_s times ∂μ_s/∂μ = α/α₀, at least `stiffness`.
    fn tangent(&self, alpha: f64, j: f64) -> f64 {
        let mu = self.matrix_strain(alpha, j);
        let h = 1e-7 * (1.0 + mu.abs());
        let slope = (self.matrix.affine(mu + h).0 - self.matrix.affine(mu - h).0) / (2.0 * h);
        (slope * alpha / self.alpha0).max(self.stiffness())
    }
}

#[derive(Clone, Debug)]
pub struct Rht {
    pub density: f64,
    pub shear_modulus: f64,
    pub compressive_strength: f64,
    /// f_t/f_c and f_s/f_c.
    pub tensile_ratio: f64,
    pub shear_ratio: f64,
    /// A, N of the failure surface; Q20, BQ of the Lode factor.
    pub a: f64,
    pub n: f64,
    pub q20: f64,
    pub bq: f64,
    /// PREFACT (0: elastic up to the failure surface) and R_c, R_t.
    pub prefact: f64,
    pub elastic_compression: f64,
    pub elastic_tension: f64,
    /// B, M, S_max of the residual surface.
    pub b: f64,
    pub m: f64,
    pub max_residual: f64,
    /// α, δ of the rate factor and ε̇₀.
    pub rate_alpha: f64,
    pub rate_delta: f64,
    pub reference_strain_rate: f64,
    pub d1: f64,
    pub d2: f64,
    pub min_fracture_strain: f64,
    /// SHRATD, the fractured shear modulus fraction.
    pub shear_ratio_damaged: f64,
    pub eos: PAlpha,
    /// When points leave the transfers (`erosion.rs`).
    pub erosion: Option<Erosion>,
}

const PLASTIC_STRAIN: usize = 0;
const DAMAGE: usize = 1;
/// α − α₀ (history starts at zero).
const DISTENSION: usize = 2;
const ENERGY: usize = 3;

/// The Willam–Warnke Lode factor R3(θ, Q2) (4-19).
pub fn lode_factor(theta: f64, q2: f64) -> f64 {
    let c = theta.cos();
    let k = 1.0 - q2 * q2;
    let root = (4.0 * k * c * c + 5.0 * q2 * q2 - 4.0 * q2).max(0.0).sqrt();
    (2.0 * k * c + (2.0 * q2 - 1.0) * root) / (4.0 * k * c * c + (2.0 * q2 - 1.0).powi(2))
}

/// θ in [0, π/3] of a deviator (principal values): cos 3θ = 27 J3/(2 σ̄³).
pub fn lode_angle(s: &nalgebra::Vector3<f64>) -> f64 {
    let q = (1.5 * s.norm_squared()).sqrt();
    if q == 0.0 {
        return PI / 3.0;
    }
    let c = (13.5 * s.x * s.y * s.z / q.powi(3)).clamp(-1.0, 1.0);
    c.acos() / 3.0
}

impl Rht {
    fn tensile_strength(&self) -> f64 {
        self.tensile_ratio * self.compressive_strength
    }

    /// Q2 = Q20 + BQ p* in [0.5, 1] (4-20).
    pub fn q2(&self, p: f64) -> f64 {
        (self.q20 + self.bq * p / self.compressive_strength).clamp(0.5, 1.0)
    }

    /// HTL* = 1/3 − A^{−1/N} (4-30, reconstructed from continuity at f_c/3).
    pub fn htl(&self) -> f64 {
        1.0 / 3.0 - self.a.powf(-1.0 / self.n)
    }

    /// The meridian's tension and shear ordinates a = f_t/(f_c Q2), b = f_s/(f_c R3ˢ)
    /// (Q2 and R3ˢ at p = 0).
    fn meridian_points(&self) -> (f64, f64) {
        let q2 = self.q2(0.0);
        let a = self.tensile_ratio / q2;
        let b = self.shear_ratio / lode_factor(PI / 6.0, q2);
        (a, b)
    }

    /// T_s = (f_t/3) b/(b − a), where the meridian reaches zero (4-28).
    pub fn tension_zero(&self) -> f64 {
        let (a, b) = self.meridian_points();
        self.tensile_strength() / 3.0 * b / (b - a)
    }

    /// σ*_TXC at the scaled pressure p_s (4-26), ≥ 0.
    pub fn compressive_meridian(&self, ps: f64) -> f64 {
        let fc = self.compressive_strength;
        let ft3 = self.tensile_strength() / 3.0;
        let (a, b) = self.meridian_points();
        let value = if ps <= 0.0 {
            ps / -ft3 * a + (ps + ft3) / ft3 * b
        } else if ps <= fc / 3.0 {
            (ps - fc / 3.0) / (-fc / 3.0) * b + ps / (fc / 3.0)
        } else {
            self.a * (ps / fc - self.htl()).powf(self.n)
        };
        value.max(0.0)
    }

    /// F_rate at pressure p and strain rate (4-18), ≥ 1.
    pub fn rate_factor(&self, p: f64, rate: f64) -> f64 {
        let e0 = self.reference_strain_rate;
        let compression = (rate / (30e-6 * e0)).powf(self.rate_alpha).max(1.0);
        let tension = (rate / (3e-6 * e0)).powf(self.rate_delta).max(1.0);
        let (c3, t3) = (self.compressive_strength / 3.0, self.tensile_strength() / 3.0);
        let f = if p >= c3 {
            compression
        } else if p <= -t3 {
            tension
        } else {
            (p + t3) / (c3 + t3) * compression + (p - c3) / (-t3 - c3) * tension
        };
        f.max(1.0)
    }

    /// σ_fail at p, θ and F_rate (4-17).
    pub fn failure_strength(&self, p: f64, theta: f64, f: f64) -> f64 {
        self.compressive_strength * self.compressive_meridian(p / f) * lode_factor(theta, self.q2(p)) * f
    }

    /// F_el between R_t and R_c (4-32).
    fn elastic_fraction(&self, p: f64) -> f64 {
        let (rc, rt) = (self.elastic_compression, self.elastic_tension);
        let c3 = self.compressive_strength * rc / 3.0;
        let t3 = self.tensile_strength() * rt / 3.0;
        if p >= c3 {
            rc
        } else if p <= -t3 {
            rt
        } else {
            (p + t3) / (c3 + t3) * rc + (p - c3) / (-t3 - c3) * rt
        }
    }

    /// σ_el at p, θ, F_rate and the current crush pressure p_0 (4-31…4-34).
    pub fn elastic_strength(&self, p: f64, theta: f64, f: f64, crush: f64) -> f64 {
        let fel = self.elastic_fraction(p);
        let pu = self.compressive_strength * self.elastic_compression / 3.0;
        let cap = if p <= pu {
            1.0
        } else if p >= crush || crush <= pu {
            0.0
        } else {
            (1.0 - ((p - pu) / (crush - pu)).powi(2)).sqrt()
        };
        let ps = p / (f * fel);
        self.compressive_strength
            * self.compressive_meridian(ps)
            * lode_factor(theta, self.q2(p))
            * f
            * fel
            * cap
    }

    /// σ_res = f_c B p*ᴹ ≤ f_c S_max, 0 in tension (4-35).
    pub fn residual_strength(&self, p: f64) -> f64 {
        if p <= 0.0 {
            return 0.0;
        }
        let fc = self.compressive_strength;
        fc * (self.b * (p / fc).powf(self.m)).min(self.max_residual)
    }

    /// G_D = (1 − D) G + D SHRATD G (4-40…4-42).
    fn damaged_shear_modulus(&self, d: f64) -> f64 {
        self.shear_modulus * (1.0 - d + d * self.shear_ratio_damaged)
    }

    /// Plastic strain to failure (4-39).
    fn fracture_strain(&self, p: f64, d: f64, f: f64) -> f64 {
        let fc = self.compressive_strength;
        let t_star = self.tension_zero() * f / fc;
        let s = (p / fc + (1.0 - d) * t_star).max(0.0);
        (self.d1 * s.powf(self.d2)).max(self.min_fracture_strain)
    }
}

impl Material for Rht {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn n_history(&self) -> usize {
        4
    }

    fn update(&self, inc: &Increment, h_new: &mut [f64]) -> Mat3 {
        let h_old = inc.history_old;
        let j_old = inc.f_old.determinant();
        let j = inc.df.determinant() * j_old;
        let mut damage = h_old[DAMAGE];
        let alpha_old = self.eos.alpha0 + h_old[DISTENSION];
        let g_old = self.damaged_shear_modulus(damage);

        // Trial deviator (Cauchy) at the old damage's shear modulus.
        let tau_dev_old = deviator(&inc.stress_old) * j_old;
        let (trial, s_trial, q_trial) = cauchy_trial(&tau_dev_old, g_old, &inc.df, j);
        let strain_increment = strain_increment(&inc.df);
        let rate = equivalent_rate(&strain_increment, inc.dt);

        // Pressure and distension (P-α), energy by two trapezoidal passes.
        let p_old = -inc.stress_old.trace() / 3.0;
        let dw_dev = tau_dev_old.component_mul(&strain_increment).sum();
        let mut energy = h_old[ENERGY] + dw_dev - p_old * (j - j_old);
        // The second pass's energy is `energy_and_pressure`'s below.
        let alpha = self.eos.distension(alpha_old, j, energy);
        energy = energy_update(h_old[ENERGY], dw_dev, p_old, j - j_old, self.eos.affine(alpha, j));
        let alpha = self.eos.distension(alpha_old, j, energy);
        // Tension cut-off (4-29), the energy from the pressure carried.
        let f_tension = self.rate_factor(-self.tensile_strength(), rate);
        let p_min = -(1.0 - damage) * self.tension_zero() * f_tension;
        // Failed and opened beyond the solid density (μ_s < 0): rubble, p = 0.
        let rubble = damage >= 1.0 && self.eos.matrix_strain(alpha, j) < 0.0;
        let p_max = if rubble { 0.0 } else { f64::INFINITY };
        let affine = self.eos.affine(alpha, j);
        let (energy, p) = energy_and_pressure(h_old[ENERGY], dw_dev, p_old, j - j_old, affine, (p_min, p_max));

        // Surfaces at the trial Lode angle.
        let theta = lode_angle(&s_trial);
        let f = self.rate_factor(p, rate);
        let fail = self.failure_strength(p, theta, f);
        let residual = self.residual_strength(p);
        let hardening = if self.prefact > 0.0 {
            3.0 * self.shear_modulus / self.prefact
        } else {
            f64::INFINITY
        };
        let eps_p_old = h_old[PLASTIC_STRAIN];
        let elastic = self
            .elastic_strength(p, theta, f, self.eos.crush_pressure_at(alpha))
            .min(fail);
        // Yield before this increment: hardening below failure, softening after.
        let yield_old = if damage > 0.0 {
            fail + damage * (residual - fail)
        } else {
            (elastic + hardening * eps_p_old).min(fail)
        };
        let mut s = s_trial;
        let mut d_eps_p = 0.0;
        if q_trial > yield_old {
            let g3 = 3.0 * g_old;
            // Hardening part up to the failure surface, then perfectly plastic on it.
            let to_failure = if damage > 0.0 || yield_old >= fail {
                0.0
            } else {
                ((fail - yield_old) / hardening).min((q_trial - yield_old) / (g3 + hardening))
            };
            let q_hardened = q_trial - g3 * to_failure;
            let reached = yield_old + hardening * to_failure;
            let on_failure = (q_hardened - reached).max(0.0) / g3;
            if on_failure > 0.0 {
                damage = (damage + on_failure / self.fracture_strain(p, damage, f)).min(1.0);
            }
            d_eps_p = to_failure + on_failure;
            let yield_new = if damage > 0.0 {
                fail + damage * (residual - fail)
            } else {
                reached
            };
            s = s_trial * (yield_new / q_trial);
        }
        h_new[PLASTIC_STRAIN] = eps_p_old + d_eps_p;
        h_new[DAMAGE] = damage;
        h_new[DISTENSION] = alpha - self.eos.alpha0;
        h_new[ENERGY] = energy;
        trial.tensor(&s) - Mat3::identity() * p
    }

    fn p_wave_modulus(&self) -> f64 {
        self.eos.stiffness() + 4.0 / 3.0 * self.shear_modulus
    }

    /// c² = (∂p/∂μ + 4GJ/3)/ρ₀ with the P-α tangent at the current distension,
    /// J ≤ 1 for a failed point (`failed_jacobian`).
    fn wave_speed(&self, j: f64, history: &[f64]) -> f64 {
        let bulk = self.eos.tangent(self.eos.alpha0 + history[DISTENSION], j);
        let j = failed_jacobian(j, history[DAMAGE]);
        ((bulk + 4.0 / 3.0 * self.shear_modulus * j) / self.density).sqrt()
    }

    /// Stored energy: σ̄²/(6G) plus p²/(2 A1) (recoverable part only).
    fn strain_energy_density(&self, _f: &Mat3, stress: &Mat3, history: &[f64]) -> f64 {
        let p = -stress.trace() / 3.0;
        let g = self.damaged_shear_modulus(history[DAMAGE]);
        equivalent(stress).powi(2) / (6.0 * g) + p * p / (2.0 * self.eos.stiffness())
    }

    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        Some(history[PLASTIC_STRAIN])
    }

    fn erodes(&self) -> bool {
        self.erosion.is_some()
    }

    fn eroded(&self, history: &[f64]) -> bool {
        self.erosion
            .is_some_and(|e| e.applies(history[DAMAGE], history[PLASTIC_STRAIN]))
    }
}

impl FromParameters for Rht {
    const NAME: &'static str = "rht";
    const KEYS: &'static [&'static str] = &[
        "youngs_modulus",
        "poisson_ratio",
        "compressive_strength",
        "tensile_ratio",
        "shear_ratio",
        "failure_coefficient",
        "failure_exponent",
        "lode_q20",
        "lode_bq",
        "prefact",
        "elastic_compression_ratio",
        "elastic_tension_ratio",
        "residual_coefficient",
        "residual_exponent",
        "max_residual_strength",
        "rate_alpha",
        "rate_delta",
        "reference_strain_rate",
        "damage_d1",
        "damage_d2",
        "min_fracture_strain",
        "damaged_shear_ratio",
        "crush_pressure",
        "lock_pressure",
        "compaction_exponent",
        "initial_distension",
        "a1",
        "a2",
        "a3",
        "b0",
        "b1",
        "t1",
        "t2",
        "erosion",
        "erosion_plastic_strain",
    ];
    /// Thesis Tables 4.4–4.6 (C48 concrete) in mm, ms, g, MPa.
    const EXAMPLE: &'static str = "youngs_modulus = 35.664e3\npoisson_ratio = 0.2\ncompressive_strength = 48.0\ntensile_ratio = 0.0833\nshear_ratio = 0.18\nfailure_coefficient = 1.6\nfailure_exponent = 0.61\nlode_q20 = 0.6805\nlode_bq = 0.0105\nprefact = 2.0\nelastic_compression_ratio = 0.53\nelastic_tension_ratio = 0.7\nresidual_coefficient = 1.6\nresidual_exponent = 0.61\nrate_alpha = 0.0292\nrate_delta = 0.0331\nreference_strain_rate = 0.001\ndamage_d1 = 0.04\ndamage_d2 = 1.0\nmin_fracture_strain = 0.01\ndamaged_shear_ratio = 0.13\ncrush_pressure = 32.0\nlock_pressure = 6.0e3\ncompaction_exponent = 3.0\ninitial_distension = 1.1270491803278688\na1 = 35.27e3\na2 = 39.58e3\na3 = 9.04e3\nb0 = 1.22\nb1 = 1.22\nt1 = 35.27e3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let (positive, non_negative) = (|k| p.positive(k), |k, d| p.non_negative(k, d));
        let e = p.youngs_modulus()?;
        let nu = p.poisson_ratio()?;
        let (_, g) = super::lame(e, nu);
        let crush = positive("crush_pressure")?;
        let lock = positive("lock_pressure")?;
        p.ensure(lock > crush, "lock_pressure", format!("must exceed crush_pressure = {crush}"))?;
        let alpha0 = p.positive_or("initial_distension", 1.0)?;
        p.ensure(
            alpha0 >= 1.0,
            "initial_distension",
            format!("α₀ = ρ_s0/ρ₀ must be at least 1; got {alpha0}"),
        )?;
        let matrix = Matrix {
            a1: positive("a1")?,
            a2: p.get("a2")?.unwrap_or(0.0),
            a3: p.get("a3")?.unwrap_or(0.0),
            b0: non_negative("b0", 0.0)?,
            b1: non_negative("b1", 0.0)?,
            t1: positive("t1")?,
            t2: p.get("t2")?.unwrap_or(0.0),
        };
        let model = Rht {
            density,
            shear_modulus: g,
            compressive_strength: positive("compressive_strength")?,
            tensile_ratio: positive("tensile_ratio")?,
            shear_ratio: positive("shear_ratio")?,
            a: positive("failure_coefficient")?,
            n: positive("failure_exponent")?,
            q20: positive("lode_q20")?,
            bq: non_negative("lode_bq", 0.0105)?,
            prefact: non_negative("prefact", 2.0)?,
            elastic_compression: positive("elastic_compression_ratio")?,
            elastic_tension: positive("elastic_tension_ratio")?,
            b: non_negative("residual_coefficient", 0.0)?,
            m: non_negative("residual_exponent", 1.0)?,
            max_residual: non_negative("max_residual_strength", 1e20)?,
            rate_alpha: non_negative("rate_alpha", 0.0)?,
            rate_delta: non_negative("rate_delta", 0.0)?,
            reference_strain_rate: p.positive_or("reference_strain_rate", 1.0)?,
            d1: positive("damage_d1")?,
            d2: non_negative("damage_d2", 1.0)?,
            min_fracture_strain: non_negative("min_fracture_strain", 0.01)?,
            shear_ratio_damaged: non_negative("damaged_shear_ratio", 0.13)?,
            eos: PAlpha {
                crush_pressure: crush,
                lock_pressure: lock,
                exponent: p.positive_or("compaction_exponent", 3.0)?,
                alpha0,
                matrix,
            },
            erosion: Erosion::from_parameters(p)?,
        };
        p.ensure(
            (0.5..=1.0).contains(&model.q20),
            "lode_q20",
            "must lie in [0.5, 1] (Q2 = 1: circular deviatoric section)",
        )?;
        p.ensure(
            model.elastic_compression <= 1.0 && model.elastic_tension <= 1.0,
            "elastic_compression_ratio",
            "the elastic-limit ratios R_c, R_t must not exceed 1",
        )?;
        let (a, b) = model.meridian_points();
        p.ensure(
            b > a,
            "shear_ratio",
            format!(
                "f_s/(f_c R3ˢ) = {b:.4} must exceed f_t/(f_c Q2) = {a:.4}: the meridian must \
                 fall towards tension"
            ),
        )?;
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver::{self, hydrostatic};
    use crate::material::registry;
    use nalgebra::Vector3;

    /// Thesis Tables 4.4–4.6 (case 1, C48) or 4.7–4.9 (case 2), mm, ms, g, MPa.
    fn case(k: usize) -> Rht {
        let mut text = registry::find("rht").unwrap().example.to_string();
        let mut density = 2.44e-3;
        if k == 2 {
            density = 2.546e-3;
            text = text
                .replace("youngs_modulus = 35.664e3", "youngs_modulus = 54.61e3")
                .replace("compressive_strength = 48.0", "compressive_strength = 153.0")
                .replace("tensile_ratio = 0.0833", "tensile_ratio = 0.1")
                .replace("rate_alpha = 0.0292", "rate_alpha = 0.0063")
                .replace("rate_delta = 0.0331", "rate_delta = 0.0063")
                .replace("crush_pressure = 32.0", "crush_pressure = 102.0")
                .replace("initial_distension = 1.1270491803278688", "initial_distension = 1.0801256873527100");
        }
        let values: toml::Table = toml::from_str(&text).unwrap();
        let p = Parameters::new("material.0", "rht", &values);
        Rht::from_parameters(density, &p).unwrap()
    }

    #[test]
    fn lode_factor_limits() {
        for theta in [0.0, 0.3, PI / 6.0, 0.9, PI / 3.0] {
            assert!((lode_factor(theta, 1.0) - 1.0).abs() < 1e-12);
            assert!((lode_factor(theta, 0.5) - 0.5 / theta.cos()).abs() < 1e-12);
        }
        for q2 in [0.5, 0.6805, 0.8, 1.0] {
            assert!((lode_factor(PI / 3.0, q2) - 1.0).abs() < 1e-12, "compression");
            assert!((lode_factor(0.0, q2) - q2).abs() < 1e-12, "tension");
        }
        // Digest A3: R3ˢ = R3(π/6, 0.6805) = 0.76166.
        assert!((lode_factor(PI / 6.0, 0.6805) - 0.76166).abs() < 5e-6);
        // θ of uniaxial tension and compression deviators.
        let t = Vector3::new(2.0, -1.0, -1.0) / 3.0;
        assert!(lode_angle(&t).abs() < 1e-7);
        assert!((lode_angle(&-t) - PI / 3.0).abs() < 1e-7);
        assert!((lode_angle(&Vector3::new(1.0, 0.0, -1.0)) - PI / 6.0).abs() < 1e-7);
    }

    #[test]
    fn derived_constants_of_the_thesis_tables() {
        // Digest A3: HTL* = −0.12945; T_s = 2.765 MPa (case 1), 13.49 MPa (case 2).
        let (c1, c2) = (case(1), case(2));
        assert!((c1.htl() + 0.12945).abs() < 5e-6, "{}", c1.htl());
        assert!((c1.tension_zero() - 2.765).abs() < 5e-4, "{}", c1.tension_zero());
        assert!((c2.tension_zero() - 13.49).abs() < 5e-3, "{}", c2.tension_zero());
        assert!((c1.eos.alpha0 - 2.75 / 2.44).abs() < 1e-12);
        assert!((c2.eos.alpha0 - 1.0801).abs() < 1e-4);
    }

    #[test]
    fn the_failure_surface_passes_through_the_uniaxial_and_shear_strengths() {
        for m in [case(1), case(2)] {
            let fc = m.compressive_strength;
            let (ft, fs) = (m.tensile_ratio * fc, m.shear_ratio * fc);
            // Quasi-static (F_rate = 1): compression at p = f_c/3, θ = π/3 …
            let c = m.failure_strength(fc / 3.0, PI / 3.0, 1.0);
            assert!((c / fc - 1.0).abs() < 1e-12, "f_c: {c}");
            // … pure shear at p = 0, θ = π/6 …
            let s = m.failure_strength(0.0, PI / 6.0, 1.0);
            assert!((s / fs - 1.0).abs() < 1e-12, "f_s: {s}");
            // … and the meridian is continuous where its pieces meet.
            let e = 1e-9;
            for ps in [0.0, fc / 3.0] {
                let jump = m.compressive_meridian(ps + e) - m.compressive_meridian(ps - e);
                assert!(jump.abs() < 1e-6, "jump {jump} at {ps}");
            }
            assert!(m.compressive_meridian(-m.tension_zero()).abs() < 1e-12);
            // Uniaxial tension at p = −f_t/3, θ = 0: f_t, with Q2 taken at p = 0 in
            // the meridian (4-23) and at p in R3, equal up to BQ p*.
            let t = m.failure_strength(-ft / 3.0, 0.0, 1.0);
            assert!((t / ft - 1.0).abs() < 0.01 * m.bq * 10.0, "f_t: {t} vs {ft}");
        }
    }

    #[test]
    fn p_alpha_crushes_irreversibly_and_locks() {
        let m = case(1);
        let eos = m.eos;
        assert_eq!(eos.crush_curve(10.0), eos.alpha0);
        assert_eq!(eos.crush_curve(7e3), 1.0);
        for p in [100.0, 1000.0, 3000.0] {
            assert!((eos.crush_pressure_at(eos.crush_curve(p)) / p - 1.0).abs() < 1e-12);
        }
        // Hydrostatic compression crushes (α falls), unloading keeps α.
        let path: Vec<Mat3> = hydrostatic(0.97, 300)
            .into_iter()
            .chain(hydrostatic(0.97, 300).into_iter().rev().map(|f| f * 1.0))
            .collect();
        let r = driver::run(&m, &path, 0.0);
        let alpha = |k: usize| eos.alpha0 + r.history[k][DISTENSION];
        let loaded = 300;
        assert!(alpha(loaded) < eos.alpha0 - 1e-3, "no crushing: α = {}", alpha(loaded));
        for k in 1..path.len() {
            assert!(alpha(k) <= alpha(k - 1) + 1e-15, "α grew at {k}");
            // While crushing the state sits on the crush curve.
            if k <= loaded && alpha(k) < alpha(k - 1) {
                let p = -r.stress[k].trace() / 3.0;
                assert!((eos.crush_curve(p) / alpha(k) - 1.0).abs() < 1e-9, "step {k}");
            }
        }
        assert_eq!(alpha(path.len() - 1), alpha(loaded));
        // Unloaded to the initial volume, the crushed material is in tension
        // (the matrix is stretched) or at the cut-off.
        let p_end = -r.stress.last().unwrap().trace() / 3.0;
        assert!(p_end < 0.0, "{p_end}");
    }

    #[test]
    fn confined_shear_goes_elastic_hardening_failure_residual() {
        let m = case(1);
        // Uniaxial strain to 1 % (elastic, then hardening), then shear to γ = 1
        // under that confinement: failure, damage to D = 1, the residual surface.
        let squeeze = |t: f64| Mat3::from_diagonal(&Vector3::new(1.0, 1.0, 1.0 - 0.01 * t));
        let mut path: Vec<Mat3> = (0..=1000).map(|k| squeeze(k as f64 / 1000.0)).collect();
        path.extend((1..=2000).map(|k| {
            let mut f = squeeze(1.0);
            f[(0, 2)] = k as f64 / 2000.0;
            f
        }));
        let r = driver::run(&m, &path, 0.0);
        let first = (1..path.len())
            .find(|&k| r.history[k][PLASTIC_STRAIN] > 0.0)
            .expect("never yields");
        let damaged = (1..path.len())
            .find(|&k| r.history[k][DAMAGE] > 0.0)
            .expect("never fails");
        assert!(first < damaged, "hardening before failure ({first}, {damaged})");
        // Onset: the last elastic state lies inside the elastic surface.
        let p_before = -r.stress[first - 1].trace() / 3.0;
        let crush = m.eos.crush_pressure_at(m.eos.alpha0 + r.history[first - 1][DISTENSION]);
        let elastic = m.elastic_strength(p_before, PI / 3.0, 1.0, crush);
        assert!(equivalent(&r.stress[first - 1]) <= elastic * (1.0 + 1e-9));
        // From failure on, the state lies on (1 − D) σ_fail + D σ_res at its own
        // Lode angle (the return is radial) and pressure (quasi-static: F = 1).
        for k in damaged..path.len() {
            let s = &r.stress[k];
            let p = -s.trace() / 3.0;
            let e = nalgebra::SymmetricEigen::new(deviator(s)).eigenvalues;
            let d = r.history[k][DAMAGE];
            let fail = m.failure_strength(p, lode_angle(&e), 1.0);
            let expected = fail + d * (m.residual_strength(p) - fail);
            let q = equivalent(s);
            assert!((q - expected).abs() <= 1e-6 * fail, "step {k}: σ̄ {q} vs {expected}");
        }
        let last = r.history.last().unwrap();
        assert_eq!(last[DAMAGE], 1.0, "not fully damaged");
        let p = -r.stress.last().unwrap().trace() / 3.0;
        let q = equivalent(r.stress.last().unwrap());
        assert!(p > 0.0);
        assert!((q / m.residual_strength(p) - 1.0).abs() < 1e-9, "σ̄ {q} vs residual");
    }

    #[test]
    fn hydrostatic_tension_stops_at_the_cut_off() {
        let m = case(1);
        let r = driver::run(&m, &hydrostatic(1.002, 100), 0.0);
        let p = -r.stress.last().unwrap().trace() / 3.0;
        assert!((p + m.tension_zero()).abs() < 1e-9, "p {p} vs −T_s {}", m.tension_zero());
    }

    #[test]
    fn failed_rubble_opened_beyond_the_solid_density_carries_no_pressure() {
        let m = case(1);
        // Failed (D = 1), fully compacted (α = 1), with a large internal energy,
        // opened to J = 1.2 (μ_s < 0) and then opened further: B0 E would give
        // 1.22 × 500 MPa of pressure; rubble carries none, and takes no work.
        let history = [2.0, 1.0, 1.0 - m.eos.alpha0, 500.0];
        let f_old = Mat3::identity() * 1.2f64.cbrt();
        let df = Mat3::identity() * (1.3f64 / 1.2).cbrt();
        let inc = Increment::new(f_old, df, 1e-3, Mat3::zeros(), &history);
        let mut h_new = [0.0; 4];
        let stress = m.update(&inc, &mut h_new);
        assert_eq!(stress, Mat3::zeros());
        assert_eq!(h_new[ENERGY], 500.0);
        // Recompacted past the solid density (J < 1/α₀ = 0.887 at α = 1), it
        // carries pressure again.
        let df = Mat3::identity() * (0.85f64 / 1.2).cbrt();
        let inc = inc.with_df(df);
        let stress = m.update(&inc, &mut h_new);
        assert!(-stress.trace() / 3.0 > 0.0, "{stress}");
    }
}
