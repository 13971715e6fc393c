//! Undrained effective-stress loading of a soil skeleton in a single-phase run
//! (issue 52, item 2; PLAXIS's "Undrained A"): the pore water cannot leave the
//! point, so every volume change compresses it and raises an excess pore
//! pressure that the skeleton does not see.
//!
//! With the water's bulk modulus K_w and the porosity n, the pore fluid adds the
//! bulk stiffness K_f = K_w/n to the skeleton (Biot coefficient 1, incompressible
//! grains; e.g. Potts & Zdravković, *Finite element analysis in geotechnical
//! engineering*, 1999, §3.4). Over an increment with ΔJ = det ΔF
//!
//!   p_ex,new = p_ex,old − K_f ln det ΔF,
//!
//! so that p_ex = −K_f ln J for the whole undrained history (path independent),
//! and the skeleton (any model of `SKELETONS`) updates its effective stress σ′
//! from σ′_old = σ_old + p_ex,old I as it would drained. The stored stress is
//!
//!   σ = σ′ − p_ex I   (Terzaghi, tension positive),
//!
//! the stress the particle transmits in the momentum balance besides a `[water]`
//! table's hydrostatic pressure; p_ex is the last history slot. The consistent
//! tangent is the skeleton's plus the fluid's: ∂σ_ij/∂ΔF_kl = ∂σ′_ij/∂ΔF_kl +
//! K_f δ_ij (ΔF⁻ᵀ)_kl, since ∂ ln det ΔF/∂ΔF = ΔF⁻ᵀ.
//!
//! Scene keys (on the skeleton's `[[material]]` table): `drainage =
//! "undrained"` (or "drained", the default), `porosity` n in (0, 1) and
//! `water_bulk_modulus` K_w (Pa, default 2.2e9).
//!
//! `drainage = "coupled"` is the same skeleton with Darcy flow between points
//! (issue 52, item 3, explicit): `hydraulic_conductivity` k and
//! `water_unit_weight` γ_w give the mobility k/γ_w. Its whole storage
//! equation, the volumetric part −K_f Δ ln J included, is then solved on the
//! grid by `physics::pore_flow`, so this update leaves p_ex as it was (the
//! stored stress σ′ − p_ex,old I) and keeps the point's ln J of the last flow
//! update in the history slot after p_ex.

use super::parameters::{KeyError, Parameters};
use super::{Increment, Material, PoreFluid, Strength, StressDerivative};
use crate::dim::Mat3;

/// The keys this module adds to a material table.
pub const KEYS: &[&str] = &[
    "drainage",
    "porosity",
    "water_bulk_modulus",
    "hydraulic_conductivity",
    "water_unit_weight",
];

/// The keys of Darcy flow (`drainage = "coupled"` only).
const FLOW_KEYS: &[&str] = &["hydraulic_conductivity", "water_unit_weight"];

/// The models that may be undrained: the soil skeletons and the elastic laws
/// (an equation of state, a rigid body or a bond law has no drained skeleton).
pub const SKELETONS: &[&str] = &[
    "linear_elastic",
    "neo_hookean",
    "hencky",
    "drucker_prager",
    "mohr_coulomb",
    "modified_cam_clay",
];

/// Bulk modulus of water at 20 °C (Pa).
pub const WATER_BULK_MODULUS: f64 = 2.2e9;

/// A skeleton loaded undrained: its effective stress and the excess pore
/// pressure of the water in its pores.
#[derive(Clone, Debug)]
pub struct Undrained {
    pub skeleton: Box<dyn Material>,
    /// K_f = K_w/n, the pore fluid's bulk stiffness per unit volume of soil.
    pub fluid_bulk_modulus: f64,
    /// k/γ_w, Darcy's mobility of the excess pore pressure (m²/(Pa s)); 0 when
    /// undrained (no flow between points).
    pub mobility: f64,
}

impl Undrained {
    /// Index of p_ex in the history.
    fn slot(&self) -> usize {
        self.skeleton.n_history()
    }

    /// The excess pore pressure held in `history` (compression positive).
    pub fn excess(&self, history: &[f64]) -> f64 {
        history[self.slot()]
    }

    /// Does the water flow between points (`drainage = "coupled"`)? Then the
    /// grid updates p_ex (`physics::pore_flow`), not `update`.
    fn coupled(&self) -> bool {
        self.mobility > 0.0
    }

    /// The increment the skeleton sees: its effective start stress and its
    /// own history.
    fn skeleton_increment<'a>(&self, inc: &Increment<'a>) -> Increment<'a> {
        let n = self.slot();
        let effective = inc.stress_old + Mat3::identity() * inc.history_old[n];
        Increment::new(inc.f_old, inc.df, inc.dt, effective, &inc.history_old[..n])
    }
}

