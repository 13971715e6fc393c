//! Modified Cam-Clay at finite strain (Roscoe & Burland 1968), on the Hencky
//! kinematics of `return_mapping.rs` (multiplicative split, exponential map,
//! principal Kirchhoff stresses), with the return mapping of Borja & Lee (1990)
//! and Borja (1991) in the finite-strain form of Borja & Tamagnini (1998): a
//! Newton iteration on the elastic volumetric strain and the plastic multiplier.
//!
//! Invariants of the Kirchhoff stress τ (tension positive): p = −tr τ/3
//! (compression positive), s = τ + p I, q = √(3/2) |s|. Logarithmic strains,
//! volumetric ε_v compression positive. With the modified indices
//! λ̃ = λ/(1 + e0), κ̃ = κ/(1 + e0) (the e–ln p′ slopes over the initial specific
//! volume v0 = 1 + e0; Borja & Tamagnini 1998 eq. 2.3):
//!
//! - elasticity: p = p_r exp(ε_v^e/κ̃), so K = ∂p/∂ε_v^e = p/κ̃ = v0 p/κ;
//!   s = 2G e^e with a constant Poisson's ratio ν, G = 3K(1 − 2ν)/(2(1 + ν)).
//!   The law is invertible (the elastic state is recovered from the stress, as
//!   in `return_mapping.rs`) but not hyperelastic: with ν constant G varies with
//!   p, and the tangent is unsymmetric (Zytynski et al. 1978). The reference p_r
//!   is the pre-consolidation pressure at the start of the increment; every
//!   result is independent of it (only differences of ε_v^e enter).
//! - yield surface (Roscoe & Burland 1968): f = q²/M² + p (p − p_c) = 0;
//!   associated flow Δε^p = Δγ ∂f/∂τ: Δε_v^p = Δγ (2p − p_c),
//!   Δε_s^p = Δγ 2q/M² (Borja 1991 eq. 12);
//! - hardening: p_c = p_c,n exp(Δε_v^p/(λ̃ − κ̃)) (Borja 1991 eq. 8).
//!
//! # Return mapping
//!
//! Trial: ε_v^tr = −tr ε^tr, e^tr = dev ε^tr, S = (ε_s^tr)² = (2/3) e^tr:e^tr.
//! The deviatoric return is radial: s = 2H e^tr with H = G(p)/(1 + 6G(p)Δγ/M²).
//! Two unknowns u = ε_v^e and Δγ solve (Borja 1991 eqs. 17–19, the deviatoric
//! one eliminated):
//!
//!   R1 = u − ε_v^tr + Δγ (2p − p_c) = 0,   R2 = f(p, q = 3H√S, p_c) = 0,
//!
//! with p = p_r exp(u/κ̃) and p_c = p_c,n exp((ε_v^tr − u)/(λ̃ − κ̃)), by Newton's
//! method from the trial state (backtracking on the scaled residual).
//!
//! # Consistent tangent
//!
//! (du, dΔγ) = −J⁻¹ ∂R/∂(ε_v^tr, S) (d ε_v^tr, dS) with J = ∂R/∂(u, Δγ), and
//! D_ab = ∂τ_a/∂ε_b = −∂p/∂ε_b + 2 e^tr_a ∂H/∂ε_b + 2H (δ_ab − 1/3)
//! (Borja 1991 eq. 26 in principal form); the elastic tangent is the same with
//! Δγ = 0. `return_mapping::stress_derivative` carries it to ∂σ/∂ΔF.
//!
//! # Initial state
//!
//! p_c,0 is `preconsolidation_pressure`, or `ocr` times the size of the yield
//! surface through the initial stress, p + q²/(M² p) (for an isotropic stress
//! OCR p′0; a K0 state with OCR = 1 lies on the surface). A given p_c,0 below the
//! surface through the initial stress is raised to it. `Material::initial_history`
//! sets it from the particle's initial stress (geostatic, a particle file's); a
//! point whose history was never initialised (p_c = 0) is initialised the same
//! way from the start stress of its first increment. At zero mean stress the
//! material has no stiffness (K = p/κ̃) and stays unstressed.
//!
//! History: ε̄p (the accumulated plastic shear strain Σ Δε_s^p), p_c, ε_v^p.
//!
//! Strength reduction reduces tan φ_cs, with M = 6 sin φ_cs/(3 − sin φ_cs)
//! (triaxial compression): M_F = 6 sin φ_F/(3 − sin φ_F), tan φ_F = tan φ_cs/F.
//!
//! Scene keys: lambda, kappa, critical_state_ratio, poisson_ratio,
//! initial_void_ratio, and one of preconsolidation_pressure, ocr.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::return_mapping::{self, Principal, PrincipalTangent, Return, ReturnMapping};
use super::{reduced_angle, Increment, Material, Strength, StressDerivative};
use crate::dim::Mat3;
use nalgebra::{Matrix2, Vector2};

