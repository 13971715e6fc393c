//! Results do not depend on the number of threads: the same scene run with 1 and
//! 2 threads gives byte-identical outputs.

use crate::common::{read_output, run_cli};
use mpm::scene::Scheme;
use strum::IntoEnumIterator;

fn run(threads: usize, shape: &str, fbar: bool) -> (Vec<u8>, Vec<u8>) {
    let overrides = [
        "solver.end_time=2.0".to_string(),
        "output.frames=0".to_string(),
        format!("grid.shape_function={shape}"),
        format!("solver.fbar={fbar}"),
    ];
    let dir = run_cli("disks.toml", threads, &overrides);
    (
        read_output(&dir, "particles_final.csv"),
        read_output(&dir, "history.csv"),
    )
}

#[test]
fn one_and_two_threads_give_identical_results() {
    // F-bar: cell sums in particle order (explicit here, the implicit path
    // shares the same trial state).
    for (shape, fbar) in [
        ("linear", false),
        ("cpdi", false),
        ("bspline2", false),
        ("linear", true),
    ] {
        let (p1, h1) = run(1, shape, fbar);
        let (p2, h2) = run(2, shape, fbar);
        assert!(
            p1 == p2,
            "{shape} (F-bar {fbar}): particles_final.csv differs between 1 and 2 threads"
        );
        assert!(
            h1 == h2,
            "{shape} (F-bar {fbar}): history.csv differs between 1 and 2 threads"
        );
    }
}

/// `problems/NAME` with the overrides on 1 and on 2 threads: particles_final.csv
/// and history.csv must be byte-identical (`what` names the case in the message).
fn same_on_one_and_two_threads(name: &str, overrides: &[String], what: &str) {
    let run = |threads: usize| {
        let dir = run_cli(name, threads, overrides);
        (
            read_output(&dir, "particles_final.csv"),
            read_output(&dir, "history.csv"),
        )
    };
    let ((p1, h1), (p2, h2)) = (run(1), run(2));
    assert!(
        p1 == p2,
        "{what}: particles_final.csv differs between 1 and 2 threads"
    );
    assert!(
        h1 == h2,
        "{what}: history.csv differs between 1 and 2 threads"
    );
}

/// Axisymmetric (hoop terms in the stencils, the stress update and the nodal
/// force): the thick cylinder, explicit, with about 4000 particles so that the
/// parallel loops split, and implicit with a Krylov solver.
#[test]
fn axisymmetric_runs_give_identical_results_on_one_and_two_threads() {
    for solver in [
        "solver={kind=\"explicit\",scheme=\"musl\",end_time=0.02,damping=0.5}",
        "solver={kind=\"implicit\",integrator=\"quasi_static\",end_time=1.0,load_steps=2,linear_solver=\"gmres\",preconditioner=\"multigrid\"}",
    ] {
        let overrides = [
            solver.to_string(),
            "grid.cells=[160,4]".to_string(),
            "load.0.region_max=[1.0078125,0.25]".to_string(),
            "output.frames=0".to_string(),
        ];
        same_on_one_and_two_threads("axisymmetric_cylinder.toml", &overrides, solver);
    }
}

/// The scatter path (`solver::explicit::scatter`), every scheme: the granular
/// collapse at twice its resolution (12,800 particles, so that both the tiles
/// of the scatter and the chunks of the particle passes split across threads),
/// Mohr–Coulomb with history and a friction base.
#[test]
fn scatter_runs_give_identical_results_on_one_and_two_threads() {
    for scheme in Scheme::iter().map(|s| s.name()) {
        let overrides = [
            format!("solver.scheme=\"{scheme}\""),
            "solver.end_time=0.004".to_string(),
            "grid.cells=[320,100]".to_string(),
            "output.frames=0".to_string(),
        ];
        same_on_one_and_two_threads("collapse.toml", &overrides, scheme);
    }
}

/// APIC (`solver::explicit::apic`) on both paths: the collapse as above with USL on the
/// box and MUSL on the node map.
#[test]
fn apic_runs_give_identical_results_on_one_and_two_threads() {
    for (scheme, transfer) in [("usl", "auto"), ("musl", "gather")] {
        let overrides = [
            format!(
                "solver={{kind=\"explicit\",scheme=\"{scheme}\",transfer=\"{transfer}\",\
                 velocity_transfer=\"apic\",end_time=0.004,cfl=0.4}}"
            ),
            "grid.cells=[320,100]".to_string(),
            "output.frames=0".to_string(),
        ];
        same_on_one_and_two_threads("collapse.toml", &overrides, &overrides[0]);
    }
}

/// Peridynamic bodies: the bond forces are gathered per particle over its
/// bonds in a fixed order, the bonds broken per bond (`physics::peridynamics`):
/// the notched plate, which cracks, is the same on 1 and 2 threads.
#[test]
fn a_cracking_peridynamic_plate_is_the_same_on_one_and_two_threads() {
    let overrides = ["output.frames=0".to_string()];
    same_on_one_and_two_threads("peridynamic_plate.toml", &overrides, "peridynamic plate");
    let correspondence = [
        "output.frames=0".to_string(),
        "body.0.bond_model=\"correspondence\"".to_string(),
        "body.0.plane=\"strain\"".to_string(),
    ];
    same_on_one_and_two_threads(
        "peridynamic_plate.toml",
        &correspondence,
        "correspondence plate",
    );
}

