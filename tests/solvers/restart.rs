//! Checkpoints and restarts (issue 12, part 1): a run restarted from a checkpoint
//! writes the same bytes as the run that was never stopped (particles_final.csv,
//! history.csv, newton.csv but for its wall-clock column, footing.csv, every
//! frame and the collection), for each solver kind, a staged scene and across a
//! stage boundary; a checkpoint that does not fit is refused with its name.

use crate::common::problem;
use mpm::run::checkpoint::VERSION;
use mpm::run::summary::Summary;
use mpm::scene::{Integrator, Scene, SolverKind};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use strum::IntoEnumIterator;

/// `mpm run problems/NAME --threads N --out DIR --set …` (and `--restart`).
fn mpm(name: &str, threads: usize, out: &Path, sets: &[&str], restart: Option<&Path>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_mpm"));
    cmd.arg("run")
        .arg(problem(name))
        .args(["--threads", &threads.to_string(), "--out"])
        .arg(out);
    for s in sets {
        cmd.args(["--set", s]);
    }
    if let Some(c) = restart {
        cmd.arg("--restart").arg(c);
    }
    cmd.output().unwrap()
}

fn succeeded(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The checkpoints in `dir`, in step order.
fn checkpoints(dir: &Path) -> Vec<PathBuf> {
    let mut c: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("checkpoint_")
        })
        .collect();
    c.sort();
    c
}

/// newton.csv without its wall_seconds column (the only column that differs
/// between two runs of the same scene).
fn without_wall_clock(text: &str) -> String {
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let wall = header.iter().position(|h| *h == "wall_seconds").unwrap();
    text.lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(wall);
            f.join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every output of `a` but summary.json and the checkpoints is in `b` with the
/// same bytes (newton.csv: but for wall_seconds); returns how many files.
fn same_outputs(a: &Path, b: &Path) -> usize {
    let mut compared = 0;
    for e in std::fs::read_dir(a).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        if name == "summary.json" || name.starts_with("checkpoint_") {
            continue;
        }
        let (x, y) = (a.join(&name), b.join(&name));
        let y = std::fs::read(&y).unwrap_or_else(|e| panic!("{}: {e}", y.display()));
        let x = std::fs::read(&x).unwrap();
        if name == "newton.csv" {
            let (x, y) = (String::from_utf8(x).unwrap(), String::from_utf8(y).unwrap());
            assert_eq!(without_wall_clock(&x), without_wall_clock(&y), "{name}");
        } else {
            assert!(x == y, "{name} differs after the restart");
        }
        compared += 1;
    }
    compared
}

/// Run `name` with checkpoints every `interval` into one directory, restart from
/// each checkpoint it kept into another, and compare. Returns the steps the
/// checkpoints were written at.
fn restarts_are_exact(name: &str, sets: &[&str], interval: f64, threads: usize) -> Vec<usize> {
    let interval = format!("output.checkpoint_interval={interval}");
    let sets: Vec<&str> = sets.iter().copied().chain([interval.as_str()]).collect();
    let whole = tempfile::tempdir().unwrap();
    succeeded(&mpm(name, 1, whole.path(), &sets, None));
    let kept = checkpoints(whole.path());
    assert_eq!(kept.len(), 2, "{name}: the last two checkpoints are kept");
    let mut steps = Vec::new();
    for c in &kept {
        let again = tempfile::tempdir().unwrap();
        succeeded(&mpm(name, threads, again.path(), &sets, Some(c)));
        let files = same_outputs(whole.path(), again.path());
        assert!(files >= 3, "{name}: {files} files compared");
        let file = c.file_name().unwrap().to_string_lossy().to_string();
        let step: usize = file["checkpoint_".len()..file.len() - 5].parse().unwrap();
        // The run did continue from the checkpoint, and its counts are the whole run's.
        let (a, b) = (summary(whole.path()), summary(again.path()));
        assert_eq!(b.resumed_from.as_ref().map(|r| r.step), Some(step));
        assert_eq!(
            (a.steps, a.solver.newton_iterations),
            (b.steps, b.solver.newton_iterations)
        );
        let stage_steps = |s: &Summary| s.stages.iter().map(|s| s.steps).collect::<Vec<_>>();
        assert_eq!(stage_steps(&a), stage_steps(&b));
        steps.push(step);
    }
    steps
}

