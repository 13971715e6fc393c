//! Every scene error names its key path (issue 12, part 3): serde type errors,
//! unknown enum values, wrong vector lengths and untagged-enum mismatches carry
//! the dotted path with the line and column; an error caused by `--set` names the
//! override, not a line of the file; a file that is not UTF-8 gets the byte offset.

use mpm::scene::Scene;
use std::path::{Path, PathBuf};

use crate::common::{problem, refusals};

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

/// `mpm check` and `mpm run` on `file` with `--set` each of `sets` refuse it with
/// an error that starts with `start` (after `error: `) and holds `words`.
fn refused_with(file: &Path, sets: &[&str], start: &str, words: &str) {
    let args: Vec<&str> = sets.iter().flat_map(|s| ["--set", *s]).collect();
    for (command, stderr) in refusals(file, &args) {
        assert!(
            stderr.starts_with(&format!("error: {start}")) && stderr.contains(words),
            "mpm {command} {args:?}: `{start}` … `{words}` expected, got: {stderr}"
        );
    }
}

/// problems/column.toml with `from` replaced by `to`, in a temporary directory.
fn column_with(from: &str, to: &str) -> (tempfile::TempDir, PathBuf) {
    let text = std::fs::read_to_string(problem("column.toml")).unwrap();
    assert!(text.contains(from), "`{from}` not in column.toml");
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("column.toml");
    std::fs::write(&file, text.replacen(from, to, 1)).unwrap();
    (dir, file)
}

/// An override that makes another key wrong (a body that leaves the grid is
/// reported at `body.0.shape`, a Δt beside the file's load_steps at
/// `solver.load_steps`) names the override and the key, not the key's line in
/// the file; the unrelated override given before it is not named.
#[test]
fn an_override_that_makes_another_key_wrong_is_named() {
    let file = problem("column.toml");
    for (set, key, words) in [
        ("body.0.max=[1.0, 60.0]", "body.0.shape", "outside the grid"),
        ("grid.max=[1.0, 40.0]", "body.0.shape", "outside the grid"),
        (
            "solver.dt=0.01",
            "solver.load_steps",
            "give either load_steps or dt",
        ),
        ("dimension=3", "gravity", "needs 3 components"),
        (
            "material.0.model=mohr_coulomb",
            "material.0.cohesion",
            "is required",
        ),
        ("reference.kind=cantilever", "load", "point load"),
    ] {
        let start = format!("{}: override `--set {set}`: key `{key}`: ", file.display());
        refused_with(&file, &["grid.cells=[1, 32]", set], &start, words);
    }
}

/// A value out of range or of the wrong type given by `--set`, at the key or in
/// a table that the override gives whole, names the override.
#[test]
fn a_bad_value_given_by_an_override_is_named() {
    let file = problem("column.toml");
    let grid = "grid={min=[0.0, 0.0], max=[1.0, 50.0], cells=[1, \"16\"]}";
    for (set, key, words) in [
        (
            "material.0.youngs_modulus=-1",
            "material.0.youngs_modulus",
            "must be a positive number",
        ),
        (
            "material.0.density=\"x\"",
            "material.0.density",
            "invalid type",
        ),
        (grid, "grid.cells.1", "invalid type"),
    ] {
        let start = format!("{}: override `--set {set}`: key `{key}`: ", file.display());
        refused_with(&file, &["solver.load_steps=10", set], &start, words);
    }
}

/// An error that the model's build finds (an initial velocity expression that is
/// not finite where the override moved the body) names the override too.
#[test]
fn a_build_error_caused_by_an_override_is_named() {
    let (_dir, file) = column_with(
        "particles_per_cell = 2\n",
        "particles_per_cell = 2\nvelocity_expr = [\"0\", \"sqrt(50.5 - y)\"]\n",
    );
    let set = "body.0.max=[1.0, 60.0]";
    let start = format!(
        "{}: override `--set {set}`: key `body.0.velocity_expr.1`: ",
        file.display()
    );
    refused_with(
        &file,
        &["grid.max=[1.0, 60.0]", set],
        &start,
        "is not finite",
    );
}

/// An error in the file keeps its line and names no override when an unrelated
/// override is given, for a value out of range and for a body outside the grid.
#[test]
fn an_error_in_the_file_is_not_blamed_on_an_unrelated_override() {
    for (from, to, at, words) in [
        (
            "youngs_modulus = 1.0e6",
            "youngs_modulus = -1.0",
            "28:18: key `material.0.youngs_modulus`",
            "must be a positive number",
        ),
        (
            "max = [1.0, 50.0]\nparticles",
            "max = [1.0, 60.0]\nparticles",
            "34:9: key `body.0.shape`",
            "outside the grid",
        ),
    ] {
        let (_dir, file) = column_with(from, to);
        let start = format!("{}:{at}: ", file.display());
        refused_with(&file, &["grid.cells=[1, 32]"], &start, words);
    }
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
