//! Staged construction (docs/staging.md): `[[body]] active` and the `[[stage]]`
//! keys `activate`, `deactivate`, `excavate` and `reset_displacement`. Every
//! refusal names its key path; the forms accepted parse and build.

use crate::common::rejected_at;
use mpm::scene::Scene;

/// A 2D scene: a `ground` body, a `fill` body with the lines `fill`, an extra
/// `[[boundary]]` `boundary`, and two quasi-static stages, the second with
/// the lines `second` (the first with `first`).
fn scene(fill: &str, boundary: &str, first: &str, second: &str) -> String {
    format!(
        "dimension = 2\ngravity = [0.0, -10.0]\n\
         [grid]\nmin = [0.0, 0.0]\nmax = [4.0, 4.0]\ncells = [4, 4]\n\
         [[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 2.0\n\
         youngs_modulus = 1.0e4\npoisson_ratio = 0.25\n\
         [[material]]\nname = \"steel\"\nmodel = \"linear_elastic\"\ndensity = 8.0\n\
         youngs_modulus = 1.0e6\npoisson_ratio = 0.25\n\
         [[body]]\nname = \"ground\"\nmaterial = \"m\"\nshape = \"rectangle\"\n\
         min = [0.0, 0.0]\nmax = [4.0, 2.0]\n\
         [[body]]\nname = \"fill\"\nmaterial = \"m\"\nshape = \"rectangle\"\n\
         min = [0.0, 2.0]\nmax = [4.0, 3.0]\n{fill}\n\
         [[boundary]]\nface = \"ymin\"\ncondition = \"fixed\"\n{boundary}\n\
         [[stage]]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n{first}\n\
         [[stage]]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n{second}\n"
    )
}

const INACTIVE: &str = "active = false";
/// A rigid plate on the fill, in contact with the other bodies, added to a scene.
const PLATE: &str = "[[body]]\nname = \"plate\"\nkind = \"rigid\"\nmaterial = \"steel\"\n\
                     shape = \"rectangle\"\nmin = [1.0, 3.0]\nmax = [3.0, 3.5]\n[[contact]]\n";

fn with_plate(text: &str) -> String {
    text.replace("[[boundary]]", &format!("{PLATE}[[boundary]]"))
}
const ACTIVATE: &str = "activate = [\"fill\"]";

fn accepted(text: &str) -> Scene {
    Scene::parse("scene.toml", text, &[]).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn accepted_forms_build_with_the_inactive_bodies_held_aside() {
    let s = accepted(&scene(INACTIVE, "", "", ACTIVATE));
    let m = mpm::model::Model::<2>::build(&s).unwrap();
    // The fill's 16 particles are held outside the model until stage 1.
    let extents = m.body_extents();
    assert_eq!(
        extents[1].particles, 16,
        "mpm check counts the inactive body"
    );
    assert_eq!(m.particles.len(), 32);
    assert!(m.particles.body.iter().all(|&b| b != 1));
    let excavate = "excavate = [{ shape = \"rectangle\", min = [0.0, 1.0], max = [2.0, 2.0] },\n\
                    { shape = \"disk\", centre = [3.0, 1.0], radius = 0.5 },\n\
                    { shape = \"polygon\", vertices = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] }]";
    accepted(&scene("", "", "", excavate));
    accepted(&scene(
        "",
        "",
        "",
        "deactivate = [\"fill\"]\nreset_displacement = true",
    ));
    // A scene that stages nothing has no staging.
    let plain = accepted(&scene("", "", "", ""));
    assert!(mpm::model::Model::<2>::build(&plain)
        .unwrap()
        .staging
        .is_none());
}

#[test]
fn refusals_name_their_keys() {
    let springs = "[[boundary]]\nface = \"xmax\"\ncondition = \"absorbing\"\nspring_distance = 2.0";
    let cases: [(&str, &str, &str, &str, &str, &str); 9] = [
        (
            "",
            "",
            "",
            "activate = [\"wall\"]",
            "stage.1.activate.0",
            "no body is named `wall`",
        ),
        (
            "",
            "",
            "",
            ACTIVATE,
            "stage.1.activate.0",
            "has been in the model already",
        ),
        (
            INACTIVE,
            "",
            "",
            "",
            "body.1.active",
            "no stage activates it",
        ),
        (
            INACTIVE,
            "",
            ACTIVATE,
            ACTIVATE,
            "stage.1.activate.0",
            "has been in the model already",
        ),
        (
            INACTIVE,
            "",
            "",
            "deactivate = [\"fill\"]\nactivate = [\"fill\"]",
            "stage.1.deactivate.0",
            "is not in the model",
        ),
        (
            "",
            "",
            "",
            "excavate = [{ shape = \"sphere\", centre = [0.0, 0.0, 0.0], radius = 1.0 }]",
            "stage.1.excavate.0.shape",
            "does not apply in 2D",
        ),
        (
            "",
            "",
            "",
            "excavate = [{ shape = \"disk\", centre = [0.0, 0.0] }]",
            "stage.1.excavate.0.radius",
            "is required",
        ),
        (
            "",
            "",
            "",
            "excavate = [{ shape = \"rectangle\", min = [2.0, 0.0], max = [1.0, 1.0] }]",
            "stage.1.excavate.0.max",
            "must exceed min",
        ),
        (
            "",
            springs,
            "",
            "reset_displacement = true",
            "stage.1.reset_displacement",
            "springs",
        ),
    ];
    for (fill, boundary, first, second, key, part) in cases {
        rejected_at(&scene(fill, boundary, first, second), key, &[part]);
    }
    // The keys act at a stage's start: not in a [solver] table.
    let text = scene("", "", "", "");
    let at = text.find("[[stage]]").unwrap();
    let solver = format!(
        "{}[solver]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\n\
         load_steps = 1\nexcavate = [{{ shape = \"disk\", centre = [0.0, 0.0], radius = 1.0 }}]\n",
        &text[..at]
    );
    rejected_at(&solver, "solver.excavate", &["[[stage]]"]);
    // A rigid body neither starts inactive nor leaves.
    let plate = with_plate(&scene("", "", "", "deactivate = [\"plate\"]"));
    accepted(&with_plate(&scene("", "", "", "")));
    rejected_at(&plate, "stage.1.deactivate.0", &["not a continuum body"]);
    let rigid = with_plate(&scene("", "", "", ""))
        .replace("kind = \"rigid\"\n", "kind = \"rigid\"\nactive = false\n");
    rejected_at(&rigid, "body.2.active", &["continuum"]);
    // An unknown key of a region.
    let typo = scene(
        "",
        "",
        "",
        "excavate = [{ shape = \"disk\", centre = [0.0, 0.0], radius = 1.0, radus = 2.0 }]",
    );
    let e = Scene::parse("scene.toml", &typo, &[]).expect_err("unknown key");
    assert!(e.to_string().contains("radus"), "{e}");
}

/// A stage that excavates every particle stops the run with a message that
/// says which stage, and keeps what it wrote before.
#[test]
fn a_stage_that_leaves_no_particle_stops_the_run() {
    let all = "excavate = [{ shape = \"rectangle\", min = [-1.0, -1.0], max = [5.0, 5.0] }]";
    let text = scene("", "", "", all);
    let (result, dir) = crate::common::run_text(&text, &[]);
    let e = result.expect_err("no particle is left");
    let message = e.to_string();
    assert!(message.contains("stage 1 leaves no particle"), "{message}");
    assert!(dir.path().join("history.csv").exists());
}