fn summary(dir: &Path) -> Summary {
    Summary::read(&dir.join("summary.json")).unwrap()
}

/// The loads live on the particles (`Particles::load`, kept only by scenes that
/// have loads): a restart in the middle of a traction pulse takes them from the
/// checkpoint.
#[test]
fn loaded_restart_is_byte_identical() {
    let steps = restarts_are_exact(
        "wave_p.toml",
        &["solver.end_time=0.02", "output.frames=2"],
        0.008,
        2,
    );
    assert!(steps[0] > 0 && steps[1] > steps[0], "{steps:?}");
}

/// APIC's affine moments are state: a restart that lost them (and formed them
/// anew by the projection of the first step) would not be byte-identical.
#[test]
fn apic_restart_is_byte_identical() {
    restarts_are_exact(
        "column_explicit.toml",
        &[
            "solver={kind=\"explicit\",scheme=\"musl\",end_time=2,cfl=0.5,damping=0.5,\
             velocity_transfer=\"apic\"}",
            "output.history_interval=0",
        ],
        0.8,
        1,
    );
}

/// Every solver kind, and every integrator of the implicit one, restarts
/// byte-identically: a kind or integrator added to `SolverKind` or
/// `Integrator` needs its scene here (the matches are exhaustive).
#[test]
fn every_solver_kind_restarts_byte_identically() {
    // The scene's own [solver] table: the kind and integrator the arm names.
    let solver = |name: &str| {
        let scene = Scene::load(&problem(name), &[]).unwrap();
        let s = scene.config.solver.unwrap();
        (s.kind, s.integrator)
    };
    for kind in SolverKind::iter() {
        match kind {
            SolverKind::Explicit => {
                assert_eq!(solver("column_explicit.toml").0, kind);
                let steps = restarts_are_exact(
                    "column_explicit.toml",
                    &["solver.end_time=2", "output.history_interval=0"],
                    0.8,
                    1,
                );
                assert!(steps[0] > 0 && steps[1] > steps[0], "{steps:?}");
            }
            SolverKind::Implicit => {
                for integrator in Integrator::iter() {
                    let (scene, sets, interval): (&str, &[&str], f64) = match integrator {
                        Integrator::QuasiStatic => ("column.toml", &[], 0.4),
                        Integrator::Newmark => {
                            ("vibrating_bar_implicit.toml", &["solver.end_time=3"], 1.2)
                        }
                    };
                    assert_eq!(solver(scene), (kind, Some(integrator)), "{scene}");
                    restarts_are_exact(scene, sets, interval, 1);
                }
            }
        }
    }
}

#[test]
fn gmres_restart_is_byte_identical() {
    restarts_are_exact(
        "column.toml",
        &[
            "solver.linear_solver=\"gmres\"",
            "solver.preconditioner=\"jacobi\"",
        ],
        0.4,
        1,
    );
}

#[test]
fn footing_restart_keeps_the_curve_and_the_plastic_history() {
    // Mohr–Coulomb (history variables), footing.csv and its summary.
    restarts_are_exact("footing_mc.toml", &["solver.load_steps=8"], 0.3, 2);
}

#[test]
fn staged_restart_crosses_into_the_next_stage() {
    // Stages of 1, 2 and 0.1: checkpoints at t ≈ 2.4 in the explicit stage and
    // at its last step (t = 3.0); both restarts go on into the Newmark stage.
    restarts_are_exact("column_staged.toml", &["stage.2.end_time=0.1"], 0.6, 1);
}

#[test]
fn staged_restart_at_a_stage_end() {
    // Stages of 1, 0.5 and 0.3, checkpoints every 1.0 s: at the last step of the
    // quasi-static stage only; the restart begins with the explicit stage.
    let dir = tempfile::tempdir().unwrap();
    let sets = [
        "stage.1.end_time=0.5",
        "stage.2.end_time=0.3",
        "output.checkpoint_interval=1.0",
    ];
    succeeded(&mpm("column_staged.toml", 1, dir.path(), &sets, None));
    let kept = checkpoints(dir.path());
    assert_eq!(kept.len(), 1);
    let again = tempfile::tempdir().unwrap();
    succeeded(&mpm(
        "column_staged.toml",
        1,
        again.path(),
        &sets,
        Some(&kept[0]),
    ));
    same_outputs(dir.path(), again.path());
    let (a, b) = (summary(dir.path()), summary(again.path()));
    let steps = |s: &Summary| s.stages.iter().map(|s| s.steps).collect::<Vec<_>>();
    assert_eq!((a.steps, steps(&a)), (b.steps, steps(&b)));
    assert_eq!(a.solver.newton_iterations, b.solver.newton_iterations);
}

