//! `[[body]] kind` and `motion` (issue 58 item 1): the new form of a rigid body
//! and the old one (a material with `model = "rigid"`) read as the same body;
//! every mistake is named by its key.

use crate::common::rejected_at;
use mpm::scene::{BodyKindName, Scene};

/// problems/rigid_disk_impact.toml: body 0 (`left`) is a free rigid disk of
/// material 1 (`steel`, model = "rigid"), in the new form.
fn impact() -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/problems/rigid_disk_impact.toml"
    );
    std::fs::read_to_string(path).unwrap()
}

/// The same scene in the old form: the motion on the material, no kind.
fn old_form(text: &str) -> String {
    text.replace("kind = \"rigid\"\nmotion = \"free\"\n", "")
        .replace(
            "model = \"rigid\"\ndensity",
            "model = \"rigid\"\nmotion = \"free\"\ndensity",
        )
}

/// "scene.toml:L:" for the line L of `text` that starts with `line`, and the
/// n-th such line (from 0).
fn at_line(text: &str, line: &str, n: usize) -> String {
    let l = (text.lines().enumerate())
        .filter(|(_, l)| l.starts_with(line))
        .nth(n)
        .unwrap()
        .0;
    format!("scene.toml:{}:", l + 1)
}

#[test]
fn the_new_and_the_old_form_read_as_the_same_rigid_body() {
    let new = Scene::parse("scene.toml", &impact(), &[]).unwrap();
    let text = old_form(&impact());
    assert!(
        !text.lines().any(|l| l.starts_with("kind = \"rigid\"")),
        "the old form has no kind"
    );
    let old = Scene::parse("scene.toml", &text, &[]).unwrap();
    for s in [&new.config, &old.config] {
        assert_eq!(s.body_kind(0), BodyKindName::Rigid);
        assert_eq!(s.body_kind(1), BodyKindName::Continuum);
        assert_eq!(s.rigid_motion(0), mpm::material::rigid::Motion::Free);
    }
    let plan = |s: &Scene| mpm::scene::contact::plan(&s.config).unwrap().unwrap();
    assert_eq!(plan(&new), plan(&old));
    assert_eq!(plan(&new).rigid, [true, false]);
    assert_eq!(plan(&new).free, [true, false]);
}

#[test]
fn a_rigid_body_of_any_material_takes_its_density_only() {
    // The steel table as an elastic material: the body is rigid by its kind.
    let text = impact().replace(
        "model = \"rigid\"\ndensity = 1000.0",
        "model = \"linear_elastic\"\ndensity = 1000.0\nyoungs_modulus = 2.0e11\npoisson_ratio = 0.3",
    );
    let s = Scene::parse("scene.toml", &text, &[]).unwrap();
    assert_eq!(s.config.body_kind(0), BodyKindName::Rigid);
    let m = mpm::model::Model::<2>::build(&s).unwrap();
    let steel = &m.materials[1];
    assert_eq!((steel.p_wave_modulus(), steel.density()), (0.0, 1000.0));
    assert!(m.kind_of(0).is_rigid() && !m.kind_of(m.particles.len() - 1).is_rigid());
}

#[test]
fn an_unknown_kind_is_named() {
    let bad = impact().replace("kind = \"rigid\"", "kind = \"rigd\"");
    let line = at_line(&bad, "kind = \"rigd\"", 0);
    rejected_at(&bad, "body.0.kind", &[&line, "rigd", "continuum", "rigid"]);
}

#[test]
fn an_unknown_motion_on_the_body_or_the_old_form_material_is_named() {
    let bad = impact().replace("motion = \"free\"", "motion = \"spinning\"");
    rejected_at(&bad, "body.0.motion", &["scene.toml:", "spinning"]);
    let bad = old_form(&impact()).replace("motion = \"free\"", "motion = \"spinning\"");
    rejected_at(&bad, "material.1.motion", &["scene.toml:", "spinning"]);
}

#[test]
fn a_motion_on_a_continuum_body_is_rejected() {
    let bad = impact().replace(
        "material = \"elastic\"",
        "motion = \"free\"\nmaterial = \"elastic\"",
    );
    let line = at_line(&bad, "motion = \"free\"", 1);
    rejected_at(
        &bad,
        "body.1.motion",
        &[&line, "does not apply to a continuum body"],
    );
    let bad = impact().replace("kind = \"rigid\"\n", "kind = \"continuum\"\n");
    let line = at_line(&bad, "kind = \"continuum\"", 0);
    rejected_at(&bad, "body.0.kind", &[&line, "has model = \"rigid\""]);
}

#[test]
fn a_motion_given_twice_is_rejected() {
    let bad = impact().replace(
        "model = \"rigid\"\ndensity",
        "model = \"rigid\"\nmotion = \"free\"\ndensity",
    );
    rejected_at(&bad, "body.0.motion", &["scene.toml:", "give it once"]);
}

#[test]
fn a_material_shared_by_a_rigid_and_a_continuum_body_is_rejected() {
    // `steel` as an elastic material, also that of body 1 (continuum).
    let shared = impact()
        .replace(
            "model = \"rigid\"\ndensity = 1000.0",
            "model = \"neo_hookean\"\ndensity = 1000.0\nyoungs_modulus = 1000.0\npoisson_ratio = 0.3",
        )
        .replace("material = \"elastic\"", "material = \"steel\"");
    let line = at_line(&shared, "material = \"steel\"", 0);
    rejected_at(
        &shared,
        "body.0.material",
        &[&line, "also the material of continuum body 1"],
    );
}

#[test]
fn a_rigid_body_without_contact_is_named_at_the_key_that_makes_it_rigid() {
    let without = |text: &str| text.replace("[[contact]]\nfriction_coefficient = 0.3\n", "");
    rejected_at(
        &without(&impact()),
        "body.0.kind",
        &["a rigid body meets other bodies only through contact"],
    );
    rejected_at(
        &without(&old_form(&impact())),
        "body.0.material",
        &["a rigid body meets other bodies only through contact"],
    );
}

#[test]
fn mpm_check_counts_the_rigid_bodies() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/problems/rigid_disk_impact.toml"
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(["check", scene])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("2 body(ies) (1 rigid)"),
        "{text}"
    );
}
