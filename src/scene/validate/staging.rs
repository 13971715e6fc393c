//! Staged construction (`scene::staging`): `[[body]] active`, and each
//! `[[stage]]`'s `activate`, `deactivate`, `excavate` and
//! `reset_displacement`. Names refer to continuum bodies; a body is activated
//! once, after starting inactive, and deactivated while it is in the model;
//! a region has its shape's keys; the keys need `[[stage]]` tables, and a
//! scene with a peridynamic body stages nothing.

use super::check::{ensure, forbidden, required, vector, Check};
use crate::scene::region::{RegionConfig, RegionShape};
use crate::scene::{BodyKindName, SceneConfig, SolverConfig};

/// The staging keys of scene `s`.
pub fn staging(s: &SceneConfig) -> Check {
    if let Some(solver) = &s.solver {
        only_in_stages(solver)?;
    }
    for (i, b) in s.bodies.iter().enumerate() {
        if b.active == Some(false) {
            inactive_body(s, i)?;
        }
    }
    if !s.stages_construction() {
        return Ok(());
    }
    let peridynamic = (0..s.bodies.len()).find(|&i| s.body_kind(i) == BodyKindName::Peridynamic);
    if let Some(i) = peridynamic {
        let key = first_staging_key(s);
        ensure(
            false,
            key,
            format!(
                "staged construction does not apply to a scene with a peridynamic body \
                 (body {i}): its bonds are built once between the particles as built"
            ),
        )?;
    }
    let mut active: Vec<bool> = s.bodies.iter().map(|b| b.active != Some(false)).collect();
    let mut entered: Vec<bool> = active.clone();
    for (k, st) in s.stages.iter().enumerate() {
        let prefix = format!("stage.{k}");
        for (n, name) in st.deactivate.iter().flatten().enumerate() {
            let key = format!("{prefix}.deactivate.{n}");
            for i in continuum_bodies(s, name, &key)? {
                ensure(
                    active[i],
                    &key,
                    format!("body {i} (`{name}`) is not in the model at this stage's start"),
                )?;
                active[i] = false;
            }
        }
        for (n, r) in st.excavate.iter().flatten().enumerate() {
            region(r, s.dimension.spatial(), &format!("{prefix}.excavate.{n}"))?;
        }
        for (n, name) in st.activate.iter().flatten().enumerate() {
            let key = format!("{prefix}.activate.{n}");
            for i in continuum_bodies(s, name, &key)? {
                ensure(
                    !entered[i],
                    &key,
                    format!(
                        "body {i} (`{name}`) has been in the model already: a body enters \
                         once, from `active = false`"
                    ),
                )?;
                (active[i], entered[i]) = (true, true);
            }
        }
        if st.reset_displacement == Some(true) {
            no_springs(s, &format!("{prefix}.reset_displacement"))?;
        }
    }
    Ok(())
}

/// The staging keys of a `[solver]` table: none (they act at a stage's start).
fn only_in_stages(st: &SolverConfig) -> Check {
    let what = "a [solver] table: staged construction acts at the start of a [[stage]]";
    forbidden(&st.activate, "solver.activate".into(), what)?;
    forbidden(&st.deactivate, "solver.deactivate".into(), what)?;
    forbidden(&st.excavate, "solver.excavate".into(), what)?;
    forbidden(
        &st.reset_displacement,
        "solver.reset_displacement".into(),
        what,
    )
}

/// Body i starts inactive: a continuum body some stage activates.
fn inactive_body(s: &SceneConfig, i: usize) -> Check {
    let key = format!("body.{i}.active");
    ensure(
        s.is_continuum(i),
        &key,
        "only a continuum body can start inactive",
    )?;
    let name = s.bodies[i].name.as_deref();
    ensure(
        name.is_some(),
        format!("body.{i}.name"),
        "a body with `active = false` needs a name, by which a stage activates it",
    )?;
    let activated = (s.stages.iter()).any(|st| {
        st.activate
            .iter()
            .flatten()
            .any(|n| Some(n.as_str()) == name)
    });
    ensure(
        activated,
        key,
        format!(
            "body `{}` starts inactive, and no stage activates it (`[[stage]] activate`)",
            name.unwrap_or_default()
        ),
    )
}