/// Staged construction (`model::staging`): a checkpoint lists its particles
/// by their index as built, and a restart rebuilds them. In the middle of an
/// excavation stage (its particles taken out at the stage's start, the
/// displacements reset) and at the end of it; after a fill layer entered and
/// before the next does.
#[test]
fn a_restart_across_a_stage_that_removes_or_adds_particles_is_byte_identical() {
    let coarse = [&crate::common::TUNNEL_COARSE[..], &["stage.1.load_steps=4"]].concat();
    let steps = restarts_are_exact("tunnel_excavation.toml", &coarse, 0.5, 1);
    assert_eq!(steps, [3, 5], "in the excavation stage and at its end");
    let steps = restarts_are_exact("fill_layers.toml", &[], 1.0, 2);
    assert_eq!(
        steps,
        [3, 4],
        "after the second and the third layer entered"
    );
}

#[test]
fn a_restart_on_another_thread_count_is_byte_identical_too() {
    restarts_are_exact("column_explicit.toml", &["solver.end_time=2"], 0.8, 2);
    restarts_are_exact("column.toml", &[], 0.4, 2);
}

/// A checkpoint of column.toml (2D), and where it is.
fn a_checkpoint() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    succeeded(&mpm(
        "column.toml",
        1,
        dir.path(),
        &["output.checkpoint_interval=0.5"],
        None,
    ));
    let c = checkpoints(dir.path()).remove(0);
    (dir, c)
}

/// Restart column.toml from `checkpoint`, expecting a refusal that names it.
fn refused(checkpoint: &Path, name: &str, sets: &[&str]) -> String {
    let out = tempfile::tempdir().unwrap();
    let o = mpm(name, 1, out.path(), sets, Some(checkpoint));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(e.contains(&checkpoint.display().to_string()), "{e}");
    assert!(
        !out.path().join("history.csv").exists(),
        "nothing was run: {e}"
    );
    e
}

#[test]
fn a_checkpoint_of_another_scene_is_refused() {
    let (_dir, c) = a_checkpoint();
    let sets = ["output.checkpoint_interval=0.5"];
    let e = refused(&c, "column.toml", &["output.checkpoint_interval=0.25"]);
    assert!(e.contains("another scene"), "{e}");
    let e = refused(&c, "column_explicit.toml", &sets);
    assert!(e.contains("another scene"), "{e}");
    let e = refused(&c, "half_space.toml", &[]);
    assert!(e.contains("2D run") || e.contains("another scene"), "{e}");
}

#[test]
fn a_damaged_truncated_or_foreign_checkpoint_is_refused() {
    let (dir, c) = a_checkpoint();
    let sets = ["output.checkpoint_interval=0.5"];
    let bytes = std::fs::read(&c).unwrap();
    let bad = dir.path().join("bad.json");

    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    assert!(refused(&bad, "column.toml", &sets).contains("truncated"));

    let mut damaged = bytes.clone();
    let at = damaged.len() - 100;
    damaged[at] = if damaged[at] == b'1' { b'2' } else { b'1' };
    std::fs::write(&bad, &damaged).unwrap();
    assert!(refused(&bad, "column.toml", &sets).contains("checksum"));

    let text = String::from_utf8(bytes.clone()).unwrap();
    let version = format!("\"version\":{VERSION},");
    assert!(
        text.contains(&version),
        "the header names version {VERSION}"
    );
    std::fs::write(&bad, text.replacen(&version, "\"version\":99,", 1)).unwrap();
    assert!(refused(&bad, "column.toml", &sets).contains("format version 99"));

    std::fs::write(&bad, b"{\"status\":\"completed\"}\n").unwrap();
    assert!(refused(&bad, "column.toml", &sets).contains("not an mpm checkpoint"));

    let missing = dir.path().join("missing.json");
    assert!(refused(&missing, "column.toml", &sets).contains("cannot read"));
}