/// The material of a table with drainage keys: the skeleton itself when
/// drained, else the skeleton wrapped. `p` holds the table's drainage keys.
pub fn wrap(skeleton: Box<dyn Material>, p: &Parameters) -> Result<Box<dyn Material>, KeyError> {
    let drainage: String = p.get("drainage")?.unwrap_or_else(|| "drained".into());
    let refuse = |keys: &[&str], what: &str| match keys.iter().find(|k| p.given(k)) {
        Some(k) => Err((p.key(k), format!("applies only with {what}"))),
        None => Ok(()),
    };
    match drainage.as_str() {
        "drained" => {
            refuse(&KEYS[1..], "drainage = \"undrained\" or \"coupled\"")?;
            Ok(skeleton)
        }
        "undrained" => {
            refuse(FLOW_KEYS, "drainage = \"coupled\"")?;
            Ok(Box::new(saturated(skeleton, p, "undrained", 0.0)?))
        }
        "coupled" => {
            let when = "drainage = \"coupled\"";
            let k: f64 = p.required_for("hydraulic_conductivity", when)?;
            p.ensure(
                k > 0.0 && k.is_finite(),
                "hydraulic_conductivity",
                "must be positive (m/s)",
            )?;
            let gamma_w: f64 = p.required_for("water_unit_weight", when)?;
            p.ensure(
                gamma_w > 0.0 && gamma_w.is_finite(),
                "water_unit_weight",
                "must be positive",
            )?;
            Ok(Box::new(saturated(skeleton, p, "coupled", k / gamma_w)?))
        }
        other => Err((
            p.key("drainage"),
            format!("unknown drainage `{other}`; use \"drained\", \"undrained\" or \"coupled\""),
        )),
    }
}

/// The skeleton with its pore water (`drainage` = `mode`), of mobility k/γ_w.
fn saturated(
    skeleton: Box<dyn Material>,
    p: &Parameters,
    mode: &str,
    mobility: f64,
) -> Result<Undrained, KeyError> {
    p.ensure(
        SKELETONS.contains(&skeleton.model()),
        "drainage",
        format!(
            "a {mode} material needs a soil skeleton: model `{}` is not one of {}",
            skeleton.model(),
            SKELETONS.join(", ")
        ),
    )?;
    let n: f64 = p.required_for("porosity", &format!("drainage = \"{mode}\""))?;
    p.ensure(n > 0.0 && n < 1.0, "porosity", "must lie in (0, 1)")?;
    let kw: f64 = p.get("water_bulk_modulus")?.unwrap_or(WATER_BULK_MODULUS);
    p.ensure(
        kw > 0.0 && kw.is_finite(),
        "water_bulk_modulus",
        "must be positive",
    )?;
    Ok(Undrained {
        skeleton,
        fluid_bulk_modulus: kw / n,
        mobility,
    })
}

