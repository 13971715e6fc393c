//! Memory of the implicit solver apart from the model: the peak resident memory
//! during each step minus the resident memory of the built model before the
//! first step (everything the solver holds: the step system, the pattern, the
//! tangent, the factor and the workspaces), beside the stored factor's values
//! (summary.json's `largest_factor_mib`).
//!
//! Runs the first stage of SCENE for `steps` steps (default 3); Linux only
//! (reads /proc/self/status and resets the peak through /proc/self/clear_refs).
//!
//! `cargo run --release --features probes --example step_memory -- SCENE [STEPS] [--set key=value ...]`

#[path = "../common/implicit_steps.rs"]
mod implicit_steps;

use implicit_steps::{scene_and_steps, steps, Moment};
use mpm::scene::Scene;
use mpm::solver::stepper::Stepper;

/// A field of /proc/self/status in MiB (VmRSS: now, VmHWM: peak).
fn status_mib(field: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let line = status
        .lines()
        .find(|l| l.starts_with(field))
        .expect("field in /proc/self/status");
    let kib: f64 = line[field.len() + 1..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .expect("a number of kB");
    kib / 1024.0
}

/// Reset the peak resident memory to the current one.
fn reset_peak() {
    std::fs::write("/proc/self/clear_refs", "5").expect("reset the peak (Linux)");
}

fn run<const D: usize>(scene: &Scene, n: usize) {
    let mut model_mib = 0.0;
    steps::<D>(scene, n, |moment| match moment {
        Moment::Built => {
            model_mib = status_mib("VmRSS:");
            println!("model built: resident {model_mib:.1} MiB");
        }
        Moment::Before(_) => reset_peak(),
        Moment::After(step, solver) => {
            let peak = status_mib("VmHWM:");
            let report = solver.report();
            let factor = report.direct.as_ref().map_or(0.0, |d| d.largest_factor_mib);
            let solver_mib = peak - model_mib;
            println!(
                "step {step}: peak {peak:.1} MiB, solver {solver_mib:.1} MiB, largest factor's \
                 values {factor:.1} MiB, solver / factor {:.2}; {} active nodes",
                solver_mib / factor,
                solver.active_nodes()
            );
        }
    });
}

fn main() {
    let (scene, n) = scene_and_steps("step_memory SCENE [STEPS] [--set k=v ...]", 3);
    match scene.config.dimension.spatial() {
        3 => run::<3>(&scene, n),
        _ => run::<2>(&scene, n),
    }
}
