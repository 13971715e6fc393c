//! HJC, the Holmquist–Johnson–Cook concrete model (Holmquist, Johnson & Cook
//! 1993; thesis `000_…` §4.1, eqs. 4-1…4-16, its EFEM update in App. B).
//!
//! Pressure from the three-regime compaction EOS (`eos::Compaction`, 4-1…4-9),
//! with the tension cut-off p ≥ −(1 − D) T (4-10) that leaves the damage as it
//! is. Strength (4-11), normalised by the compressive strength f_c
//! (p* = p/f_c, T* = T/f_c):
//!
//!   p ≥ 0: σ_y = f_c min([A(1 − D) + B p*ᴺ] F, S_max)
//!   p < 0: σ_y = f_c min([A(1 − D) + A p/T] F, S_max)   (falls to 0 at the cut-off)
//!
//! with F = |1 + C ln ε̇*| (ε̇* ≥ 10⁻⁶; thesis and LS-DYNA) or the clamped form
//! (`rate_form`, as JH-2). The tension branch takes the thesis' sign (+A p/T):
//! LS-DYNA behaves as −A p/T (4-16), which raises the strength in tension; the
//! thesis shows this with one element and calls it an error, and OpenRadioss'
//! LAW126 uses +A p/T too. Radial return on the Cauchy deviator with the damage
//! of the step start; damage (4-13, 4-14)
//!
//!   D += (Δε_p + Δμ_p) / max(D1 (p* + T*)^{D2}, ε_f,min)
//!
//! also without deviatoric yield (crushing alone damages). The thesis' App. B
//! skips the damage where D1 (p* + T*)^{D2} < ε_f,min; the equation's floor is
//! used here. History: ε̄p, D, μ_max, μ_p.

use super::deviatoric::{cauchy_trial, deviator, equivalent, equivalent_rate, strain_increment};
use super::eos::Compaction;
use super::jh2::RateForm;
use super::erosion::{failed_jacobian, Erosion};
use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material};
use crate::dim::Mat3;

#[derive(Clone, Debug)]
pub struct Hjc {
    pub density: f64,
    pub shear_modulus: f64,
    pub eos: Compaction,
    /// A, B, N, C.
    pub a: f64,
    pub b: f64,
    pub n: f64,
    pub c: f64,
    pub compressive_strength: f64,
    pub tensile_strength: f64,
    /// S_max, the normalised strength cap.
    pub max_strength: f64,
    pub d1: f64,
    pub d2: f64,
    pub min_fracture_strain: f64,
    pub reference_strain_rate: f64,
    pub rate_form: RateForm,
    /// When points leave the transfers (`erosion.rs`).
    pub erosion: Option<Erosion>,
}

const PLASTIC_STRAIN: usize = 0;
const DAMAGE: usize = 1;
const MAX_STRAIN: usize = 2;
const PLASTIC_VOLUME: usize = 3;

impl Hjc {
    /// F of the strain rate.
    pub fn rate_factor(&self, rate: f64) -> f64 {
        self.rate_form.factor(self.c, rate / self.reference_strain_rate)
    }

    /// σ_y at pressure p, damage D and rate factor F (4-11).
    pub fn yield_stress(&self, p: f64, damage: f64, f: f64) -> f64 {
        let fc = self.compressive_strength;
        let normalised = if p >= 0.0 {
            self.a * (1.0 - damage) + self.b * (p / fc).powf(self.n)
        } else {
            self.a * (1.0 - damage + p / self.tensile_strength)
        };
        fc * (normalised * f).clamp(0.0, self.max_strength)
    }

    /// ε_p^f + μ_p^f = max(D1 (p* + T*)^{D2}, ε_f,min) (4-14).
    pub fn fracture_strain(&self, p: f64) -> f64 {
        let fc = self.compressive_strength;
        let s = ((p + self.tensile_strength) / fc).max(0.0);
        (self.d1 * s.powf(self.d2)).max(self.min_fracture_strain)
    }
}

impl Material for Hjc {
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
        let g = self.shear_modulus;
        let j_old = inc.f_old.determinant();
        let j = inc.df.determinant() * j_old;
        let damage_old = h_old[DAMAGE];

        // Pressure (4-1…4-9) and the cut-off (4-10).
        let eos = self
            .eos
            .update(1.0 / j - 1.0, h_old[MAX_STRAIN], h_old[PLASTIC_VOLUME]);
        let d_mu_p = eos.plastic_strain - h_old[PLASTIC_VOLUME];
        let p = eos.pressure.max(-(1.0 - damage_old) * self.tensile_strength);