/// FNV-1a 64 (the checkpoint's checksum), to alter a body and keep it valid.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[test]
fn the_restart_takes_its_state_from_the_checkpoint() {
    // A checkpoint with 1000 J more work done (and its checksum redone): the
    // restarted run carries it into history.csv.
    let (dir, c) = a_checkpoint();
    let text = std::fs::read_to_string(&c).unwrap();
    let (_, body) = text.trim_end().split_once('\n').unwrap();
    let mut ck: serde_json::Value = serde_json::from_str(body).unwrap();
    let work = ck["external_work"].as_f64().unwrap();
    ck["external_work"] = serde_json::json!(work + 1000.0);
    let body = serde_json::to_string(&ck).unwrap();
    let header = format!(
        "{{\"format\":\"mpm checkpoint\",\"version\":{VERSION},\"body_bytes\":{},\"body_fnv1a64\":\"{:016x}\"}}",
        body.len(),
        fnv1a64(body.as_bytes())
    );
    let moved = dir.path().join("moved.json");
    std::fs::write(&moved, format!("{header}\n{body}\n")).unwrap();
    let sets = ["output.checkpoint_interval=0.5"];
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    succeeded(&mpm("column.toml", 1, a.path(), &sets, Some(&c)));
    succeeded(&mpm("column.toml", 1, b.path(), &sets, Some(&moved)));
    let work = |d: &Path| {
        let t = crate::common::Table::read(&d.join("history.csv")).unwrap();
        *t.col("external_work").last().unwrap()
    };
    let more = work(b.path()) - work(a.path());
    assert!((more - 1000.0).abs() < 1e-6, "{more} J more work");
}

#[test]
fn checkpoint_keys_are_checked() {
    for (key, value) in [
        ("checkpoint_interval", "0"),
        ("checkpoint_interval", "-1"),
        ("checkpoint_wall_seconds", "0"),
        ("checkpoint_wall_seconds", "\"10\""),
    ] {
        let set = format!("output.{key}={value}");
        let e = mpm::scene::Scene::load(&problem("column.toml"), std::slice::from_ref(&set))
            .err()
            .unwrap_or_else(|| panic!("{set} accepted"))
            .to_string();
        assert!(e.contains(&format!("output.{key}")), "{set}: {e}");
    }
}

#[test]
fn a_lagged_direct_restart_refactorizes_and_stays_within_the_tolerances() {
    // The lagged factorization is not saved: the restart factorizes afresh, so
    // the last bits may differ (docs/robustness.md); the results agree closely.
    let sets = [
        "solver.linear_solver=\"gmres\"",
        "solver.preconditioner=\"lagged_direct\"",
        "output.checkpoint_interval=0.4",
    ];
    let whole = tempfile::tempdir().unwrap();
    succeeded(&mpm("column.toml", 1, whole.path(), &sets, None));
    let again = tempfile::tempdir().unwrap();
    let first = checkpoints(whole.path()).remove(0);
    succeeded(&mpm("column.toml", 1, again.path(), &sets, Some(&first)));
    let read = |d: &Path| crate::common::Table::read(&d.join("particles_final.csv")).unwrap();
    let (a, b) = (read(whole.path()), read(again.path()));
    for column in ["x", "y", "syy"] {
        let scale = a.col(column).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let worst = (a.col(column).iter().zip(b.col(column)))
            .fold(0.0_f64, |w, (u, v)| w.max((u - v).abs()));
        // Measured 0, 1.8e-13, 2.0e-11: a floor at the Newton tolerance, which
        // the refactorized preconditioner's other GMRES path may reach.
        crate::common::assert_within(
            &format!("{column}: restarted against whole, relative"),
            worst / scale,
            1e-9,
        );
    }
}

#[test]
fn wall_clock_checkpoints_keep_the_last_two_and_restart_exactly() {
    // Due after every step (1e-9 s of wall clock): 452 checkpoints written, the
    // last two kept; the earlier one (the step before the last) restarts exactly.
    let sets = ["solver.end_time=2", "output.checkpoint_wall_seconds=1e-9"];
    let whole = tempfile::tempdir().unwrap();
    succeeded(&mpm("column_explicit.toml", 1, whole.path(), &sets, None));
    let kept = checkpoints(whole.path());
    let steps = summary(whole.path()).steps;
    let names: Vec<String> = (kept.iter())
        .map(|c| c.file_name().unwrap().to_string_lossy().to_string())
        .collect();
    assert_eq!(
        names,
        [
            format!("checkpoint_{:09}.json", steps - 1),
            format!("checkpoint_{steps:09}.json")
        ]
    );
    let again = tempfile::tempdir().unwrap();
    succeeded(&mpm(
        "column_explicit.toml",
        1,
        again.path(),
        &sets,
        Some(&kept[0]),
    ));
    assert!(same_outputs(whole.path(), again.path()) >= 3);
}

