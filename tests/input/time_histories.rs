//! Time histories (`time_history`, `gravity_history`): a bad inline row names
//! its key path and line; a bad line of a CSV file names the file, the line
//! and column and the scene key; keys that do not go together are refused at
//! the key.

use mpm::scene::{Scene, SceneError};

use crate::common::{rejected_at, GOOD};

const LOAD: &str = "[[load]]\nkind = \"point\"\nregion_min = [0.0, 0.0]\nregion_max = [2.0, 1.0]\nforce = [1.0, 0.0]\n";

fn with_load(keys: &str) -> String {
    format!("{GOOD}{LOAD}{keys}\n")
}

#[test]
fn an_inline_table_and_a_file_are_read() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("f.csv"), "t,f\n0,0\n1,2\n").unwrap();
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, with_load("time_history = \"f.csv\"")).unwrap();
    Scene::load(&file, &[]).unwrap();
    Scene::parse("scene.toml", &with_load("time_history = [[0.0, 1.0]]"), &[]).unwrap();
}

#[test]
fn inline_rows_are_checked_at_their_key() {
    let text = with_load("time_history = [[0.0, 0.0], [1.0, 1.0], [1.0, 2.0]]");
    rejected_at(
        &text,
        "load.0.time_history.2",
        &["scene.toml:30:", "increase strictly"],
    );
    let text = with_load("time_history = [[0.0, 0.0, 1.0]]");
    rejected_at(
        &text,
        "load.0.time_history.0",
        &["[time, value]", "3 entries"],
    );
    rejected_at(
        &with_load("time_history = []"),
        "load.0.time_history",
        &["at least one"],
    );
    let text = with_load("time_history = 3.0");
    rejected_at(
        &text,
        "load.0.time_history",
        &["a table of [time, value] rows, or the path"],
    );
}

/// Writes `csv` next to a scene whose load reads it; the scene's error.
fn csv_error(csv: &str) -> SceneError {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.csv"), csv).unwrap();
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, with_load("time_history = \"base.csv\"")).unwrap();
    Scene::load(&file, &[]).expect_err("must be rejected")
}

#[test]
fn a_bad_csv_line_names_the_file_line_column_and_key() {
    let e = csv_error("time,value\n0,0\n1,1x\n");
    assert!(e.file.ends_with("base.csv"), "{e}");
    assert_eq!(e.position, Some((3, 3)), "{e}");
    assert_eq!(e.key.as_deref(), Some("load.0.time_history"), "{e}");
    let s = e.to_string();
    assert!(
        s.contains("`1x` is not a finite number") && s.contains("scene.toml"),
        "{s}"
    );
    let e = csv_error("0,0\n0.5,1\n0.5,2\n");
    assert_eq!(e.position, Some((3, 1)), "{e}");
    assert!(e.message.contains("increase strictly"), "{e}");
    assert!(csv_error("0,0,0\n").message.contains("3 fields"));
    assert!(csv_error("time,value\n")
        .message
        .contains("no `time, value` row"));
}

#[test]
fn a_missing_file_is_named_at_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, with_load("time_history = \"nowhere.csv\"")).unwrap();
    let e = Scene::load(&file, &[]).expect_err("must be rejected");
    assert_eq!(e.key.as_deref(), Some("load.0.time_history"), "{e}");
    assert_eq!(e.position.map(|p| p.0), Some(30), "{e}");
    assert!(
        e.message.contains("cannot read the time history file")
            && e.message.contains("nowhere.csv"),
        "{e}"
    );
}

#[test]
fn keys_that_do_not_go_together_are_refused() {
    let history = "time_history = [[0.0, 1.0]]";
    rejected_at(
        &with_load(&format!("{history}\npulse_duration = 0.1")),
        "load.0.pulse_duration",
        &["time history"],
    );
    rejected_at(
        &with_load(&format!("{history}\nramp_time = 0.1")),
        "load.0.ramp_time",
        &["time history"],
    );
    let face = |keys: &str| format!("{GOOD}[[boundary]]\nface = \"xmin\"\n{keys}\n");
    rejected_at(
        &face("condition = \"velocity\"\nacceleration = [1.0, 0.0]"),
        "boundary.0.time_history",
        &["is required for a face with `acceleration`"],
    );
    rejected_at(
        &face(&format!(
            "condition = \"velocity\"\nvelocity = [1.0, 0.0]\ndisplacement = [1.0, 0.0]\n{history}"
        )),
        "boundary.0.displacement",
        &["one of velocity, acceleration and displacement"],
    );
    rejected_at(
        &face(&format!("condition = \"fixed\"\n{history}")),
        "boundary.0.time_history",
        &["does not apply"],
    );
    rejected_at(
        &face("condition = \"fixed\"\nacceleration = [1.0, 0.0]"),
        "boundary.0.acceleration",
        &["only to velocity"],
    );
    rejected_at(
        &face(&format!("condition = \"absorbing\"\n{history}")),
        "boundary.0.time_history",
        &["incoming_velocity"],
    );
    rejected_at(
        &face("condition = \"velocity\"\nvelocity = [1.0, 0.0]\nincoming_velocity = [1.0, 0.0]"),
        "boundary.0.incoming_velocity",
        &["only to absorbing"],
    );
    rejected_at(
        &face("condition = \"absorbing\"\nincoming_velocity = [1.0]"),
        "boundary.0.incoming_velocity",
        &["needs 2 components"],
    );
    let gravity = |keys: &str| {
        format!(
            "gravity_history = [[0.0, 1.0]]\n{}",
            GOOD.replace("cfl = 0.5", keys)
        )
    };
    rejected_at(
        &gravity("cfl = 0.5"),
        "gravity_history",
        &["scales `gravity`"],
    );
    let text = format!(
        "gravity = [0.0, -9.81]\n{}",
        gravity("gravity_ramp_time = 0.1")
    );
    rejected_at(&text, "solver.gravity_ramp_time", &["gravity_history"]);
}
