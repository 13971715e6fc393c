//! Mohr–Coulomb elastoplasticity at finite strain (thesis 3-34, 3-35) with
//! non-associated flow, a tension cut-off and strain softening, on the Hencky
//! kinematics of `principal.rs`.
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
//! cut-off, {T}, {T_1, T_2}, {1–3, T}, {1–3, 1–2, T}, {1–3, 2–3, T},
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

use super::principal::{self, Elasticity, Principal, PrincipalTangent, Return, ReturnMapping};
use super::{Increment, Material, StressDerivative};
use crate::dim::Mat3;
use nalgebra::{DMatrix, DVector};

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

/// Cohesion, friction angle and dilation angle (radians), or their derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strength {
    pub cohesion: f64,
    pub friction_angle: f64,
    pub dilation_angle: f64,
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
const CUT_OFF_SETS: [&[Surface]; 6] = [
    &[Tension(0)],
    &[Tension(0), Tension(1)],
    &[MAIN, Tension(0)],
    &[MAIN, EXTENSION, Tension(0)],
    &[MAIN, COMPRESSION, Tension(0)],
    &[Tension(0), Tension(1), Tension(2)],
];

/// f = a·τ − k with flow direction n, and their derivatives with respect to κ.
struct Linear {
    a: Principal,
    da: Principal,
    k: f64,
    dk: f64,
    n: Principal,
    dn: Principal,
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
    multipliers: Vec<f64>,
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

    /// Newton's method on (Δγ, κ) for the active set (module documentation).
    fn solve(
        &self,
        el: &Elasticity,
        set: &[Surface],
        piece: Piece,
        tau_trial: &Principal,
        kappa_old: f64,
        stress_tolerance: f64,
    ) -> Option<Solution> {
        let m = set.len();
        let de = el.stiffness();
        let mut dg = vec![0.0; m];
        let mut kappa = kappa_old;
        for _ in 0..40 {
            let surfaces: Vec<Linear> = set.iter().map(|&s| self.linear(s, piece, kappa)).collect();
            let plastic: Principal = surfaces.iter().zip(&dg).map(|(s, g)| s.n * *g).sum();
            let plastic_dkappa: Principal = surfaces.iter().zip(&dg).map(|(s, g)| s.dn * *g).sum();
            let tau = tau_trial - de * plastic;
            let (h, dh) = equivalent_strain(&plastic);
            let mut r = DVector::zeros(m + 1);
            let mut jac = DMatrix::zeros(m + 1, m + 1);
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
            let lu = jac.clone().lu();
            if converged {
                // ∂r/∂ε^tr: rows a_iᵀ D^e for the surfaces, zero for κ.
                let mut b = DMatrix::zeros(m + 1, 3);
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
            for (j, g) in dg.iter_mut().enumerate() {
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
            multipliers: Vec::new(),
        }
    }

    /// Return mapping in ordered principal space.
    fn ordered_return(&self, eps: &Principal, kappa_old: f64) -> Solution {
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
                multipliers: Vec::new(),
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
                let s = self.solve(&el, set, piece, &tau_trial, kappa_old, stress_tolerance)?;
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
        // an edge always applies. Keep the trial rather than fail.
        Solution {
            tau: tau_trial,
            tangent: el.stiffness(),
            kappa: kappa_old,
            multipliers: Vec::new(),
        }
    }
}

impl ReturnMapping for MohrCoulomb {
    fn elasticity(&self) -> Elasticity {
        self.elastic()
    }

    fn return_map(&self, eps: &Principal, h_old: &[f64], h_new: &mut [f64]) -> Return {
        // Order the principal strains (the trial stresses have the same order).
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eps[b].total_cmp(&eps[a]));
        let sorted = Principal::from_fn(|i, _| eps[order[i]]);
        let s = self.ordered_return(&sorted, h_old[0]);
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

impl Material for MohrCoulomb {
    fn model(&self) -> &'static str {
        "mohr_coulomb"
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn n_history(&self) -> usize {
        1
    }

    fn update(&self, inc: &Increment, history_new: &mut [f64]) -> Mat3 {
        principal::update(self, inc, history_new)
    }

    fn p_wave_modulus(&self) -> f64 {
        let el = self.elastic();
        el.lambda + 2.0 * el.mu
    }

    fn strain_energy_density(&self, f: &Mat3, stress: &Mat3, _history: &[f64]) -> f64 {
        principal::stored_energy_density(&self.elastic(), f, stress)
    }

    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        principal::stress_derivative(self, inc)
    }
}
