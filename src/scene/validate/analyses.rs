//! The tables of the analyses around the run: `[geostatic]`,
//! `[strength_reduction]` and `[bench]`.

use super::check::{ensure, required, vector, Check};
use crate::material::Material;
use crate::scene::{
    BenchConfig, BodyKindName, BodyShape, GeostaticConfig, SceneConfig, SolverKind,
    StrengthReductionConfig,
};

pub fn geostatic(g: &GeostaticConfig, s: &SceneConfig, materials: &[Box<dyn Material>]) -> Check {
    let gravity = s.gravity.as_deref().unwrap_or(&[]);
    let nonzero = gravity.iter().filter(|&&x| x != 0.0).count();
    ensure(
        nonzero == 1,
        "geostatic",
        "needs `gravity` along one grid axis (the vertical)",
    )?;
    if let Some(k0) = g.k0 {
        ensure(
            k0 > 0.0 && k0.is_finite(),
            "geostatic.k0",
            "must be a positive number",
        )?;
    }
    for (i, b) in s.bodies.iter().enumerate() {
        // A rigid or a peridynamic body takes no K0 state (a correspondence
        // body starts unstressed: docs/scene.md).
        if s.body_kind(i) != BodyKindName::Continuum {
            continue;
        }
        ensure(
            b.shape != BodyShape::Particles,
            format!("body.{i}.shape"),
            "[geostatic] measures depths below a body's top surface, which a particle \
             file does not give: give the initial stresses in the file's stress columns \
             (docs/geometry.md)",
        )?;
        let k = s
            .materials
            .iter()
            .position(|m| m.name == b.material)
            .unwrap();
        let (m, built) = (&s.materials[k], &materials[k]);
        ensure(
            built.integrates_from_stored_stress(),
            format!("body.{i}.material"),
            format!(
                "[geostatic] needs models whose stress update starts from the stored stress, so that the K0 stresses persist (hyperelastic models compute the stress from F alone); `{}` is {}",
                m.name, m.model
            ),
        )?;
        ensure(
            g.k0.is_some() || built.frictional_strength().is_some(),
            "geostatic.k0",
            format!(
                "is required: material `{}` has no friction angle for K0 = 1 − sin φ",
                m.name
            ),
        )?;
    }
    Ok(())
}

pub fn strength_reduction(
    r: &StrengthReductionConfig,
    s: &SceneConfig,
    materials: &[Box<dyn Material>],
) -> Check {
    let p = "strength_reduction";
    ensure(
        r.search.len() == 2
            && r.search.iter().all(|f| f.is_finite())
            && r.search[0] > 0.0
            && r.search[1] > r.search[0],
        format!("{p}.search"),
        "must be [F_low, F_high] with 0 < F_low < F_high",
    )?;
    ensure(
        r.tolerance() > 0.0 && r.tolerance().is_finite(),
        format!("{p}.tolerance"),
        "must be a positive number",
    )?;
    ensure(
        r.max_trials() >= 2,
        format!("{p}.max_trials"),
        "must be at least 2",
    )?;
    ensure(
        r.max_trials() <= 200,
        format!("{p}.max_trials"),
        "must be at most 200",
    )?;
    if let Some(m) = &r.monitor {
        vector(m, s.dimension.spatial(), &format!("{p}.monitor"))?;
    }
    if let Some(d) = r.max_displacement {
        required(&r.monitor, format!("{p}.monitor"), "max_displacement")?;
        ensure(
            d > 0.0 && d.is_finite(),
            format!("{p}.max_displacement"),
            "must be a positive length",
        )?;
    }
    // Something a factor divides, as strength reduction does it.
    ensure(
        materials
            .iter()
            .any(|m| m.with_reduced_strength(1.0).is_some()),
        p,
        "needs a material with a frictional strength, c and φ (nothing to reduce)",
    )?;
    ensure(
        s.stages().iter().any(|st| st.kind == SolverKind::Implicit),
        p,
        "needs an implicit stage: a trial fails when its Newton iteration does",
    )
}

/// The `[bench]` table (also used for a separate bench file, `prefix` = "bench").
/// Configuration names are resolved by `mpm bench`, which knows the built-in ones.
pub fn bench(b: &BenchConfig, prefix: &str) -> Check {
    let key = |k: &str| format!("{prefix}.{k}");
    for (i, dt) in b.dt.iter().flatten().enumerate() {
        ensure(
            *dt > 0.0 && dt.is_finite(),
            key(&format!("dt.{i}")),
            "must be a positive number",
        )?;
    }
    for (i, n) in b.load_steps.iter().flatten().enumerate() {
        ensure(
            *n >= 1,
            key(&format!("load_steps.{i}")),
            "must be at least 1",
        )?;
    }
    ensure(
        b.cells.is_none() || b.refine.is_none(),
        key("refine"),
        "give either cells or refine, not both",
    )?;
    for (i, c) in b.cells.iter().flatten().enumerate() {
        ensure(
            !c.is_empty() && c.iter().all(|&n| n >= 1),
            key(&format!("cells.{i}")),
            "every entry needs at least one cell per direction",
        )?;
    }
    for (i, f) in b.refine.iter().flatten().enumerate() {
        ensure(*f >= 1, key(&format!("refine.{i}")), "must be at least 1")?;
    }
    if let Some(t) = b.timeout {
        ensure(
            t > 0.0 && t.is_finite(),
            key("timeout"),
            "must be a positive number of seconds",
        )?;
    }
    for (i, c) in b.custom.iter().enumerate() {
        let dup = b.custom[..i].iter().any(|o| o.name == c.name);
        ensure(
            !dup,
            key(&format!("configuration.{i}.name")),
            format!("configuration `{}` is defined twice", c.name),
        )?;
        let ok = !c.name.is_empty()
            && c.name
                .chars()
                .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-');
        ensure(
            ok,
            key(&format!("configuration.{i}.name")),
            "use letters, digits, `_` and `-` only (it names the run directories)",
        )?;
        for (j, o) in c.set.iter().enumerate() {
            ensure(
                o.contains('='),
                key(&format!("configuration.{i}.set.{j}")),
                format!("`{o}` is not of the form KEY=VALUE"),
            )?;
        }
    }
    for (j, o) in b.set.iter().enumerate() {
        ensure(
            o.contains('='),
            key(&format!("set.{j}")),
            format!("`{o}` is not of the form KEY=VALUE"),
        )?;
    }
    Ok(())
}
