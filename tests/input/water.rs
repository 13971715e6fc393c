//! The `[water]` table (docs/pore_water.md): every refusal names its key path,
//! and the forms it accepts (a level in 2D, 3D and axisymmetric mode, a
//! polyline in 2D, parallel seepage in a tilted frame) parse.

use crate::common::rejected_at;
use mpm::scene::Scene;

/// A scene of `dimension` with `gravity` and the `[water]` lines `water`.
fn scene(dimension: &str, gravity: &str, water: &str) -> String {
    let three = dimension == "3";
    let v = |a: &str, b: &str, c: &str| match three {
        true => format!("[{a}, {b}, {c}]"),
        false => format!("[{a}, {b}]"),
    };
    format!(
        "dimension = {dimension}\ngravity = {gravity}\n[grid]\nmin = {}\nmax = {}\ncells = {}\n\
         [[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 2.0\n\
         youngs_modulus = 1.0e4\npoisson_ratio = 0.25\n\
         [[body]]\nmaterial = \"m\"\nshape = \"{}\"\nmin = {}\nmax = {}\n\
         [water]\n{water}\n\
         [solver]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n",
        v("0.0", "0.0", "0.0"),
        v("2.0", "5.0", "2.0"),
        match three {
            true => "[2, 5, 2]",
            false => "[2, 5]",
        },
        if three { "box" } else { "rectangle" },
        v("0.0", "0.0", "0.0"),
        v("2.0", "4.0", "2.0"),
    )
}

const DOWN: &str = "[0.0, -10.0]";

fn accepted(text: &str) {
    Scene::parse("scene.toml", text, &[]).unwrap_or_else(|e| panic!("{e}\n{text}"));
}

#[test]
fn accepted_forms() {
    accepted(&scene("2", DOWN, "unit_weight = 10.0\nlevel = 3.0"));
    accepted(&scene(
        "2",
        DOWN,
        "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0], [2.0, 2.0]]\nseepage = \"parallel\"",
    ));
    accepted(&scene(
        "\"axisymmetric\"",
        DOWN,
        "unit_weight = 10.0\nlevel = 3.0",
    ));
    accepted(&scene(
        "\"axisymmetric\"",
        DOWN,
        "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0], [2.0, 2.0]]",
    ));
    accepted(&scene(
        "3",
        "[0.0, -10.0, 0.0]",
        "unit_weight = 10.0\nlevel = 3.0",
    ));
    // An infinite slope in its slope-aligned frame.
    accepted(&scene(
        "2",
        "[4.47, -8.94]",
        "unit_weight = 10.0\nlevel = 4.0\nseepage = \"parallel\"",
    ));
}

#[test]
fn refusals_name_their_keys() {
    let cases: [(&str, &str, &str, &str, &str); 10] = [
        ("2", DOWN, "level = 3.0", "water.unit_weight", "is required"),
        (
            "2",
            DOWN,
            "unit_weight = -9.81\nlevel = 3.0",
            "water.unit_weight",
            "positive",
        ),
        (
            "2",
            DOWN,
            "unit_weight = 10.0",
            "water",
            "`level` or `phreatic_line`",
        ),
        (
            "2",
            DOWN,
            "unit_weight = 10.0\nlevel = 3.0\nphreatic_line = [[0.0, 3.0], [2.0, 2.0]]",
            "water.phreatic_line",
            "not both",
        ),
        (
            "2",
            DOWN,
            "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0], [2.0, 2.0], [1.0, 2.0]]",
            "water.phreatic_line.2",
            "increase strictly",
        ),
        (
            "2",
            DOWN,
            "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0, 1.0], [2.0, 2.0]]",
            "water.phreatic_line.0",
            "two finite numbers",
        ),
        (
            "2",
            DOWN,
            "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0]]",
            "water.phreatic_line",
            "two points",
        ),
        (
            "3",
            "[0.0, -10.0, 0.0]",
            "unit_weight = 10.0\nphreatic_line = [[0.0, 3.0], [2.0, 2.0]]",
            "water.phreatic_line",
            "give `level` in 3D",
        ),
        (
            "2",
            "[4.47, -8.94]",
            "unit_weight = 10.0\nlevel = 3.0",
            "water",
            "along one grid axis",
        ),
        (
            "2",
            "[0.0, 0.0]",
            "unit_weight = 10.0\nlevel = 3.0",
            "water",
            "needs `gravity`",
        ),
    ];
    for (dimension, gravity, water, key, words) in cases {
        rejected_at(&scene(dimension, gravity, water), key, &[words]);
    }
    // An unknown seepage is a serde error at its key.
    rejected_at(
        &scene(
            "2",
            DOWN,
            "unit_weight = 10.0\nlevel = 3.0\nseepage = \"radial\"",
        ),
        "water.seepage",
        &["radial"],
    );
}

