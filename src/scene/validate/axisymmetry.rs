//! `dimension = "axisymmetric"`: what the r–z half plane needs (x = r ≥ 0,
//! gravity along the axis) and the features that do not have an axisymmetric
//! form yet, refused at their key.

use super::check::{ensure, Check};
use crate::scene::{Condition, Face, SceneConfig};

/// The checks of an axisymmetric scene (its grid, bodies and conditions
/// validated as 2D ones).
pub fn axisymmetry(s: &SceneConfig) -> Check {
    ensure(
        s.grid.min[0] >= 0.0,
        "grid.min",
        format!(
            "an axisymmetric grid lies in r = x ≥ 0 (the axis is x = 0); grid.min has x = {}",
            s.grid.min[0]
        ),
    )?;
    if let Some(g) = &s.gravity {
        ensure(
            g[0] == 0.0,
            "gravity",
            "an axisymmetric body can only be loaded along its axis: gravity needs x = r \
             component 0",
        )?;
    }
    let axis = s.grid.min[0] == 0.0;
    for (i, b) in s.boundaries.iter().enumerate() {
        let key = |k: &str| format!("boundary.{i}.{k}");
        ensure(
            b.condition != Condition::Absorbing,
            key("condition"),
            "absorbing faces are not implemented in axisymmetric mode",
        )?;
        ensure(
            b.footing_width.is_none(),
            key("footing_width"),
            "the footing's pressure is per unit width; it is not implemented in \
             axisymmetric mode",
        )?;
        let on_axis = axis && Face::parse(&b.face, 2) == Face::parse("xmin", 2);
        if on_axis {
            let radial = b.condition == Condition::Velocity
                && b.velocity.as_ref().is_some_and(|v| v[0] != 0.0)
                && b.components
                    .as_ref()
                    .is_none_or(|c| c.iter().any(|a| a == "x"));
            ensure(
                b.condition != Condition::Friction && !radial,
                key("condition"),
                "the xmin face is the axis (r = 0), where the radial velocity is zero \
                 by symmetry (set automatically): only fixed, roller or a velocity \
                 with x component 0 may act there",
            )?;
        }
    }
    Ok(())
}
