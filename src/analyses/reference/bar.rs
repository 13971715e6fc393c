//! Axially vibrating bar, fixed at x = min and free at x = max, in its first mode:
//! the period is T = 4 L / c with c = √(M/ρ), M = E (1 − ν)/((1 + ν)(1 − 2ν)) the
//! constrained modulus (lateral rollers: uniaxial strain; M = E at ν = 0). The
//! measured period comes from the zero crossings of the body's mean velocity in
//! history.csv; the error is |T_h / T − 1|.

use super::measure::{body0_box, body0_material, ErrorMeasure, KeyError};
use crate::output::Table;
use crate::scene::SceneConfig;
use std::path::Path;

#[derive(Clone, Debug)]
pub struct BarPeriod {
    /// The analytical period 4 L / c.
    pub period: f64,
}

impl BarPeriod {
    /// From the scene: body 0's length along x and its material.
    pub fn from_scene(s: &SceneConfig) -> Result<BarPeriod, KeyError> {
        let (lo, hi) = body0_box(s)?;
        let (rho, e, nu) = body0_material(s)?;
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        Ok(BarPeriod {
            period: 4.0 * (hi[0] - lo[0]) / (m / rho).sqrt(),
        })
    }
}

/// Times at which a sampled signal changes sign (linear interpolation).
pub fn zero_crossings(t: &[f64], y: &[f64]) -> Vec<f64> {
    (1..t.len())
        .filter(|&i| (y[i - 1] > 0.0) != (y[i] > 0.0))
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * y[i - 1] / (y[i - 1] - y[i]))
        .collect()
}

/// Mean period of an oscillating signal from its zero crossings (two per period),
/// or None with fewer than two crossings.
pub fn period(t: &[f64], y: &[f64]) -> Option<f64> {
    let zc = zero_crossings(t, y);
    (zc.len() >= 2).then(|| 2.0 * (zc[zc.len() - 1] - zc[0]) / (zc.len() - 1) as f64)
}

impl ErrorMeasure for BarPeriod {
    fn description(&self) -> String {
        format!(
            "vibrating bar: |T_h/T − 1| of the first-mode period, T = 4L/c = {}",
            self.period
        )
    }

    fn error(&self, out: &Path) -> Result<f64, String> {
        let h = Table::read(&out.join("history.csv"))?;
        let measured = period(h.column("t")?, h.column("body0_vx")?).ok_or(
            "fewer than two zero crossings of body0_vx in history.csv: run longer than T/2",
        )?;
        Ok((measured / self.period - 1.0).abs())
    }
}