        // Trial Cauchy deviator and radial return at the step start's damage.
        let tau_dev_old = deviator(&inc.stress_old) * j_old;
        let (trial, s_trial, q_trial) = cauchy_trial(&tau_dev_old, g, &inc.df, j);
        let rate = equivalent_rate(&strain_increment(&inc.df), inc.dt);
        let sigma_y = self.yield_stress(p, damage_old, self.rate_factor(rate));
        let (s, d_eps_p) = if q_trial > sigma_y {
            let scale = if q_trial > 0.0 { sigma_y / q_trial } else { 0.0 };
            (s_trial * scale, (q_trial - sigma_y) / (3.0 * g))
        } else {
            (s_trial, 0.0)
        };

        // Damage from plastic shear and crushing (4-13, 4-14).
        let increment = d_eps_p + d_mu_p.max(0.0);
        h_new[DAMAGE] = (damage_old + increment / self.fracture_strain(p)).min(1.0);
        h_new[PLASTIC_STRAIN] = h_old[PLASTIC_STRAIN] + d_eps_p;
        h_new[MAX_STRAIN] = eos.max_strain;
        h_new[PLASTIC_VOLUME] = eos.plastic_strain;
        trial.tensor(&s) - Mat3::identity() * p
    }

    fn p_wave_modulus(&self) -> f64 {
        self.eos.stiffness(0.0) + 4.0 / 3.0 * self.shear_modulus
    }

    /// c² = (∂p/∂μ + 4GJ/3)/ρ₀, J ≤ 1 for a failed point (`failed_jacobian`).
    fn wave_speed(&self, j: f64, history: &[f64]) -> f64 {
        let bulk = self.eos.stiffness(1.0 / j - 1.0);
        let j = failed_jacobian(j, history[DAMAGE]);
        ((bulk + 4.0 / 3.0 * self.shear_modulus * j) / self.density).sqrt()
    }

    /// Shear energy σ̄²/(6G) plus p²/(2K) with the largest bulk modulus in use:
    /// a measure of the recoverable energy only (crushing dissipates).
    fn strain_energy_density(&self, _f: &Mat3, stress: &Mat3, _history: &[f64]) -> f64 {
        let p = -stress.trace() / 3.0;
        equivalent(stress).powi(2) / (6.0 * self.shear_modulus)
            + p * p / (2.0 * self.eos.stiffness(0.0))
    }

    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    fn erodes(&self) -> bool {
        self.erosion.is_some()
    }

    fn eroded(&self, history: &[f64]) -> bool {
        self.erosion
            .is_some_and(|e| e.applies(history[DAMAGE], history[PLASTIC_STRAIN]))
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        Some(history[PLASTIC_STRAIN])
    }
}

