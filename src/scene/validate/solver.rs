//! The `[solver]` table or the `[[stage]]` tables: ranges of the settings and
//! which optional keys apply (`scene::solver::SCOPES`), a material without an
//! analytic tangent only with a Krylov solver, and the stages' strength factors.

use super::check::{ensure, required, Check};
use crate::material::Material;
use crate::scene::{
    Integrator, LinearSolver, PreconditionerKind, SceneConfig, SolverConfig, SolverKind,
    VelocityTransfer,
};

/// A material without an analytic tangent cannot run on an implicit stage with
/// the direct solver.
pub fn needs_krylov(s: &SceneConfig, materials: &[Box<dyn Material>]) -> Check {
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

/// A stage's `strength_reduction_factor`: F > 0, something to reduce, and no
/// `[strength_reduction]` search (whose trial factor holds for every stage).
pub fn stage_strength_factor(
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
    // Something a factor divides, as strength reduction does it.
    ensure(
        materials
            .iter()
            .any(|m| m.with_reduced_strength(1.0).is_some()),
        key.clone(),
        "needs a material with a frictional strength, c and φ (nothing to reduce)",
    )?;
    ensure(
        s.strength_reduction.is_none(),
        key,
        "cannot be combined with a [strength_reduction] search: each trial divides the \
         strengths by its own factor in every stage; remove one of the two",
    )
}

/// Caps on the iteration counts a scene may ask for, so that no loop runs
/// without end on a tolerance it cannot reach.
pub const MAX_NEWTON_ITERATIONS: usize = 1000;
pub const MAX_CUTBACKS: usize = 50;
pub const MAX_KRYLOV_ITERATIONS: usize = 100_000;

pub fn solver(s: &SolverConfig, prefix: &str) -> Check {
    let key = |k: &str| format!("{prefix}.{k}");
    ensure(
        s.end_time > 0.0 && s.end_time.is_finite(),
        key("end_time"),
        "must be a positive number",
    )?;
    if let Some(dt) = s.dt {
        ensure(
            dt > 0.0 && dt.is_finite(),
            key("dt"),
            "must be a positive number",
        )?;
    }
    if let Some((k, outside)) = s.key_out_of_scope() {
        return Err((key(k), format!("does not apply to {outside}")));
    }
    match s.kind {
        SolverKind::Explicit => explicit(s, prefix),
        SolverKind::Implicit => implicit(s, prefix),
    }
}

fn explicit(s: &SolverConfig, prefix: &str) -> Check {
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
        s.flip.is_none() || s.velocity_transfer() == VelocityTransfer::Flip,
        format!("{prefix}.flip"),
        "applies to velocity_transfer = \"flip\" only (APIC has no FLIP fraction)",
    )?;
    ensure(
        (0.0..1.0).contains(&s.damping()),
        format!("{prefix}.damping"),
        "must lie in [0, 1)",
    )?;
    let ramp = s.gravity_ramp_time();
    ensure(
        ramp >= 0.0 && ramp.is_finite(),
        format!("{prefix}.gravity_ramp_time"),
        format!("must be a finite time ≥ 0; got {ramp}"),
    )?;
    for (key, value) in [
        ("bulk_viscosity_quadratic", s.bulk_viscosity_quadratic),
        ("bulk_viscosity_linear", s.bulk_viscosity_linear),
    ] {
        if let Some(c) = value {
            ensure(
                (0.0..=10.0).contains(&c),
                format!("{prefix}.{key}"),
                format!("must lie in [0, 10] (standard: 1.5 quadratic, 0.06 linear); got {c}"),
            )?;
        }
    }
    Ok(())
}

fn implicit(s: &SolverConfig, prefix: &str) -> Check {
    match s.integrator() {
        Integrator::Newmark => {
            required(&s.dt, format!("{prefix}.dt"), "the Newmark integrator")?;
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
    at_most(
        s.max_iterations(),
        MAX_NEWTON_ITERATIONS,
        format!("{prefix}.max_iterations"),
    )?;
    if let Some(n) = s.max_rising_iterations() {
        ensure(
            n >= 1,
            format!("{prefix}.max_rising_iterations"),
            "must be at least 1 (consecutive iterations whose residual rose)",
        )?;
    }
    if let Some(n) = s.stall_iterations() {
        ensure(
            n >= 1,
            format!("{prefix}.stall_iterations"),
            "must be at least 1 (iterations over which the residual must fall by 10 %)",
        )?;
    }
    ensure(
        s.max_cutbacks() <= MAX_CUTBACKS,
        format!("{prefix}.max_cutbacks"),
        format!("must be at most {MAX_CUTBACKS} (each halves the step)"),
    )?;
    linear_solver(s, prefix)
}

/// Ranges of the Krylov keys; CG cannot solve the unsymmetric F-bar tangent.
fn linear_solver(s: &SolverConfig, prefix: &str) -> Check {
    let key = |k: &str| format!("{prefix}.{k}");
    match s.linear_solver() {
        LinearSolver::Direct => return Ok(()),
        LinearSolver::Cg => ensure(
            !s.fbar(),
            key("fbar"),
            "F-bar makes the tangent unsymmetric, which linear_solver = \"cg\" cannot \
             solve: use linear_solver = \"gmres\" or \"direct\"",
        )?,
        LinearSolver::Gmres => at_most(
            s.krylov_restart(),
            MAX_KRYLOV_ITERATIONS,
            key("krylov_restart"),
        )?,
    }
    if let Some(eta) = s.krylov_tolerance {
        ensure(
            eta > 0.0 && eta < 1.0,
            key("krylov_tolerance"),
            format!("must lie in (0, 1) (a relative residual of the linear solve); got {eta}"),
        )?;
    }
    if s.multigrid_coarse_unknowns.is_some() {
        ensure(
            matches!(
                s.preconditioner(),
                PreconditionerKind::Multigrid | PreconditionerKind::LaggedMultigrid
            ),
            key("multigrid_coarse_unknowns"),
            "applies to preconditioner = \"multigrid\" or \"lagged_multigrid\" only",
        )?;
        at_most(
            s.multigrid_coarse_unknowns(),
            MAX_COARSE_UNKNOWNS,
            key("multigrid_coarse_unknowns"),
        )?;
    }
    at_most(
        s.krylov_max_iterations(),
        MAX_KRYLOV_ITERATIONS,
        key("krylov_max_iterations"),
    )
}

/// Largest coarsest multigrid level accepted (its factorization is the direct
/// solver's).
const MAX_COARSE_UNKNOWNS: usize = 10_000_000;

/// A count in [1, max].
fn at_most(n: usize, max: usize, key: String) -> Check {
    ensure(n >= 1, key.clone(), "must be at least 1")?;
    ensure(n <= max, key, format!("must be at most {max}"))
}