/// History slots.
const EQUIVALENT_PLASTIC_STRAIN: usize = 0;
const PRECONSOLIDATION: usize = 1;
const PLASTIC_VOLUMETRIC_STRAIN: usize = 2;

/// How the initial pre-consolidation pressure is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Preconsolidation {
    /// p_c,0 itself.
    Pressure(f64),
    /// The over-consolidation ratio OCR ≥ 1 of the surface through the initial stress.
    Ratio(f64),
}

/// Modified Cam-Clay: pressure-dependent elasticity, elliptical yield surface,
/// volumetric hardening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModifiedCamClay {
    /// Reference mass density ρ0.
    pub density: f64,
    /// Compression index λ (slope of the normal compression line in e–ln p′).
    pub lambda: f64,
    /// Swelling index κ, 0 < κ < λ.
    pub kappa: f64,
    /// Critical-state ratio M = q/p′ at critical state, 0 < M < 3.
    pub critical_state_ratio: f64,
    /// Poisson's ratio ν (constant; G follows K).
    pub poisson_ratio: f64,
    /// Initial void ratio e0 (v0 = 1 + e0).
    pub initial_void_ratio: f64,
    pub preconsolidation: Preconsolidation,
}

/// Mean pressure p = −tr τ/3 and deviator s of a stress.
fn invariants(tau: &Mat3) -> (f64, Mat3) {
    let p = -tau.trace() / 3.0;
    (p, tau + Mat3::identity() * p)
}

/// The state of the local problem at (u, Δγ), with its residual and derivatives.
struct Local {
    p: f64,
    pc: f64,
    /// H = G/(1 + 6GΔγ/M²) and its derivatives in u and Δγ.
    h: f64,
    h_u: f64,
    h_gamma: f64,
    /// (R1, R2).
    r: Vector2<f64>,
    /// ∂R/∂(u, Δγ).
    jacobian: Matrix2<f64>,
    /// ∂R/∂(ε_v^tr, S).
    r_trial: Matrix2<f64>,
}

impl ModifiedCamClay {
    /// κ̃ = κ/v0.
    fn kappa_tilde(&self) -> f64 {
        self.kappa / (1.0 + self.initial_void_ratio)
    }

    /// λ̃ − κ̃ = (λ − κ)/v0.
    fn plastic_index(&self) -> f64 {
        (self.lambda - self.kappa) / (1.0 + self.initial_void_ratio)
    }

