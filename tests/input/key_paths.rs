//! Every scene error names its key path (issue 12, part 3): serde type errors,
//! unknown enum values, wrong vector lengths and untagged-enum mismatches carry
//! the dotted path with the line and column; an error caused by `--set` names the
//! override, not a line of the file; a file that is not UTF-8 gets the byte offset.

use mpm::scene::Scene;

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

[[stage]]
kind = "explicit"
end_time = 1.0
cfl = 0.5

[[stage]]
kind = "implicit"
end_time = 2.0
dt = 0.1
"#;

fn err(text: &str, overrides: &[&str]) -> mpm::scene::SceneError {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scene::parse("scene.toml", text, &overrides).expect_err("must be rejected")
}

/// The error names `key`, points at `position` and contains `words`.
fn at(text: &str, key: &str, position: (usize, usize), words: &str) {
    let e = err(text, &[]);
    assert_eq!(e.key.as_deref(), Some(key), "{e}");
    assert_eq!(e.position, Some(position), "{e}");
    assert!(e.set.is_none(), "{e}");
    let s = e.to_string();
    assert!(
        s.contains(&format!("key `{key}`")) && s.contains(words),
        "{s}"
    );
}

#[test]
fn the_two_stage_scene_is_valid() {
    Scene::parse("scene.toml", GOOD, &[]).unwrap();
}

#[test]
fn a_type_error_names_its_key() {
    at(
        &GOOD.replace("density = 1.0", "density = \"0.2\""),
        "material.0.density",
        (11, 11),
        "invalid type: string \"0.2\", expected f64",
    );
    at(
        &GOOD.replace("cells = [4, 1]", "cells = [4, \"1\"]"),
        "grid.cells.1",
        (6, 13),
        "expected usize",
    );
}

#[test]
fn an_unknown_enum_value_names_its_key() {
    at(
        &GOOD.replace("shape = \"rectangle\"", "shape = \"rectangel\""),
        "body.0.shape",
        (17, 9),
        "unknown variant `rectangel`",
    );
    at(
        &(GOOD.to_string() + "linear_solver = \"gmress\"\n"),
        "stage.1.linear_solver",
        (30, 17),
        "unknown variant `gmress`",
    );
    at(
        &(GOOD.to_string() + "direct_ordering = \"nested\"\n"),
        "stage.1.direct_ordering",
        (30, 19),
        "unknown variant `nested`",
    );
}

#[test]
fn a_polar_fill_of_a_rectangle_is_refused_at_its_key() {
    at(
        &GOOD.replace("max = [2.0, 1.0]\n", "max = [2.0, 1.0]\nfill = \"polar\"\n"),
        "body.0.fill",
        (20, 8),
        "`polar` fills a disk or a cylinder only",
    );
    at(
        &GOOD.replace("max = [2.0, 1.0]\n", "max = [2.0, 1.0]\nfill = \"rings\"\n"),
        "body.0.fill",
        (20, 8),
        "unknown variant `rings`",
    );
}

#[test]
fn a_wrong_vector_length_names_its_key() {
    at(
        &GOOD.replace("max = [2.0, 1.0]", "max = [2.0, 1.0, 3.0]"),
        "body.0.max",
        (19, 7),
        "needs 2 components",
    );
    at(
        &GOOD.replace("dimension = 2\n", "dimension = 2\ngravity = [0.0]\n"),
        "gravity",
        (2, 11),
        "needs 2 components",
    );
}

#[test]
fn an_untagged_enum_mismatch_names_its_key() {
    at(
        &GOOD.replace(
            "max = [2.0, 1.0]",
            "max = [2.0, 1.0]\nparticles_per_cell = \"two\"",
        ),
        "body.0.particles_per_cell",
        (20, 22),
        "a number of particles per direction",
    );
}

#[test]
fn unknown_and_missing_keys_are_named_in_full() {
    at(
        &GOOD.replace("cfl = 0.5", "cfl = 0.5\nend_tme = 2.0"),
        "stage.0.end_tme",
        (25, 1),
        "unknown field `end_tme`",
    );
    let e = err(&GOOD.replace("end_time = 2.0\n", ""), &[]);
    assert_eq!(e.key.as_deref(), Some("stage.1.end_time"), "{e}");
    assert!(e.to_string().contains("missing field `end_time`"), "{e}");
}

#[test]
fn an_error_from_an_override_names_the_override() {
    for (set, key, words) in [
        (
            "material.0.density=\"x\"",
            "material.0.density",
            "expected f64",
        ),
        ("stage.1.dt=-1", "stage.1.dt", "must be a positive number"),
        ("body.0.shape=circle", "body.0.shape", "unknown variant"),
        ("body.0.max=[1,2,3]", "body.0.max", "needs 2 components"),
        ("grid.celss=[2,2]", "grid.celss", "unknown field"),
    ] {
        let e = err(GOOD, &["grid.cells=[8,2]", set]);
        assert_eq!(e.set.as_deref(), Some(set), "{e}");
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
        assert!(e.position.is_none(), "{e}");
        let s = e.to_string();
        assert!(
            s.starts_with("scene.toml: ") && s.contains(&format!("--set {set}")),
            "{s}"
        );
        assert!(s.contains(words), "{s}");
    }
    // A malformed override is named too.
    let e = err(GOOD, &["grid.cells"]);
    assert_eq!(e.set.as_deref(), Some("grid.cells"), "{e}");
}

#[test]
fn an_error_in_the_file_keeps_its_line_when_overrides_add_keys() {
    // The override adds a key to [grid] (a line in the overridden text): the bad
    // value further down is still reported at its line in the file.
    let text = GOOD.replace("dt = 0.1", "dt = \"0.1\"");
    let e = err(&text, &["grid.shape_function=cpdi"]);
    assert_eq!(e.key.as_deref(), Some("stage.1.dt"), "{e}");
    assert_eq!(e.position, Some((29, 6)), "{e}");
    assert!(e.set.is_none(), "{e}");
}

#[test]
fn a_file_that_is_not_utf8_gets_the_byte_offset() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.toml");
    let mut bytes = GOOD.as_bytes().to_vec();
    let offset = GOOD.find("\"m\"").unwrap() + 1;
    bytes[offset] = 0xe9; // 'é' in Latin-1
    std::fs::write(&path, &bytes).unwrap();
    let e = Scene::load(&path, &[]).unwrap_err().to_string();
    assert!(
        e.contains("not UTF-8") && e.contains(&format!("byte offset {offset}")),
        "{e}"
    );
    assert!(e.contains("latin1.toml:9:9"), "{e}");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("check")
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("byte offset"));
}
