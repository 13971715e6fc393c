//! The `[[boundary]]` and `[[load]]` tables: faces, which keys each condition
//! and load kind takes, regions.

use super::check::{ensure, forbidden, required, vector, Check};
use crate::scene::{axis, BoundaryConfig, Condition, Face, LoadConfig, LoadKind, SceneConfig};

pub fn boundary(b: &BoundaryConfig, i: usize, dim: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    let face_names = if dim == 2 {
        "xmin, xmax, ymin, ymax"
    } else {
        "xmin, xmax, ymin, ymax, zmin, zmax"
    };
    ensure(
        Face::parse(&b.face, dim).is_some(),
        key("face"),
        format!("must be one of {face_names}"),
    )?;
    if b.condition != Condition::Absorbing {
        let what = "a fixed, roller, velocity or friction condition (only to absorbing)";
        forbidden(&b.spring_distance, key("spring_distance"), what)?;
        forbidden(&b.spring_stiffness, key("spring_stiffness"), what)?;
    }
    face_motion(b, i, dim)?;
    if b.condition != Condition::Friction {
        let what = "a fixed, roller, velocity or absorbing condition (only to friction)";
        forbidden(&b.friction_coefficient, key("friction_coefficient"), what)?;
    }
    if b.condition != Condition::Drained {
        let what = "a fixed, roller, velocity, absorbing or friction condition (only to drained)";
        forbidden(&b.pore_pressure, key("pore_pressure"), what)?;
    }
    region(b, i, dim)?;
    if b.condition != Condition::Velocity {
        forbidden(
            &b.footing_width,
            key("footing_width"),
            "a velocity condition",
        )?;
    }
    if let Some(w) = b.footing_width {
        ensure(
            w > 0.0 && w.is_finite(),
            key("footing_width"),
            format!("must be a positive width; got {w}"),
        )?;
    }
    match b.condition {
        Condition::Friction => friction(b, i),
        Condition::Fixed | Condition::Roller => {
            forbidden(&b.velocity, key("velocity"), "fixed or roller conditions")?;
            forbidden(
                &b.components,
                key("components"),
                "fixed or roller conditions",
            )
        }
        Condition::Absorbing => absorbing(b, i),
        Condition::Drained => {
            let what = "a drained condition (it holds the pore pressure, not the velocity)";
            forbidden(&b.velocity, key("velocity"), what)?;
            forbidden(&b.components, key("components"), what)?;
            let p = b.pore_pressure.unwrap_or(0.0);
            ensure(
                p.is_finite(),
                key("pore_pressure"),
                format!("must be a finite pressure; got {p}"),
            )
        }
        Condition::Velocity => {
            for (k, c) in b.components.iter().flatten().enumerate() {
                let ok = axis(c).is_some_and(|a| a < dim);
                ensure(
                    ok,
                    format!("boundary.{i}.components.{k}"),
                    "must be \"x\", \"y\" or (3D) \"z\"",
                )?;
            }
            Ok(())
        }
    }
}

/// The motion of a face and its time history: a velocity condition takes one
/// of `velocity`, `acceleration` (with a time history) or `displacement` (with
/// a time history); an absorbing face an `incoming_velocity` (a compliant
/// base); `time_history` goes with one of them.
fn face_motion(b: &BoundaryConfig, i: usize, dim: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    let given: Vec<(&str, &Vec<f64>)> = [
        ("velocity", &b.velocity),
        ("acceleration", &b.acceleration),
        ("displacement", &b.displacement),
    ]
    .into_iter()
    .filter_map(|(k, v)| Some((k, v.as_ref()?)))
    .collect();
    if !matches!(b.condition, Condition::Velocity | Condition::Friction) {
        let what = "fixed, roller or absorbing conditions (only to velocity and friction)";
        forbidden(&b.acceleration, key("acceleration"), what)?;
        forbidden(&b.displacement, key("displacement"), what)?;
    }
    if b.condition != Condition::Absorbing {
        let what = "a fixed, roller, velocity or friction condition (only to absorbing)";
        forbidden(&b.incoming_velocity, key("incoming_velocity"), what)?;
    }
    match b.condition {
        Condition::Velocity => {
            ensure(
                !given.is_empty(),
                key("velocity"),
                "is required for a velocity condition (or `acceleration` or `displacement` with a `time_history`)",
            )?;
            motion_vector(b, i, dim, &given)?;
            if b.footing_width.is_some() {
                let what = "a footing (it moves at a constant velocity)";
                forbidden(&b.time_history, key("time_history"), what)?;
            }
            Ok(())
        }
        Condition::Absorbing => {
            if let Some(v) = &b.incoming_velocity {
                vector(v, dim, &key("incoming_velocity"))?;
            }
            let what =
                "an absorbing face without `incoming_velocity` (it scales the incoming wave)";
            match b.incoming_velocity {
                Some(_) => Ok(()),
                None => forbidden(&b.time_history, key("time_history"), what),
            }
        }
        Condition::Friction if !given.is_empty() => {
            motion_vector(b, i, dim, &given)?;
            let (name, v) = given[0];
            let axis = Face::parse(&b.face, dim).unwrap().axis;
            ensure(
                v[axis] == 0.0,
                key(name),
                format!(
                    "a friction face moves along itself only: its component normal to \
                     the face (axis {axis}) must be 0; got {}",
                    v[axis]
                ),
            )
        }
        Condition::Friction => forbidden(
            &b.time_history,
            key("time_history"),
            "a friction face at rest (give the wall's `velocity`, `acceleration` or \
             `displacement` with it)",
        ),
        _ => forbidden(
            &b.time_history,
            key("time_history"),
            "fixed or roller conditions (only to velocity, friction and absorbing faces)",
        ),
    }
}