    /// G/p = 3(1 − 2ν)/(2(1 + ν) κ̃): G = 3K(1 − 2ν)/(2(1 + ν)), K = p/κ̃.
    fn shear_per_pressure(&self) -> f64 {
        let nu = self.poisson_ratio;
        3.0 * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu) * self.kappa_tilde())
    }

    /// P-wave modulus K + 4G/3 at mean pressure p.
    fn p_wave_modulus_at(&self, p: f64) -> f64 {
        p / self.kappa_tilde() + 4.0 / 3.0 * self.shear_per_pressure() * p
    }

    /// f = q²/M² + p (p − p_c) (Roscoe & Burland 1968).
    pub fn yield_function(&self, p: f64, q: f64, pc: f64) -> f64 {
        let m = self.critical_state_ratio;
        q * q / (m * m) + p * (p - pc)
    }

    /// The size of the yield surface through (p, q): p + q²/(M² p).
    fn surface_through(&self, p: f64, q: f64) -> f64 {
        let m = self.critical_state_ratio;
        p + q * q / (m * m * p)
    }

    /// p_c,0 of a point whose initial (Kirchhoff) stress is `tau` (module documentation).
    pub fn initial_preconsolidation(&self, tau: &Mat3) -> f64 {
        let (p, s) = invariants(tau);
        if p <= 0.0 {
            return 0.0;
        }
        let through = self.surface_through(p, (1.5 * s.norm_squared()).sqrt());
        match self.preconsolidation {
            Preconsolidation::Pressure(pc) => pc.max(through),
            Preconsolidation::Ratio(ocr) => ocr * through,
        }
    }

    /// M reduced by tan φ_cs/F (module documentation).
    pub fn reduced_ratio(&self, factor: f64) -> f64 {
        let phi = reduced_angle(self.critical_state_angle(), factor);
        6.0 * phi.sin() / (3.0 - phi.sin())
    }

    /// φ_cs of M = 6 sin φ/(3 − sin φ): sin φ = 3M/(6 + M).
    pub fn critical_state_angle(&self) -> f64 {
        let m = self.critical_state_ratio;
        (3.0 * m / (6.0 + m)).asin()
    }

    /// The local problem at (u, Δγ) for the trial (ε_v^tr, S) from p_c,n = p_r.
    fn local(&self, pc_n: f64, ev_trial: f64, s: f64, u: f64, gamma: f64) -> Local {
        let m2 = self.critical_state_ratio.powi(2);
        let (a, b) = (1.0 / self.kappa_tilde(), 1.0 / self.plastic_index());
        let p = pc_n * (u * a).exp(); // p = p_r exp(ε_v^e/κ̃)
        let pc = pc_n * ((ev_trial - u) * b).exp(); // p_c = p_c,n exp(Δε_v^p/(λ̃ − κ̃))
        let g = self.shear_per_pressure() * p;
        let d = 1.0 + 6.0 * g * gamma / m2;
        let h = g / d;
        let (h_u, h_gamma) = (a * g / (d * d), -6.0 * h * h / m2);
        let df_dp = 2.0 * p - pc;
        let q2 = 9.0 * h * h * s;
        let r = Vector2::new(u - ev_trial + gamma * df_dp, q2 / m2 + p * (p - pc));
        let dq2 = 18.0 * h * s / m2; // ∂(q²/M²)/∂H
        let jacobian = Matrix2::new(
            1.0 + gamma * (2.0 * a * p + b * pc),
            df_dp,
            dq2 * h_u + df_dp * a * p + p * b * pc,
            dq2 * h_gamma,
        );
        let r_trial = Matrix2::new(
            -1.0 - gamma * b * pc,
            0.0,
            -p * b * pc,
            9.0 * h * h / m2,
        );
        Local {
            p,
            pc,
            h,
            h_u,
            h_gamma,
            r,
            jacobian,
            r_trial,
        }
    }

    /// u(Δγ), the root of R1 (increasing in u for Δγ ≥ 0), by Newton's method
    /// kept inside a bracket (bisection when a step leaves it).
    fn elastic_volumetric(&self, pc_n: f64, ev_trial: f64, s: f64, gamma: f64) -> f64 {
        let r1 = |u: f64| self.local(pc_n, ev_trial, s, u, gamma);
        let step = self.kappa_tilde();
        let (mut lo, mut hi) = (ev_trial, ev_trial);
        while r1(lo).r[0] > 0.0 {
            lo -= step * (ev_trial - lo + 1.0);
        }
        while r1(hi).r[0] < 0.0 {
            hi += step * (hi - ev_trial + 1.0);
        }
        let mut u = 0.5 * (lo + hi);
        for _ in 0..200 {
            let l = r1(u);
            if l.r[0] == 0.0 {
                break;
            }
            if l.r[0] > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            let newton = u - l.r[0] / l.jacobian[(0, 0)];
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - u).abs() <= 1e-16 * (1.0 + u.abs()) {
                return next;
            }
            u = next;
        }
        u
    }

    /// f along Δγ ↦ (u(Δγ), Δγ) and its derivative dR2/dΔγ + ∂R2/∂u du/dΔγ.
    fn yield_along(&self, pc_n: f64, ev_trial: f64, s: f64, gamma: f64) -> (f64, f64, f64) {
        let u = self.elastic_volumetric(pc_n, ev_trial, s, gamma);
        let l = self.local(pc_n, ev_trial, s, u, gamma);
        let du = -l.jacobian[(0, 1)] / l.jacobian[(0, 0)];
        (l.r[1], l.jacobian[(1, 1)] + l.jacobian[(1, 0)] * du, u)
    }

    /// (u, Δγ) on the yield surface: R1 solved for u at each Δγ, and f(Δγ) = 0
    /// by Newton's method inside a bracket [0, Δγ_hi] (f > 0 at Δγ = 0, and
    /// f → −p_c²/4 as Δγ → ∞), bisection when a step leaves it.
    fn solve(&self, pc_n: f64, ev_trial: f64, s: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (0.0, 1.0 / pc_n);
        while self.yield_along(pc_n, ev_trial, s, hi).0 > 0.0 {
            (lo, hi) = (hi, 2.0 * hi);
        }
        let mut gamma = lo;
        for _ in 0..200 {
            let (f, df, u) = self.yield_along(pc_n, ev_trial, s, gamma);
            if f.abs() <= 1e-15 * pc_n * pc_n {
                return (u, gamma);
            }
            if f > 0.0 {
                lo = gamma;
            } else {
                hi = gamma;
            }
            let newton = gamma - f / df;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - gamma).abs() <= 1e-15 * gamma {
                return (self.elastic_volumetric(pc_n, ev_trial, s, next), next);
            }
            gamma = next;
        }
        (self.elastic_volumetric(pc_n, ev_trial, s, gamma), gamma)
    }

    /// Principal stresses τ_a = −p + 2H e_a and D_ab for the trial deviator `e`
    /// and the local solution, with (du, dΔγ)/d(ε_v^tr, S) = `dy`.
    fn stress_and_tangent(&self, e: &Principal, l: &Local, dy: &Matrix2<f64>) -> Return {
        let one = Principal::repeat(1.0);
        let tau = e * (2.0 * l.h) - one * l.p;
        // dε_v^tr/dε_b = −1, dS/dε_b = (4/3) e_b.
        let d_of = |row: usize| -one * dy[(row, 0)] + e * (4.0 / 3.0 * dy[(row, 1)]);
        let (du, dgamma) = (d_of(0), d_of(1));
        let dp = du * (l.p / self.kappa_tilde());
        let dh = du * l.h_u + dgamma * l.h_gamma;
        let projector = PrincipalTangent::identity() - PrincipalTangent::repeat(1.0 / 3.0);
        let tangent = -one * dp.transpose() + e * (2.0 * dh).transpose() + projector * (2.0 * l.h);
        Return { tau, tangent }
    }

    /// The history at the start of an increment, p_c initialised from the start
    /// stress if it never was.
    fn start_history(&self, inc: &Increment) -> [f64; 3] {
        let mut h = [0.0; 3];
        h.copy_from_slice(inc.history_old);
        if h[PRECONSOLIDATION] <= 0.0 {
            let tau = inc.stress_old * inc.f_old.determinant();
            h[PRECONSOLIDATION] = self.initial_preconsolidation(&tau);
        }
        h
    }
}

