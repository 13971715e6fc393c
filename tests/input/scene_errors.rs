//! Bad input gives a clear error naming the file, the key and the line and column,
//! a non-zero exit code and no panic.

use mpm::scene::Scene;
use std::process::Command;

const GOOD: &str = r#"dimension = 2

[grid]
min = [0.0, 0.0]
max = [4.0, 1.0]
cells = [4, 1]

[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 100.0
poisson_ratio = 0.3

[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [2.0, 1.0]

[solver]
kind = "explicit"
end_time = 1.0
cfl = 0.5
"#;

fn err(text: &str) -> String {
    Scene::parse("scene.toml", text, &[])
        .expect_err("must be rejected")
        .to_string()
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
    let e = err(&GOOD.replace("cfl = 0.5", "cfl = 0.5\nend_tme = 2.0"));
    assert!(
        e.contains("scene.toml:25:1") && e.contains("unknown field `end_tme`"),
        "{e}"
    );
}

#[test]
fn mistyped_value_points_at_the_value() {
    let e = err(&GOOD.replace("density = 1.0", "density = \"heavy\""));
    assert!(
        e.contains("scene.toml:11:11") && e.contains("expected f64"),
        "{e}"
    );
}

#[test]
fn unknown_model_is_named() {
    let e = err(&GOOD.replace("\"linear_elastic\"", "\"linear_elastc\""));
    assert!(
        e.contains("scene.toml:10:9") && e.contains("unknown variant `linear_elastc`"),
        "{e}"
    );
}

#[test]
fn negative_density() {
    let e = err(&GOOD.replace("density = 1.0", "density = -1.0"));
    assert!(
        e.contains("scene.toml:11:11") && e.contains("key `material.0.density`"),
        "{e}"
    );
}

#[test]
fn negative_modulus() {
    let e = err(&GOOD.replace("youngs_modulus = 100.0", "youngs_modulus = -5.0"));
    assert!(
        e.contains("scene.toml:12:18") && e.contains("key `material.0.youngs_modulus`"),
        "{e}"
    );
}

#[test]
fn poisson_ratio_at_one_half_for_a_compressible_model() {
    let e = err(&GOOD.replace("poisson_ratio = 0.3", "poisson_ratio = 0.5"));
    assert!(
        e.contains("scene.toml:13:17") && e.contains("poisson_ratio") && e.contains("compressible"),
        "{e}"
    );
}

#[test]
fn body_outside_the_grid() {
    let e = err(&GOOD.replace("max = [2.0, 1.0]", "max = [5.0, 1.0]"));
    assert!(
        e.contains("key `body.0.shape`")
            && e.contains("outside the grid")
            && e.contains("scene.toml:17:9"),
        "{e}"
    );
}

#[test]
fn cfl_above_one() {
    let e = err(&GOOD.replace("cfl = 0.5", "cfl = 1.2"));
    assert!(
        e.contains("scene.toml:24:7") && e.contains("key `solver.cfl`"),
        "{e}"
    );
}

#[test]
fn wrong_vector_length_and_missing_material() {
    let e = err(&GOOD.replace(
        "min = [0.0, 0.0]\nmax = [2.0, 1.0]",
        "min = [0.0, 0.0, 0.0]\nmax = [2.0, 1.0]",
    ));
    assert!(
        e.contains("key `body.0.min`") && e.contains("needs 2 components"),
        "{e}"
    );
    let e = err(&GOOD.replace("material = \"m\"", "material = \"steel\""));
    assert!(
        e.contains("key `body.0.material`") && e.contains("no material is named `steel`"),
        "{e}"
    );
}

#[test]
fn keys_of_another_shape_are_rejected() {
    let e = err(&GOOD.replace("max = [2.0, 1.0]", "max = [2.0, 1.0]\nradius = 0.3"));
    assert!(
        e.contains("key `body.0.radius`") && e.contains("does not apply"),
        "{e}"
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
    let e = err(&implicit("preconditioner = \"jacobi\""));
    assert!(
        e.contains("scene.toml:25:18")
            && e.contains("key `solver.preconditioner`")
            && e.contains("linear_solver = \"direct\""),
        "{e}"
    );
    let e = err(&implicit("linear_solver = \"cg\"\nkrylov_restart = 10"));
    assert!(
        e.contains("scene.toml:26:18") && e.contains("key `solver.krylov_restart`"),
        "{e}"
    );
    let e = err(&implicit(
        "linear_solver = \"gmres\"\nkrylov_tolerance = 1.5",
    ));
    assert!(
        e.contains("scene.toml:26:20") && e.contains("must lie in (0, 1)"),
        "{e}"
    );
    let e = err(&implicit(
        "linear_solver = \"gmres\"\nkrylov_max_iterations = 0",
    ));
    assert!(e.contains("key `solver.krylov_max_iterations`"), "{e}");
    let e = err(&implicit("linear_solver = \"bicgstab\""));
    assert!(
        e.contains("scene.toml:25:17") && e.contains("unknown variant `bicgstab`"),
        "{e}"
    );
    let e = err(&GOOD.replace("cfl = 0.5", "cfl = 0.5\nlinear_solver = \"gmres\""));
    assert!(
        e.contains("key `solver.linear_solver`") && e.contains("explicit"),
        "{e}"
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
    let e = err(&implicit("linear_solver = \"cg\"\nfbar = true"));
    assert!(
        e.contains("scene.toml:26:8") && e.contains("key `solver.fbar`") && e.contains("gmres"),
        "{e}"
    );
    let e = err(&implicit("fbar = 1"));
    assert!(e.contains("scene.toml:25:8") && e.contains("bool"), "{e}");
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
    let e = err(&ogden("linear_solver = \"direct\""));
    assert!(
        e.contains("scene.toml:26:17")
            && e.contains("material `m` (model `ogden`) has no analytic tangent")
            && e.contains("gmres"),
        "{e}"
    );
    let e = err(&ogden(""));
    assert!(
        e.contains("key `solver.kind`") && e.contains("no analytic tangent"),
        "{e}"
    );
    let e = err(&ogden("linear_solver = \"cg\"").replace("alpha = [2.0, -1.0]", "alpha = [2.0]"));
    assert!(
        e.contains("key `material.0.alpha`") && e.contains("one entry per term"),
        "{e}"
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
        let e = err(&GEO.replacen(from, to, 1));
        assert!(
            e.contains(at) && e.contains(&format!("key `{key}`")) && e.contains(msg),
            "{e}"
        );
    }
}

#[test]
fn geomaterial_keys_of_the_other_model_and_missing_keys() {
    let e = err(&GEO.replace(
        "mohr_coulomb_fit = \"plane_strain\"",
        "mohr_coulomb_fit = \"plane_strain\"\ntensile_strength = 0.0",
    ));
    assert!(
        e.contains("scene.toml:32:20")
            && e.contains("key `material.1.tensile_strength`")
            && e.contains("does not apply to model `drucker_prager`"),
        "{e}"
    );
    let e = err(&GEO.replace("mohr_coulomb_fit = \"plane_strain\"\n", ""));
    assert!(
        e.contains("key `material.1.mohr_coulomb_fit`") && e.contains("is required"),
        "{e}"
    );
    let e = err(&GEO.replace("\"plane_strain\"", "\"planestrain\""));
    assert!(
        e.contains("scene.toml:31:20") && e.contains("unknown variant `planestrain`"),
        "{e}"
    );
    let e = err(&GEO.replace("softening_start = 0.0\n", ""));
    assert!(
        e.contains("key `material.0.softening_start`") && e.contains("strain softening"),
        "{e}"
    );
    let e = err(&GEO.replace(
        "cohesion = 1.0e4\nfriction_angle = 30.0\ndilation_angle = 10.0",
        "cohesion = 0.0\nfriction_angle = 0.0\ndilation_angle = 0.0",
    ));
    assert!(e.contains("no strength"), "{e}");
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
    let e = err(&with("friction_coefficient = -0.1"));
    assert!(e.contains("scene.toml:25:24") && e.contains("≥ 0"), "{e}");
    let e = err(&with("friction_coefficient = 0.4\nvelocity = [0.0, 0.0]"));
    assert!(e.contains("boundary.0.velocity"), "{e}");
}

#[test]
fn friction_coefficient_only_on_friction_faces() {
    let text = GOOD.replace(
        "[solver]",
        "[[boundary]]\nface = \"ymin\"\ncondition = \"roller\"\nfriction_coefficient = 0.4\n\n[solver]",
    );
    let e = err(&text);
    assert!(
        e.contains("boundary.0.friction_coefficient") && e.contains("only to friction"),
        "{e}"
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
    let e = err(&staged_geo("strength_reduction_factor = \"2\""));
    assert!(
        e.contains("scene.toml:48:29") && e.contains("expected f64"),
        "{e}"
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
    let e = err(&text);
    assert!(
        e.contains("scene.toml:25:29") && e.contains("nothing to reduce"),
        "{e}"
    );
    // A material key it is not.
    let e = err(&GEO.replace(
        "tensile_strength = 1.0e3",
        "tensile_strength = 1.0e3\nstrength_reduction_factor = 2.0",
    ));
    assert!(
        e.contains("scene.toml:22:1") && e.contains("unknown field `strength_reduction_factor`"),
        "{e}"
    );
    // With a [strength_reduction] search, whose trial factor holds in every stage.
    let search = "strength_reduction_factor = 2.0\n\n[strength_reduction]\nsearch = [1.0, 2.0]";
    let e = err(&staged_geo(search));
    assert!(
        e.contains("scene.toml:48:29")
            && e.contains("stage.1.strength_reduction_factor")
            && e.contains("[strength_reduction] search"),
        "{e}"
    );
}
