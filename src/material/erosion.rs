//! When a high-rate model's particle is eroded (left out of the particle–grid
//! transfers, `physics::transfer::stencils`): at failure (damage D = 1,
//! `erosion = true`), or past an equivalent plastic strain
//! (`erosion_plastic_strain`, the usual criterion for concrete, whose HJC and RHT
//! residual strength keeps a fully damaged point in compression).

use super::parameters::{KeyError, Parameters};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Erosion {
    /// Erode at D = 1.
    pub at_failure: bool,
    /// Erode at ε̄p ≥ this.
    pub plastic_strain: Option<f64>,
}

impl Erosion {
    /// The criteria of a material table, `None` when it has none.
    pub fn from_parameters(p: &Parameters) -> Result<Option<Erosion>, KeyError> {
        let at_failure = p.get("erosion")?.unwrap_or(false);
        let plastic_strain: Option<f64> = p.get("erosion_plastic_strain")?;
        if let Some(e) = plastic_strain {
            p.ensure(
                e > 0.0 && e.is_finite(),
                "erosion_plastic_strain",
                format!("must be a positive number; got {e}"),
            )?;
        }
        Ok((at_failure || plastic_strain.is_some()).then_some(Erosion {
            at_failure,
            plastic_strain,
        }))
    }

    /// Whether a point with this damage and plastic strain is eroded.
    pub fn applies(&self, damage: f64, plastic_strain: f64) -> bool {
        (self.at_failure && damage >= 1.0)
            || self.plastic_strain.is_some_and(|e| plastic_strain >= e)
    }
}

/// The Jacobian that sets a point's wave speed (c² ∝ J through ρ = ρ₀/J): a
/// failed point (D = 1) carries no stress in tension in JC, JH-2, HJC and RHT,
/// and it carries stress again only once recompressed to about J = 1, so its
/// stiffness then belongs to ρ₀, not to the diluted density of a point that
/// has opened (ejecta reach J of several hundred and would otherwise set the
/// step of the whole run).
pub fn failed_jacobian(j: f64, damage: f64) -> f64 {
    if damage >= 1.0 {
        j.min(1.0)
    } else {
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn either_criterion_erodes() {
        let at_failure = Erosion {
            at_failure: true,
            plastic_strain: None,
        };
        assert!(at_failure.applies(1.0, 0.0) && !at_failure.applies(0.99, 5.0));
        let by_strain = Erosion {
            at_failure: false,
            plastic_strain: Some(0.5),
        };
        assert!(by_strain.applies(0.0, 0.5) && !by_strain.applies(1.0, 0.49));
        let both = Erosion {
            at_failure: true,
            plastic_strain: Some(0.5),
        };
        assert!(both.applies(1.0, 0.0) && both.applies(0.0, 0.6) && !both.applies(0.5, 0.1));
        let none: toml::Table = toml::from_str("youngs_modulus = 1.0").unwrap();
        let p = Parameters::new("material.0", "hjc", &none);
        assert_eq!(Erosion::from_parameters(&p).unwrap(), None);
        let bad: toml::Table = toml::from_str("erosion_plastic_strain = -1.0").unwrap();
        let p = Parameters::new("material.0", "hjc", &bad);
        let e = Erosion::from_parameters(&p).unwrap_err();
        assert_eq!(e.0, "material.0.erosion_plastic_strain");
    }
}