#[test]
fn contact_restart_is_byte_identical() {
    // Checkpoints between history rows: contact.csv's impulse since its last row is
    // carried in the checkpoint.
    restarts_are_exact(
        "contact_disks.toml",
        &[
            "solver.end_time=1.0",
            "output.frames=0",
            "output.history_interval=0.013",
        ],
        0.35,
        1,
    );
}

#[test]
fn impact_restart_is_byte_identical() {
    // Bulk viscosity (q from the step-start grid velocity: no state of its own),
    // Johnson-Cook with damage and erosion (history.csv's eroded columns).
    restarts_are_exact(
        "erosion_rod.toml",
        &[
            "solver.end_time=1.2e-5",
            "output.history_interval=0.7e-6",
            "output.frames=3",
        ],
        5.0e-6,
        1,
    );
}

#[test]
fn implicit_contact_restart_keeps_the_friction_history() {
    // A rough rigid footing (implicit penalty contact, μ = 10): the particles'
    // tangential contact forces are carried across steps, and a checkpoint keeps
    // them (the state's `contact_tangential`); contact.csv goes on. The penalty
    // comes from the particles' initial volumes, so a contact set up at the
    // restart has the same.
    restarts_are_exact(
        "contact_footing_implicit.toml",
        &[
            "grid.cells=[20,14]",
            "solver.load_steps=10",
            "contact.0.friction_coefficient=10",
        ],
        0.3,
        2,
    );
}

#[test]
fn implicit_deformable_contact_restart_keeps_the_meetings_gaps_and_friction() {
    // A block sliding on a deformable base (Newmark, split nodes, μ = 0.3): each
    // meeting's gap, tangential force and reference particles at a step's end
    // are carried to the next step under its grid node and fields, and a
    // checkpoint keeps them (`contact_tangential`); without them the restarted
    // run takes the gaps from the particles and differs.
    restarts_are_exact(
        "contact_incline_implicit.toml",
        &[
            "solver.end_time=0.06",
            "output.frames=0",
            "output.history_interval=0.01",
        ],
        0.025,
        2,
    );
}

/// particles_NNNN.csv and particle_times.csv go on after a restart as they do
/// in the uninterrupted run (the checkpoint keeps which times were taken).
#[test]
fn particle_files_restart_byte_identically() {
    let sets = ["solver.end_time=0.1", "output.particle_interval=0.02"];
    restarts_are_exact("sliding_block.toml", &sets, 0.03, 1);
}

/// Peridynamic bonds are state: a restart that rebuilt them intact would heal
/// the crack of the notched plate, and its damage would differ.
#[test]
fn a_peridynamic_restart_keeps_the_broken_bonds() {
    let steps = restarts_are_exact("peridynamic_plate.toml", &["output.frames=2"], 7.0e-6, 2);
    assert!(steps[0] > 0 && steps[1] > steps[0], "{steps:?}");
}

/// A correspondence body's particles carry F, stress and history of their own
/// (`model::peridynamics::state`): the checkpoint keeps them with the bonds.
#[test]
fn a_correspondence_restart_keeps_the_stress_state() {
    let sets = [
        "output.frames=2",
        "body.0.bond_model=\"correspondence\"",
        "body.0.plane=\"strain\"",
    ];
    let steps = restarts_are_exact("peridynamic_plate.toml", &sets, 7.0e-6, 2);
    assert!(steps[0] > 0 && steps[1] > steps[0], "{steps:?}");
}

/// A peridynamic body meeting a continuum one through the nodal contact
/// restarts byte-identically, in contact (the exchange and its delivery are
/// rebuilt every step from the particles).
#[test]
fn a_peridynamic_and_continuum_contact_restarts_byte_identically() {
    let steps = restarts_are_exact("peridynamic_strikes_mpm.toml", &[], 8.0e-6, 2);
    assert!(steps[0] > 0 && steps[1] > steps[0], "{steps:?}");
}
