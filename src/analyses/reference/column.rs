//! Column under self-weight: at the material point from height Y the Cauchy stress
//! is σ_yy = −ρ g (l0 − Y), the weight above it over an unchanged cross-section
//! (lateral rollers), exact at finite strain (reference README item 2). Error:
//! normalised L2 over the reference volume,
//! e = √(Σ V0 (σ_yy − σ_a)² / Σ V0) / (ρ g l0).

use super::measure::{body0_box, body0_material, ErrorMeasure, KeyError};
use crate::output::Table;
use crate::scene::SceneConfig;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Column {
    /// The vertical axis (along gravity): 1 in 2D (y), 2 in 3D (z) usually.
    pub axis: usize,
    /// ρ g.
    pub rho_g: f64,
    /// Reference height of the top surface and of the column (l0).
    pub top: f64,
    pub height: f64,
}

const POSITION: [&str; 3] = ["X0", "Y0", "Z0"];
const NORMAL_STRESS: [&str; 3] = ["sxx", "syy", "szz"];

impl Column {
    /// From the scene: gravity along one axis, body 0 a rectangle or box, its
    /// material's density.
    pub fn from_scene(s: &SceneConfig) -> Result<Column, KeyError> {
        let g = s.gravity.clone().unwrap_or_default();
        let axes: Vec<usize> = (0..g.len()).filter(|&d| g[d] != 0.0).collect();
        let [axis] = axes[..] else {
            return Err((
                "gravity".into(),
                "the column reference needs gravity along exactly one axis".into(),
            ));
        };
        if g[axis] > 0.0 {
            return Err((
                "gravity".into(),
                "the column reference needs gravity pointing towards −axis (the base at min)"
                    .into(),
            ));
        }
        let (lo, hi) = body0_box(s)?;
        let (rho, _, _) = body0_material(s)?;
        Ok(Column {
            axis,
            rho_g: rho * g[axis].abs(),
            top: hi[axis],
            height: hi[axis] - lo[axis],
        })
    }

    /// The normalised L2 stress error of a final particle state.
    pub fn error_of(&self, particles: &Table) -> Result<f64, String> {
        let y0 = particles.column(POSITION[self.axis])?;
        let sigma = particles.column(NORMAL_STRESS[self.axis])?;
        let v0 = particles.column("volume0")?;
        let (mut num, mut vol) = (0.0, 0.0);
        for i in 0..y0.len() {
            let exact = -self.rho_g * (self.top - y0[i]);
            num += v0[i] * (sigma[i] - exact).powi(2);
            vol += v0[i];
        }
        Ok((num / vol).sqrt() / (self.rho_g * self.height))
    }
}

impl ErrorMeasure for Column {
    fn description(&self) -> String {
        format!(
            "column: normalised L2 error of {} against −ρg(l0 − {}), ρg = {}, l0 = {}",
            NORMAL_STRESS[self.axis], POSITION[self.axis], self.rho_g, self.height
        )
    }

    fn error(&self, out: &Path) -> Result<f64, String> {
        self.error_of(&Table::read(&out.join("particles_final.csv"))?)
    }
}
