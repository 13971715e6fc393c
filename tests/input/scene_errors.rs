//! Bad input gives a clear error naming the file, the key and the line and column,
//! a non-zero exit code and no panic.

use mpm::scene::Scene;
use std::process::Command;

use crate::common::GOOD;

fn err(text: &str) -> String {
    Scene::parse("scene.toml", text, &[])
        .expect_err("must be rejected")
        .to_string()
}

/// The scene is rejected with an error that contains every one of `parts` (the
/// position, the key, the words of the message).
fn rejected(text: &str, parts: &[&str]) {
    let e = err(text);
    for part in parts {
        assert!(e.contains(part), "`{part}` not in: {e}");
    }
}

#[test]
fn the_reference_scene_is_valid() {
    Scene::parse("scene.toml", GOOD, &[]).unwrap();
}

#[test]
fn malformed_toml_gives_line_and_column() {
    let e = err(&GOOD.replace("cells = [4, 1]", "cells = [4, 1"));
    assert!(
        e.starts_with("scene.toml:8:1") && e.contains("invalid array"),
        "{e}"
    );
}

#[test]
fn unknown_key_is_named_with_its_line() {
    rejected(
        &GOOD.replace("cfl = 0.5", "cfl = 0.5\nend_tme = 2.0"),
        &["scene.toml:25:1", "unknown field `end_tme`"],
    );
}

#[test]
fn mistyped_value_points_at_the_value() {
    rejected(
        &GOOD.replace("density = 1.0", "density = \"heavy\""),
        &["scene.toml:11:11", "expected f64"],
    );
}

#[test]
fn unknown_model_is_named() {
    rejected(
        &GOOD.replace("\"linear_elastic\"", "\"linear_elastc\""),
        &["scene.toml:10:9", "unknown variant `linear_elastc`"],
    );
}

#[test]
fn negative_density() {
    rejected(
        &GOOD.replace("density = 1.0", "density = -1.0"),
        &["scene.toml:11:11", "key `material.0.density`"],
    );
}

#[test]
fn negative_modulus() {
    rejected(
        &GOOD.replace("youngs_modulus = 100.0", "youngs_modulus = -5.0"),
        &["scene.toml:12:18", "key `material.0.youngs_modulus`"],
    );
}

#[test]
fn poisson_ratio_at_one_half_for_a_compressible_model() {
    rejected(
        &GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = 0.5"),
        &["scene.toml:13:17", "poisson_ratio", "compressible"],
    );
}

#[test]
fn body_outside_the_grid() {
    rejected(
        &GOOD.replace("max = [2.0, 1.0]", "max = [5.0, 1.0]"),
        &["key `body.0.shape`", "outside the grid", "scene.toml:17:9"],
    );
}

#[test]
fn cfl_above_one() {
    rejected(
        &GOOD.replace("cfl = 0.5", "cfl = 1.2"),
        &["scene.toml:24:7", "key `solver.cfl`"],
    );
}

#[test]
fn wrong_vector_length_and_missing_material() {
    rejected(
        &GOOD.replace(
            "min = [0.0, 0.0]\nmax = [2.0, 1.0]",
            "min = [0.0, 0.0, 0.0]\nmax = [2.0, 1.0]",
        ),
        &["key `body.0.min`", "needs 2 components"],
    );
    rejected(
        &GOOD.replace("material = \"m\"", "material = \"steel\""),
        &["key `body.0.material`", "no material is named `steel`"],
    );
}

#[test]
fn keys_of_another_shape_are_rejected() {
    rejected(
        &GOOD.replace("max = [2.0, 1.0]", "max = [2.0, 1.0]\nradius = 0.3"),
        &["key `body.0.radius`", "does not apply"],
    );
}