impl ReturnMapping for ModifiedCamClay {
    /// ε^e = −(κ̃/3) ln(p/p_r) I + s/(2G(p)), p_r = p_c,n.
    fn elastic_strain(&self, tau: &Mat3, history: &[f64]) -> Mat3 {
        let (p, s) = invariants(tau);
        let volumetric = self.kappa_tilde() * (p / history[PRECONSOLIDATION]).ln();
        s / (2.0 * self.shear_per_pressure() * p) - Mat3::identity() * (volumetric / 3.0)
    }

    fn return_map(&self, eps: &Principal, h_old: &[f64], h_new: &mut [f64]) -> Return {
        let pc_n = h_old[PRECONSOLIDATION];
        let ev_trial = -eps.sum();
        let e = eps + Principal::repeat(ev_trial / 3.0);
        let s = 2.0 / 3.0 * e.norm_squared();
        h_new.copy_from_slice(h_old);
        let trial = self.local(pc_n, ev_trial, s, ev_trial, 0.0);
        let q_trial = 3.0 * trial.h * s.sqrt();
        if self.yield_function(trial.p, q_trial, pc_n) <= 1e-12 * pc_n * pc_n {
            return self.stress_and_tangent(&e, &trial, &Matrix2::new(1.0, 0.0, 0.0, 0.0));
        }
        let (u, gamma) = self.solve(pc_n, ev_trial, s);
        let l = self.local(pc_n, ev_trial, s, u, gamma);
        let q = 3.0 * l.h * s.sqrt();
        h_new[PRECONSOLIDATION] = l.pc;
        h_new[PLASTIC_VOLUMETRIC_STRAIN] += ev_trial - u;
        h_new[EQUIVALENT_PLASTIC_STRAIN] +=
            gamma * 2.0 * q / self.critical_state_ratio.powi(2); // Δε_s^p = Δγ ∂f/∂q
        let dy = -l
            .jacobian
            .try_inverse()
            .expect("Modified Cam-Clay: singular local Jacobian")
            * l.r_trial;
        self.stress_and_tangent(&e, &l, &dy)
    }
}

