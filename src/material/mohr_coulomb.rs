//! Mohr–Coulomb elastoplasticity at finite strain (thesis 3-34, 3-35) with
//! non-associated flow, a tension cut-off and strain softening, on the Hencky
//! kinematics of `return_mapping.rs`.
//!
//! In ordered principal Kirchhoff stresses τ_1 ≥ τ_2 ≥ τ_3 (tension positive) the
//! yield function is (3-35)
//!
//!   f = τ_1 − τ_3 + (τ_1 + τ_3) sin φ − 2c cos φ,
//!
//! the plastic potential g the same with the dilation angle ψ, and the tension
//! cut-off (optional) is τ_1 ≤ T with associated flow. Cohesion, friction and
//! dilation soften linearly with the equivalent plastic strain ε̄p from their peak
//! values (ε̄p ≤ ε_start) to their residual values (ε̄p ≥ ε_end);
//! Δε̄p = √(2/3) |dev Δεp| (the measure of thesis 3-60).
//!
//! # Return mapping
//!
//! Every surface involved is linear in τ: f_i = a_i(κ)·τ − k_i(κ), with flow
//! direction n_i(κ) (κ = ε̄p). A return onto a set A of active surfaces solves
//!
//!   τ = τ^tr − D^e Σ_{j∈A} Δγ_j n_j(κ),   f_i(τ, κ) = 0 (i ∈ A),
//!   κ = κ_old + √(2/3) |dev Σ Δγ_j n_j(κ)|
//!
//! by Newton's method in (Δγ, κ) (one step without softening). The sets are
//! tried in order — the main plane {1–3}; the edges {1–3, 1–2} (τ_2 = τ_3,
//! triaxial extension) and {1–3, 2–3} (τ_1 = τ_2, triaxial compression); with a
//! cut-off, {T}, {T_1, T_2}, {1–3, T}, {1–3, T_1, T_2}, {1–3, 1–2, T},
//! {1–3, 2–3, T},
//! {T_1, T_2, T_3} — and the first one with Δγ ≥ 0 whose stress keeps the
//! principal order and satisfies f ≤ 0 and τ_1 ≤ T is taken. The apex
//! τ = c cot φ I is the last resort (trial beyond it): there the stress is
//! hydrostatic, all deviatoric trial strain becomes plastic, so
//! κ = κ_old + √(2/3)|dev ε^tr| is explicit. (Non-associated flow cannot reach the
//! apex with the plane flows when ψ = 0, which is why it is treated separately.)
//!
//! The algorithmic tangent follows from the implicit function theorem on the
//! same equations: d(Δγ, κ)/dε^tr = −J⁻¹ ∂r/∂ε^tr with the Newton matrix J, and
//! dτ = D^e (dε^tr − Σ n_j dΔγ_j − Σ Δγ_j n_j' dκ).
//!
//! History: one slot, the equivalent plastic strain ε̄p.
//!
//! Scene keys: youngs_modulus, poisson_ratio, cohesion, friction_angle,
//! dilation_angle (degrees); optional softening (residual_cohesion,
//! residual_friction_angle, residual_dilation_angle, softening_start,
//! softening_end) and tensile_strength.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::return_mapping::{
    Elasticity, Frictional, Principal, PrincipalTangent, Return, ReturnMapping,
};
use super::{reduced_angle, Strength};
use crate::dim::Mat3;
use nalgebra::{SMatrix, SVector};

/// The local Newton system has at most three surfaces and κ; smaller sets are
/// padded with identity rows, which partial-pivoting LU leaves untouched.
const MAX_UNKNOWNS: usize = 4;
type LocalMatrix = SMatrix<f64, MAX_UNKNOWNS, MAX_UNKNOWNS>;
type LocalVector = SVector<f64, MAX_UNKNOWNS>;

/// Linear strain softening from the peak to the residual strength parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Softening {
    pub residual_cohesion: f64,
    /// Radians.
    pub residual_friction_angle: f64,
    /// Radians.
    pub residual_dilation_angle: f64,
    /// Equivalent plastic strain at which softening starts …
    pub start: f64,
    /// … and at which the residual values are reached (> start).
    pub end: f64,
}

/// Mohr–Coulomb solid: Hencky elasticity, Mohr–Coulomb pyramid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulomb {
    /// Reference mass density ρ0.
    pub density: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    /// Peak strength (angles in radians; 0 ≤ ψ ≤ φ < π/2, c ≥ 0).
    pub peak: Strength,
    pub softening: Option<Softening>,
    /// Tension cut-off T ≥ 0 on the major principal stress.
    pub tensile_strength: Option<f64>,
}