#[test]
fn overrides_are_checked_like_the_file() {
    let e = Scene::parse("scene.toml", GOOD, &["solver.cfl=3".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("key `solver.cfl`"), "{e}");
    let e = Scene::parse("scene.toml", GOOD, &["solver.cfll=0.3".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `cfll`"), "{e}");
    let s = Scene::parse(
        "scene.toml",
        GOOD,
        &["grid.cells=[8,2]".into(), "grid.shape_function=cpdi".into()],
    )
    .unwrap();
    assert_eq!(s.config.grid.cells, vec![8, 2]);
}

/// The implicit reference scene with extra [solver] lines from line 25 on.
fn implicit(extra: &str) -> String {
    GOOD.replace(
        "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5",
        &format!("kind = \"implicit\"\nend_time = 1.0\ndt = 0.1\n{extra}"),
    )
}

#[test]
fn linear_solver_keys_are_checked() {
    Scene::parse(
        "scene.toml",
        &implicit("linear_solver = \"gmres\"\npreconditioner = \"lagged_direct\"\nkrylov_restart = 50\nkrylov_tolerance = 1e-3"),
        &[],
    )
    .unwrap();
    rejected(
        &implicit("preconditioner = \"jacobi\""),
        &[
            "scene.toml:25:18",
            "key `solver.preconditioner`",
            "linear_solver = \"direct\"",
        ],
    );
    rejected(
        &implicit("linear_solver = \"cg\"\nkrylov_restart = 10"),
        &["scene.toml:26:18", "key `solver.krylov_restart`"],
    );
    rejected(
        &implicit("linear_solver = \"gmres\"\nkrylov_tolerance = 1.5"),
        &["scene.toml:26:20", "must lie in (0, 1)"],
    );
    rejected(
        &implicit("linear_solver = \"gmres\"\nkrylov_max_iterations = 0"),
        &["key `solver.krylov_max_iterations`"],
    );
    rejected(
        &implicit("linear_solver = \"bicgstab\""),
        &["scene.toml:25:17", "unknown variant `bicgstab`"],
    );
    rejected(
        &GOOD.replace("cfl = 0.5", "cfl = 0.5\nlinear_solver = \"gmres\""),
        &["key `solver.linear_solver`", "explicit"],
    );
}

#[test]
fn fbar_is_checked() {
    // Explicit, implicit direct and implicit GMRES accept it.
    for text in [
        GOOD.replace("cfl = 0.5", "cfl = 0.5\nfbar = true"),
        implicit("fbar = true"),
        implicit("fbar = true\nlinear_solver = \"gmres\""),
    ] {
        Scene::parse("scene.toml", &text, &[]).unwrap();
    }
    // CG cannot solve the unsymmetric F-bar tangent.
    rejected(
        &implicit("linear_solver = \"cg\"\nfbar = true"),
        &["scene.toml:26:8", "key `solver.fbar`", "gmres"],
    );
    rejected(&implicit("fbar = 1"), &["scene.toml:25:8", "bool"]);
}

#[test]
fn a_model_without_tangent_needs_a_krylov_solver() {
    let ogden = |solver: &str| {
        implicit(solver).replace(
            "model = \"linear_elastic\"\ndensity = 1.0\nyoungs_modulus = 100.0",
            "model = \"ogden\"\ndensity = 1.0\nmu = [30.0, -5.0]\nalpha = [2.0, -1.0]",
        )
    };
    Scene::parse("scene.toml", &ogden("linear_solver = \"cg\""), &[]).unwrap();
    rejected(
        &ogden("linear_solver = \"direct\""),
        &[
            "scene.toml:26:17",
            "material `m` (model `ogden`) has no analytic tangent",
            "gmres",
        ],
    );
    rejected(&ogden(""), &["key `solver.kind`", "no analytic tangent"]);
    rejected(
        &ogden("linear_solver = \"cg\"").replace("alpha = [2.0, -1.0]", "alpha = [2.0]"),
        &["key `material.0.alpha`", "one entry per term"],
    );
    let e =
        err(&ogden("linear_solver = \"cg\"").replace("alpha = [2.0, -1.0]", "alpha = [2.0, 1.0]"));
    assert!(e.contains("mu_p * alpha_p > 0"), "{e}");
}

/// The binary reports the error on stderr with exit code 2 and never panics.
#[test]
fn cli_exits_non_zero_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, GOOD.replace("density = 1.0", "density = -1.0")).unwrap();
    for args in [
        vec!["check"],
        vec!["run", "--out", dir.path().join("o").to_str().unwrap()],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
            .args(&args)
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains("bad.toml:11:11") && stderr.contains("material.0.density"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(["check", "/nonexistent/scene.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read"));
}

/// `mpm check` and `mpm run` on a limit-analysis file or a bench settings file say
/// which command takes it.
#[test]
fn other_kinds_of_file_get_a_hint() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    for (file, hint) in [
        ("limit_slope.toml", "run it with `mpm limit`"),
        ("bench/column_bench.toml", "`mpm bench SCENE --config FILE`"),
    ] {
        for command in ["check", "run"] {
            let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
                .args([command, root.join(file).to_str().unwrap()])
                .args(
                    ["--out", "/nonexistent/never-written"]
                        .iter()
                        .take(if command == "run" { 2 } else { 0 }),
                )
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{stderr}");
            assert!(stderr.contains(hint), "{command} {file}: {stderr}");
        }
    }
}

const GEO: &str = r#"dimension = 2

[grid]
min = [0.0, 0.0]
max = [4.0, 1.0]
cells = [4, 1]

[[material]]
name = "soil"
model = "mohr_coulomb"
density = 2000.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
cohesion = 1.0e4
friction_angle = 30.0
dilation_angle = 10.0
residual_cohesion = 2.0e3
residual_friction_angle = 25.0
softening_start = 0.0
softening_end = 0.05
tensile_strength = 1.0e3

[[material]]
name = "cone"
model = "drucker_prager"
density = 2000.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
cohesion = 1.0e4
friction_angle = 30.0
mohr_coulomb_fit = "plane_strain"

[[body]]
material = "soil"
shape = "rectangle"
min = [0.0, 0.0]
max = [2.0, 1.0]

[solver]
kind = "explicit"
end_time = 1.0
"#;

#[test]
fn the_geomaterial_scene_is_valid() {
    let s = Scene::parse("scene.toml", GEO, &[]).unwrap();
    assert_eq!(s.config.materials.len(), 2);
}

#[test]
fn geomaterial_parameters_out_of_range() {
    let cases = [
        (
            "friction_angle = 30.0",
            "friction_angle = 95.0",
            "scene.toml:15:18",
            "material.0.friction_angle",
            "[0, 90)",
        ),
        (
            "dilation_angle = 10.0",
            "dilation_angle = 35.0",
            "scene.toml:16:18",
            "material.0.dilation_angle",
            "friction_angle = 30",
        ),
        (
            "cohesion = 1.0e4\nfriction_angle = 30.0\ndilation",
            "cohesion = -1.0\nfriction_angle = 30.0\ndilation",
            "scene.toml:14:12",
            "material.0.cohesion",
            "negative cohesion",
        ),
        (
            "residual_cohesion = 2.0e3",
            "residual_cohesion = 2.0e4",
            "scene.toml:17:21",
            "material.0.residual_cohesion",
            "residual no larger than peak",
        ),
        (
            "residual_friction_angle = 25.0",
            "residual_friction_angle = 31.0",
            "scene.toml:18:27",
            "material.0.residual_friction_angle",
            "residual no larger than peak",
        ),
        (
            "softening_end = 0.05",
            "softening_end = 0.0",
            "scene.toml:20:17",
            "material.0.softening_end",
            "must exceed softening_start",
        ),
        (
            "tensile_strength = 1.0e3",
            "tensile_strength = -1.0",
            "scene.toml:21:20",
            "material.0.tensile_strength",
            "≥ 0",
        ),
    ];
    for (from, to, at, key, msg) in cases {
        rejected(
            &GEO.replacen(from, to, 1),
            &[at, &format!("key `{key}`"), msg],
        );
    }
}

#[test]
fn geomaterial_keys_of_the_other_model_and_missing_keys() {
    rejected(
        &GEO.replace(
            "mohr_coulomb_fit = \"plane_strain\"",
            "mohr_coulomb_fit = \"plane_strain\"\ntensile_strength = 0.0",
        ),
        &[
            "scene.toml:32:20",
            "key `material.1.tensile_strength`",
            "does not apply to model `drucker_prager`",
        ],
    );
    rejected(
        &GEO.replace("mohr_coulomb_fit = \"plane_strain\"\n", ""),
        &["key `material.1.mohr_coulomb_fit`", "is required"],
    );
    rejected(
        &GEO.replace("\"plane_strain\"", "\"planestrain\""),
        &["scene.toml:31:20", "unknown variant `planestrain`"],
    );
    rejected(
        &GEO.replace("softening_start = 0.0\n", ""),
        &["key `material.0.softening_start`", "strain softening"],
    );
    rejected(
        &GEO.replace(
            "cohesion = 1.0e4\nfriction_angle = 30.0\ndilation_angle = 10.0",
            "cohesion = 0.0\nfriction_angle = 0.0\ndilation_angle = 0.0",
        ),
        &["no strength"],
    );
}

#[test]
fn friction_face_needs_a_valid_coefficient() {
    let face = "\n[[boundary]]\nface = \"ymin\"\ncondition = \"friction\"\n";
    let with = |extra: &str| GOOD.replace("[solver]", &format!("{face}{extra}\n[solver]"));
    Scene::parse("scene.toml", &with("friction_coefficient = 0.4"), &[]).unwrap();
    let e = err(&with(""));
    assert!(
        e.starts_with("scene.toml:") && e.contains("boundary.0.friction_coefficient"),
        "{e}"
    );
    rejected(
        &with("friction_coefficient = -0.1"),
        &["scene.toml:25:24", "≥ 0"],
    );
    // A shaken wall moves along itself: a tangential velocity, or a vector
    // with a time history; never into the body or away from it.
    for motion in [
        "velocity = [0.5, 0.0]",
        "acceleration = [-4.9, 0.0]\ntime_history = [[0.0, 1.0], [0.2, 0.0]]",
    ] {
        Scene::parse(
            "scene.toml",
            &with(&format!("friction_coefficient = 0.4\n{motion}")),
            &[],
        )
        .unwrap();
    }
    rejected(
        &with("friction_coefficient = 0.4\nvelocity = [0.0, 1.0]"),
        &["boundary.0.velocity", "moves along itself"],
    );
    rejected(
        &with("friction_coefficient = 0.4\nacceleration = [1.0, 0.0]"),
        &["boundary.0.time_history", "acceleration"],
    );
    rejected(
        &with("friction_coefficient = 0.4\ntime_history = [[0.0, 1.0]]"),
        &["boundary.0.time_history", "at rest"],
    );
    rejected(
        &with("friction_coefficient = 0.4\ncomponents = [\"x\"]"),
        &["boundary.0.components"],
    );
}

#[test]
fn friction_coefficient_only_on_friction_faces() {
    let text = GOOD.replace(
        "[solver]",
        "[[boundary]]\nface = \"ymin\"\ncondition = \"roller\"\nfriction_coefficient = 0.4\n\n[solver]",
    );
    rejected(
        &text,
        &["boundary.0.friction_coefficient", "only to friction"],
    );
}

#[test]
fn friction_face_is_accepted_by_the_implicit_solver() {
    let text = GOOD
        .replace(
            "[solver]",
            "[[boundary]]\nface = \"ymin\"\ncondition = \"friction\"\nfriction_coefficient = 0.4\n\n[solver]",
        )
        .replace(
            "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5",
            "kind = \"implicit\"\nend_time = 1.0\ndt = 0.1",
        );
    // Held fixed in implicit steps (docs/scene.md, friction faces).
    Scene::parse("scene.toml", &text, &[]).unwrap();
}

/// GEO as two stages: implicit gravity, then explicit with `factor` (a line of
/// TOML for the second stage, e.g. "strength_reduction_factor = 2.0").
fn staged_geo(factor: &str) -> String {
    GEO.replace(
        "[solver]\nkind = \"explicit\"\nend_time = 1.0\n",
        &format!(
            "[[stage]]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n\n\
             [[stage]]\nkind = \"explicit\"\nend_time = 1.0\n{factor}\n"
        ),
    )
}

#[test]
fn stage_strength_reduction_factor_is_checked() {
    let s = Scene::parse(
        "scene.toml",
        &staged_geo("strength_reduction_factor = 2.0"),
        &[],
    );
    assert_eq!(
        s.unwrap().config.stages[1].strength_reduction_factor,
        Some(2.0)
    );
    for bad in ["0.0", "-1.5", "nan"] {
        let e = err(&staged_geo(&format!("strength_reduction_factor = {bad}")));
        assert!(
            e.contains("scene.toml:48:29")
                && e.contains("stage.1.strength_reduction_factor")
                && e.contains("positive number"),
            "{bad}: {e}"
        );
    }
    rejected(
        &staged_geo("strength_reduction_factor = \"2\""),
        &["scene.toml:48:29", "expected f64"],
    );
    // Overrides are checked like the file.
    let e = Scene::parse(
        "scene.toml",
        &staged_geo(""),
        &["stage.0.strength_reduction_factor=-2".into()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("stage.0.strength_reduction_factor"), "{e}");
}

#[test]
fn stage_strength_reduction_factor_in_the_wrong_place() {
    // Nothing to reduce: only elastic materials.
    let text = GOOD.replace("cfl = 0.5", "cfl = 0.5\nstrength_reduction_factor = 2.0");
    rejected(&text, &["scene.toml:25:29", "nothing to reduce"]);
    // A material key it is not.
    rejected(
        &GEO.replace(
            "tensile_strength = 1.0e3",
            "tensile_strength = 1.0e3\nstrength_reduction_factor = 2.0",
        ),
        &[
            "scene.toml:22:1",
            "unknown field `strength_reduction_factor`",
        ],
    );
    // With a [strength_reduction] search, whose trial factor holds in every stage.
    let search = "strength_reduction_factor = 2.0\n\n[strength_reduction]\nsearch = [1.0, 2.0]";
    rejected(
        &staged_geo(search),
        &[
            "scene.toml:48:29",
            "stage.1.strength_reduction_factor",
            "[strength_reduction] search",
        ],
    );
}

/// A `[reference]` that does not fit its scene is rejected with its key by every
/// command that loads scenes (`mpm check`, `mpm run`, `mpm bench`), before any run.
#[test]
fn a_reference_that_does_not_fit_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    let text = format!("{GOOD}\n[reference]\nkind = \"column\"\nbeam = \"reissner\"\n");
    std::fs::write(&path, text).unwrap();
    let out = dir.path().join("o");
    for args in [
        vec!["check"],
        vec!["run", "--out", out.to_str().unwrap()],
        vec!["bench", "--out", out.to_str().unwrap()],
    ] {
        let result = Command::new(env!("CARGO_BIN_EXE_mpm"))
            .args(&args)
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("bad.toml:28:8")
                && stderr.contains("key `reference.beam`")
                && stderr.contains("cantilever"),
            "{args:?}: {stderr}"
        );
    }
    assert!(
        !out.join("bench.csv").exists(),
        "bench stopped before running"
    );
}

/// `[reference] file` belongs to `kind = "displacement_field"`, which needs it.
#[test]
fn a_reference_file_goes_with_the_displacement_field_kind() {
    let dir = tempfile::tempdir().unwrap();
    // `mpm check` of the good scene with this [reference] table.
    let check = |table: &str| {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, format!("{GOOD}\n[reference]\n{table}\n")).unwrap();
        let result = Command::new(env!("CARGO_BIN_EXE_mpm"))
            .arg("check")
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr).into_owned();
        (result.status.code(), stderr)
    };
    for (table, words) in [
        (
            "kind = \"column\"\nfile = \"ref.csv\"",
            ["key `reference.file`", "displacement_field"],
        ),
        (
            "kind = \"displacement_field\"",
            ["key `reference.file`", "particles_final.csv"],
        ),
    ] {
        let (code, stderr) = check(table);
        assert_eq!(code, Some(2), "{table}: {stderr}");
        assert!(
            words.iter().all(|w| stderr.contains(w)) && stderr.contains("bad.toml:"),
            "{table}: {stderr}"
        );
    }
    // Given, the file is read only when an error is measured (mpm bench): the
    // reference run may come after the scene.
    let (code, stderr) =
        check("kind = \"displacement_field\"\nfile = \"later/particles_final.csv\"");
    assert_eq!(code, Some(0), "{stderr}");
}

