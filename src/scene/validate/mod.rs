//! Physical and structural checks after parsing. Each failure names the dotted key
//! path (`material.0.poisson_ratio`) so the error can point at its line.
//!
//! One file per group of tables: `grid_bodies`, `conditions` (boundaries and
//! loads), `materials`, `solver` (solver and stages) and `analyses` (geostatic,
//! strength reduction, bench), `water`; `check` holds the checks they share.

mod analyses;
mod axisymmetry;
mod check;
mod conditions;
mod drainage;
mod grid_bodies;
mod histories;
mod materials;
mod peridynamic;
mod solver;
mod staging;
mod water;

pub use analyses::bench;
pub use check::Check;
pub use grid_bodies::inside_grid;

use crate::scene::contact::ContactPlan;
use crate::scene::{
    DomainStress, LinearSolver, LinearSystems, OutputConfig, SceneConfig, ShapeFunction,
    SolverConfig, SolverKind,
};
use analyses::{geostatic, strength_reduction};
use axisymmetry::axisymmetry;
use check::{ensure, vector};
use conditions::{boundary, load};
use grid_bodies::{body, grid};
use materials::materials;
use solver::{needs_krylov, solver, stage_strength_factor};
use water::water;

/// Check a parsed scene, table by table; the first failure names its key.
pub fn validate(s: &SceneConfig) -> Check {
    let dim = s.dimension.spatial();
    ensure(
        dim == 2 || dim == 3,
        "dimension",
        "must be 2 (plane strain), 3 or \"axisymmetric\"",
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
    histories::time_histories(s)?;
    histories::gravity_history(s)?;
    if s.dimension.is_axisymmetric() {
        axisymmetry(s)?;
    }
    if let Some(plan) = crate::scene::contact::plan(s)? {
        implicit_contact(s, &plan)?;
    }
    if s.grid.domain_stress == DomainStress::Linear {
        linear_domain_stress(s)?;
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
    staging::staging(s)?;
    ensure(
        s.output.history_interval >= 0.0,
        "output.history_interval",
        "must be ≥ 0",
    )?;
    particle_output_times(&s.output, s.total_time())?;
    for (key, value) in [
        ("checkpoint_interval", s.output.checkpoint_interval),
        ("checkpoint_wall_seconds", s.output.checkpoint_wall_seconds),
    ] {
        if let Some(v) = value {
            ensure(
                v > 0.0 && v.is_finite(),
                format!("output.{key}"),
                "must be > 0",
            )?;
        }
    }
    let direct = |st: &SolverConfig| {
        st.kind != SolverKind::Implicit || st.linear_solver() == LinearSolver::Direct
    };
    ensure(
        s.output.linear_systems == LinearSystems::None || s.stages().into_iter().all(direct),
        "output.linear_systems",
        "is written by the direct linear solver: give linear_solver = \"direct\" (the \
         default) to every implicit stage",
    )?;
    if let Some(g) = &s.geostatic {
        geostatic(g, s, &materials)?;
    }
    if let Some(w) = &s.water {
        water(w, s)?;
    }
    drainage::drainage(s)?;
    if let Some(r) = &s.strength_reduction {
        strength_reduction(r, s, &materials)?;
    }
    if let Some(b) = &s.bench {
        bench(b, "bench")?;
    }
    Ok(())
}

/// The most particle files `particle_interval` may ask for.
const MAX_PARTICLE_FILES: f64 = 100_000.0;

/// `particle_times` within the run (0 ≤ t ≤ its end), `particle_interval` > 0
/// and not so small that it floods the output directory.
fn particle_output_times(o: &OutputConfig, end: f64) -> Check {
    for (i, &t) in o.particle_times.iter().flatten().enumerate() {
        ensure(
            t.is_finite() && (0.0..=end * (1.0 + 1e-12)).contains(&t),
            format!("output.particle_times.{i}"),
            format!("must be a time of the run, between 0 and its end {end:e}"),
        )?;
    }
    if let Some(interval) = o.particle_interval {
        ensure(
            interval > 0.0 && interval.is_finite(),
            "output.particle_interval",
            "must be > 0",
        )?;
        ensure(
            end / interval < MAX_PARTICLE_FILES,
            "output.particle_interval",
            format!(
                "would write {:.0} particle files over the run's {end:e}; at most {MAX_PARTICLE_FILES:.0}",
                (end / interval).floor() + 1.0
            ),
        )?;
    }
    Ok(())
}

/// `domain_stress = "linear"` (`solver::implicit::stress_gradient`): box domains
/// (cpGIMP, cpB-spline), implicit stages only, without F-bar (whose tangent
/// it does not combine with), not in axisymmetric mode, and not with CG (the
/// tangent is unsymmetric).
fn linear_domain_stress(s: &SceneConfig) -> Check {
    let key = "grid.domain_stress";
    ensure(
        matches!(
            s.grid.shape_function,
            ShapeFunction::Cpgimp | ShapeFunction::Cpbspline2
        ),
        key,
        format!(
            "\"linear\" integrates over box particle domains: it needs shape_function = \
             \"cpgimp\" or \"cpbspline2\", not \"{}\"",
            s.grid.shape_function.name()
        ),
    )?;
    ensure(
        !s.dimension.is_axisymmetric(),
        key,
        "\"linear\" is not implemented in axisymmetric mode",
    )?;
    for (k, st) in s.stages().iter().enumerate() {
        let what = match s.stages.is_empty() {
            true => "the solver".to_string(),
            false => format!("stage {k}"),
        };
        ensure(
            st.kind == SolverKind::Implicit,
            key,
            format!(
                "\"linear\" is implemented in the implicit solver only, and {what} is explicit"
            ),
        )?;
        ensure(
            !st.fbar(),
            key,
            format!("\"linear\" does not combine with F-bar, and {what} has fbar = true"),
        )?;
        ensure(
            st.linear_solver() != LinearSolver::Cg,
            key,
            format!(
                "\"linear\" makes the tangent unsymmetric, and {what} has linear_solver = \
                 \"cg\": use \"direct\" or \"gmres\""
            ),
        )?;
    }
    Ok(())
}

/// Contact in explicit stages: node-based, not with B-splines. In implicit
/// stages: a penalty against rigid bodies with a prescribed motion or between
/// the split nodes of deformable bodies (`solver::implicit::terms::contact`), not in
/// axisymmetric mode.
/// Implicit contact between two deformable bodies (`names`) splits their
/// shared nodes: refused with what does not know split nodes.
fn deformable_pair(s: &SceneConfig, what: &str, names: &str) -> Check {
    use crate::scene::solver::PreconditionerKind::{LaggedMultigrid, Multigrid};
    for (k, st) in s.stages().iter().enumerate() {
        if st.kind == SolverKind::Explicit {
            continue;
        }
        ensure(
            !matches!(st.preconditioner(), Multigrid | LaggedMultigrid),
            "contact",
            format!(
                "{what} between {names} gives each body its own nodes where they meet, \
                 and stage {k}'s multigrid coarsens the grid's nodes only: use another \
                 preconditioner or the direct solver"
            ),
        )?;
        ensure(
            !st.fbar(),
            "contact",
            format!(
                "{what} between {names} keeps the bodies apart, and stage {k}'s F-bar \
                 averages the dilation over cells that both bodies share"
            ),
        )?;
    }
    ensure(
        s.grid.domain_stress == DomainStress::Constant,
        "grid.domain_stress",
        format!("{what} between {names} is not implemented with a linear domain stress"),
    )?;
    ensure(
        s.grid.shape_function != crate::scene::ShapeFunction::Bspline3,
        "grid.shape_function",
        format!(
            "{what} between {names} is not implemented with cubic B-splines (two blocks \
             resting on each other came out wrong beside the interface)"
        ),
    )
}

fn implicit_contact(s: &SceneConfig, plan: &ContactPlan) -> Check {
    use crate::scene::ShapeFunction::{Bspline2, Bspline3, Cpbspline2};
    let stages = s.stages();
    if stages.iter().any(|st| st.kind == SolverKind::Explicit) {
        ensure(
            !matches!(s.grid.shape_function, Bspline2 | Bspline3 | Cpbspline2),
            "grid.shape_function",
            "contact in the explicit solver works with linear, ugimp, cpgimp and cpdi: \
             B-spline supports span 3-4 cells, so bodies share nodes along faces that do \
             not touch and catch there (a block that should slide 0.43 m slides 0.01 m; \
             docs/contact.md)",
        )?;
    }
    let Some(k) = stages.iter().position(|st| st.kind != SolverKind::Explicit) else {
        return Ok(());
    };
    let what = format!("stage {k} is implicit, and implicit contact");
    ensure(
        !s.dimension.is_axisymmetric(),
        "dimension",
        format!("{what} is not implemented in axisymmetric mode"),
    )?;
    for i in 0..plan.fields {
        for j in i + 1..plan.fields {
            // Two rigid bodies pass through each other (neither is on the grid).
            let Some(law) = plan.law(i as u32, j as u32) else {
                continue;
            };
            if plan.rigid[i] && plan.rigid[j] {
                continue;
            }
            let body = |f: usize| plan.field_of_body.iter().position(|&b| b as usize == f);
            let (a, b) = (body(i).unwrap_or(0), body(j).unwrap_or(0));
            let names = format!("bodies {a} and {b}");
            if !plan.rigid[i] && !plan.rigid[j] {
                deformable_pair(s, &what, &names)?;
            }
            ensure(
                !plan.free[i] && !plan.free[j],
                "contact",
                format!(
                    "{what} needs rigid bodies with a prescribed motion, and one of {names} \
                     is free (`motion = \"free\"`)"
                ),
            )?;
            ensure(
                law.adhesion == 0.0,
                "contact",
                format!("{what} has no adhesion (between {names})"),
            )?;
        }
    }
    Ok(())
}