/// The linear pieces of the softening law, in the order κ passes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Piece {
    Peak,
    Softening,
    Residual,
}

/// One active surface in the ordered principal space (indices 0 ≥ 1 ≥ 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Surface {
    /// The Mohr–Coulomb plane through τ_i (major) and τ_j (minor).
    Plane(usize, usize),
    /// The cut-off τ_i = T.
    Tension(usize),
}

use Surface::{Plane, Tension};

const MAIN: Surface = Plane(0, 2);
/// Partner of the main plane on the edge τ_2 = τ_3.
const EXTENSION: Surface = Plane(0, 1);
/// Partner of the main plane on the edge τ_1 = τ_2.
const COMPRESSION: Surface = Plane(1, 2);

const PYRAMID_SETS: [&[Surface]; 3] = [&[MAIN], &[MAIN, EXTENSION], &[MAIN, COMPRESSION]];
const CUT_OFF_SETS: [&[Surface]; 7] = [
    &[Tension(0)],
    &[Tension(0), Tension(1)],
    &[MAIN, Tension(0)],
    &[MAIN, Tension(0), Tension(1)],
    &[MAIN, EXTENSION, Tension(0)],
    &[MAIN, COMPRESSION, Tension(0)],
    &[Tension(0), Tension(1), Tension(2)],
];

/// f = a·τ − k with flow direction n, and their derivatives with respect to κ.
#[derive(Clone, Copy)]
struct Linear {
    a: Principal,
    da: Principal,
    k: f64,
    dk: f64,
    n: Principal,
    dn: Principal,
}

impl Linear {
    /// A placeholder for the slots beyond an active set.
    const UNSET: Linear = Linear {
        a: Principal::new(0.0, 0.0, 0.0),
        da: Principal::new(0.0, 0.0, 0.0),
        k: 0.0,
        dk: 0.0,
        n: Principal::new(0.0, 0.0, 0.0),
        dn: Principal::new(0.0, 0.0, 0.0),
    };
}

fn unit(i: usize) -> Principal {
    Principal::ith(i, 1.0)
}

/// a = (1 + sin θ) e_i − (1 − sin θ) e_j and its derivative for dθ/dκ = `dtheta`.
fn plane_direction(i: usize, j: usize, theta: f64, dtheta: f64) -> (Principal, Principal) {
    let s = theta.sin();
    let v = unit(i) * (1.0 + s) - unit(j) * (1.0 - s);
    let dv = (unit(i) + unit(j)) * (theta.cos() * dtheta);
    (v, dv)
}

/// √(2/3)|dev e| and its gradient (2/3) dev e / h (zero at h = 0).
fn equivalent_strain(e: &Principal) -> (f64, Principal) {
    let dev = e - Principal::repeat(e.sum() / 3.0);
    let h = (2.0 / 3.0 * dev.norm_squared()).sqrt();
    let grad = if h > 0.0 {
        dev * (2.0 / 3.0 / h)
    } else {
        Principal::zeros()
    };
    (h, grad)
}

/// A converged return onto a set of surfaces (ordered principal space).
struct Solution {
    tau: Principal,
    tangent: PrincipalTangent,
    kappa: f64,
    /// Δγ per active surface; zero beyond the active set.
    multipliers: [f64; 3],
}

impl MohrCoulomb {
    fn elastic(&self) -> Elasticity {
        Elasticity::new(self.youngs_modulus, self.poisson_ratio)
    }

    /// Strength parameters at equivalent plastic strain κ and their κ-derivatives.
    pub fn strength(&self, kappa: f64) -> (Strength, Strength) {
        self.strength_in(self.piece_of(kappa), kappa)
    }

    /// The linear piece of the softening law that holds κ.
    fn piece_of(&self, kappa: f64) -> Piece {
        match self.softening {
            Some(s) if kappa >= s.end => Piece::Residual,
            Some(s) if kappa > s.start => Piece::Softening,
            _ => Piece::Peak,
        }
    }

    /// Whether κ lies in `piece` (to `tolerance`).
    fn in_piece(&self, piece: Piece, kappa: f64, tolerance: f64) -> bool {
        let Some(s) = self.softening else {
            return true;
        };
        match piece {
            Piece::Peak => kappa <= s.start + tolerance,
            Piece::Softening => kappa >= s.start - tolerance && kappa <= s.end + tolerance,
            Piece::Residual => kappa >= s.end - tolerance,
        }
    }

