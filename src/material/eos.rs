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
                Eos::polynomial(p)
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

    /// The polynomial EOS of keys k1 (required, > 0), k2, k3 (default 0), whose
    /// compression branch must rise over the range a run reaches (μ ≤ 1).
    pub fn polynomial(p: &Parameters) -> Result<Eos, KeyError> {
        let k1 = p.positive("k1")?;
        let k2: f64 = p.get("k2")?.unwrap_or(0.0);
        let k3: f64 = p.get("k3")?.unwrap_or(0.0);
        let eos = Eos::Polynomial { k1, k2, k3 };
        let monotone = (0..=100).all(|i| eos.tangent(i as f64 / 100.0) > 0.0);
        p.ensure(
            monotone,
            "k2",
            "with these k1, k2, k3 the pressure falls with compression for some μ in [0, 1]",
        )?;
        Ok(eos)
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

/// The HJC three-regime compaction EOS (thesis `000_…` 4-1…4-10, Holmquist,
/// Johnson & Cook 1993), whose state is the largest compression reached μ_max and
/// the plastic volumetric strain μ_p:
/// - elastic, μ_max ≤ μ_crush: p = K_el μ, K_el = P_crush/μ_crush (4-1, 4-2);
/// - crushing (loading, μ = μ_max < μ_plock): the straight line
///   p = (1 − F) P_crush + F P_lock, F = (μ_max − μ_crush)/(μ_plock − μ_crush)
///   (4-6, 4-7), and μ_p from μ̄ = (μ − μ_p)/(1 + μ_p) = p/((1 − F) K_el + F K1) (4-8);
/// - unloading or reloading inside the crushing range: with μ̄ from the stored μ_p,
///   p = (1 − F) K_el μ̄ + F (K1 μ̄ + K2 μ̄² + K3 μ̄³) (K1 μ̄ alone for μ̄ < 0) (4-9);
/// - locked, μ_max ≥ μ_plock: p = K1 μ̄ + K2 μ̄² + K3 μ̄³ (K1 μ̄ for μ̄ < 0) with
///   μ̄ = (μ − μ_lock)/(1 + μ_lock) (4-4, 4-5), μ_plock where this reaches P_lock.
///
/// The tension cut-off p ≥ −(1 − D) T (4-10) belongs to the strength model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compaction {
    pub crush_pressure: f64,
    pub crush_strain: f64,
    pub lock_pressure: f64,
    pub lock_strain: f64,
    pub k1: f64,
    pub k2: f64,
    pub k3: f64,
    /// μ at which the locked branch reaches P_lock.
    pub plock_strain: f64,
}

/// The compaction state after an update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompactionState {
    pub pressure: f64,
    pub max_strain: f64,
    pub plastic_strain: f64,
}

impl Compaction {
    /// The EOS, μ_plock found from K1 x + K2 x² + K3 x³ = P_lock (Newton from the
    /// linear guess). `None` if that has no root in (0, 1] with a rising curve.
    pub fn new(
        (crush_pressure, crush_strain): (f64, f64),
        (lock_pressure, lock_strain): (f64, f64),
        (k1, k2, k3): (f64, f64, f64),
    ) -> Option<Compaction> {
        let poly = |x: f64| x * (k1 + x * (k2 + x * k3));
        let slope = |x: f64| k1 + x * (2.0 * k2 + 3.0 * x * k3);
        let mut x = lock_pressure / k1;
        for _ in 0..100 {
            let step = (poly(x) - lock_pressure) / slope(x);
            x -= step;
            if step.abs() <= 1e-15 * x.abs() {
                break;
            }
        }
        let ok = x > 0.0 && x <= 1.0 && (poly(x) / lock_pressure - 1.0).abs() < 1e-12;
        let ok = ok && (0..=100).all(|i| slope(x * i as f64 / 100.0) > 0.0);
        let plock_strain = x * (1.0 + lock_strain) + lock_strain;
        (ok && plock_strain > crush_strain).then_some(Compaction {
            crush_pressure,
            crush_strain,
            lock_pressure,
            lock_strain,
            k1,
            k2,
            k3,
            plock_strain,
        })
    }

    fn elastic_modulus(&self) -> f64 {
        self.crush_pressure / self.crush_strain
    }

    /// K1 μ̄ + K2 μ̄² + K3 μ̄³ (μ̄ ≥ 0), K1 μ̄ (μ̄ < 0).
    fn locked(&self, mu_bar: f64) -> f64 {
        if mu_bar >= 0.0 {
            mu_bar * (self.k1 + mu_bar * (self.k2 + mu_bar * self.k3))
        } else {
            self.k1 * mu_bar
        }
    }

    /// F of the largest compression reached.
    fn compaction(&self, max_strain: f64) -> f64 {
        ((max_strain - self.crush_strain) / (self.plock_strain - self.crush_strain)).clamp(0.0, 1.0)
    }