#[test]
fn prism_mistakes_are_named() {
    let text = std::fs::read_to_string(crate::common::problem("slope_3d.toml")).unwrap();
    Scene::parse("scene.toml", &text, &[]).expect("the shipped prism is valid");
    let extent = "extent = [0.0, 5.0]";
    for (from, to, parts) in [
        (
            extent,
            "extent = [5.0, 0.0]",
            ["key `body.0.extent`", "to > from"],
        ),
        (
            extent,
            "extent = [0.0]",
            ["key `body.0.extent`", "[from, to]"],
        ),
        (extent, "", ["key `body.0.extent`", "required"]),
        (
            "axis = \"y\"",
            "axis = \"w\"",
            ["key `body.0.axis`", "unknown axis `w`"],
        ),
        (
            "[35.0, 0.0]",
            "[35.0]",
            ["key `body.0.vertices.1`", "2 finite coordinates"],
        ),
    ] {
        rejected(&text.replace(from, to), &parts);
    }
    // A prism is 3D; `axis` and `extent` belong to prisms only.
    rejected(
        &GOOD.replace("shape = \"rectangle\"", "shape = \"prism\""),
        &["key `body.0.shape`", "3D shape but dimension = 2"],
    );
    rejected(
        &GOOD.replace("max = [2.0, 1.0]", "max = [2.0, 1.0]\naxis = \"y\""),
        &["key `body.0.axis`", "does not apply"],
    );
}

