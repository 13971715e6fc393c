//! `dimension = "axisymmetric"`: the key's values, and the combinations the
//! axisymmetric mode does not support, refused at their key with its line and
//! column (and some it does, accepted).

use crate::common::GOOD;
use mpm::scene::{Dimension, Scene};

/// GOOD as an axisymmetric scene (x = r from the axis).
fn axisymmetric() -> String {
    GOOD.replace("dimension = 2", "dimension = \"axisymmetric\"")
}

fn rejected(text: &str, parts: &[&str]) {
    let e = Scene::parse("scene.toml", text, &[])
        .expect_err("must be rejected")
        .to_string();
    for part in parts {
        assert!(e.contains(part), "`{part}` not in: {e}");
    }
}

#[test]
fn dimension_takes_2_3_or_axisymmetric() {
    let s = Scene::parse("scene.toml", &axisymmetric(), &[]).unwrap();
    assert_eq!(s.config.dimension, Dimension::Axisymmetric);
    assert_eq!(s.config.dimension.spatial(), 2);
    let s = Scene::parse("scene.toml", GOOD, &[]).unwrap();
    assert_eq!(s.config.dimension, Dimension::Cartesian(2));
    let s = Scene::parse("scene.toml", GOOD, &["dimension=\"axisymmetric\"".into()]).unwrap();
    assert!(s.config.dimension.is_axisymmetric());
    rejected(
        &GOOD.replace("dimension = 2", "dimension = \"axisymetric\""),
        &[
            "scene.toml:1:13",
            "key `dimension`",
            "unknown dimension `axisymetric`: expected 2, 3 or \"axisymmetric\"",
        ],
    );
    rejected(
        &GOOD.replace("dimension = 2", "dimension = 4"),
        &[
            "scene.toml:1:1",
            "key `dimension`",
            "must be 2 (plane strain), 3 or \"axisymmetric\"",
        ],
    );
    rejected(
        &GOOD.replace("dimension = 2", "dimension = -2"),
        &[
            "scene.toml:1:13",
            "key `dimension`",
            "expected 2, 3 or \"axisymmetric\"",
        ],
    );
    rejected(
        &GOOD.replace("dimension = 2", "dimension = 2.5"),
        &[
            "scene.toml:1:13",
            "key `dimension`",
            "expected 2, 3 or \"axisymmetric\"",
        ],
    );
}

#[test]
fn the_grid_lies_in_r_at_least_zero_and_gravity_along_the_axis() {
    rejected(
        &axisymmetric().replace(
            "min = [0.0, 0.0]\nmax = [4.0, 1.0]",
            "min = [-1.0, 0.0]\nmax = [4.0, 1.0]",
        ),
        &["scene.toml:4:7", "key `grid.min`", "r = x ≥ 0"],
    );
    rejected(
        &axisymmetric().replace("\n[grid]", "gravity = [1.0, -9.81]\n\n[grid]"),
        &["scene.toml:2:1", "key `gravity`", "along its axis"],
    );
}

#[test]
fn unsupported_combinations_are_refused_at_their_key() {
    let a = axisymmetric();
    // Every shape function, CPDI too; F-bar takes the hoop stretch in both solvers.
    for (from, to) in [
        ("cells = [4, 1]", "cells = [4, 1]\nshape_function = \"cpdi\""),
        ("cfl = 0.5", "cfl = 0.5\nfbar = true"),
        (
            "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5",
            "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 2\nfbar = true",
        ),
    ] {
        Scene::parse("scene.toml", &a.replace(from, to), &[]).unwrap();
    }
    rejected(
        &a.replace(
            "[solver]",
            "[[boundary]]\nface = \"xmax\"\ncondition = \"absorbing\"\n\n[solver]",
        ),
        &[
            "scene.toml:23:13",
            "key `boundary.0.condition`",
            "absorbing faces are not implemented",
        ],
    );
    rejected(
        &a.replace(
            "[solver]",
            "[[boundary]]\nface = \"xmin\"\ncondition = \"friction\"\nfriction_coefficient = 0.3\n\n[solver]",
        ),
        &["scene.toml:23:13", "key `boundary.0.condition`", "the xmin face is the axis"],
    );
    rejected(
        &a.replace(
            "[solver]",
            "[[boundary]]\nface = \"xmin\"\ncondition = \"velocity\"\nvelocity = [0.1, 0.0]\n\n[solver]",
        ),
        &["scene.toml:23:13", "key `boundary.0.condition`", "x component 0"],
    );
    rejected(
        &a.replace(
            "[solver]",
            "[[boundary]]\nface = \"ymax\"\ncondition = \"velocity\"\nvelocity = [0.0, -0.1]\nfooting_width = 0.5\n\n[solver]",
        ),
        &["scene.toml:25:17", "key `boundary.0.footing_width`", "not implemented in axisymmetric mode"],
    );
    // A grid away from the axis (a hollow cylinder) may carry any xmin condition
    // the plane-strain scene may.
    Scene::parse(
        "scene.toml",
        &a.replace("min = [0.0, 0.0]\nmax = [4.0, 1.0]", "min = [1.0, 0.0]\nmax = [4.0, 1.0]")
            .replace("min = [0.0, 0.0]\nmax = [2.0, 1.0]", "min = [1.0, 0.0]\nmax = [2.0, 1.0]")
            .replace(
                "[solver]",
                "[[boundary]]\nface = \"xmin\"\ncondition = \"velocity\"\nvelocity = [0.1, 0.0]\n\n[solver]",
            ),
        &[],
    )
    .unwrap();
}