/// The bodies named `name` (at `key`): at least one, all continuum bodies.
fn continuum_bodies(
    s: &SceneConfig,
    name: &str,
    key: &str,
) -> Result<Vec<usize>, (String, String)> {
    let bodies = s.bodies_named(name);
    if bodies.is_empty() {
        let names: Vec<&str> = s.bodies.iter().filter_map(|b| b.name.as_deref()).collect();
        return Err((
            key.into(),
            format!("no body is named `{name}` (the named bodies: {names:?})"),
        ));
    }
    for &i in &bodies {
        ensure(
            s.is_continuum(i),
            key,
            format!(
                "body {i} (`{name}`) is not a continuum body: only those enter and leave by stages"
            ),
        )?;
    }
    Ok(bodies)
}

/// A region's shape for the dimension and its keys.
fn region(r: &RegionConfig, dim: usize, prefix: &str) -> Check {
    let shape: &str = r.shape.into();
    let two_d = matches!(
        r.shape,
        RegionShape::Rectangle | RegionShape::Disk | RegionShape::Polygon
    );
    ensure(
        two_d == (dim == 2),
        format!("{prefix}.shape"),
        format!("a {shape} region does not apply in {dim}D"),
    )?;
    let key = |k: &str| format!("{prefix}.{k}");
    match r.shape {
        RegionShape::Rectangle | RegionShape::Box => {
            required(&r.min, key("min"), shape)?;
            required(&r.max, key("max"), shape)?;
            let (lo, hi) = (r.min.as_ref().unwrap(), r.max.as_ref().unwrap());
            vector(lo, dim, &key("min"))?;
            vector(hi, dim, &key("max"))?;
            ensure(
                (0..dim).all(|d| lo[d] < hi[d]),
                key("max"),
                "must exceed min in every component",
            )
        }
        RegionShape::Disk | RegionShape::Sphere => {
            required(&r.centre, key("centre"), shape)?;
            required(&r.radius, key("radius"), shape)?;
            vector(r.centre.as_ref().unwrap(), dim, &key("centre"))?;
            let radius = r.radius.unwrap();
            ensure(
                radius > 0.0 && radius.is_finite(),
                key("radius"),
                "must be > 0",
            )
        }
        RegionShape::Polygon => {
            required(&r.vertices, key("vertices"), shape)?;
            let v = r.vertices.as_ref().unwrap();
            ensure(
                v.len() >= 3,
                key("vertices"),
                "a polygon needs at least 3 vertices",
            )?;
            for (k, p) in v.iter().enumerate() {
                vector(p, 2, &key(&format!("vertices.{k}")))?;
            }
            Ok(())
        }
    }
}

/// A displacement reset moves the reference positions, from which an
/// absorbing face's springs measure their stretch: not with springs.
fn no_springs(s: &SceneConfig, key: &str) -> Check {
    let spring = (s.boundaries.iter())
        .position(|b| b.spring_distance.is_some() || b.spring_stiffness.is_some());
    match spring {
        None => Ok(()),
        Some(j) => ensure(
            false,
            key,
            format!(
                "boundary {j}'s springs measure their stretch from the reference positions, \
                 which a displacement reset would move: leave it out"
            ),
        ),
    }
}

/// The first staging key of the scene, for a message about staging as a whole.
fn first_staging_key(s: &SceneConfig) -> String {
    if let Some(i) = s.bodies.iter().position(|b| b.active == Some(false)) {
        return format!("body.{i}.active");
    }
    let k = s
        .stages
        .iter()
        .position(|st| st.changes_model())
        .unwrap_or(0);
    let st = &s.stages[k];
    let key = [
        ("deactivate", st.deactivate.is_some()),
        ("excavate", st.excavate.is_some()),
        ("activate", st.activate.is_some()),
        ("reset_displacement", st.reset_displacement.is_some()),
    ]
    .into_iter()
    .find(|(_, given)| *given)
    .map_or("activate", |(k, _)| k);
    format!("stage.{k}.{key}")
}