/// The one motion vector of a velocity or friction face (`given`, not empty):
/// `dim` components; `acceleration` and `displacement` need a time history.
fn motion_vector(b: &BoundaryConfig, i: usize, dim: usize, given: &[(&str, &Vec<f64>)]) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    if let Some((second, _)) = given.get(1) {
        return Err((
            key(second),
            format!(
                "a face takes one of velocity, acceleration and displacement; `{}` is given too",
                given[0].0
            ),
        ));
    }
    let (name, v) = given[0];
    vector(v, dim, &key(name))?;
    if name != "velocity" {
        let what = format!("a face with `{name}` (the factor of the vector on the run's clock)");
        required(&b.time_history, key("time_history"), &what)?;
    }
    Ok(())
}

/// Keys of a friction face: a coefficient μ ≥ 0, no components (its motion,
/// tangential, is checked with the other faces' in `face_motion`).
fn friction(b: &BoundaryConfig, i: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    let what = "a friction condition (the wall moves as a whole)";
    forbidden(&b.components, key("components"), what)?;
    required(
        &b.friction_coefficient,
        key("friction_coefficient"),
        "a friction condition",
    )?;
    let mu = b.friction_coefficient.unwrap();
    ensure(
        mu >= 0.0 && mu.is_finite(),
        key("friction_coefficient"),
        format!("must be a finite number ≥ 0; got {mu}"),
    )
}

/// A region of a face: both corners or neither, each with `dim` components, min ≤ max;
/// not on absorbing faces.
fn region(b: &BoundaryConfig, i: usize, dim: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    if !b.condition.prescribes_velocity() && b.condition != Condition::Drained {
        let what = "a fixed, roller, velocity or drained condition (not to absorbing or friction)";
        forbidden(&b.region_min, key("region_min"), what)?;
        return forbidden(&b.region_max, key("region_max"), what);
    }
    match (&b.region_min, &b.region_max) {
        (None, None) => Ok(()),
        (Some(_), None) => required(&b.region_max, key("region_max"), "a face with region_min"),
        (None, Some(_)) => required(&b.region_min, key("region_min"), "a face with region_max"),
        (Some(lo), Some(hi)) => {
            vector(lo, dim, &key("region_min"))?;
            vector(hi, dim, &key("region_max"))?;
            ensure(
                lo.iter().zip(hi).all(|(a, b)| a <= b),
                key("region_max"),
                "must be ≥ region_min in every component",
            )
        }
    }
}

/// Keys of an absorbing face: no velocity, at most one way of giving springs.
fn absorbing(b: &BoundaryConfig, i: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    let what = "an absorbing condition";
    forbidden(&b.velocity, key("velocity"), what)?;
    forbidden(&b.components, key("components"), what)?;
    if let Some(r) = b.spring_distance {
        ensure(
            r > 0.0 && r.is_finite(),
            key("spring_distance"),
            format!("must be a positive distance (from the wave source to the face); got {r}"),
        )?;
        forbidden(
            &b.spring_stiffness,
            key("spring_stiffness"),
            "a face that sets spring_distance (give one of the two)",
        )?;
    }
    if let Some(k) = &b.spring_stiffness {
        ensure(
            k.len() == 2,
            key("spring_stiffness"),
            format!("needs 2 entries [normal, tangential], has {}", k.len()),
        )?;
        ensure(
            k.iter().all(|k| *k >= 0.0 && k.is_finite()),
            key("spring_stiffness"),
            "stiffnesses per unit area must be finite and ≥ 0",
        )?;
    }
    Ok(())
}

pub fn load(l: &LoadConfig, i: usize, s: &SceneConfig) -> Check {
    let dim = s.dimension.spatial();
    let key = |k: &str| format!("load.{i}.{k}");
    vector(&l.region_min, dim, &key("region_min"))?;
    vector(&l.region_max, dim, &key("region_max"))?;
    if let Some(b) = &l.body {
        let known = s.bodies.iter().any(|x| x.name.as_deref() == Some(b));
        ensure(known, key("body"), format!("no body is named `{b}`"))?;
    }
    ensure(
        l.ramp_time >= 0.0 && l.ramp_time.is_finite(),
        key("ramp_time"),
        "must be ≥ 0",
    )?;
    if let Some(t) = l.pulse_duration {
        ensure(
            t > 0.0 && t.is_finite(),
            key("pulse_duration"),
            "must be a positive number",
        )?;
        ensure(
            l.ramp_time == 0.0,
            key("pulse_duration"),
            "a load is either ramped (ramp_time) or a pulse (pulse_duration), not both",
        )?;
    }
    if l.time_history.is_some() {
        let what = "a load with a time history (it replaces the ramp and the pulse)";
        forbidden(&l.pulse_duration, key("pulse_duration"), what)?;
        ensure(
            l.ramp_time == 0.0,
            key("ramp_time"),
            format!("does not apply to {what}"),
        )?;
    }
    match l.kind {
        LoadKind::Point => {
            required(&l.force, key("force"), "a point load")?;
            forbidden(&l.traction, key("traction"), "a point load")?;
            forbidden(&l.face, key("face"), "a point load")?;
            vector(l.force.as_ref().unwrap(), dim, &key("force"))
        }
        LoadKind::Traction => {
            required(&l.traction, key("traction"), "a traction")?;
            required(&l.face, key("face"), "a traction")?;
            forbidden(&l.force, key("force"), "a traction")?;
            vector(l.traction.as_ref().unwrap(), dim, &key("traction"))?;
            let ok = Face::parse(l.face.as_ref().unwrap(), dim).is_some();
            ensure(
                ok,
                key("face"),
                "must name a particle face: xmin, xmax, ymin, ymax (zmin, zmax)",
            )
        }
    }
}
