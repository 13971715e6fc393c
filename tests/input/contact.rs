//! `[[contact]]` tables: every mistake is named by its key, with the line and
//! column of the file (issue 14 item 4).

use crate::common::rejected_at;
use mpm::scene::Scene;

/// problems/contact_disks.toml with `contact` as its contact table(s).
fn scene(contact: &str) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/contact_disks.toml");
    let text = std::fs::read_to_string(path).unwrap();
    text.replace("[[contact]]\nfriction_coefficient = 0.3\n", contact)
}

#[test]
fn the_contact_scenes_are_valid() {
    Scene::parse("scene.toml", &scene("[[contact]]\nbodies = [\"left\", \"right\"]\nfriction_coefficient = 0.3\nadhesion = 10.0\ngap_factor = 1.0\nnormal = \"average\"\nrigid_projection = false\n"), &[]).unwrap();
    Scene::parse("scene.toml", &scene("[[contact]]\n"), &[]).unwrap();
}

#[test]
fn an_unknown_body_is_named() {
    rejected_at(
        &scene("[[contact]]\nbodies = [\"left\", \"rigth\"]\n"),
        "contact.0.bodies.1",
        &["scene.toml:44:", "no body is named `rigth`"],
    );
}

#[test]
fn a_body_paired_with_itself_is_rejected() {
    rejected_at(
        &scene("[[contact]]\nbodies = [\"left\", \"left\"]\n"),
        "contact.0.bodies",
        &["scene.toml:44:", "pairs body `left` with itself"],
    );
}

#[test]
fn a_pair_needs_two_bodies() {
    rejected_at(
        &scene("[[contact]]\nbodies = [\"left\"]\n"),
        "contact.0.bodies",
        &["scene.toml:44:", "names two bodies, has 1"],
    );
}

#[test]
fn negative_friction_and_adhesion_and_a_zero_gap_factor_are_rejected() {
    rejected_at(
        &scene("[[contact]]\nfriction_coefficient = -0.1\n"),
        "contact.0.friction_coefficient",
        &["scene.toml:44:", "must be a finite number ≥ 0"],
    );
    rejected_at(
        &scene("[[contact]]\nadhesion = -5.0\n"),
        "contact.0.adhesion",
        &["scene.toml:44:", "must be a finite number ≥ 0"],
    );
    rejected_at(
        &scene("[[contact]]\ngap_factor = 0.0\n"),
        "contact.0.gap_factor",
        &["scene.toml:44:", "must be a finite number > 0"],
    );
}

#[test]
fn a_rigid_projection_that_is_not_a_bool_is_named() {
    rejected_at(
        &scene("[[contact]]\nrigid_projection = \"yes\"\n"),
        "contact.0.rigid_projection",
        &["scene.toml:44:", "expected a boolean"],
    );
}

#[test]
fn an_unknown_normal_and_an_unknown_key_are_named() {
    rejected_at(
        &scene("[[contact]]\nnormal = \"mass_gradient\"\n"),
        "contact.0.normal",
        &["scene.toml:44:", "unknown variant `mass_gradient`"],
    );
    rejected_at(
        &scene("[[contact]]\nfriction = 0.3\n"),
        "contact.0.friction",
        &["unknown field `friction`"],
    );
}

#[test]
fn a_pair_declared_twice_is_rejected() {
    rejected_at(
        &scene("[[contact]]\nbodies = [\"left\", \"right\"]\n\n[[contact]]\nbodies = [\"right\", \"left\"]\n"),
        "contact.1",
        &["scene.toml:46:", "declares the contact of bodies 0 and 1 again (also in contact.0)"],
    );
}

