//! The impact scenes' keys (issue 15): each mistake in a high-rate material, an
//! equation of state, the bulk viscosity or a cylinder body is named by its key
//! with line and column.

use crate::common::rejected_at;
use mpm::scene::Scene;

fn taylor() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/taylor_bar.toml");
    std::fs::read_to_string(path).unwrap()
}

fn replaced(from: &str, to: &str) -> String {
    let text = taylor();
    assert!(text.contains(from), "{from}");
    text.replace(from, to)
}

#[test]
fn the_impact_scenes_are_valid() {
    Scene::parse("scene.toml", &taylor(), &[]).unwrap();
    let plate = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/shock_plate.toml");
    Scene::load(std::path::Path::new(plate), &[]).unwrap();
}

#[test]
fn equation_of_state_mistakes_are_named() {
    rejected_at(
        &replaced("eos = \"mie_gruneisen\"", "eos = \"gruneisen\""),
        "material.0.eos",
        &[
            "scene.toml:",
            "unknown equation of state `gruneisen`",
            "mie_gruneisen",
        ],
    );
    rejected_at(
        &replaced("sound_speed = 3940.0\n", ""),
        "material.0.sound_speed",
        &["is required for eos = \"mie_gruneisen\""],
    );
    rejected_at(
        &replaced(
            "eos = \"mie_gruneisen\"",
            "eos = \"polynomial\"\nk1 = 1.0e11",
        ),
        "material.0.sound_speed",
        &["does not apply to eos = \"polynomial\""],
    );
    rejected_at(
        &replaced("hugoniot_slope = 1.49", "hugoniot_slope = -1.0"),
        "material.0.hugoniot_slope",
        &["must lie in [0, 10)"],
    );
}

#[test]
fn johnson_cook_mistakes_are_named() {
    rejected_at(
        &replaced("yield_stress = 157.0e6", "yield_stress = -1.0"),
        "material.0.yield_stress",
        &["must be a number ≥ 0"],
    );
    rejected_at(
        &replaced(
            "hardening_exponent = 1.0",
            "hardening_exponent = 1.0\nmelting_temperature = 1356.0",
        ),
        "material.0.thermal_exponent",
        &["is required for thermal softening"],
    );
    rejected_at(
        &replaced(
            "hardening_exponent = 1.0",
            "hardening_exponent = 1.0\ntaylor_quinney = 0.9",
        ),
        "material.0.taylor_quinney",
        &["applies only with melting_temperature"],
    );
    rejected_at(
        &replaced(
            "hardening_exponent = 1.0",
            "hardening_exponent = 1.0\ndamage_d1 = 0.5",
        ),
        "material.0.damage_d2",
        &["is required for Johnson–Cook damage"],
    );
    rejected_at(
        &replaced(
            "hardening_exponent = 1.0",
            "hardening_exponent = 1.0\nhel_strength = 1.0",
        ),
        "material.0.hel_strength",
        &["does not apply to model `johnson_cook`"],
    );
}

#[test]
fn ceramic_and_concrete_mistakes_are_named() {
    let jh2 = "model = \"jh2\"\ndensity = 3.226e-3\nshear_modulus = 127.0e3\nk1 = 201.0e3\nintact_coefficient = 0.85\ntensile_strength = 320.0\nhel_strength = 6.0e3\nhel_pressure = 5.0e3\ndamage_d1 = 0.02\nrate_form = \"sometimes\"\n";
    let material = |body: &str| {
        let text = taylor();
        let start = text.find("model = \"johnson_cook\"").unwrap();
        let end = text.find("[[body]]").unwrap();
        format!("{}{body}\n{}", &text[..start], &text[end..])
    };
    rejected_at(
        &material(jh2),
        "material.0.rate_form",
        &["unknown variant `sometimes`"],
    );
    let hjc = "model = \"hjc\"\ndensity = 2.44e-3\nshear_modulus = 14.86e3\nintact_coefficient = 0.79\ncompressive_strength = 48.0\ntensile_strength = 4.0\ndamage_d1 = 0.04\ncrush_pressure = 16.0\ncrush_strain = 0.001\nlock_pressure = 10.0\nk1 = 85.0e3\n";
    rejected_at(
        &material(hjc),
        "material.0.lock_pressure",
        &["must exceed crush_pressure = 16"],
    );
    let unreachable = hjc.replace("lock_pressure = 10.0", "lock_pressure = 800.0\nk2 = -1.0e7");
    rejected_at(
        &material(&unreachable),
        "material.0.k1",
        &["must rise to lock_pressure"],
    );
}

#[test]
fn bulk_viscosity_and_cylinder_mistakes_are_named() {
    rejected_at(
        &replaced(
            "bulk_viscosity_linear = 0.06",
            "bulk_viscosity_linear = -0.06",
        ),
        "solver.bulk_viscosity_linear",
        &["must lie in [0, 10]"],
    );
    let implicit = replaced(
        "kind = \"explicit\"\nscheme = \"musl\"",
        "kind = \"implicit\"\nlinear_solver = \"gmres\"",
    );
    let implicit = implicit.replace("cfl = 0.5\n", "");
    rejected_at(
        &implicit,
        "solver.bulk_viscosity_quadratic",
        &["does not apply"],
    );
    rejected_at(
        &replaced("height = 25.4e-3", "height = 0.0"),
        "body.0.height",
        &["must be a positive number"],
    );
    rejected_at(
        &replaced("height = 25.4e-3\n", ""),
        "body.0.height",
        &["required"],
    );
    // Crossing a face without a roller is still an error.
    let text = replaced(
        "face = \"xmin\"\ncondition = \"roller\"",
        "face = \"xmin\"\ncondition = \"fixed\"",
    );
    rejected_at(&text, "body.0.shape", &["outside the grid", "roller"]);
}