    /// p, μ_max and μ_p at μ from the state before.
    pub fn update(&self, mu: f64, max_old: f64, plastic_old: f64) -> CompactionState {
        let max_strain = max_old.max(mu);
        let state = |pressure, plastic_strain| CompactionState {
            pressure,
            max_strain,
            plastic_strain,
        };
        let k_el = self.elastic_modulus();
        if max_strain <= self.crush_strain {
            return state(k_el * mu, 0.0);
        }
        if max_strain >= self.plock_strain {
            let mu_bar = (mu - self.lock_strain) / (1.0 + self.lock_strain);
            return state(self.locked(mu_bar), self.lock_strain);
        }
        let f = self.compaction(max_strain);
        if mu >= max_old {
            // Crushing: along the line, μ_p from (4-8).
            let p = (1.0 - f) * self.crush_pressure + f * self.lock_pressure;
            let mu_bar = p / ((1.0 - f) * k_el + f * self.k1);
            let plastic = ((mu - mu_bar) / (1.0 + mu_bar)).max(plastic_old);
            return state(p, plastic);
        }
        let mu_bar = (mu - plastic_old) / (1.0 + plastic_old);
        state(
            (1.0 - f) * k_el * mu_bar + f * self.locked(mu_bar),
            plastic_old,
        )
    }

    /// ∂p/∂μ on the current branch (for the wave speed): the largest of the
    /// elastic, unloading and locked moduli at μ.
    pub fn stiffness(&self, mu: f64) -> f64 {
        let h = 1e-7;
        let locked = (self.locked(mu + h) - self.locked(mu - h)) / (2.0 * h);
        self.elastic_modulus().max(self.k1).max(locked)
    }
}

/// E_new of the energy equation dE = dW_dev − p dJ (per reference volume) with
/// the trapezoidal rule and p_new = a + b E_new, solved in closed form:
/// E_new = (E_old + ΔW_dev − ½(p_old + a) ΔJ) / (1 + ½ b ΔJ) (Wilkins' scheme).
/// The rule is singular at ΔJ = −2/b, which only a point opened far beyond its
/// reference volume and recompressed fast can reach (fragments at J ≫ 1); where
/// 1 + ½ b ΔJ < ½ the exact solution of dE/dJ = −(a + bE) for a, b fixed over
/// the step is used instead: E_new = (E_old + ΔW_dev + a/b) e^{−bΔJ} − a/b.
pub fn energy_update(e_old: f64, dw_dev: f64, p_old: f64, dj: f64, (a, b): (f64, f64)) -> f64 {
    let denominator = 1.0 + 0.5 * b * dj;
    if denominator >= 0.5 {
        (e_old + dw_dev - 0.5 * (p_old + a) * dj) / denominator
    } else {
        (e_old + dw_dev + a / b) * (-b * dj).exp() - a / b
    }
}