#[test]
fn implicit_contact_of_deformable_bodies_refusals_and_explicit_contact_no_b_splines() {
    let implicit = |extra: &str| {
        scene("[[contact]]\n").replace(
            "kind = \"explicit\"",
            &format!("kind = \"implicit\"\ndt = 0.1\n{extra}"),
        )
    };
    rejected_at(
        &implicit("linear_solver = \"cg\"\npreconditioner = \"multigrid\""),
        "contact",
        &[
            "stage 0 is implicit",
            "between bodies 0 and 1 gives each body its own nodes",
            "multigrid coarsens the grid's nodes only",
        ],
    );
    rejected_at(
        &implicit("fbar = true"),
        "contact",
        &[
            "between bodies 0 and 1 keeps the bodies apart",
            "F-bar averages the dilation",
        ],
    );
    rejected_at(
        &implicit("").replace("\"cpgimp\"", "\"bspline3\""),
        "grid.shape_function",
        &["between bodies 0 and 1 is not implemented with cubic B-splines"],
    );
    rejected_at(
        &scene("[[contact]]\n").replace("\"cpgimp\"", "\"bspline2\""),
        "grid.shape_function",
        &[
            "scene.toml:16:",
            "contact in the explicit solver works with linear, ugimp, cpgimp and cpdi",
        ],
    );
    rejected_at(
        &scene("[[contact]]\npenalty_factor = 0.0\n"),
        "contact.0.penalty_factor",
        &["must be a finite number > 0"],
    );
}

#[test]
fn glued_bodies_cannot_also_be_in_contact() {
    // A third body with no contact to either glues left and right into one field.
    let third = "[[body]]\nname = \"third\"\nmaterial = \"elastic\"\nshape = \"rectangle\"\nmin = [0.1, 0.8]\nmax = [0.3, 0.9]\n\n";
    let text = scene("[[contact]]\nbodies = [\"left\", \"right\"]\n")
        .replace("\n[[contact]]\n", &format!("\n{third}[[contact]]\n"));
    rejected_at(
        &text,
        "contact.0",
        &["are declared in contact, but other bodies"],
    );
}

#[test]
fn more_than_64_velocity_fields_are_refused() {
    // 65 small bodies, every pair in contact: 65 fields.
    let bodies: String = (0..65)
        .map(|k| {
            let x = 0.02 * k as f64;
            format!(
                "[[body]]\nname = \"b{k}\"\nmaterial = \"elastic\"\nshape = \"rectangle\"\n\
                 min = [{x}, 0.0]\nmax = [{}, 0.01]\n\n",
                x + 0.01
            )
        })
        .collect();
    let text = scene("[[contact]]\n");
    let first = text.find("[[body]]").unwrap();
    let contact = text.find("\n[[contact]]\n").unwrap();
    let text = format!("{}{bodies}{}", &text[..first], &text[contact + 1..]);
    rejected_at(&text, "contact", &["65 velocity fields; at most 64"]);
}

#[test]
fn a_rigid_body_needs_contact_with_every_other_body() {
    let rigid = "[[material]]\nname = \"steel\"\nmodel = \"rigid\"\ndensity = 7800.0\n\n";
    let with_rigid = |contact: &str| {
        scene(contact)
            .replacen("[[body]]", &format!("{rigid}[[body]]"), 1)
            .replacen(
                "material = \"elastic\"\nshape = \"disk\"\ncentre = [1.0",
                "material = \"steel\"\nshape = \"disk\"\ncentre = [1.0",
                1,
            )
    };
    Scene::parse("scene.toml", &with_rigid("[[contact]]\n"), &[]).unwrap();
    rejected_at(
        &with_rigid(""),
        "body.1.material",
        &["a rigid body meets other bodies only through contact"],
    );
}

#[test]
fn a_rigid_motion_other_than_prescribed_or_free_is_named() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/problems/rigid_striker.toml"
    ))
    .unwrap();
    Scene::parse("scene.toml", &text, &[]).unwrap();
    let bad = text.replace("motion = \"free\"", "motion = \"spinning\"");
    rejected_at(&bad, "body.0.motion", &["scene.toml:", "spinning"]);
}
