//! The checks of a run before it allocates and steps: the memory estimate,
//! the model's build and each stage's step count.

use crate::model::memory::{self, Estimate};
use crate::model::{BodyExtent, Model};
use crate::run::options::RunOptions;
use crate::scene::{Scene, SceneError, SolverKind};
use crate::solver::explicit::Explicit;

/// What a run checks before it allocates and steps: the memory estimate, then the
/// model's build (a body that holds no particle, an absorbing face with no
/// material, …). `mpm check` calls it, so it rejects what `mpm run` would; an
/// error that an override causes names the override (`Scene::blame`). Returns
/// each body's particles as built (`Model::body_extents`).
pub fn set_up_check(scene: &Scene, opts: &RunOptions) -> Result<Vec<BodyExtent>, SceneError> {
    before_steps(scene, opts).map_err(|e| scene.blame(e, |s| before_steps(s, opts)))
}

/// [`set_up_check`] without naming the override an error comes from.
pub(super) fn before_steps(
    scene: &Scene,
    opts: &RunOptions,
) -> Result<Vec<BodyExtent>, SceneError> {
    check_memory(scene, opts)?;
    match scene.config.dimension.spatial() {
        2 => built(scene, &Model::<2>::build(scene)?),
        3 => built(scene, &Model::<3>::build(scene)?),
        d => unreachable!("validated dimension {d}"),
    }
}

/// The step counts of a built model checked, and its bodies' extents.
fn built<const D: usize>(scene: &Scene, model: &Model<D>) -> Result<Vec<BodyExtent>, SceneError> {
    check_steps(scene, model)?;
    Ok(model.body_extents())
}

/// The most steps a stage may take: more is a mistake in the scene (a run of
/// 10⁹ steps of the smallest scene takes hours), refused before it starts.
pub const MAX_STEPS: f64 = 1e9;

/// Each stage's step count, from its Δt (explicit: cfl × the critical step of
/// the model as built), within [`MAX_STEPS`].
pub(super) fn check_steps<const D: usize>(
    scene: &Scene,
    model: &Model<D>,
) -> Result<(), SceneError> {
    let dt_critical = Explicit::critical_dt(model);
    let c = &scene.config;
    for (k, sc) in c.stages().into_iter().enumerate() {
        let prefix = match c.solver {
            Some(_) => "solver".to_string(),
            None => format!("stage.{k}"),
        };
        let dt = match sc.kind {
            SolverKind::Explicit => sc.dt.unwrap_or(sc.cfl() * dt_critical),
            SolverKind::Implicit => sc.implicit_dt(),
        };
        let steps = sc.end_time / dt;
        if steps.is_nan() || steps > MAX_STEPS {
            let why = match (sc.kind, sc.dt) {
                (SolverKind::Explicit, None) => format!(
                    " (cfl × the critical step min h/(c + |v|) = {dt_critical:.3e} of the model as built)"
                ),
                _ => String::new(),
            };
            return Err(scene.at_key(
                &format!("{prefix}.end_time"),
                format!(
                    "the stage would take {steps:.3e} steps of Δt = {dt:.3e}{why}, more than \
                     {MAX_STEPS:e}: shorten it or take larger steps"
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn check_memory(scene: &Scene, opts: &RunOptions) -> Result<(), SceneError> {
    Estimate::of(&scene.config)
        .check(memory::limit(opts.memory_limit))
        .map_err(|(key, m)| scene.at_key(&key, m))
}
