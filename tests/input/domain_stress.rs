//! `[grid] domain_stress`: what `"linear"` does not combine with is named at
//! the key, with its line and column (issue 16 item 2).

use mpm::scene::{Scene, ShapeFunction};
use strum::IntoEnumIterator;

/// problems/column.toml with `domain_stress = "linear"` in its grid table and
/// `solver` appended to its solver table.
fn column(shape: &str, solver: &str) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/column.toml");
    let text = std::fs::read_to_string(path).unwrap();
    text.replace(
        "shape_function = \"cpgimp\"\n",
        &format!("shape_function = \"{shape}\"\ndomain_stress = \"linear\"\n"),
    )
    .replace("load_steps = 20\n", &format!("load_steps = 20\n{solver}"))
}

/// The error names `grid.domain_stress` at its line (column 17, the value),
/// and holds `part`.
fn rejected(text: &str, part: &str) {
    let e = Scene::parse("column.toml", text, &[]).expect_err("must be rejected");
    assert_eq!(e.key.as_deref(), Some("grid.domain_stress"), "{e}");
    let s = e.to_string();
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("domain_stress"))
        .unwrap();
    for part in [format!("column.toml:{line}:17:").as_str(), part] {
        assert!(s.contains(part), "`{part}` not in: {s}");
    }
}

/// The families whose particle domain is an axis-aligned box that follows F:
/// `domain_stress = "linear"` is accepted with these and refused with every
/// other family in `ShapeFunction::iter()`, so a family added there is checked
/// here either way.
const BOX_DOMAINS: [ShapeFunction; 2] = [ShapeFunction::Cpgimp, ShapeFunction::Cpbspline2];

#[test]
fn linear_domain_stress_is_accepted_with_box_domains_in_implicit_stages() {
    for shape in BOX_DOMAINS {
        let text = column(
            shape.name(),
            "linear_solver = \"gmres\"\npreconditioner = \"lagged_direct\"\n",
        );
        Scene::parse("column.toml", &text, &[]).unwrap_or_else(|e| panic!("{shape:?}: {e}"));
    }
}

#[test]
fn linear_domain_stress_needs_a_box_domain() {
    for shape in ShapeFunction::iter().filter(|s| !BOX_DOMAINS.contains(s)) {
        let shape = shape.name();
        rejected(&column(shape, ""), &format!("not \"{shape}\""));
    }
}

#[test]
fn linear_domain_stress_refuses_explicit_stages_fbar_and_cg() {
    rejected(
        &column("cpbspline2", "fbar = true\n"),
        "does not combine with F-bar",
    );
    rejected(
        &column("cpbspline2", "linear_solver = \"cg\"\n"),
        "linear_solver = \"cg\"",
    );
    let explicit = column("cpgimp", "").replace("kind = \"implicit\"", "kind = \"explicit\"");
    rejected(&explicit, "implicit solver only");
}

#[test]
fn an_unknown_domain_stress_is_named() {
    let text = column("cpgimp", "").replace("\"linear\"", "\"quadratic\"");
    let e = Scene::parse("column.toml", &text, &[]).expect_err("must be rejected");
    assert_eq!(e.key.as_deref(), Some("grid.domain_stress"), "{e}");
    assert!(
        e.to_string().contains("expected `constant` or `linear`"),
        "{e}"
    );
}
