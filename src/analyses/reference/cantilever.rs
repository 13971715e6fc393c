//! Cantilever with a vertical dead end load (problems/cantilever.toml): the mean
//! deflection of the loaded particles against the elastica of a cantilever as long
//! as their mean reference distance from the clamp, a (the rest of the beam is
//! unloaded), at k_a = P a²/EI. Plane strain: EI = E/(1 − ν²) d³/12 (unit
//! thickness). By default the beam is Reissner's (the elastica with extension
//! P/EA and shear P/(κGA), κ = 5/6), the beam model of a 2D continuum;
//! `beam = "elastica"` gives the classical inextensible elastica. Error
//! |v / v_ref − 1|. Details: tests/verification/cantilever.rs, papers/cantilever_elastica/.

use super::elastica::elastica;
use super::measure::{body0_box, body0_material, ErrorMeasure, KeyError};
use crate::output::Table;
use crate::scene::{Beam, LoadKind, SceneConfig};
use std::path::Path;

#[derive(Clone, Debug)]
pub struct CantileverTip {
    /// Clamp position (body 0's min x).
    pub x_clamp: f64,
    /// Region of the end load (reference positions).
    pub region_min: Vec<f64>,
    pub region_max: Vec<f64>,
    /// Load magnitude P (downwards).
    pub force: f64,
    /// Plane-strain bending, axial and shear stiffness (unit thickness).
    pub ei: f64,
    pub ea: f64,
    pub kga: f64,
    pub beam: Beam,
}

impl CantileverTip {
    /// From the scene: 2D, body 0 a rectangle clamped at its min x, load 0 a
    /// vertical point load.
    pub fn from_scene(s: &SceneConfig) -> Result<CantileverTip, KeyError> {
        if s.dimension != crate::scene::Dimension::Cartesian(2) {
            return Err(("dimension".into(), "the cantilever reference is 2D".into()));
        }
        let (lo, hi) = body0_box(s)?;
        let (_, e, nu) = body0_material(s)?;
        let load = s.loads.first().ok_or((
            "load".to_string(),
            "the cantilever reference needs a point load as load 0".to_string(),
        ))?;
        let force = match (load.kind, &load.force) {
            (LoadKind::Point, Some(f)) if f[0] == 0.0 && f[1] < 0.0 => -f[1],
            _ => {
                return Err((
                    "load.0.force".into(),
                    "the cantilever reference needs load 0 to be a downward point load \
                     [0, -P]"
                        .into(),
                ))
            }
        };
        let d = hi[1] - lo[1];
        let e_ps = e / (1.0 - nu * nu);
        Ok(CantileverTip {
            x_clamp: lo[0],
            region_min: load.region_min.clone(),
            region_max: load.region_max.clone(),
            force,
            ei: e_ps * d.powi(3) / 12.0,
            ea: e_ps * d,
            kga: 5.0 / 6.0 * e / (2.0 * (1.0 + nu)) * d,
            beam: s
                .reference
                .as_ref()
                .and_then(|r| r.beam)
                .unwrap_or(Beam::Reissner),
        })
    }

    /// Deflection of the beam model at distance a from the clamp, loaded there.
    pub fn reference_deflection(&self, a: f64) -> f64 {
        let (a_e, a_s) = match self.beam {
            Beam::Reissner => (self.force / self.ea, self.force / self.kga),
            Beam::Elastica => (0.0, 0.0),
        };
        elastica(self.force * a * a / self.ei, a_e, a_s).0 * a
    }

    /// (a, measured deflection): the loaded particles' mean distance from the clamp
    /// and mean downward displacement.
    pub fn loaded_deflection(&self, particles: &Table) -> Result<(f64, f64), String> {
        let (x0, y0) = (particles.column("X0")?, particles.column("Y0")?);
        let y = particles.column("y")?;
        let inside = |i: usize| {
            (x0[i] >= self.region_min[0] && x0[i] <= self.region_max[0])
                && (y0[i] >= self.region_min[1] && y0[i] <= self.region_max[1])
        };
        let sel: Vec<usize> = (0..x0.len()).filter(|&i| inside(i)).collect();
        if sel.is_empty() {
            return Err("no particle lies in the load region".into());
        }
        let n = sel.len() as f64;
        let a = sel.iter().map(|&i| x0[i] - self.x_clamp).sum::<f64>() / n;
        let v = -sel.iter().map(|&i| y[i] - y0[i]).sum::<f64>() / n;
        Ok((a, v))
    }
}

impl ErrorMeasure for CantileverTip {
    fn description(&self) -> String {
        let beam = match self.beam {
            Beam::Reissner => "Reissner's beam (elastica with extension and shear)",
            Beam::Elastica => "the classical elastica",
        };
        format!(
            "cantilever: |v/v_ref − 1| of the loaded particles' deflection against {beam}, \
             P = {}",
            self.force
        )
    }

    fn error(&self, out: &Path) -> Result<f64, String> {
        let (a, v) = self.loaded_deflection(&Table::read(&out.join("particles_final.csv"))?)?;
        Ok((v / self.reference_deflection(a) - 1.0).abs())
    }
}