impl FromParameters for Hjc {
    const NAME: &'static str = "hjc";
    const KEYS: &'static [&'static str] = &[
        "shear_modulus",
        "intact_coefficient",
        "pressure_coefficient",
        "pressure_exponent",
        "rate_coefficient",
        "compressive_strength",
        "tensile_strength",
        "max_strength",
        "damage_d1",
        "damage_d2",
        "min_fracture_strain",
        "crush_pressure",
        "crush_strain",
        "lock_pressure",
        "lock_strain",
        "k1",
        "k2",
        "k3",
        "reference_strain_rate",
        "rate_form",
        "erosion",
        "erosion_plastic_strain",
    ];
    /// The 48 MPa concrete of the HJC literature in mm, ms, g, MPa (the thesis'
    /// units; digest A1/`impact-data.md` §2.3).
    const EXAMPLE: &'static str = "shear_modulus = 14.86e3\nintact_coefficient = 0.79\npressure_coefficient = 1.6\npressure_exponent = 0.61\nrate_coefficient = 0.007\ncompressive_strength = 48.0\ntensile_strength = 4.0\nmax_strength = 7.0\ndamage_d1 = 0.04\ndamage_d2 = 1.0\nmin_fracture_strain = 0.01\ncrush_pressure = 16.0\ncrush_strain = 0.001\nlock_pressure = 800.0\nlock_strain = 0.1\nk1 = 85.0e3\nk2 = -171.0e3\nk3 = 208.0e3\nreference_strain_rate = 0.001";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let (positive, non_negative) = (|k| p.positive(k), |k, d| p.non_negative(k, d));
        let crush = (positive("crush_pressure")?, positive("crush_strain")?);
        let lock = (positive("lock_pressure")?, non_negative("lock_strain", 0.0)?);
        p.ensure(
            lock.0 > crush.0,
            "lock_pressure",
            format!("must exceed crush_pressure = {}", crush.0),
        )?;
        let k = (positive("k1")?, p.get("k2")?.unwrap_or(0.0), p.get("k3")?.unwrap_or(0.0));
        let eos = Compaction::new(crush, lock, k).ok_or_else(|| {
            (
                p.key("k1"),
                "the locked curve K1 μ̄ + K2 μ̄² + K3 μ̄³ must rise to lock_pressure within μ̄ ≤ 1, \
                 beyond crush_strain"
                    .to_string(),
            )
        })?;
        let reference_strain_rate = p.positive_or("reference_strain_rate", 1.0)?;
        Ok(Hjc {
            density,
            shear_modulus: positive("shear_modulus")?,
            eos,
            a: positive("intact_coefficient")?,
            b: non_negative("pressure_coefficient", 0.0)?,
            n: non_negative("pressure_exponent", 1.0)?,
            c: non_negative("rate_coefficient", 0.0)?,
            compressive_strength: positive("compressive_strength")?,
            tensile_strength: positive("tensile_strength")?,
            max_strength: non_negative("max_strength", 1e20)?,
            d1: positive("damage_d1")?,
            d2: non_negative("damage_d2", 1.0)?,
            min_fracture_strain: non_negative("min_fracture_strain", 0.01)?,
            reference_strain_rate,
            rate_form: p.get("rate_form")?.unwrap_or(RateForm::Absolute),
            erosion: Erosion::from_parameters(p)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver::{self, hydrostatic};
    use nalgebra::Vector3;

    /// Thesis Tables 4.1–4.3 (mm, ms, g, MPa): linear EOS p = 16e3 μ.
    fn thesis() -> Hjc {
        Hjc {
            density: 2.44e-3,
            shear_modulus: 14.86e3,
            eos: Compaction::new((16.0, 0.001), (800.0, 0.0), (16e3, 0.0, 0.0)).unwrap(),
            a: 0.79,
            b: 1.6,
            n: 0.61,
            c: 0.007,
            compressive_strength: 48.0,
            tensile_strength: 4.0,
            max_strength: 7.0,
            d1: 0.04,
            d2: 1.0,
            min_fracture_strain: 0.01,
            reference_strain_rate: 0.001,
            rate_form: RateForm::Absolute,
            erosion: None,
        }
    }

    fn uniaxial(strains: impl Iterator<Item = f64>) -> Vec<Mat3> {
        strains
            .map(|e| Mat3::from_diagonal(&Vector3::new(1.0, 1.0, 1.0 + e)))
            .collect()
    }

    fn pressure(s: &Mat3) -> f64 {
        -s.trace() / 3.0
    }

    /// Every step of a path: on or inside the surface at the step start's damage,
    /// on it when yielding, the damage the sum of (Δε_p + Δμ_p)/ε_f.
    fn check_path(m: &Hjc, path: &[Mat3], dt: f64) -> (usize, driver::Response) {
        let r = driver::run(m, path, dt);
        let mut yielding = 0;
        for k in 1..path.len() {
            let (h, h_old) = (&r.history[k], &r.history[k - 1]);
            let de = strain_increment(&(path[k] * path[k - 1].try_inverse().unwrap()));
            let f = m.rate_factor(equivalent_rate(&de, dt));
            let p = pressure(&r.stress[k]);
            let sy = m.yield_stress(p, h_old[DAMAGE], f);
            let q = equivalent(&r.stress[k]);
            let d_eps = h[PLASTIC_STRAIN] - h_old[PLASTIC_STRAIN];
            if d_eps > 0.0 {
                yielding += 1;
                assert!((q - sy).abs() <= 1e-9 * sy.max(1.0), "step {k}: σ̄ {q} vs σ_y {sy}");
            } else {
                assert!(q <= sy * (1.0 + 1e-9) + 1e-12, "step {k}: σ̄ {q} outside σ_y {sy}");
            }
            let d_mu = (h[PLASTIC_VOLUME] - h_old[PLASTIC_VOLUME]).max(0.0);
            let expected = (h_old[DAMAGE] + (d_eps + d_mu) / m.fracture_strain(p)).min(1.0);
            assert!((h[DAMAGE] - expected).abs() < 1e-12, "step {k}: D {}", h[DAMAGE]);
        }
        (yielding, r)
    }

    #[test]
    fn thesis_element_compressed_follows_the_strength_and_damage_laws() {
        let m = thesis();
        let path = uniaxial((0..=1000).map(|k| -0.03 * k as f64 / 1000.0));
        let (yielding, r) = check_path(&m, &path, 1e-4);
        assert!(yielding > 500, "{yielding} yielding steps");
        // Linear EOS: p = 16e3 μ at every step.
        for (f, s) in path.iter().zip(&r.stress) {
            let mu = 1.0 / f.determinant() - 1.0;
            assert!((pressure(s) - 16e3 * mu).abs() < 1e-9 * (1.0 + 16e3 * mu));
        }
        let d = r.history.last().unwrap()[DAMAGE];
        assert!(d > 0.01 && d < 1.0, "D {d}");
    }

    #[test]
    fn tension_is_cut_off_without_damage_and_weakens_the_strength() {
        // Uniaxial extension: the pressure falls to the cut-off −(1 − D) T and stays
        // there; on the way, σ_y = f_c A (1 − D + p/T) F falls with tension (the
        // thesis' sign; LS-DYNA's −A p/T would raise it).
        let m = thesis();
        let path = uniaxial((0..=400).map(|k| 0.002 * k as f64 / 400.0));
        let (yielding, r) = check_path(&m, &path, 1e-4);
        assert!(yielding > 10, "{yielding}");
        let last = r.stress.len() - 1;
        let d = r.history[last][DAMAGE];
        let cut = -(1.0 - r.history[last - 1][DAMAGE]) * 4.0;
        assert!((pressure(&r.stress[last]) - cut).abs() < 1e-9, "p {}", pressure(&r.stress[last]));
        assert!(d < 1.0);
        let f = m.rate_factor(0.0);
        assert!(m.yield_stress(-2.0, 0.0, f) < m.yield_stress(0.0, 0.0, f));
        assert_eq!(m.yield_stress(-4.0, 0.0, 1.0), 0.0);
    }

    #[test]
    fn crushing_alone_damages_the_concrete() {
        // The 48 MPa concrete with its compaction EOS, compressed hydrostatically:
        // no deviator, so D = Σ Δμ_p / ε_f.
        let m = Hjc {
            eos: Compaction::new((16.0, 0.001), (800.0, 0.1), (85e3, -171e3, 208e3)).unwrap(),
            ..thesis()
        };
        let path = hydrostatic(0.98, 400);
        let (yielding, r) = check_path(&m, &path, 0.0);
        assert_eq!(yielding, 0);
        let h = r.history.last().unwrap();
        assert!(h[PLASTIC_VOLUME] > 0.0 && h[DAMAGE] > 0.0, "{h:?}");
        assert!(h[PLASTIC_STRAIN] == 0.0);
    }

    #[test]
    fn the_strength_is_capped_at_s_max() {
        let m = thesis();
        // B p*^N alone passes S_max = 7 above p* = (7/1.6)^(1/0.61) ≈ 11.2.
        assert_eq!(m.yield_stress(48.0 * 20.0, 0.0, 1.0), 48.0 * 7.0);
        let below = 48.0 * (0.79 + 1.6 * 2f64.powf(0.61));
        assert!((m.yield_stress(96.0, 0.0, 1.0) - below).abs() < 1e-12);
    }

    #[test]
    fn a_failed_point_opened_in_tension_keeps_the_wave_speed_of_the_intact_density() {
        let m = thesis();
        let (intact, failed) = ([0.0, 0.5, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]);
        // Intact: c² = (K + 4GJ/3)/ρ₀ grows with J through ρ = ρ₀/J.
        let c1 = m.wave_speed(1.0, &intact);
        let k = m.eos.stiffness(0.0);
        assert!((c1 * c1 * m.density / (k + 4.0 / 3.0 * m.shear_modulus) - 1.0).abs() < 1e-12);
        assert!(m.wave_speed(1.2, &intact) > c1);
        // Failed (D = 1) ejecta opened to J = 400 carry no stress: not c ∝ √J.
        let opened = m.wave_speed(400.0, &failed);
        assert!((opened / m.wave_speed(1.0, &failed) - 1.0).abs() < 1e-12, "{opened} {c1}");
        // Compressed, a failed point stiffens like an intact one.
        assert_eq!(m.wave_speed(0.9, &failed), m.wave_speed(0.9, &intact));
    }
}