/// E_new and p_new for a point whose pressure is bounded, p_min ≤ p ≤ p_max (a
/// tension cut-off below; above, zero for failed material opened beyond its
/// solid density, rubble whose fragments do not touch): the EOS pressure at
/// `energy_update`'s E_new where it is within the bounds; otherwise the point
/// carries the bound, and its energy takes the work of the pressure it carries,
/// E_new = E_old + ΔW_dev − ½(p_old + p_bound) ΔJ (with the EOS pressure there, a
/// point cut off in tension would gain the energy its uncut EOS gives it, and
/// release it as pressure on recompaction; rubble would push itself apart with
/// its Grüneisen term Γ E, which grows without bound as it is recompacted).
pub fn energy_and_pressure(
    e_old: f64,
    dw_dev: f64,
    p_old: f64,
    dj: f64,
    (a, b): (f64, f64),
    (p_min, p_max): (f64, f64),
) -> (f64, f64) {
    let energy = energy_update(e_old, dw_dev, p_old, dj, (a, b));
    let p = a + b * energy;
    if (p_min..=p_max).contains(&p) {
        return (energy, p);
    }
    let bound = p.clamp(p_min, p_max);
    (e_old + dw_dev - 0.5 * (p_old + bound) * dj, bound)
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

    /// The 48 MPa concrete of the HJC literature (MPa): P_crush 16, μ_crush 0.001,
    /// P_lock 800, μ_lock 0.1, K1 85e3, K2 −171e3, K3 208e3.
    fn concrete() -> Compaction {
        Compaction::new((16.0, 0.001), (800.0, 0.1), (85e3, -171e3, 208e3)).unwrap()
    }

    #[test]
    fn compaction_follows_its_three_regimes() {
        let eos = concrete();
        let poly = |x: f64| x * (85e3 + x * (-171e3 + x * 208e3));
        let x = (eos.plock_strain - 0.1) / 1.1;
        assert!(
            (poly(x) / 800.0 - 1.0).abs() < 1e-12,
            "μ_plock {}",
            eos.plock_strain
        );
        // Elastic.
        let s = eos.update(0.0005, 0.0, 0.0);
        assert_eq!((s.pressure, s.plastic_strain), (8.0, 0.0));
        // Crushing: on the line from (μ_crush, P_crush) to (μ_plock, P_lock).
        let (mut max, mut plastic) = (0.0, 0.0);
        let mu_load = 0.05;
        for k in 1..=100 {
            let mu = mu_load * k as f64 / 100.0;
            let s = eos.update(mu, max, plastic);
            if mu > 0.001 {
                let line = 16.0 + (800.0 - 16.0) * (mu - 0.001) / (eos.plock_strain - 0.001);
                assert!((s.pressure / line - 1.0).abs() < 1e-12, "μ {mu}");
                assert!(s.plastic_strain >= plastic, "μ_p falls while crushing");
            }
            (max, plastic) = (s.max_strain, s.plastic_strain);
        }
        assert!(plastic > 0.0);
        // Unloading: μ_p kept, the pressure vanishes at μ = μ_p and the
        // reloading curve passes the crushing point again.
        let s = eos.update(plastic, max, plastic);
        assert!(s.pressure.abs() < 1e-12 && s.plastic_strain == plastic);
        let back = eos.update(mu_load - 1e-12, max, plastic);
        let line = 16.0 + (800.0 - 16.0) * (mu_load - 0.001) / (eos.plock_strain - 0.001);
        assert!(
            (back.pressure / line - 1.0).abs() < 0.05,
            "{} vs {line}",
            back.pressure
        );
        // Locked.
        let mu = eos.plock_strain + 0.02;
        let s = eos.update(mu, max, plastic);
        assert!((s.pressure - poly((mu - 0.1) / 1.1)).abs() < 1e-9);
        assert_eq!(s.plastic_strain, 0.1);
        // With μ_lock = 0 and K_el = K1 (thesis Table 4.1) it is p = K1 μ throughout.
        let linear = Compaction::new((16.0, 0.001), (800.0, 0.0), (16e3, 0.0, 0.0)).unwrap();
        let (mut max, mut plastic) = (0.0, 0.0);
        for mu in [0.0005, 0.01, 0.03, 0.02, -0.001, 0.04, 0.06, 0.01] {
            let s = linear.update(mu, max, plastic);
            assert!(
                (s.pressure - 16e3 * mu).abs() < 1e-9,
                "μ {mu}: {}",
                s.pressure
            );
            (max, plastic) = (s.max_strain, s.plastic_strain);
        }
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

    #[test]
    fn a_fast_recompaction_takes_the_exact_solution_instead_of_the_singular_rule() {
        // dE/dJ = −(a + bE) with a, b fixed: E = (E₀ + a/b) e^{−bΔJ} − a/b.
        let (a, b) = (-3.0e4, 1.22);
        let exact = |e0: f64, dj: f64| (e0 + a / b) * (-b * dj).exp() - a / b;
        // ΔJ = −2/b makes the trapezoidal denominator vanish: finite, exact.
        let dj = -2.0 / b;
        let e = energy_update(50.0, 0.0, 0.0, dj, (a, b));
        assert!(
            e.is_finite() && (e / exact(50.0, dj) - 1.0).abs() < 1e-12,
            "{e}"
        );
        // Small steps keep the trapezoidal rule, second-order close to exact.
        for dj in [-1e-2, -1e-3] {
            let e = energy_update(50.0, 0.0, a + b * 50.0, dj, (a, b));
            let error = (e - exact(50.0, dj)).abs() / (a.abs() * dj.abs());
            assert!(error < 0.1 * (b * dj).powi(2), "ΔJ {dj}: {error}");
        }
    }

    #[test]
    fn a_point_cut_off_in_tension_takes_the_work_of_the_pressure_it_carries() {
        let (a, b) = (-3.0e4 * 0.2, 1.22);
        let (e_old, p_old, dj) = (100.0, 0.0, 0.05);
        // The EOS would give a + bE ≪ 0: the point carries p_min = 0 and no work.
        let (e, p) = energy_and_pressure(e_old, 0.0, p_old, dj, (a, b), (0.0, f64::INFINITY));
        assert_eq!((e, p), (e_old, 0.0));
        // Above the cut-off: the EOS pressure and the trapezoidal energy.
        let (e, p) = energy_and_pressure(
            e_old,
            0.0,
            p_old,
            dj,
            (a, b),
            (f64::NEG_INFINITY, f64::INFINITY),
        );
        assert_eq!(e, energy_update(e_old, 0.0, p_old, dj, (a, b)));
        assert_eq!(p, a + b * e);
        // A cut-off at −T: the energy of p = −T over ΔJ.
        let (e, p) = energy_and_pressure(e_old, 0.0, -4.0, dj, (a, b), (-4.0, f64::INFINITY));
        assert_eq!(p, -4.0);
        assert!((e - (e_old + 4.0 * dj)).abs() < 1e-12);
        // Rubble (p_max = 0) with a large Grüneisen energy: no pressure, and the
        // energy keeps the work of the pressure it had.
        let (e, p) = energy_and_pressure(1e5, 0.0, 0.0, -0.5, (a, b), (0.0, 0.0));
        assert_eq!((e, p), (1e5, 0.0));
    }
}