/// Time histories (issue 55): the slope under a ground motion through its
/// compliant base (`problems/slope_ground_motion.toml`, 3440 particles), into
/// the shaking; and the same slope with its base a velocity face that follows
/// the record as an acceleration (`FaceMotion`), explicit and Newmark.
#[test]
fn ground_motion_runs_give_identical_results_on_one_and_two_threads() {
    let shaking = [
        "output.frames=0".to_string(),
        "stage.1.end_time=0.3".to_string(),
    ];
    same_on_one_and_two_threads("slope_ground_motion.toml", &shaking, "compliant base");
    let dir = tempfile::tempdir().unwrap();
    let problems = crate::common::problem("");
    std::fs::copy(
        problems.join("ground_motion.csv"),
        dir.path().join("ground_motion.csv"),
    )
    .unwrap();
    let text = std::fs::read_to_string(problems.join("slope_ground_motion.toml")).unwrap();
    let base = "condition = \"absorbing\"\nspring_distance = 2.0";
    let start = text.find(base).expect("the scene's base");
    let end = start + text[start..].find("\n\n").unwrap();
    let moving =
        "condition = \"velocity\"\nacceleration = [1.0, 0.0]\ntime_history = \"ground_motion.csv\"";
    let text = format!("{}{moving}{}", &text[..start], &text[end..]);
    let explicit = "kind = \"explicit\"\nscheme = \"musl\"\nend_time = 3.0\ncfl = 0.4\nflip = 0.99";
    assert!(text.contains(explicit), "the scene's shaking stage");
    let newmark = "kind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 0.3\ndt = 0.01";
    for (stage, what) in [(explicit, "explicit"), (newmark, "Newmark")] {
        let file = dir.path().join(format!("slope_moving_base_{what}.toml"));
        std::fs::write(&file, text.replace(explicit, stage)).unwrap();
        let name = file.to_str().unwrap();
        same_on_one_and_two_threads(name, &shaking, &format!("acceleration face, {what}"));
    }
}

/// A pore-water field (`[water]`, `model::water`): the Griffiths & Lane slope
/// with a water table (`problems/slope_water_table.toml`, its strength reduction
/// off), K0 on the effective stress then full gravity, implicit; and 0.3 s of
/// explicit MUSL after it (the box scatter's force with σ′ − p I).
#[test]
fn water_table_runs_give_identical_results_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(crate::common::problem("slope_water_table.toml")).unwrap();
    let search = text
        .find("[strength_reduction]")
        .expect("the scene's search");
    let end = search + text[search..].find("\n\n").unwrap();
    let single = format!("{}{}", &text[..search], &text[end..]);
    let file = dir.path().join("slope_water_table.toml");
    std::fs::write(&file, &single).unwrap();
    let coarse = [
        "output.frames=0".to_string(),
        "grid.cells=[40,12]".to_string(),
    ];
    same_on_one_and_two_threads(file.to_str().unwrap(), &coarse, "water table, implicit");
    let solver = single.find("[solver]").unwrap();
    let next = solver + single[solver..].find("\n\n").unwrap();
    let staged = format!(
        "{}[[stage]]\n{}\n\n[[stage]]\nkind = \"explicit\"\nscheme = \"musl\"\nend_time = 0.3\ncfl = 0.4{}",
        &single[..solver],
        &single[solver + "[solver]\n".len()..next],
        &single[next..]
    );
    let file = dir.path().join("slope_water_table_staged.toml");
    std::fs::write(&file, staged).unwrap();
    same_on_one_and_two_threads(file.to_str().unwrap(), &coarse, "water table, explicit");
}

/// Staged construction (`model::staging`): particles taken out of and put
/// into the arrays at a stage's start keep their order, so the excavation and
/// the layered fill are the same on 1 and 2 threads, implicit, and with an
/// explicit stage after the fill's last layer.
#[test]
fn staged_construction_gives_identical_results_on_one_and_two_threads() {
    let coarse: Vec<String> = (crate::common::TUNNEL_COARSE
        .iter()
        .chain(&["output.frames=0"]))
    .map(|s| s.to_string())
    .collect();
    same_on_one_and_two_threads("tunnel_excavation.toml", &coarse, "excavation");
    same_on_one_and_two_threads("fill_layers.toml", &[], "layered fill");
    let text = std::fs::read_to_string(crate::common::problem("fill_layers.toml")).unwrap();
    let last = "activate = [\"layer3\"]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\n\
                end_time = 1.0\nload_steps = 1";
    assert!(text.contains(last), "the fill's last stage");
    let explicit = "activate = [\"layer3\"]\nkind = \"explicit\"\nend_time = 0.02\ndamping = 0.05";
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fill_layers_explicit.toml");
    std::fs::write(&file, text.replace(last, explicit)).unwrap();
    let name = file.to_str().unwrap();
    same_on_one_and_two_threads(name, &[], "layered fill, explicit last layer");
}

/// Coupled pore flow (`physics::pore_flow`): every nodal sum gathers in
/// particle order, so the Terzaghi column, widened to 8000 particles that the
/// parallel loops split, is the same on 1 and 2 threads.
#[test]
fn coupled_pore_flow_is_the_same_on_one_and_two_threads() {
    let overrides = [
        "grid.cells=[20, 100]".to_string(),
        "solver.end_time=0.01".to_string(),
        "output.particle_times=[]".to_string(),
    ];
    same_on_one_and_two_threads("terzaghi.toml", &overrides, "coupled pore flow");
}

/// A peridynamic bar striking a continuum one through the nodal contact: the
/// exchange's delivery through the consistent mass is solved serially
/// (`solver::explicit::contact`), so the run is the same on 1 and 2 threads.
#[test]
fn a_peridynamic_bar_striking_a_continuum_bar_is_the_same_on_one_and_two_threads() {
    let overrides = ["solver.end_time=1.5e-5".to_string()];
    same_on_one_and_two_threads(
        "peridynamic_strikes_mpm.toml",
        &overrides,
        "peridynamic striker",
    );
}