    /// Strength on one linear piece of the softening law, extended beyond it (so
    /// that a local Newton iteration sees a smooth function).
    fn strength_in(&self, piece: Piece, kappa: f64) -> (Strength, Strength) {
        let p = self.peak;
        let (w, dw, s) = match (self.softening, piece) {
            (None, _) | (_, Piece::Peak) => (0.0, 0.0, None),
            (Some(s), Piece::Residual) => (1.0, 0.0, Some(s)),
            (Some(s), Piece::Softening) => {
                let span = s.end - s.start;
                ((kappa - s.start) / span, 1.0 / span, Some(s))
            }
        };
        let blend = |peak: f64, residual: Option<f64>| match residual {
            None => (peak, 0.0),
            Some(r) => (peak + w * (r - peak), dw * (r - peak)),
        };
        let (c, dc) = blend(p.cohesion, s.map(|s| s.residual_cohesion));
        let (phi, dphi) = blend(p.friction_angle, s.map(|s| s.residual_friction_angle));
        let (psi, dpsi) = blend(p.dilation_angle, s.map(|s| s.residual_dilation_angle));
        (
            Strength {
                cohesion: c,
                friction_angle: phi,
                dilation_angle: psi,
            },
            Strength {
                cohesion: dc,
                friction_angle: dphi,
                dilation_angle: dpsi,
            },
        )
    }

    /// Yield function (3-35) of ordered principal stresses at κ.
    pub fn yield_function(&self, tau: &Principal, kappa: f64) -> f64 {
        let (s, _) = self.strength(kappa);
        let sp = s.friction_angle.sin();
        tau[0] - tau[2] + (tau[0] + tau[2]) * sp - 2.0 * s.cohesion * s.friction_angle.cos()
    }

    fn linear(&self, surface: Surface, piece: Piece, kappa: f64) -> Linear {
        match surface {
            Plane(i, j) => {
                let (s, ds) = self.strength_in(piece, kappa);
                let (phi, c) = (s.friction_angle, s.cohesion);
                let (a, da) = plane_direction(i, j, phi, ds.friction_angle);
                let (n, dn) = plane_direction(i, j, s.dilation_angle, ds.dilation_angle);
                Linear {
                    a,
                    da,
                    k: 2.0 * c * phi.cos(),
                    dk: 2.0 * (ds.cohesion * phi.cos() - c * phi.sin() * ds.friction_angle),
                    n,
                    dn,
                }
            }
            Tension(i) => Linear {
                a: unit(i),
                da: Principal::zeros(),
                k: self.tensile_strength.unwrap_or(f64::INFINITY),
                dk: 0.0,
                n: unit(i),
                dn: Principal::zeros(),
            },
        }
    }

    /// The surfaces of `set` linearized at κ, in `out`.
    fn linearize(&self, set: &[Surface], piece: Piece, kappa: f64, out: &mut [Linear; 3]) {
        for (o, &surface) in out.iter_mut().zip(set) {
            *o = self.linear(surface, piece, kappa);
        }
    }

