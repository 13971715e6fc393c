//! A rigid body written in the new form (`[[body]] kind = "rigid"`, as the
//! shipped scenes are), in the old form (no kind, a material with
//! `model = "rigid"` carrying the motion) and with a material of another model
//! (of which a rigid body takes only the density) runs to the same outputs,
//! byte for byte: the particles, history.csv, contact.csv and the frames.

use crate::common::{problem, run_text};

/// The scene in the old form: the rigid body's `kind` and `motion` moved to its
/// material (`model = "rigid"` there already).
fn old_form(text: &str) -> String {
    let motion = text.contains("kind = \"rigid\"\nmotion = \"free\"\n");
    let text = (text.replace("kind = \"rigid\"\nmotion = \"free\"\n", ""))
        .replace("kind = \"rigid\"\n", "");
    match motion {
        true => text.replace(
            "model = \"rigid\"\ndensity",
            "model = \"rigid\"\nmotion = \"free\"\ndensity",
        ),
        false => text,
    }
}

/// The scene with the rigid body's material (`model = "rigid"`, density 1000)
/// an elastic one of the same density.
fn elastic_material(text: &str) -> String {
    text.replace(
        "model = \"rigid\"\ndensity = 1000.0",
        "model = \"linear_elastic\"\ndensity = 1000.0\nyoungs_modulus = 2.0e11\npoisson_ratio = 0.3",
    )
}

/// The output files of a run of `text` compared here, by name, with their bytes.
fn outputs(text: &str, overrides: &[&str]) -> Vec<(String, Vec<u8>)> {
    let (result, dir) = run_text(text, overrides);
    result.expect("the scene runs");
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.ends_with(".vtu")
                || ["particles_final.csv", "history.csv", "contact.csv"].contains(&&*name)
        })
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    files.sort();
    assert!(
        files.len() >= 4,
        "{:?}",
        files.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    files
}

/// The three forms of problems/NAME give the same outputs.
fn same_in_every_form(name: &str, overrides: &[&str]) {
    let text = std::fs::read_to_string(problem(name)).unwrap();
    let rigid_kind = |t: &str| t.lines().any(|l| l == "kind = \"rigid\"");
    assert!(rigid_kind(&text), "{name} is in the new form");
    let old = old_form(&text);
    assert!(!rigid_kind(&old));
    let new = outputs(&text, overrides);
    for (form, other) in [
        ("old form", old),
        ("elastic material", elastic_material(&text)),
    ] {
        assert_ne!(other, text);
        let got = outputs(&other, overrides);
        assert_eq!(got.len(), new.len(), "{name}, {form}");
        for ((file, a), (_, b)) in new.iter().zip(&got) {
            assert!(a == b, "{name}, {form}: {file} differs");
        }
    }
}

#[test]
fn a_free_rigid_disk_is_the_same_body_in_every_form() {
    // Explicit, Newton–Euler (problems/rigid_disk_impact.toml).
    same_in_every_form(
        "rigid_disk_impact.toml",
        &["solver.end_time=0.03", "output.frames=2"],
    );
}

#[test]
fn a_prescribed_rigid_plate_is_the_same_body_in_every_form() {
    // Explicit (problems/contact_plate.toml) and implicit
    // (problems/contact_plate_implicit.toml), the plate at its velocity.
    same_in_every_form(
        "contact_plate.toml",
        &["solver.end_time=0.05", "output.frames=2"],
    );
    same_in_every_form(
        "contact_plate_implicit.toml",
        &[
            "solver.end_time=0.4",
            "solver.load_steps=4",
            "output.frames=2",
        ],
    );
}
