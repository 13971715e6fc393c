//! Physical and structural checks after parsing. Each failure names the dotted key
//! path (`material.0.poisson_ratio`) so the error can point at its line.

use super::config::*;
use super::grid::{axis, Face, GridConfig};
use crate::material::Material;

type Check = Result<(), (String, String)>;

fn ensure(ok: bool, path: impl Into<String>, msg: impl Into<String>) -> Check {
    if ok {
        Ok(())
    } else {
        Err((path.into(), msg.into()))
    }
}

fn vector(v: &[f64], dim: usize, path: &str) -> Check {
    ensure(
        v.len() == dim,
        path,
        format!(
            "needs {dim} components (dimension = {dim}), has {}",
            v.len()
        ),
    )?;
    ensure(
        v.iter().all(|x| x.is_finite()),
        path,
        "components must be finite numbers",
    )
}

fn required<T>(v: &Option<T>, path: String, what: &str) -> Result<(), (String, String)> {
    ensure(v.is_some(), path, format!("is required for {what}"))
}

fn forbidden<T>(v: &Option<T>, path: String, what: &str) -> Check {
    ensure(v.is_none(), path, format!("does not apply to {what}"))
}

pub fn validate(s: &SceneConfig) -> Check {
    let dim = s.dimension;
    ensure(
        dim == 2 || dim == 3,
        "dimension",
        "must be 2 (plane strain) or 3",
    )?;
    if let Some(g) = &s.gravity {
        vector(g, dim, "gravity")?;
    }
    grid(&s.grid, dim)?;
    let materials = materials(s)?;
    ensure(
        !s.bodies.is_empty(),
        "body",
        "the scene defines no [[body]]",
    )?;
    for (i, b) in s.bodies.iter().enumerate() {
        body(b, i, s)?;
    }
    for (i, b) in s.boundaries.iter().enumerate() {
        boundary(b, i, dim)?;
        let earlier = s.boundaries[..i].iter().any(|b| b.footing_width.is_some());
        if b.footing_width.is_some() && earlier {
            return Err((
                format!("boundary.{i}.footing_width"),
                "only one boundary may be a footing".into(),
            ));
        }
    }
    for (i, l) in s.loads.iter().enumerate() {
        load(l, i, s)?;
    }
    needs_krylov(s, &materials)?;
    match (&s.solver, s.stages.is_empty()) {
        (Some(solver_config), true) => {
            solver(solver_config, "solver")?;
            stage_strength_factor(solver_config, "solver", s, &materials)?;
        }
        (None, false) => {
            for (k, st) in s.stages.iter().enumerate() {
                solver(st, &format!("stage.{k}"))?;
                stage_strength_factor(st, &format!("stage.{k}"), s, &materials)?;
            }
        }
        (Some(_), false) => {
            return Err((
                "stage".into(),
                "give either [solver] or [[stage]] tables, not both".into(),
            ))
        }
        (None, true) => {
            return Err((
                "solver".into(),
                "the scene needs a [solver] table or [[stage]] tables".into(),
            ))
        }
    }
    ensure(
        s.output.history_interval >= 0.0,
        "output.history_interval",
        "must be ≥ 0",
    )?;
    if let Some(g) = &s.geostatic {
        geostatic(g, s, &materials)?;
    }
    if let Some(r) = &s.strength_reduction {
        strength_reduction(r, s, &materials)?;
    }
    if let Some(b) = &s.bench {
        bench(b, "bench")?;
    }
    Ok(())
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

/// The `[[material]]` tables: a positive density, the model's own keys and
/// checks (`material::registry`), a unique name. Returns the materials as built.
fn materials(s: &SceneConfig) -> Result<Vec<Box<dyn Material>>, (String, String)> {
    ensure(
        !s.materials.is_empty(),
        "material",
        "the scene defines no [[material]]",
    )?;
    let mut built = Vec::new();
    for (i, m) in s.materials.iter().enumerate() {
        ensure(
            m.density > 0.0 && m.density.is_finite(),
            format!("material.{i}.density"),
            "must be a positive number",
        )?;
        built.push(m.build(i)?);
        let dup = s.materials[..i].iter().any(|o| o.name == m.name);
        ensure(
            !dup,
            format!("material.{i}.name"),
            format!("material name `{}` is used twice", m.name),
        )?;
    }
    Ok(built)
}

/// A material without an analytic tangent cannot run on an implicit stage with
/// the direct solver.
fn needs_krylov(s: &SceneConfig, materials: &[Box<dyn Material>]) -> Check {
    let Some(i) = materials.iter().position(|m| !m.has_analytic_tangent()) else {
        return Ok(());
    };
    let m = &s.materials[i];
    let stages: Vec<(String, &SolverConfig)> = match &s.solver {
        Some(solver) => vec![("solver".into(), solver)],
        None => (s.stages.iter().enumerate())
            .map(|(k, st)| (format!("stage.{k}"), st))
            .collect(),
    };
    for (prefix, st) in stages {
        let direct = st.kind == SolverKind::Implicit && st.linear_solver() == LinearSolver::Direct;
        let key = match st.linear_solver {
            Some(_) => format!("{prefix}.linear_solver"),
            None => format!("{prefix}.kind"),
        };
        ensure(
            !direct,
            key,
            format!(
                "material `{}` (model `{}`) has no analytic tangent, which the direct \
                 implicit solver needs: set linear_solver = \"gmres\" (or \"cg\" for \
                 symmetric problems) in this table",
                m.name, m.model
            ),
        )?;
    }
    Ok(())
}

fn grid(g: &GridConfig, dim: usize) -> Check {
    vector(&g.min, dim, "grid.min")?;
    vector(&g.max, dim, "grid.max")?;
    ensure(
        g.cells.len() == dim,
        "grid.cells",
        format!("needs {dim} entries"),
    )?;
    ensure(
        g.cells.iter().all(|&c| c >= 1),
        "grid.cells",
        "every direction needs at least one cell",
    )?;
    let ok = (0..dim).all(|d| g.max[d] > g.min[d]);
    ensure(ok, "grid.max", "must exceed grid.min in every direction")
}

fn body(b: &BodyConfig, i: usize, s: &SceneConfig) -> Check {
    let dim = s.dimension;
    let key = |k: &str| format!("body.{i}.{k}");
    let known = s.materials.iter().any(|m| m.name == b.material);
    ensure(
        known,
        key("material"),
        format!("no material is named `{}`", b.material),
    )?;
    let (lo, hi) = body_bounds(b, i, dim)?;
    let inside = (0..dim).all(|d| lo[d] >= s.grid.min[d] && hi[d] <= s.grid.max[d]);
    ensure(
        inside,
        key("shape"),
        format!(
            "the body spans {lo:?}..{hi:?}, outside the grid {:?}..{:?}",
            s.grid.min, s.grid.max
        ),
    )?;
    match &b.particles_per_cell {
        PerDirection::Same(n) => ensure(*n >= 1, key("particles_per_cell"), "must be at least 1")?,
        PerDirection::Each(v) => ensure(
            v.len() == dim && v.iter().all(|&n| n >= 1),
            key("particles_per_cell"),
            format!("needs {dim} entries, each at least 1"),
        )?,
    }
    if let Some(v) = &b.velocity {
        vector(v, dim, &key("velocity"))?;
    }
    if let Some(exprs) = &b.velocity_expr {
        ensure(
            exprs.len() == dim,
            key("velocity_expr"),
            format!("needs {dim} expressions"),
        )?;
        for (c, e) in exprs.iter().enumerate() {
            crate::scene::expr::eval(e, &[0.0; 3])
                .map_err(|m| (format!("body.{i}.velocity_expr.{c}"), m))?;
        }
    }
    Ok(())
}

/// Bounding box of a body's geometry, checking the keys its shape needs.
fn body_bounds(
    b: &BodyConfig,
    i: usize,
    dim: usize,
) -> Result<(Vec<f64>, Vec<f64>), (String, String)> {
    let key = |k: &str| format!("body.{i}.{k}");
    let what = format!("shape `{:?}`", b.shape).to_lowercase();
    let shape_dim = match b.shape {
        BodyShape::Rectangle | BodyShape::Disk | BodyShape::Polygon => 2,
        BodyShape::Box | BodyShape::Sphere => 3,
    };
    ensure(
        shape_dim == dim,
        key("shape"),
        format!("{what} is a {shape_dim}D shape but dimension = {dim}"),
    )?;
    match b.shape {
        BodyShape::Rectangle | BodyShape::Box => {
            required(&b.min, key("min"), &what)?;
            required(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            let (lo, hi) = (b.min.clone().unwrap(), b.max.clone().unwrap());
            vector(&lo, dim, &key("min"))?;
            vector(&hi, dim, &key("max"))?;
            ensure(
                (0..dim).all(|d| hi[d] > lo[d]),
                key("max"),
                "must exceed min in every direction",
            )?;
            Ok((lo, hi))
        }
        BodyShape::Disk | BodyShape::Sphere => {
            required(&b.centre, key("centre"), &what)?;
            required(&b.radius, key("radius"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            let c = b.centre.clone().unwrap();
            vector(&c, dim, &key("centre"))?;
            let r = b.radius.unwrap();
            ensure(
                r > 0.0 && r.is_finite(),
                key("radius"),
                "must be a positive number",
            )?;
            Ok((
                c.iter().map(|x| x - r).collect(),
                c.iter().map(|x| x + r).collect(),
            ))
        }
        BodyShape::Polygon => {
            required(&b.vertices, key("vertices"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            let v = b.vertices.as_ref().unwrap();
            ensure(
                v.len() >= 3,
                key("vertices"),
                "a polygon needs at least 3 vertices",
            )?;
            for (k, p) in v.iter().enumerate() {
                vector(p, 2, &format!("body.{i}.vertices.{k}"))?;
            }
            let lo = (0..2)
                .map(|d| v.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min))
                .collect();
            let hi = (0..2)
                .map(|d| v.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max))
                .collect();
            Ok((lo, hi))
        }
    }
}

fn boundary(b: &BoundaryConfig, i: usize, dim: usize) -> Check {
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
    if b.condition != Condition::Friction {
        let what = "a fixed, roller, velocity or absorbing condition (only to friction)";
        forbidden(&b.friction_coefficient, key("friction_coefficient"), what)?;
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
        Condition::Velocity => {
            required(&b.velocity, key("velocity"), "a velocity condition")?;
            vector(b.velocity.as_ref().unwrap(), dim, &key("velocity"))?;
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

/// Keys of a friction face: a coefficient μ ≥ 0 and no velocity.
fn friction(b: &BoundaryConfig, i: usize) -> Check {
    let key = |k: &str| format!("boundary.{i}.{k}");
    let what = "a friction condition (the wall is at rest)";
    forbidden(&b.velocity, key("velocity"), what)?;
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
    if matches!(b.condition, Condition::Absorbing | Condition::Friction) {
        let what = "a fixed, roller or velocity condition (not to absorbing or friction)";
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

fn load(l: &LoadConfig, i: usize, s: &SceneConfig) -> Check {
    let dim = s.dimension;
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

/// Whether the scene has a material whose strength a factor divides.
fn has_frictional_material(materials: &[Box<dyn Material>]) -> bool {
    materials.iter().any(|m| m.frictional_strength().is_some())
}

/// A stage's `strength_reduction_factor`: F > 0, something to reduce, and no
/// `[strength_reduction]` search (whose trial factor holds for every stage).
fn stage_strength_factor(
    st: &SolverConfig,
    prefix: &str,
    s: &SceneConfig,
    materials: &[Box<dyn Material>],
) -> Check {
    let Some(f) = st.strength_reduction_factor else {
        return Ok(());
    };
    let key = format!("{prefix}.strength_reduction_factor");
    ensure(
        f > 0.0 && f.is_finite(),
        key.clone(),
        format!("must be a positive number (c and tan φ are divided by it); got {f}"),
    )?;
    ensure(
        has_frictional_material(materials),
        key.clone(),
        "needs a drucker_prager or mohr_coulomb material (nothing to reduce)",
    )?;
    ensure(
        s.strength_reduction.is_none(),
        key,
        "cannot be combined with a [strength_reduction] search: each trial divides the \
         strengths by its own factor in every stage; remove one of the two",
    )
}

fn solver(s: &SolverConfig, prefix: &str) -> Check {
    ensure(
        s.end_time > 0.0 && s.end_time.is_finite(),
        format!("{prefix}.end_time"),
        "must be a positive number",
    )?;
    if let Some(dt) = s.dt {
        ensure(
            dt > 0.0 && dt.is_finite(),
            format!("{prefix}.dt"),
            "must be a positive number",
        )?;
    }
    match s.kind {
        SolverKind::Explicit => explicit(s, prefix),
        SolverKind::Implicit => implicit(s, prefix),
    }
}

fn explicit(s: &SolverConfig, prefix: &str) -> Check {
    let what = "the explicit solver";
    forbidden(&s.integrator, format!("{prefix}.integrator"), what)?;
    forbidden(&s.beta, format!("{prefix}.beta"), what)?;
    forbidden(&s.gamma, format!("{prefix}.gamma"), what)?;
    forbidden(&s.mass, format!("{prefix}.mass"), what)?;
    forbidden(&s.load_steps, format!("{prefix}.load_steps"), what)?;
    forbidden(
        &s.residual_tolerance,
        format!("{prefix}.residual_tolerance"),
        what,
    )?;
    forbidden(
        &s.displacement_tolerance,
        format!("{prefix}.displacement_tolerance"),
        what,
    )?;
    forbidden(&s.max_iterations, format!("{prefix}.max_iterations"), what)?;
    forbidden(&s.line_search, format!("{prefix}.line_search"), what)?;
    forbidden(&s.max_cutbacks, format!("{prefix}.max_cutbacks"), what)?;
    forbidden(&s.gravity_ramp, format!("{prefix}.gravity_ramp"), what)?;
    forbidden(
        &s.min_node_support,
        format!("{prefix}.min_node_support"),
        what,
    )?;
    forbidden(&s.linear_solver, format!("{prefix}.linear_solver"), what)?;
    forbidden(&s.preconditioner, format!("{prefix}.preconditioner"), what)?;
    forbidden(
        &s.krylov_tolerance,
        format!("{prefix}.krylov_tolerance"),
        what,
    )?;
    forbidden(&s.krylov_restart, format!("{prefix}.krylov_restart"), what)?;
    forbidden(
        &s.krylov_max_iterations,
        format!("{prefix}.krylov_max_iterations"),
        what,
    )?;
    let cfl = s.cfl();
    ensure(
        cfl > 0.0 && cfl <= 1.0,
        format!("{prefix}.cfl"),
        format!("must lie in (0, 1]: the explicit step is cfl × the critical step; got {cfl}"),
    )?;
    ensure(
        (0.0..=1.0).contains(&s.flip()),
        format!("{prefix}.flip"),
        "must lie in [0, 1] (1 = FLIP, 0 = PIC)",
    )?;
    ensure(
        (0.0..1.0).contains(&s.damping()),
        format!("{prefix}.damping"),
        "must lie in [0, 1)",
    )
}

fn implicit(s: &SolverConfig, prefix: &str) -> Check {
    let what = "the implicit solver";
    forbidden(&s.scheme, format!("{prefix}.scheme"), what)?;
    forbidden(&s.cfl, format!("{prefix}.cfl"), what)?;
    forbidden(&s.flip, format!("{prefix}.flip"), what)?;
    forbidden(&s.damping, format!("{prefix}.damping"), what)?;
    match s.integrator() {
        Integrator::Newmark => {
            required(&s.dt, format!("{prefix}.dt"), "the Newmark integrator")?;
            forbidden(
                &s.gravity_ramp,
                format!("{prefix}.gravity_ramp"),
                "the Newmark integrator (gravity is always in full)",
            )?;
            forbidden(
                &s.load_steps,
                format!("{prefix}.load_steps"),
                "the Newmark integrator (give dt)",
            )?;
            ensure(
                s.beta() > 0.0 && s.beta() <= 1.0,
                format!("{prefix}.beta"),
                "must lie in (0, 1]",
            )?;
            ensure(
                s.gamma() >= 0.0 && s.gamma() <= 1.5,
                format!("{prefix}.gamma"),
                "must lie in [0, 1.5]",
            )?;
        }
        Integrator::QuasiStatic => {
            forbidden(
                &s.beta,
                format!("{prefix}.beta"),
                "the quasi-static integrator",
            )?;
            forbidden(
                &s.gamma,
                format!("{prefix}.gamma"),
                "the quasi-static integrator",
            )?;
            forbidden(
                &s.mass,
                format!("{prefix}.mass"),
                "the quasi-static integrator",
            )?;
            ensure(
                s.dt.is_some() != s.load_steps.is_some(),
                format!("{prefix}.load_steps"),
                "give either load_steps or dt",
            )?;
            if let Some(n) = s.load_steps {
                ensure(n >= 1, format!("{prefix}.load_steps"), "must be at least 1")?;
            }
        }
    }
    for (key, v) in [
        ("residual_tolerance", s.residual_tolerance()),
        ("displacement_tolerance", s.displacement_tolerance()),
    ] {
        ensure(
            v > 0.0 && v < 1.0,
            format!("{prefix}.{key}"),
            "must lie in (0, 1)",
        )?;
    }
    let support = s.min_node_support();
    ensure(
        (0.0..0.5).contains(&support),
        format!("{prefix}.min_node_support"),
        format!("must lie in [0, 0.5) (a fraction of one cell volume); got {support}"),
    )?;
    ensure(
        s.max_iterations() >= 1,
        format!("{prefix}.max_iterations"),
        "must be at least 1",
    )?;
    linear_solver(s, prefix)
}

/// Keys of the linear solver: Krylov keys only with a Krylov solver, the restart
/// only with GMRES.
fn linear_solver(s: &SolverConfig, prefix: &str) -> Check {
    let key = |k: &str| format!("{prefix}.{k}");
    match s.linear_solver() {
        LinearSolver::Direct => {
            let what = "linear_solver = \"direct\" (set \"gmres\" or \"cg\")";
            forbidden(&s.preconditioner, key("preconditioner"), what)?;
            forbidden(&s.krylov_tolerance, key("krylov_tolerance"), what)?;
            forbidden(&s.krylov_restart, key("krylov_restart"), what)?;
            return forbidden(&s.krylov_max_iterations, key("krylov_max_iterations"), what);
        }
        LinearSolver::Cg => {
            forbidden(
                &s.krylov_restart,
                key("krylov_restart"),
                "linear_solver = \"cg\" (it is the GMRES restart length)",
            )?;
            ensure(
                !s.fbar(),
                key("fbar"),
                "F-bar makes the tangent unsymmetric, which linear_solver = \"cg\" cannot \
                 solve: use linear_solver = \"gmres\" or \"direct\"",
            )?
        }
        LinearSolver::Gmres => ensure(
            s.krylov_restart() >= 1,
            key("krylov_restart"),
            "must be at least 1",
        )?,
    }
    if let Some(eta) = s.krylov_tolerance {
        ensure(
            eta > 0.0 && eta < 1.0,
            key("krylov_tolerance"),
            format!("must lie in (0, 1) (a relative residual of the linear solve); got {eta}"),
        )?;
    }
    ensure(
        s.krylov_max_iterations() >= 1,
        key("krylov_max_iterations"),
        "must be at least 1",
    )
}

fn geostatic(g: &GeostaticConfig, s: &SceneConfig, materials: &[Box<dyn Material>]) -> Check {
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
                "[geostatic] needs models that integrate from the stored stress (linear_elastic, drucker_prager, mohr_coulomb); `{}` is {}",
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

fn strength_reduction(
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
    if let Some(m) = &r.monitor {
        vector(m, s.dimension, &format!("{p}.monitor"))?;
    }
    if let Some(d) = r.max_displacement {
        required(&r.monitor, format!("{p}.monitor"), "max_displacement")?;
        ensure(
            d > 0.0 && d.is_finite(),
            format!("{p}.max_displacement"),
            "must be a positive length",
        )?;
    }
    ensure(
        has_frictional_material(materials),
        p,
        "needs a drucker_prager or mohr_coulomb material (nothing to reduce)",
    )?;
    ensure(
        s.stages().iter().any(|st| st.kind == SolverKind::Implicit),
        p,
        "needs an implicit stage: a trial fails when its Newton iteration does",
    )
}