    /// Newton's method on (Δγ, κ) for the active set (module documentation).
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &self,
        el: &Elasticity,
        set: &[Surface],
        piece: Piece,
        tau_trial: &Principal,
        kappa_old: f64,
        stress_tolerance: f64,
        with_tangent: bool,
    ) -> Option<Solution> {
        let m = set.len();
        let de = el.stiffness();
        let mut dg = [0.0; 3];
        let mut kappa = kappa_old;
        let mut linearized = [Linear::UNSET; 3];
        // Without softening the surfaces do not move with κ.
        let moving = self.softening.is_some();
        for iteration in 0..40 {
            if iteration == 0 || moving {
                self.linearize(set, piece, kappa, &mut linearized);
            }
            let surfaces = &linearized[..m];
            let dg_active = &dg[..m];
            let plastic: Principal = surfaces.iter().zip(dg_active).map(|(s, g)| s.n * *g).sum();
            let plastic_dkappa: Principal =
                surfaces.iter().zip(dg_active).map(|(s, g)| s.dn * *g).sum();
            let tau = tau_trial - de * plastic;
            let (h, dh) = equivalent_strain(&plastic);
            let mut r = LocalVector::zeros();
            let mut jac = LocalMatrix::identity();
            for (i, si) in surfaces.iter().enumerate() {
                r[i] = si.a.dot(&tau) - si.k;
                for (j, sj) in surfaces.iter().enumerate() {
                    jac[(i, j)] = -si.a.dot(&(de * sj.n));
                }
                jac[(i, m)] = si.da.dot(&tau) - si.dk - si.a.dot(&(de * plastic_dkappa));
            }
            r[m] = kappa - kappa_old - h;
            for (j, sj) in surfaces.iter().enumerate() {
                jac[(m, j)] = -dh.dot(&sj.n);
            }
            jac[(m, m)] = 1.0 - dh.dot(&plastic_dkappa);
            let converged = (0..m).all(|i| r[i].abs() <= stress_tolerance)
                && r[m].abs() <= 1e-14 * (1.0 + kappa.abs());
            if converged && !with_tangent {
                return Some(Solution {
                    tau,
                    tangent: PrincipalTangent::zeros(),
                    kappa,
                    multipliers: dg,
                });
            }
            let lu = jac.lu();
            if converged {
                // ∂r/∂ε^tr: rows a_iᵀ D^e for the surfaces, zero for κ.
                let mut b = SMatrix::<f64, MAX_UNKNOWNS, 3>::zeros();
                for (i, si) in surfaces.iter().enumerate() {
                    let row = (de * si.a).transpose();
                    for c in 0..3 {
                        b[(i, c)] = row[c];
                    }
                }
                let dx = lu.solve(&(-b))?;
                let mut flow = PrincipalTangent::zeros();
                for (j, sj) in surfaces.iter().enumerate() {
                    for c in 0..3 {
                        flow.set_column(c, &(flow.column(c) + sj.n * dx[(j, c)]));
                    }
                }
                for c in 0..3 {
                    flow.set_column(c, &(flow.column(c) + plastic_dkappa * dx[(m, c)]));
                }
                return Some(Solution {
                    tau,
                    tangent: de - de * flow,
                    kappa,
                    multipliers: dg,
                });
            }
            let step = lu.solve(&(-r))?;
            for (j, g) in dg[..m].iter_mut().enumerate() {
                *g += step[j];
            }
            kappa += step[m];
            if !kappa.is_finite() {
                return None;
            }
        }
        None
    }

    /// Whether a converged return is admissible: non-negative multipliers, the
    /// principal order kept, and the stress inside the pyramid and the cut-off.
    fn admissible(&self, s: &Solution, stress_tolerance: f64, strain_tolerance: f64) -> bool {
        let t = &s.tau;
        s.multipliers.iter().all(|&g| g >= -strain_tolerance)
            && t[0] >= t[1] - stress_tolerance
            && t[1] >= t[2] - stress_tolerance
            && self.yield_function(t, s.kappa) <= stress_tolerance
            && self
                .tensile_strength
                .is_none_or(|cut| t[0] <= cut + stress_tolerance)
    }

    /// Return to the apex τ = c cot φ I (ordered space; needs φ > 0).
    fn apex(&self, eps_trial: &Principal, kappa_old: f64) -> Solution {
        let (h, dh) = equivalent_strain(eps_trial);
        let kappa = kappa_old + h;
        let (s, ds) = self.strength(kappa);
        let (c, phi) = (s.cohesion, s.friction_angle);
        let p = c / phi.tan();
        let dp = ds.cohesion / phi.tan() - c * ds.friction_angle / phi.sin().powi(2);
        Solution {
            tau: Principal::repeat(p),
            tangent: Principal::repeat(1.0) * (dh * dp).transpose(),
            kappa,
            multipliers: [0.0; 3],
        }
    }

    /// Return mapping in ordered principal space; the tangent is zero unless
    /// `with_tangent`.
    fn ordered_return(&self, eps: &Principal, kappa_old: f64, with_tangent: bool) -> Solution {
        let el = self.elastic();
        let tau_trial = el.stress(eps);
        let scale = tau_trial.amax()
            + self.peak.cohesion
            + self.tensile_strength.unwrap_or(0.0)
            + f64::MIN_POSITIVE;
        let stress_tolerance = 1e-11 * scale;
        let strain_tolerance = stress_tolerance / el.mu;
        let inside_cut_off = self
            .tensile_strength
            .is_none_or(|cut| tau_trial[0] <= cut + stress_tolerance);
        if self.yield_function(&tau_trial, kappa_old) <= stress_tolerance && inside_cut_off {
            return Solution {
                tau: tau_trial,
                tangent: el.stiffness(),
                kappa: kappa_old,
                multipliers: [0.0; 3],
            };
        }
        let cut_off_sets: &[&[Surface]] = if self.tensile_strength.is_some() {
            &CUT_OFF_SETS
        } else {
            &[]
        };
        let first_piece = self.piece_of(kappa_old);
        let pieces = [Piece::Peak, Piece::Softening, Piece::Residual];
        let last_piece = if self.softening.is_some() {
            Piece::Residual
        } else {
            Piece::Peak
        };
        let pieces = pieces
            .iter()
            .filter(|&&p| p >= first_piece && p <= last_piece);
        let admissible = PYRAMID_SETS
            .iter()
            .chain(cut_off_sets)
            .flat_map(|set| pieces.clone().map(move |&piece| (set, piece)))
            .filter_map(|(set, piece)| {
                let s = self.solve(
                    &el,
                    set,
                    piece,
                    &tau_trial,
                    kappa_old,
                    stress_tolerance,
                    with_tangent,
                )?;
                let kappa_tolerance = 1e-12 * (1.0 + s.kappa.abs());
                self.in_piece(piece, s.kappa, kappa_tolerance).then_some(s)
            })
            .find(|s| self.admissible(s, stress_tolerance, strain_tolerance));
        if let Some(s) = admissible {
            return s;
        }
        if self.strength(kappa_old).0.friction_angle > 0.0 {
            return self.apex(eps, kappa_old);
        }
        // Not reached for a Tresca prism (φ = 0) without cut-off: the main plane or
        // an edge always applies (`every_return_is_admissible` samples this).
        debug_assert!(
            false,
            "no admissible Mohr–Coulomb return for τ^tr = {tau_trial:?}"
        );
        Solution {
            tau: tau_trial,
            tangent: el.stiffness(),
            kappa: kappa_old,
            multipliers: [0.0; 3],
        }
    }

    /// [`MohrCoulomb::ordered_return`] for principal strains in any order.
    fn unordered_return(
        &self,
        eps: &Principal,
        h_old: &[f64],
        h_new: &mut [f64],
        with_tangent: bool,
    ) -> Return {
        // Order the principal strains (the trial stresses have the same order).
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eps[b].total_cmp(&eps[a]));
        let sorted = Principal::from_fn(|i, _| eps[order[i]]);
        let s = self.ordered_return(&sorted, h_old[0], with_tangent);
        h_new[0] = s.kappa;
        let mut tau = Principal::zeros();
        let mut tangent = PrincipalTangent::zeros();
        for i in 0..3 {
            tau[order[i]] = s.tau[i];
            for j in 0..3 {
                tangent[(order[i], order[j])] = s.tangent[(i, j)];
            }
        }
        Return { tau, tangent }
    }
}