impl Material for Undrained {
    fn model(&self) -> &'static str {
        self.skeleton.model()
    }

    fn density(&self) -> f64 {
        self.skeleton.density()
    }

    fn n_history(&self) -> usize {
        self.skeleton.n_history() + 1 + usize::from(self.coupled())
    }

    fn update(&self, inc: &Increment, history_new: &mut [f64]) -> Mat3 {
        let n = self.slot();
        let effective = self
            .skeleton
            .update(&self.skeleton_increment(inc), &mut history_new[..n]);
        history_new[n..].copy_from_slice(&inc.history_old[n..]);
        let p = match self.coupled() {
            true => inc.history_old[n],
            false => inc.history_old[n] - self.fluid_bulk_modulus * inc.df.determinant().ln(),
        };
        history_new[n] = p;
        effective - Mat3::identity() * p
    }

    /// The undrained P-wave modulus: the skeleton's plus K_f.
    fn p_wave_modulus(&self) -> f64 {
        self.skeleton.p_wave_modulus() + self.fluid_bulk_modulus
    }

    fn wave_speed(&self, j: f64, history: &[f64]) -> f64 {
        let c = self.skeleton.wave_speed(j, &history[..self.slot()]);
        (c * c + self.fluid_bulk_modulus * j / self.density()).sqrt()
    }

    /// The skeleton's energy at its effective stress plus the water's,
    /// p_ex²/(2 K_f) (= K_f (ln J)²/2 undrained), per current volume.
    fn strain_energy_density(&self, f: &Mat3, stress: &Mat3, history: &[f64]) -> f64 {
        let n = self.slot();
        let p = history[n];
        let effective = stress + Mat3::identity() * p;
        self.skeleton
            .strain_energy_density(f, &effective, &history[..n])
            + 0.5 * p * p / self.fluid_bulk_modulus / f.determinant()
    }

    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let mut d = self
            .skeleton
            .stress_derivative(&self.skeleton_increment(inc))?;
        if self.coupled() {
            return Some(d); // p_ex does not follow ΔF within the point
        }
        let df_inv_t = inc.df.try_inverse()?.transpose();
        for (k, l) in (0..3).flat_map(|k| (0..3).map(move |l| (k, l))) {
            for i in 0..3 {
                d[(4 * i, 3 * k + l)] += self.fluid_bulk_modulus * df_inv_t[(k, l)];
                // K_f δ_ij ΔF⁻ᵀ_kl
            }
        }
        Some(d)
    }

    fn has_analytic_tangent(&self) -> bool {
        self.skeleton.has_analytic_tangent()
    }

    fn integrates_from_stored_stress(&self) -> bool {
        self.skeleton.integrates_from_stored_stress()
    }

    /// The start stress is effective (p_ex = 0 before undrained loading).
    fn initial_history(&self, stress: &Mat3, history: &mut [f64]) {
        let n = self.slot();
        self.skeleton.initial_history(stress, &mut history[..n]);
    }

    fn frictional_strength(&self) -> Option<Strength> {
        self.skeleton.frictional_strength()
    }

    fn with_reduced_strength(&self, factor: f64) -> Option<Box<dyn Material>> {
        Some(Box::new(Undrained {
            skeleton: self.skeleton.with_reduced_strength(factor)?,
            fluid_bulk_modulus: self.fluid_bulk_modulus,
            mobility: self.mobility,
        }))
    }

    fn equivalent_plastic_strain(&self, history: &[f64]) -> Option<f64> {
        self.skeleton
            .equivalent_plastic_strain(&history[..self.slot()])
    }

    fn excess_pore_pressure(&self, history: &[f64]) -> Option<f64> {
        Some(self.excess(history))
    }

    fn pore_fluid(&self) -> Option<PoreFluid> {
        Some(PoreFluid {
            bulk_modulus: self.fluid_bulk_modulus,
            mobility: self.mobility,
            slot: self.slot(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver::tangent_error;
    use crate::material::linear_elastic::LinearElastic;
    use crate::material::modified_cam_clay::{ModifiedCamClay, Preconsolidation};
    use crate::material::mohr_coulomb::MohrCoulomb;
    use crate::material::testing::{assert_refused_at_keys, general_f, increment, rotated};

    const P0: f64 = 2.0e5;

    fn cam_clay(ocr: f64) -> Box<dyn Material> {
        Box::new(ModifiedCamClay {
            density: 1800.0,
            lambda: 0.2,
            kappa: 0.04,
            critical_state_ratio: 1.2,
            poisson_ratio: 0.3,
            initial_void_ratio: 1.0,
            preconsolidation: Preconsolidation::Ratio(ocr),
        })
    }

    fn start(m: &dyn Material) -> (Mat3, Vec<f64>) {
        let sigma = Mat3::identity() * -P0;
        let mut h = vec![0.0; m.n_history()];
        m.initial_history(&sigma, &mut h);
        (sigma, h)
    }

    /// Elastic skeleton, isotropic compression: p_ex = −K_f ln J exactly, and
    /// the total pressure K ln-strain shared in the ratio K_f : K′.
    #[test]
    fn elastic_skeleton_shares_a_volume_change_with_the_water() {
        let e = LinearElastic::new(2000.0, 1.0e7, 0.25);
        let k_skeleton = 1.0e7 / (3.0 * 0.5);
        let m = Undrained {
            skeleton: Box::new(e),
            fluid_bulk_modulus: 1.0e8,
            mobility: 0.0,
        };
        let stretch = 0.999_f64;
        let df = Mat3::identity() * stretch;
        let mut h = vec![0.0; m.n_history()];
        let s = m.update(
            &increment(Mat3::identity(), df, Mat3::zeros(), &[0.0]),
            &mut h,
        );
        let ln_j = 3.0 * stretch.ln();
        assert!((h[0] + 1.0e8 * ln_j).abs() < 1e-9 * 1.0e8 * ln_j.abs());
        let effective = s + Mat3::identity() * h[0];
        // Hughes–Winget's volumetric increment tr G = 3·2(s−1)/(s+1).
        let tr_g = 6.0 * (stretch - 1.0) / (stretch + 1.0);
        assert!((effective[(0, 0)] - k_skeleton * tr_g).abs() < 1e-6 * k_skeleton * tr_g.abs());
    }

    #[test]
    fn tangent_matches_finite_differences() {
        let mc = MohrCoulomb {
            density: 2000.0,
            youngs_modulus: 2.0e7,
            poisson_ratio: 0.3,
            peak: Strength {
                cohesion: 1.0e4,
                friction_angle: 30f64.to_radians(),
                dilation_angle: 5f64.to_radians(),
            },
            softening: None,
            tensile_strength: None,
        };
        let skeletons: Vec<Box<dyn Material>> = vec![
            Box::new(LinearElastic::new(2000.0, 1.0e7, 0.3)),
            Box::new(mc),
            cam_clay(2.0),
        ];
        for skeleton in skeletons {
            let m = Undrained {
                skeleton,
                fluid_bulk_modulus: 5.0e7,
                mobility: 0.0,
            };
            let (sigma, mut h) = start(&m);
            let n = h.len() - 1;
            h[n] = 3.0e4;
            let general = Mat3::identity() + (general_f() - Mat3::identity()) * 0.005;
            for df in [rotated([0.998, 1.001, 0.997]), general] {
                let inc = increment(Mat3::identity(), df, sigma - Mat3::identity() * 3.0e4, &h);
                let err = tangent_error(&m, &inc, 1e-7);
                assert!(err < 1e-5, "{}: tangent error {err:.2e}", m.model());
            }
        }
    }

    fn build(extra: &str) -> Result<Box<dyn Material>, KeyError> {
        let text = format!("youngs_modulus = 1e7\npoisson_ratio = 0.3\n{extra}");
        let values: toml::Table = toml::from_str(&text).unwrap();
        crate::material::registry::build("material.0", "linear_elastic", 2000.0, &values)
    }

    #[test]
    fn drainage_keys_build_the_wrapper_or_are_refused_at_their_keys() {
        let m = build("drainage = \"undrained\"\nporosity = 0.4").unwrap();
        assert_eq!(m.n_history(), 1);
        assert!((m.p_wave_modulus() - (1.0e7 * 0.7 / (1.3 * 0.4) + 2.2e9 / 0.4)).abs() < 1.0);
        assert_eq!(build("drainage = \"drained\"").unwrap().n_history(), 0);
        let coupled = build(
            "drainage = \"coupled\"\nporosity = 0.4\nhydraulic_conductivity = 1e-4\n\
             water_unit_weight = 9810.0",
        )
        .unwrap();
        assert_eq!(
            coupled.n_history(),
            2,
            "p_ex and ln J of the last flow update"
        );
        let fluid = coupled.pore_fluid().unwrap();
        assert_eq!((fluid.slot, fluid.bulk_modulus), (0, 2.2e9 / 0.4));
        assert!((fluid.mobility - 1e-4 / 9810.0).abs() < 1e-24);
        let cases = [
            (
                "porosity = 0.4",
                "material.0.porosity",
                "only with drainage",
            ),
            (
                "drainage = \"undrained\"",
                "material.0.porosity",
                "is required",
            ),
            (
                "drainage = \"undrained\"\nporosity = 1.0",
                "material.0.porosity",
                "(0, 1)",
            ),
            (
                "drainage = \"coupled\"\nporosity = 0.4\nwater_unit_weight = 9810.0",
                "material.0.hydraulic_conductivity",
                "is required",
            ),
            (
                "drainage = \"coupled\"\nporosity = 0.4\nhydraulic_conductivity = 0.0\n\
                 water_unit_weight = 9810.0",
                "material.0.hydraulic_conductivity",
                "positive",
            ),
            (
                "drainage = \"undrained\"\nporosity = 0.4\nwater_unit_weight = 9810.0",
                "material.0.water_unit_weight",
                "only with drainage = \"coupled\"",
            ),
            (
                "drainage = \"partly\"",
                "material.0.drainage",
                "unknown drainage",
            ),
            (
                "drainage = \"undrained\"\nporosity = 0.4\nwater_bulk_modulus = -1.0",
                "material.0.water_bulk_modulus",
                "positive",
            ),
        ];
        assert_refused_at_keys(build, &cases);
        let values: toml::Table =
            toml::from_str("drainage = \"undrained\"\nporosity = 0.4").unwrap();
        let err = crate::material::registry::build("material.0", "rigid", 2000.0, &values)
            .expect_err("rigid skeleton");
        assert_eq!(err.0, "material.0.drainage");
    }
}
