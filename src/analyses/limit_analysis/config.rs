//! The `mpm limit` scene file (TOML, unknown keys rejected). Keys are documented
//! in `docs/limit_analysis.md`; errors name the file, the key and its line and
//! column like the MPM scene files.

use super::cone::{MohrCoulomb, MAX_ITERATIONS};
use super::model::{MeshSize, Model, SlopeGeometry};
use crate::scene::{blame, SceneError, Source};
use serde::Deserialize;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Problem {
    Footing,
    Slope,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitConfig {
    pub problem: Problem,
    pub soil: SoilConfig,
    pub footing: Option<FootingConfig>,
    pub slope: Option<SlopeConfig>,
    pub mesh: MeshConfig,
    #[serde(default)]
    pub solver: SolverConfig,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SoilConfig {
    pub cohesion: f64,
    /// Degrees.
    pub friction_angle: f64,
    /// Slope only (the footing soil is weightless).
    pub unit_weight: Option<f64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FootingConfig {
    pub half_width: f64,
    pub domain_width: f64,
    pub domain_depth: f64,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlopeConfig {
    pub height: f64,
    pub gradient: f64,
    pub crest_length: f64,
    #[serde(default)]
    pub toe_length: f64,
    #[serde(default)]
    pub foundation_depth: f64,
    #[serde(default = "default_search")]
    pub search: Vec<f64>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn default_search() -> Vec<f64> {
    vec![1.0, 2.0]
}

fn default_tolerance() -> f64 {
    0.01
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshConfig {
    pub fine_size: f64,
    #[serde(default = "default_growth")]
    pub growth: f64,
    pub max_size: f64,
    #[serde(default = "default_refinements")]
    pub refinements: Vec<u32>,
}

/// The conic solver (clarabel).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverConfig {
    /// Interior-point iterations for each bound.
    #[serde(default = "default_max_iterations")]
    pub max_iterations: u32,
}

impl Default for SolverConfig {
    fn default() -> Self {
        SolverConfig {
            max_iterations: default_max_iterations(),
        }
    }
}

fn default_max_iterations() -> u32 {
    MAX_ITERATIONS
}

fn default_growth() -> f64 {
    1.2
}

fn default_refinements() -> Vec<u32> {
    vec![0]
}

/// A parsed and validated limit-analysis scene.
#[derive(Clone, Debug)]
pub struct LimitScene {
    pub file: String,
    pub config: LimitConfig,
}

type Check = Result<(), (String, String)>;

fn ensure(ok: bool, key: &str, msg: &str) -> Check {
    if ok {
        Ok(())
    } else {
        Err((key.to_string(), msg.to_string()))
    }
}

fn positive(v: f64, key: &str) -> Check {
    ensure(v > 0.0 && v.is_finite(), key, "must be a positive number")
}

fn validate(c: &LimitConfig) -> Check {
    positive(c.soil.cohesion, "soil.cohesion")?;
    let phi = c.soil.friction_angle;
    ensure(
        (0.0..90.0).contains(&phi),
        "soil.friction_angle",
        "must be in degrees, 0 ≤ φ < 90",
    )?;
    match c.problem {
        Problem::Footing => {
            ensure(
                c.soil.unit_weight.is_none_or(|g| g == 0.0),
                "soil.unit_weight",
                "the footing problem is weightless (Prandtl): leave unit_weight out",
            )?;
            ensure(
                c.slope.is_none(),
                "slope",
                "does not apply to problem = \"footing\"",
            )?;
            let Some(f) = &c.footing else {
                return Err((
                    "footing".into(),
                    "problem = \"footing\" needs a [footing] table".into(),
                ));
            };
            positive(f.half_width, "footing.half_width")?;
            positive(f.domain_depth, "footing.domain_depth")?;
            ensure(
                f.domain_width > f.half_width && f.domain_width.is_finite(),
                "footing.domain_width",
                "must exceed footing.half_width",
            )?;
        }
        Problem::Slope => {
            ensure(
                c.footing.is_none(),
                "footing",
                "does not apply to problem = \"slope\"",
            )?;
            let Some(g) = c.soil.unit_weight else {
                return Err((
                    "soil.unit_weight".into(),
                    "is required for problem = \"slope\"".into(),
                ));
            };
            positive(g, "soil.unit_weight")?;
            let Some(s) = &c.slope else {
                return Err((
                    "slope".into(),
                    "problem = \"slope\" needs a [slope] table".into(),
                ));
            };
            positive(s.height, "slope.height")?;
            ensure(
                s.gradient >= 0.0 && s.gradient.is_finite(),
                "slope.gradient",
                "must be ≥ 0 (horizontal : vertical; 0 is a vertical cut)",
            )?;
            positive(s.crest_length, "slope.crest_length")?;
            ensure(
                s.toe_length >= 0.0 && s.toe_length.is_finite(),
                "slope.toe_length",
                "must be ≥ 0",
            )?;
            ensure(
                s.foundation_depth >= 0.0 && s.foundation_depth.is_finite(),
                "slope.foundation_depth",
                "must be ≥ 0",
            )?;
            ensure(
                s.search.len() == 2 && s.search[0] > 0.0 && s.search[1] > s.search[0],
                "slope.search",
                "must be two factors 0 < low < high",
            )?;
            positive(s.tolerance, "slope.tolerance")?;
        }
    }
    let m = &c.mesh;
    positive(m.fine_size, "mesh.fine_size")?;
    ensure(
        m.max_size >= m.fine_size && m.max_size.is_finite(),
        "mesh.max_size",
        "must be at least mesh.fine_size",
    )?;
    ensure(
        (1.0..=2.0).contains(&m.growth),
        "mesh.growth",
        "must be between 1 (uniform) and 2",
    )?;
    ensure(
        !m.refinements.is_empty() && m.refinements.iter().all(|&r| r <= 5),
        "mesh.refinements",
        "must list one or more refinement levels, each between 0 and 5",
    )?;
    ensure(
        c.solver.max_iterations >= 1,
        "solver.max_iterations",
        "must be at least 1",
    )?;
    let cells = match c.problem {
        Problem::Footing => {
            let f = c.footing.as_ref().unwrap();
            (f.domain_width / m.fine_size) * (f.domain_depth / m.fine_size)
        }
        Problem::Slope => {
            let s = c.slope.as_ref().unwrap();
            (s.gradient * s.height + s.crest_length) * s.height / m.fine_size.powi(2)
        }
    };
    ensure(
        cells < 4e6,
        "mesh.fine_size",
        "is far too small for the domain (more than a few million cells)",
    )
}

impl LimitScene {
    pub fn load(path: &Path, overrides: &[String]) -> Result<LimitScene, SceneError> {
        let file = path.display().to_string();
        let text = crate::scene::read_text(&file, path)?;
        LimitScene::parse(&file, &text, overrides)
    }

    /// Parse the text; an error that an override causes names the override
    /// (`scene::blame`).
    pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<LimitScene, SceneError> {
        LimitScene::parse_as_given(file, text, overrides)
            .map_err(|e| blame(e, overrides, |o| LimitScene::parse_as_given(file, text, o)))
    }

    fn parse_as_given(
        file: &str,
        text: &str,
        overrides: &[String],
    ) -> Result<LimitScene, SceneError> {
        let applied = crate::scene::overrides::apply(file, text, overrides)?;
        let source = Source::new(file, text, &applied, overrides);
        let config: LimitConfig = source.deserialize()?;
        validate(&config).map_err(|(key, msg)| source.at_key(&key, msg))?;
        Ok(LimitScene {
            file: file.to_string(),
            config,
        })
    }

    pub fn strength(&self) -> MohrCoulomb {
        MohrCoulomb {
            cohesion: self.config.soil.cohesion,
            friction_angle: self.config.soil.friction_angle.to_radians(),
        }
    }

    pub fn mesh_size(&self, refinements: u32) -> MeshSize {
        let m = &self.config.mesh;
        MeshSize {
            fine: m.fine_size,
            growth: m.growth,
            max: m.max_size,
            refinements,
        }
    }

    /// The model at one refinement level.
    pub fn model(&self, refinements: u32) -> Model {
        let c = &self.config;
        let size = self.mesh_size(refinements);
        let model = match c.problem {
            Problem::Footing => {
                let f = c.footing.as_ref().expect("validated");
                Model::footing(
                    self.strength(),
                    f.half_width,
                    f.domain_width,
                    f.domain_depth,
                    size,
                )
            }
            Problem::Slope => {
                let s = c.slope.as_ref().expect("validated");
                let geometry = SlopeGeometry {
                    height: s.height,
                    gradient: s.gradient,
                    crest: s.crest_length,
                    toe: s.toe_length,
                    foundation_depth: s.foundation_depth,
                };
                Model::slope(
                    self.strength(),
                    c.soil.unit_weight.expect("validated"),
                    geometry,
                    size,
                )
            }
        };
        Model {
            max_iterations: c.solver.max_iterations,
            ..model
        }
    }
}
