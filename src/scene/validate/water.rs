//! The `[water]` table: its unit weight, one phreatic surface (a level or, in
//! 2D and axisymmetric mode, a polyline increasing along the horizontal axis)
//! and the gravity it needs (along one axis; tilted only for parallel seepage
//! below a level, the slope-aligned frame of an infinite slope).

use super::check::{ensure, required, Check};
use crate::scene::{Dimension, SceneConfig, Seepage, WaterConfig};

pub fn water(w: &WaterConfig, s: &SceneConfig) -> Check {
    required(&w.unit_weight, "water.unit_weight".into(), "[water]")?;
    let gamma = w.unit_weight.unwrap();
    ensure(
        gamma > 0.0 && gamma.is_finite(),
        "water.unit_weight",
        "must be a positive number (γ_w = ρ_w g in the scene's units)",
    )?;
    surface(w, s.dimension)?;
    gravity(w, s.gravity.as_deref().unwrap_or(&[]))
}

/// Exactly one of `level` and `phreatic_line`, finite, the polyline in 2D only.
fn surface(w: &WaterConfig, dimension: Dimension) -> Check {
    match (w.level, &w.phreatic_line) {
        (Some(_), Some(_)) => Err((
            "water.phreatic_line".into(),
            "give either `level` or `phreatic_line`, not both".into(),
        )),
        (None, None) => Err((
            "water".into(),
            "needs a phreatic surface: `level` or `phreatic_line`".into(),
        )),
        (Some(h), None) => ensure(h.is_finite(), "water.level", "must be a finite number"),
        (None, Some(line)) => {
            ensure(
                dimension != Dimension::Cartesian(3),
                "water.phreatic_line",
                "is a 2D (and axisymmetric) water table, a function of the horizontal \
                 coordinate; give `level` in 3D",
            )?;
            polyline(line)
        }
    }
}

/// At least two points [horizontal, elevation], finite, strictly increasing
/// along the horizontal axis.
fn polyline(line: &[Vec<f64>]) -> Check {
    let key = "water.phreatic_line";
    ensure(line.len() >= 2, key, "needs at least two points")?;
    for (i, p) in line.iter().enumerate() {
        ensure(
            p.len() == 2 && p.iter().all(|x| x.is_finite()),
            format!("{key}.{i}"),
            "must be a point [horizontal, elevation] of two finite numbers",
        )?;
    }
    for i in 1..line.len() {
        ensure(
            line[i][0] > line[i - 1][0],
            format!("{key}.{i}"),
            "the horizontal coordinate must increase strictly along the line",
        )?;
    }
    Ok(())
}

/// Gravity along one axis (the vertical), or, for parallel seepage below a
/// level, tilted (the level is then the grid plane most nearly horizontal).
fn gravity(w: &WaterConfig, g: &[f64]) -> Check {
    let nonzero = g.iter().filter(|&&x| x != 0.0).count();
    ensure(
        nonzero > 0,
        "water",
        "needs `gravity`: the pore pressure is its hydrostatic part",
    )?;
    let tilted_allowed = w.seepage == Seepage::Parallel && w.level.is_some();
    ensure(
        nonzero == 1 || tilted_allowed,
        "water",
        "needs `gravity` along one grid axis (the vertical); a tilted gravity (a \
         slope-aligned frame) is allowed only with seepage = \"parallel\" below a `level`",
    )
}