impl ReturnMapping for MohrCoulomb {
    fn elastic_strain(&self, tau: &Mat3, _history: &[f64]) -> Mat3 {
        self.elastic().strain_of_stress(tau)
    }

    fn return_map(&self, eps: &Principal, h_old: &[f64], h_new: &mut [f64]) -> Return {
        self.unordered_return(eps, h_old, h_new, true)
    }

    fn return_stress(&self, eps: &Principal, h_old: &[f64], h_new: &mut [f64]) -> Principal {
        self.unordered_return(eps, h_old, h_new, false).tau
    }
}

impl FromParameters for MohrCoulomb {
    const NAME: &'static str = "mohr_coulomb";
    const KEYS: &'static [&'static str] = &[
        "youngs_modulus",
        "poisson_ratio",
        "cohesion",
        "friction_angle",
        "dilation_angle",
        "residual_cohesion",
        "residual_friction_angle",
        "residual_dilation_angle",
        "softening_start",
        "softening_end",
        "tensile_strength",
    ];
    const EXAMPLE: &'static str = "youngs_modulus = 1.0e6\npoisson_ratio = 0.3\ncohesion = 1.0e3\nfriction_angle = 30.0\ndilation_angle = 10.0";

    /// Angles in degrees in the scene, radians here.
    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let youngs_modulus = p.youngs_modulus()?;
        let poisson_ratio = p.poisson_ratio()?;
        let (c, phi, psi) = p.mohr_coulomb_strength()?;
        let softening = softening(p, c, phi, psi)?;
        let tensile_strength: Option<f64> = p.get("tensile_strength")?;
        if let Some(t) = tensile_strength {
            p.ensure(
                t >= 0.0 && t.is_finite(),
                "tensile_strength",
                format!("must be a number ≥ 0; got {t}"),
            )?;
        }
        Ok(MohrCoulomb {
            density,
            youngs_modulus,
            poisson_ratio,
            peak: Strength {
                cohesion: c,
                friction_angle: phi.to_radians(),
                dilation_angle: psi.to_radians(),
            },
            softening,
            tensile_strength,
        })
    }
}