impl FromParameters for ModifiedCamClay {
    const NAME: &'static str = "modified_cam_clay";
    const KEYS: &'static [&'static str] = &[
        "lambda",
        "kappa",
        "critical_state_ratio",
        "poisson_ratio",
        "initial_void_ratio",
        "preconsolidation_pressure",
        "ocr",
    ];
    const EXAMPLE: &'static str = "lambda = 0.2\nkappa = 0.04\ncritical_state_ratio = 1.2\npoisson_ratio = 0.3\ninitial_void_ratio = 1.0\nocr = 2.0";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let lambda = p.positive("lambda")?;
        let kappa = p.positive("kappa")?;
        p.ensure(
            kappa < lambda,
            "kappa",
            format!("must be below lambda = {lambda} (the swelling line is flatter than the normal compression line); got {kappa}"),
        )?;
        let m: f64 = p.positive("critical_state_ratio")?;
        p.ensure(
            m < 3.0,
            "critical_state_ratio",
            format!("must lie in (0, 3) (M = 6 sin φ/(3 − sin φ) < 3); got {m}"),
        )?;
        let poisson_ratio = p.poisson_ratio()?;
        let initial_void_ratio = p.positive("initial_void_ratio")?;
        Ok(ModifiedCamClay {
            density,
            lambda,
            kappa,
            critical_state_ratio: m,
            poisson_ratio,
            initial_void_ratio,
            preconsolidation: preconsolidation(p)?,
        })
    }
}

/// Exactly one of `preconsolidation_pressure` (> 0) and `ocr` (≥ 1).
fn preconsolidation(p: &Parameters) -> Result<Preconsolidation, KeyError> {
    let (pressure, ocr) = (p.given("preconsolidation_pressure"), p.given("ocr"));
    p.ensure(
        !(pressure && ocr),
        "ocr",
        "give either ocr or preconsolidation_pressure, not both",
    )?;
    if pressure {
        return Ok(Preconsolidation::Pressure(
            p.positive("preconsolidation_pressure")?,
        ));
    }
    let ocr: f64 = p.required_for(
        "ocr",
        &format!("{} (or give preconsolidation_pressure)", p.what()),
    )?;
    p.ensure(
        ocr >= 1.0 && ocr.is_finite(),
        "ocr",
        format!("must be ≥ 1 (a stress beyond the pre-consolidation pressure would lie outside the yield surface); got {ocr}"),
    )?;
    Ok(Preconsolidation::Ratio(ocr))
}

impl ModifiedCamClay {
    /// The increment with its start history initialised, or `None` at zero
    /// mean stress (no stiffness: the point stays unstressed).
    fn prepared<'a>(&self, inc: &Increment, history: &'a [f64; 3]) -> Option<Increment<'a>> {
        let (p, _) = invariants(&inc.stress_old);
        (p > 0.0 && history[PRECONSOLIDATION] > 0.0).then(|| {
            Increment::new(inc.f_old, inc.df, inc.dt, inc.stress_old, history)
        })
    }
}

impl Material for ModifiedCamClay {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn n_history(&self) -> usize {
        3
    }

    fn initial_history(&self, stress: &Mat3, history: &mut [f64]) {
        history[PRECONSOLIDATION] = self.initial_preconsolidation(stress);
    }

    fn update(&self, inc: &Increment, history_new: &mut [f64]) -> Mat3 {
        let start = self.start_history(inc);
        match self.prepared(inc, &start) {
            Some(i) => return_mapping::update(self, &i, history_new),
            None => {
                history_new.copy_from_slice(&start);
                Mat3::zeros()
            }
        }
    }