#[test]
fn gravity_ramp_time_is_checked() {
    rejected(
        &GOOD.replace("cfl = 0.5", "cfl = 0.5\ngravity_ramp_time = -1.0"),
        &["key `solver.gravity_ramp_time`", "finite time ≥ 0"],
    );
    // Newmark takes it; quasi-static load steps ramp gravity with the load.
    Scene::parse("scene.toml", &implicit("gravity_ramp_time = 0.1\n"), &[])
        .expect("Newmark takes a gravity ramp");
    rejected(
        &implicit("integrator = \"quasi_static\"\ngravity_ramp_time = 0.1\n"),
        &[
            "key `solver.gravity_ramp_time`",
            "does not apply to the quasi-static",
            "gravity_ramp)",
        ],
    );
}

#[test]
fn a_flip_fraction_with_apic_is_refused() {
    rejected(
        &GOOD.replace(
            "cfl = 0.5",
            "cfl = 0.5\nvelocity_transfer = \"apic\"\nflip = 0.9",
        ),
        &[
            "scene.toml:26:8",
            "solver.flip",
            "applies to velocity_transfer = \"flip\"",
        ],
    );
    rejected(
        &GOOD.replace("cfl = 0.5", "cfl = 0.5\nvelocity_transfer = \"apic_\""),
        &["scene.toml:25:21", "unknown variant `apic_`"],
    );
    let implicit = "[solver]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\n\
                    end_time = 1.0\nload_steps = 1\nvelocity_transfer = \"apic\"\n";
    let e = err(&format!(
        "{}{implicit}",
        GOOD.split("[solver]").next().unwrap()
    ));
    assert!(
        e.contains("solver.velocity_transfer") && e.contains("does not apply"),
        "{e}"
    );
}

#[test]
fn particle_output_times_outside_the_run_or_too_dense() {
    let with = |o: &str| format!("{GOOD}\n[output]\n{o}\n");
    rejected(
        &with("particle_times = [0.5, 1.5]"),
        &[
            "scene.toml:27:",
            "key `output.particle_times.1`",
            "between 0 and its end 1e0",
        ],
    );
    rejected(
        &with("particle_times = [-0.1]"),
        &["key `output.particle_times.0`"],
    );
    rejected(
        &with("particle_interval = 0.0"),
        &["key `output.particle_interval`", "must be > 0"],
    );
    rejected(
        &with("particle_interval = 1e-6"),
        &[
            "key `output.particle_interval`",
            "would write 1000001 particle files",
        ],
    );
    Scene::parse("scene.toml", &with("particle_times = [0.0, 1.0]"), &[]).unwrap();
}