/// The softening keys, given peak c, φ, ψ (degrees): residual values no larger
/// than the peak ones (defaults c, φ and min(ψ, φ_r)), 0 ≤ softening_start <
/// softening_end, both required when any softening key is given.
fn softening(p: &Parameters, c: f64, phi: f64, psi: f64) -> Result<Option<Softening>, KeyError> {
    let keys = [
        "residual_cohesion",
        "residual_friction_angle",
        "residual_dilation_angle",
        "softening_start",
        "softening_end",
    ];
    if !keys.iter().any(|k| p.given(k)) {
        return Ok(None);
    }
    let what = "strain softening";
    let start: f64 = p.required_for("softening_start", what)?;
    let end: f64 = p.required_for("softening_end", what)?;
    p.ensure(
        start >= 0.0 && start.is_finite(),
        "softening_start",
        format!("must be a plastic strain ≥ 0; got {start}"),
    )?;
    p.ensure(
        end > start && end.is_finite(),
        "softening_end",
        format!("must exceed softening_start = {start}; got {end}"),
    )?;
    let c_r = p.get("residual_cohesion")?.unwrap_or(c);
    let phi_r = p.get("residual_friction_angle")?.unwrap_or(phi);
    let psi_r = p.get("residual_dilation_angle")?.unwrap_or(psi.min(phi_r));
    p.ensure(
        c_r >= 0.0 && c_r <= c,
        "residual_cohesion",
        format!("must lie in [0, cohesion = {c}] (residual no larger than peak); got {c_r}"),
    )?;
    p.ensure(
        phi_r >= 0.0 && phi_r <= phi,
        "residual_friction_angle",
        format!("must lie in [0, friction_angle = {phi}] degrees (residual no larger than peak); got {phi_r}"),
    )?;
    p.ensure(
        phi_r > 0.0 || phi == 0.0,
        "residual_friction_angle",
        "must be positive when friction_angle is (the pyramid keeps its apex)",
    )?;
    p.ensure(
        psi_r >= 0.0 && psi_r <= phi_r,
        "residual_dilation_angle",
        format!("must lie in [0, residual_friction_angle = {phi_r}] degrees; got {psi_r}"),
    )?;
    p.ensure(
        c_r > 0.0 || phi_r > 0.0,
        "residual_cohesion",
        "residual cohesion and friction are both zero: no residual strength",
    )?;
    Ok(Some(Softening {
        residual_cohesion: c_r,
        residual_friction_angle: phi_r.to_radians(),
        residual_dilation_angle: psi_r.to_radians(),
        start,
        end,
    }))
}

/// Its `Material` implementation is the one of `return_mapping::Frictional`.
impl Frictional for MohrCoulomb {
    fn elasticity(&self) -> Elasticity {
        self.elastic()
    }

    fn reference_density(&self) -> f64 {
        self.density
    }

    fn peak_strength(&self) -> Strength {
        self.peak
    }