    /// At p = p_c,0 when given, else 0 (with `ocr` no pressure is known before
    /// the stresses are; the explicit step uses `wave_speed`, which reads p_c).
    fn p_wave_modulus(&self) -> f64 {
        match self.preconsolidation {
            Preconsolidation::Pressure(pc) => self.p_wave_modulus_at(pc),
            Preconsolidation::Ratio(_) => 0.0,
        }
    }

    /// c = √(M(p_c) J/ρ0): inside the yield surface p ≤ p_c.
    fn wave_speed(&self, j: f64, history: &[f64]) -> f64 {
        let pc = history[PRECONSOLIDATION];
        let pc = if pc > 0.0 { pc } else { self.p_wave_modulus() };
        (self.p_wave_modulus_at(pc) * j / self.density).sqrt()
    }

    /// (κ̃ p + q²/(6G))/J: the work of unloading to zero stress along the
    /// elastic law at the current shear modulus.
    fn strain_energy_density(&self, f: &Mat3, stress: &Mat3, _history: &[f64]) -> f64 {
        let j = f.determinant();
        let (p, s) = invariants(&(stress * j));
        if p <= 0.0 {
            return 0.0;
        }
        let q2 = 1.5 * s.norm_squared();
        (self.kappa_tilde() * p + q2 / (6.0 * self.shear_per_pressure() * p)) / j
    }

    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let start = self.start_history(inc);
        match self.prepared(inc, &start) {
            Some(i) => return_mapping::stress_derivative(self, &i),
            None => Some(StressDerivative::zeros()),
        }
    }

    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    /// φ_cs, for Jáky's K0 = 1 − sin φ_cs of a normally consolidated soil.
    fn frictional_strength(&self) -> Option<Strength> {
        Some(Strength {
            cohesion: 0.0,
            friction_angle: self.critical_state_angle(),
            dilation_angle: 0.0,
        })
    }

    fn with_reduced_strength(&self, factor: f64) -> Option<Box<dyn Material>> {
        Some(Box::new(ModifiedCamClay {
            critical_state_ratio: self.reduced_ratio(factor),
            ..*self
        }))
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        history.first().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::testing::{assert_refused_at_keys, increment, rotated};

    const P0: f64 = 2.0e5;

    fn model(ocr: f64) -> ModifiedCamClay {
        ModifiedCamClay {
            density: 1800.0,
            lambda: 0.2,
            kappa: 0.04,
            critical_state_ratio: 1.2,
            poisson_ratio: 0.3,
            initial_void_ratio: 1.0,
            preconsolidation: Preconsolidation::Ratio(ocr),
        }
    }

    /// p, q and f of a Cauchy stress at volume ratio J, with p_c.
    fn state(m: &ModifiedCamClay, sigma: &Mat3, j: f64, pc: f64) -> (f64, f64, f64) {
        let (p, s) = invariants(&(sigma * j));
        let q = (1.5 * s.norm_squared()).sqrt();
        (p, q, m.yield_function(p, q, pc))
    }

    /// A rotated, stretched F_old and a compressive start stress with shear
    /// (q ≈ 0.28 p), its history initialised at `ocr`.
    fn start(m: &ModifiedCamClay) -> (Mat3, Mat3, [f64; 3]) {
        let f_old = driver::rotation_z(0.4)
            * Mat3::new(1.01, 0.002, 0.0, 0.0, 0.995, 0.001, 0.0, 0.0, 0.998);
        let s = Mat3::new(
            -2.2e5, 1.0e4, 2.0e3, 1.0e4, -1.8e5, -3.0e3, 2.0e3, -3.0e3, -2.0e5,
        );
        let mut h = [0.0; 3];
        m.initial_history(&(s * f_old.determinant()), &mut h);
        (f_old, s, h)
    }

    #[test]
    fn tangent_matches_finite_differences_in_loading_and_unloading() {
        // (OCR, expected state, principal stretches of ΔF).
        let cases = [
            (1.0, "elastic", [1.0 + 2e-3, 1.0 + 1e-3, 1.0 + 1.5e-3]),
            (1.0, "plastic", [1.0 - 2e-3, 1.0 - 1e-3, 1.0 - 1.5e-3]),
            (1.0, "plastic", [1.0 - 2e-2, 1.0 + 1e-2, 1.0 + 1e-2]),
            (4.0, "elastic", [1.0 - 2e-3, 1.0 + 1e-3, 1.0 - 1e-3]),
            (4.0, "plastic", [1.0 - 6e-2, 1.0 + 3e-2, 1.0 + 3e-2]),
            (4.0, "plastic", [1.0 - 4e-2, 1.0 + 3e-2, 1.0 + 2e-2]),
        ];
        for (ocr, expect, d) in cases {
            let m = model(ocr);
            let (f_old, s_old, h) = start(&m);
            let i = increment(f_old, rotated(d), s_old, &h);
            let mut h_new = [0.0; 3];
            let sigma = m.update(&i, &mut h_new);
            let got = if h_new[PRECONSOLIDATION] == h[PRECONSOLIDATION] {
                "elastic"
            } else {
                let (_, _, f) = state(&m, &sigma, i.f.determinant(), h_new[PRECONSOLIDATION]);
                assert!(
                    f.abs() < 1e-10 * h_new[PRECONSOLIDATION].powi(2),
                    "on the surface after the return: {f:e}"
                );
                "plastic"
            };
            assert_eq!(got, expect, "OCR {ocr}, ΔF = {d:?}");
            let e = driver::tangent_error(&m, &i, 1e-7);
            eprintln!("MCC OCR {ocr} {got:>7} ΔF {d:?}: tangent vs FD {e:.2e}");
            assert!(e < 1e-6, "OCR {ocr} {got}: tangent vs central FD {e:e} < 1e-6");
        }
    }

    #[test]
    fn isotropic_compression_follows_the_normal_compression_and_swelling_lines() {
        // ln J = −λ̃ ln(p/p0) on the normal compression line (OCR 1), −κ̃ ln(p/p0)
        // back along the swelling line.
        let m = model(1.0);
        let mut h0 = vec![0.0; 3];
        m.initial_history(&(Mat3::identity() * -P0), &mut h0);
        let down = driver::hydrostatic(0.9, 20);
        let loaded = driver::run_from(&m, &down, 0.0, Mat3::identity() * -P0, h0);
        let (lt, kt) = (0.2 / 2.0, 0.04 / 2.0);
        let j = 0.9f64.powi(3);
        // The closed forms hold for the Kirchhoff stress τ = Jσ.
        let p1 = -j * loaded.stress[20].trace() / 3.0;
        let expect = P0 * (-j.ln() / lt).exp();
        let e = (p1 - expect).abs() / expect;
        eprintln!("NCL: p = {p1:.6e}, closed form {expect:.6e}, rel. error {e:.1e}");
        assert!(e < 1e-12, "p on the NCL to 1e-12: {e:e}");
        let pc1 = loaded.history[20][PRECONSOLIDATION];
        assert!((pc1 - p1).abs() < 1e-10 * p1, "p_c = p on the NCL");
        let evp = loaded.history[20][PLASTIC_VOLUMETRIC_STRAIN];
        assert!((evp - (lt - kt) * (p1 / P0).ln()).abs() < 1e-12, "ε_v^p");
        let up: Vec<Mat3> = driver::hydrostatic(0.92 / 0.9, 10)
            .into_iter()
            .map(|f| f * 0.9)
            .collect();
        let unloaded = driver::run_from(
            &m,
            &up,
            0.0,
            loaded.stress[20],
            loaded.history[20].clone(),
        );
        let p2 = -0.92f64.powi(3) * unloaded.stress[10].trace() / 3.0;
        let expect = p1 * (-(0.92f64 / 0.9).powi(3).ln() / kt).exp();
        let e = (p2 - expect).abs() / expect;
        eprintln!("swelling line: p = {p2:.6e}, closed form {expect:.6e}, rel. error {e:.1e}");
        assert!(e < 1e-12, "p on the swelling line to 1e-12: {e:e}");
        assert_eq!(unloaded.history[10][PRECONSOLIDATION], pc1, "elastic unloading");
    }

    #[test]
    fn initial_preconsolidation_from_ocr_and_the_initial_stress() {
        let m = model(2.0);
        let iso = m.initial_preconsolidation(&(Mat3::identity() * -P0));
        assert!((iso - 2.0 * P0).abs() < 1e-9, "isotropic: OCR p′0");
        // K0 = 0.5: OCR 1 puts the state on the surface.
        let k0 = Mat3::from_diagonal(&[-0.5 * P0, -0.5 * P0, -P0].into());
        let nc = model(1.0);
        let pc = nc.initial_preconsolidation(&k0);
        let (_, _, f) = state(&nc, &k0, 1.0, pc);
        assert!(f.abs() < 1e-12 * pc * pc, "K0 state on the surface at OCR 1: f = {f:e}");
        let given = ModifiedCamClay {
            preconsolidation: Preconsolidation::Pressure(1.0e5),
            ..nc
        };
        assert_eq!(given.initial_preconsolidation(&k0), pc, "raised to the surface");
        assert_eq!(m.initial_preconsolidation(&Mat3::zeros()), 0.0);
        // Unstressed: no stiffness, stays unstressed.
        let mut h = [0.0; 3];
        let i = increment(Mat3::identity(), rotated([0.99, 1.0, 1.0]), Mat3::zeros(), &[0.0; 3]);
        assert_eq!(m.update(&i, &mut h), Mat3::zeros());
    }

    #[test]
    fn strength_reduction_divides_tan_phi_cs() {
        let m = model(1.0);
        let phi = m.critical_state_angle();
        let s = phi.sin();
        assert!((6.0 * s / (3.0 - s) - 1.2).abs() < 1e-14, "M = 6 sin φ/(3 − sin φ)");
        assert!((m.reduced_ratio(1.0) - 1.2).abs() < 1e-14, "F = 1: M as given");
        let reduced = ModifiedCamClay {
            critical_state_ratio: m.reduced_ratio(1.5),
            ..m
        };
        let ratio = phi.tan() / reduced.critical_state_angle().tan();
        assert!((ratio - 1.5).abs() < 1e-13, "tan φ_cs / tan φ_F = F: {ratio}");
    }

    fn build(extra: &str) -> Result<Box<dyn Material>, KeyError> {
        let text = format!("lambda = 0.2\nkappa = 0.04\ncritical_state_ratio = 1.2\npoisson_ratio = 0.3\ninitial_void_ratio = 1.0\n{extra}");
        let values: toml::Table = toml::from_str(&text).unwrap();
        crate::material::registry::build("material.0", "modified_cam_clay", 1800.0, &values)
    }

    #[test]
    fn bad_parameters_are_refused_at_their_keys() {
        assert!(build("ocr = 2.0").is_ok());
        assert!(build("preconsolidation_pressure = 3.0e5").is_ok());
        let cases = [
            ("ocr = 0.5", "material.0.ocr", "≥ 1"),
            ("ocr = 2.0\npreconsolidation_pressure = 1e5", "material.0.ocr", "not both"),
            ("", "material.0.ocr", "is required"),
            ("preconsolidation_pressure = -1.0", "material.0.preconsolidation_pressure", "positive"),
            ("ocr = 1.0\nlambda = -0.2", "material.0.lambda", "positive"),
            ("ocr = 1.0\nkappa = 0.2", "material.0.kappa", "below lambda"),
            ("ocr = 1.0\nkappa = 0.3", "material.0.kappa", "below lambda"),
            ("ocr = 1.0\ncritical_state_ratio = 0.0", "material.0.critical_state_ratio", "positive"),
            ("ocr = 1.0\ncritical_state_ratio = 3.0", "material.0.critical_state_ratio", "(0, 3)"),
            ("ocr = 1.0\npoisson_ratio = 0.5", "material.0.poisson_ratio", "(-1, 0.5)"),
            ("ocr = 1.0\ninitial_void_ratio = 0.0", "material.0.initial_void_ratio", "positive"),
        ];
        assert_refused_at_keys(build_overriding, &cases);
    }

    /// The defaults of `build` with the keys of `extra` replaced.
    fn build_overriding(extra: &str) -> Result<Box<dyn Material>, KeyError> {
        let mut values: toml::Table = toml::from_str(
            "lambda = 0.2\nkappa = 0.04\ncritical_state_ratio = 1.2\npoisson_ratio = 0.3\ninitial_void_ratio = 1.0",
        )
        .unwrap();
        values.extend(toml::from_str::<toml::Table>(extra).unwrap());
        crate::material::registry::build("material.0", "modified_cam_clay", 1800.0, &values)
    }
}
