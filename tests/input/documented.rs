//! Every value a scene may name is documented: the compiler does not see
//! docs/scene.md, so a shape function, solver kind, scheme, integrator, linear
//! solver, body kind, body shape or material model added without its documentation fails
//! here (docs/architecture.md, the recipes).

use mpm::material::registry;
use mpm::scene::{
    BodyKindName, BodyShape, Integrator, LinearSolver, Scheme, ShapeFunction, SolverKind,
};
use strum::IntoEnumIterator;

fn scene_md() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/scene.md");
    std::fs::read_to_string(path).expect("docs/scene.md")
}

/// The names docs/scene.md does not write as code (`name`).
fn undocumented<'a>(names: impl IntoIterator<Item = &'a str>) -> Vec<&'a str> {
    let doc = scene_md();
    (names.into_iter())
        .filter(|n| !doc.contains(&format!("`{n}`")))
        .collect()
}

#[test]
fn every_enumerated_scene_value_is_documented() {
    let mut names: Vec<&str> = Vec::new();
    names.extend(ShapeFunction::iter().map(|v| v.name()));
    names.extend(SolverKind::iter().map(|v| v.name()));
    names.extend(Scheme::iter().map(|v| v.name()));
    names.extend(Integrator::iter().map(|v| v.name()));
    names.extend(LinearSolver::iter().map(|v| v.name()));
    names.extend(BodyKindName::iter().map(<&str>::from));
    names.extend(BodyShape::iter().map(|v| v.name()));
    let missing = undocumented(names);
    assert!(
        missing.is_empty(),
        "docs/scene.md names none of {missing:?}"
    );
}

#[test]
fn every_material_model_is_documented() {
    let names = registry::names();
    assert!(names.len() >= 12, "{names:?}");
    let missing = undocumented(names.iter().copied());
    assert!(
        missing.is_empty(),
        "docs/scene.md names none of {missing:?}"
    );
}