/// Coupled pore flow (`drainage = "coupled"`, `condition = "drained"`): its
/// keys are refused at their paths, it runs in explicit stages only, and a
/// drained face needs a coupled material.
#[test]
fn coupled_flow_is_refused_where_it_cannot_apply() {
    let coupled = "drainage = \"coupled\"\nporosity = 0.4\nhydraulic_conductivity = 1e-4\n\
                   water_unit_weight = 10.0\n";
    let with = |material: &str, boundary: &str, solver: &str| {
        crate::common::GOOD
            .replace(
                "poisson_ratio = 0.3\n",
                &format!("poisson_ratio = 0.3\n{material}"),
            )
            .replace("[solver]\n", &format!("{boundary}[solver]\n"))
            .replace("kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5\n", solver)
    };
    let explicit = "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5\n";
    let implicit =
        "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n";
    let drained = "[[boundary]]\nface = \"ymax\"\ncondition = \"drained\"\n";
    accepted(&with(coupled, drained, explicit));
    rejected_at(
        &with(coupled, drained, implicit),
        "solver.kind",
        &["explicit stages only", "issue 52"],
    );
    rejected_at(
        &with("", drained, explicit),
        "boundary.0.condition",
        &["drainage = \"coupled\""],
    );
    rejected_at(
        &with(
            "drainage = \"coupled\"\nporosity = 0.4\nwater_unit_weight = 10.0\n",
            "",
            explicit,
        ),
        "material.0.hydraulic_conductivity",
        &["required"],
    );
    rejected_at(
        &with(
            "drainage = \"undrained\"\nporosity = 0.4\nhydraulic_conductivity = 1e-4\n",
            "",
            explicit,
        ),
        "material.0.hydraulic_conductivity",
        &["drainage = \"coupled\""],
    );
    rejected_at(
        &with(
            coupled,
            "[[boundary]]\nface = \"ymax\"\ncondition = \"drained\"\nvelocity = [0.0, 0.0]\n",
            explicit,
        ),
        "boundary.0.velocity",
        &["drained"],
    );
    rejected_at(
        &with(
            coupled,
            "[[boundary]]\nface = \"ymax\"\ncondition = \"roller\"\npore_pressure = 1.0\n",
            explicit,
        ),
        "boundary.0.pore_pressure",
        &["only to drained"],
    );
    accepted(&with(
        coupled,
        "[[boundary]]\nface = \"ymax\"\ncondition = \"drained\"\npore_pressure = 1.0e4\n",
        explicit,
    ));
    // A drained region must hold a node of its face (checked as the model is built).
    let off = with(
        coupled,
        "[[boundary]]\nface = \"ymax\"\ncondition = \"drained\"\n\
         region_min = [0.2, 0.0]\nregion_max = [0.4, 0.5]\n",
        explicit,
    );
    let scene = Scene::parse("scene.toml", &off, &[]).expect("valid scene");
    let e = mpm::model::Model::<2>::build(&scene)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("boundary.0.region_min") && e.contains("no grid node"),
        "{e}"
    );
}
