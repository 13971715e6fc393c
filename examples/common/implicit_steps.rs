//! What the implicit memory examples share: the scene of the command line
//! (`SCENE [N] [--set key=value ...]`) and its first stage stepped N times,
//! with a look before the first step and around each one.

// Each example reads only part of what `Moment` carries.
#![allow(dead_code)]

use mpm::model::Model;
use mpm::scene::Scene;
use mpm::solver::implicit::Implicit;
use mpm::solver::stepper::Stepper;
use std::path::Path;

/// When `steps` calls its observer.
pub enum Moment<'a, const D: usize> {
    /// The model is built, no step taken.
    Built,
    /// Step `n` (from 1) is about to start.
    Before(usize),
    /// Step `n` is done.
    After(usize, &'a Implicit<D>),
}

/// The scene and the step count of the command line (`default` steps when
/// none is given), or a panic with `usage`.
pub fn scene_and_steps(usage: &str, default: usize) -> (Scene, usize) {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_path = args.first().unwrap_or_else(|| panic!("usage: {usage}"));
    let steps = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(default);
    let sets: Vec<String> = args
        .windows(2)
        .filter(|w| w[0] == "--set")
        .map(|w| w[1].clone())
        .collect();
    let scene = Scene::load(Path::new(scene_path), &sets).unwrap_or_else(|e| panic!("{e}"));
    (scene, steps)
}

/// Build the model of `scene` and take `n` implicit steps of its first stage.
pub fn steps<const D: usize>(scene: &Scene, n: usize, mut observe: impl FnMut(Moment<'_, D>)) {
    let stage = scene.config.stages()[0];
    let mut model = Model::<D>::build(scene).expect("model");
    let mut solver = Implicit::<D>::new(scene.config.grid.shape_function, stage, 0.0);
    let dt = stage.implicit_dt();
    observe(Moment::Built);
    let mut t = 0.0;
    for step in 0..n {
        observe(Moment::Before(step + 1));
        solver.step(&mut model, t, dt, step).expect("converged");
        t += dt;
        observe(Moment::After(step + 1, &solver));
    }
}