    /// Peak and residual strengths are reduced alike; the tension cut-off is kept.
    fn reduced(&self, factor: f64) -> Self {
        let reduce = |s: Strength| Strength {
            cohesion: s.cohesion / factor,
            friction_angle: reduced_angle(s.friction_angle, factor),
            dilation_angle: reduced_angle(s.dilation_angle, factor),
        };
        let softening = self.softening.map(|s| {
            let residual = reduce(Strength {
                cohesion: s.residual_cohesion,
                friction_angle: s.residual_friction_angle,
                dilation_angle: s.residual_dilation_angle,
            });
            Softening {
                residual_cohesion: residual.cohesion,
                residual_friction_angle: residual.friction_angle,
                residual_dilation_angle: residual.dilation_angle,
                ..s
            }
        });
        MohrCoulomb {
            peak: reduce(self.peak),
            softening,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Mat3;
    use crate::material::testing::{increment, rotated};
    use crate::material::{driver, Increment, Material};
    use nalgebra::Vector3;
    use std::collections::BTreeSet;

    const C: f64 = 1.0e4;

    fn strength(c: f64, phi_deg: f64, psi_deg: f64) -> Strength {
        Strength {
            cohesion: c,
            friction_angle: phi_deg.to_radians(),
            dilation_angle: psi_deg.to_radians(),
        }
    }

    fn model(phi_deg: f64, psi_deg: f64) -> MohrCoulomb {
        MohrCoulomb {
            density: 2000.0,
            youngs_modulus: 2.0e7,
            poisson_ratio: 0.3,
            peak: strength(C, phi_deg, psi_deg),
            softening: None,
            tensile_strength: None,
        }
    }

    fn softening() -> Softening {
        Softening {
            residual_cohesion: 0.2 * C,
            residual_friction_angle: 25f64.to_radians(),
            residual_dilation_angle: 0.0,
            start: 0.0,
            end: 0.05,
        }
    }

    fn start(confinement: f64) -> (Mat3, Mat3) {
        let f_old = driver::rotation_z(0.4)
            * Mat3::new(1.01, 0.002, 0.0, 0.0, 0.995, 0.001, 0.0, 0.0, 0.998);
        let dev = Mat3::new(-0.1, 0.05, 0.01, 0.05, 0.1, -0.02, 0.01, -0.02, 0.0);
        (f_old, (Mat3::identity() + dev * 0.3) * -confinement)
    }

    /// Where the return ended: elastic, or the active parts (plane, the edges
    /// τ1 = τ2 and τ2 = τ3, the apex, the cut-off T).
    fn state(m: &MohrCoulomb, i: &Increment) -> String {
        let mut h = [0.0];
        let s = m.update(i, &mut h) * i.f.determinant();
        if h[0] == i.history_old[0] {
            return "elastic".into();
        }
        let mut t = nalgebra::SymmetricEigen::new(s).eigenvalues;
        t.as_mut_slice().sort_by(|a, b| b.total_cmp(a));
        let tol = 1e-8 * (C + t.amax());
        let mut parts = Vec::new();
        if (t[0] - t[2]).abs() < tol {
            parts.push("apex");
        } else {
            if m.yield_function(&t, h[0]).abs() < tol {
                parts.push("plane");
            }
            if (t[0] - t[1]).abs() < tol {
                parts.push("edge 1=2");
            }
            if (t[1] - t[2]).abs() < tol {
                parts.push("edge 2=3");
            }
        }
        if m.tensile_strength
            .is_some_and(|cut| (t[0] - cut).abs() < tol)
        {
            parts.push("cut-off");
        }
        assert!(
            m.yield_function(&t, h[0]) < tol,
            "inside the pyramid after the return"
        );
        parts.join(" + ")
    }

    /// Tangent against central differences for a set of increments; returns the
    /// states visited.
    fn check(
        m: &MohrCoulomb,
        name: &str,
        kappa: f64,
        confinement: f64,
        trials: &[[f64; 3]],
    ) -> BTreeSet<String> {
        let (f_old, s_old) = start(confinement);
        let history = [kappa];
        let mut seen = BTreeSet::new();
        for d in trials {
            let i = increment(f_old, rotated(*d), s_old, &history);
            let st = state(m, &i);
            let e = driver::tangent_error(m, &i, 1e-7);
            eprintln!("MC {name:<28} {st:<22}: tangent vs FD {e:.2e}");
            assert!(
                e < 1e-6,
                "{name}, {st}, ΔF = {d:?}: tangent vs central FD {e:e} < 1e-6"
            );
            seen.insert(st);
        }
        seen
    }

    const PYRAMID_TRIALS: [[f64; 3]; 6] = [
        [1.0 + 2e-5, 1.0 - 1e-5, 1.0],
        [1.02, 1.0, 0.98],
        [1.01, 1.01, 0.98],
        [1.02, 0.99, 0.99],
        [1.025, 1.0, 0.99],
        [1.03, 1.02, 1.025],
    ];

    fn expect(seen: &BTreeSet<String>, wanted: &[&str], name: &str) {
        for w in wanted {
            assert!(
                seen.contains(*w),
                "{name}: state `{w}` not reached (saw {seen:?})"
            );
        }
    }

    #[test]
    fn tangent_matches_finite_differences_on_plane_edges_and_apex() {
        let all = [
            "elastic",
            "plane",
            "plane + edge 1=2",
            "plane + edge 2=3",
            "apex",
        ];
        for (phi, psi) in [(30.0, 30.0), (30.0, 10.0), (30.0, 0.0)] {
            let name = format!("φ = {phi}, ψ = {psi}");
            let seen = check(&model(phi, psi), &name, 0.0, 1e5, &PYRAMID_TRIALS);
            expect(&seen, &all, &name);
        }
        // Tresca: no apex; the hydrostatic trial stays elastic.
        let seen = check(&model(0.0, 0.0), "Tresca", 0.0, 1e5, &PYRAMID_TRIALS);
        expect(&seen, &all[..4], "Tresca");
    }

    #[test]
    fn tangent_matches_finite_differences_while_softening() {
        let mut m = model(30.0, 10.0);
        m.softening = Some(softening());
        let all = ["plane", "plane + edge 1=2", "plane + edge 2=3", "apex"];
        // From the peak (κ = 0, softening starts at once) and mid-way (κ = 0.01).
        for kappa in [0.0, 0.01] {
            let name = format!("softening from κ = {kappa}");
            let seen = check(&m, &name, kappa, 1e5, &PYRAMID_TRIALS);
            expect(&seen, &all, &name);
        }
        // Past the residual strain: the residual strength, constant.
        let seen = check(&m, "residual", 0.2, 1e5, &PYRAMID_TRIALS);
        expect(&seen, &all, "residual");
    }

    #[test]
    fn tangent_matches_finite_differences_with_tension_cut_off() {
        let mut m = model(30.0, 10.0);
        m.tensile_strength = Some(0.5 * C);
        let trials = [
            [1.001, 1.0002, 0.9999],
            [1.001, 1.0009, 0.9999],
            [1.002, 0.9996, 0.9994],
            [1.003, 1.003, 0.9985],
            [1.003, 0.999, 0.999],
            [1.03, 1.02, 1.025],
        ];
        let mut seen = check(&m, "cut-off T = c/2", 0.0, 1e4, &trials);
        let confined = [[1.01, 1.0, 0.998], [1.01, 1.002, 1.0], [1.01, 1.0, 1.0]];
        seen.extend(check(&m, "cut-off T = c/2, confined", 0.0, 1e5, &confined));
        for w in [
            "cut-off",
            "edge 1=2 + cut-off",
            "plane + cut-off",
            "plane + edge 1=2 + cut-off",
            "plane + edge 2=3 + cut-off",
            "apex + cut-off",
        ] {
            assert!(
                seen.contains(w),
                "cut-off state `{w}` not reached (saw {seen:?})"
            );
        }
        m.softening = Some(softening());
        check(&m, "cut-off with softening", 0.01, 1e4, &trials);
        check(&m, "cut-off with softening, confined", 0.01, 1e5, &confined);
    }

    #[test]
    fn plane_return_closed_form_without_softening() {
        // De Souza Neto et al. (8.2): Δγ = f^tr / a with
        // a = 4G(1 + sin φ sin ψ/3) + 4K sin φ sin ψ (our own derivation, same result).
        let m = model(30.0, 10.0);
        let el = m.elastic();
        let eps = Vector3::new(0.004, 0.0005, -0.005);
        let mut h = [0.0];
        let ret = m.return_map(&eps, &[0.0], &mut h);
        let tau_tr = el.stress(&eps);
        let (sp, sq) = (m.peak.friction_angle.sin(), m.peak.dilation_angle.sin());
        let a = 4.0 * el.mu * (1.0 + sp * sq / 3.0) + 4.0 * el.bulk() * sp * sq;
        let dg = m.yield_function(&tau_tr, 0.0) / a;
        let n = Vector3::new(1.0 + sq, 0.0, -(1.0 - sq));
        let expect = tau_tr - el.stiffness() * n * dg;
        assert!(
            (ret.tau - expect).norm() < 1e-9 * expect.norm(),
            "plane return in closed form"
        );
        let dev = n - Principal::repeat(n.sum() / 3.0);
        let dk = dg * (2.0 / 3.0 * dev.norm_squared()).sqrt();
        assert!((h[0] - dk).abs() < 1e-15, "Δε̄p = √(2/3)|dev Δεp|");
    }

    /// Trial strains over all of principal space (deterministic pseudo-random
    /// sample, volumetric and deviatoric parts up to 5 %): every return must end
    /// inside the pyramid and below the cut-off, in the principal order of the
    /// trial.
    #[test]
    fn every_return_is_admissible_and_the_same_without_tangent() {
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut variants = vec![
            model(30.0, 10.0),
            model(30.0, 0.0),
            model(0.0, 0.0),
            model(40.0, 40.0),
        ];
        let mut soft = model(30.0, 10.0);
        soft.softening = Some(softening());
        variants.push(soft);
        for mut m in variants.clone() {
            m.tensile_strength = Some(0.3 * C);
            variants.push(m);
        }
        let el = variants[0].elastic();
        let mut count = 0;
        for m in &variants {
            for _ in 0..2000 {
                let eps = Vector3::new(uniform(), uniform(), uniform()) * 0.05;
                let kappa = 0.03 * (uniform() + 1.0);
                let mut h = [0.0];
                let ret = m.return_map(&eps, &[kappa], &mut h);
                let mut h_stress_only = [0.0];
                let tau = m.return_stress(&eps, &[kappa], &mut h_stress_only);
                assert!(
                    tau == ret.tau && h_stress_only == h,
                    "the stress-only return is the same return"
                );
                let mut order = [0, 1, 2];
                order.sort_by(|&a, &b| eps[b].total_cmp(&eps[a]));
                let t = Vector3::from_fn(|i, _| ret.tau[order[i]]);
                let scale = el.stress(&eps).amax() + C;
                let tol = 1e-9 * scale;
                assert!(
                    t[0] >= t[1] - tol && t[1] >= t[2] - tol,
                    "principal order kept"
                );
                assert!(
                    m.yield_function(&t, h[0]) <= tol,
                    "f ≤ 0 after the return: {m:?} ε = {eps:?}"
                );
                assert!(
                    m.tensile_strength.is_none_or(|cut| t[0] <= cut + tol),
                    "τ1 ≤ T after the return"
                );
                assert!(h[0] >= kappa, "ε̄p never decreases");
                count += 1;
            }
        }
        eprintln!("{count} sampled returns admissible");
    }
}
