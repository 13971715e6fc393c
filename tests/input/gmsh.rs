//! Gmsh mesh bodies (`shape = "mesh"`, issue 55, item 1; docs/geometry.md):
//! particles at the elements' Gauss points whose volumes sum to the mesh's
//! area or volume and whose first moments give its centroid, to round-off;
//! physical groups select a body's elements; ASCII and binary files give the
//! same particles; every bad file is an error at the body's `file` key naming
//! the scene file, the .msh file and the line or the element.

use crate::common::gmsh::{msh_ascii, msh_binary, rectangle, Block};
use crate::common::problem;
use mpm::model::Model;
use mpm::scene::Scene;
use std::path::Path;

/// A 2D scene on the grid [0, 4] × [0, 3] (4 × 3 cells); `BODY` is replaced by
/// the body's keys and `MORE` by further tables.
const PLANE: &str = r#"
dimension = 2
gravity = [0.0, -10.0]

[grid]
min = [0.0, 0.0]
max = [4.0, 3.0]
cells = [4, 3]

[[material]]
name = "soil"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25

[[material]]
name = "rock"
model = "linear_elastic"
density = 2500.0
youngs_modulus = 4.0e6
poisson_ratio = 0.2

[[body]]
material = "soil"
BODY
MORE
[[boundary]]
face = "ymin"
condition = "fixed"

[solver]
kind = "explicit"
end_time = 0.01

[output]
frames = 0
"#;

fn model(dir: &Path, text: &str) -> Result<Model<2>, mpm::scene::SceneError> {
    let scene = Scene::parse(dir.join("scene.toml").to_str().unwrap(), text, &[])?;
    Model::<2>::build(&scene)
}

fn scene(body: &str, more: &str) -> String {
    PLANE.replace("BODY", body).replace("MORE", more)
}

/// The particles' total volume and centroid of body b.
fn volume_and_centroid(
    x: &[mpm::dim::Vector<2>],
    v: &[f64],
    body: &[u32],
    b: u32,
) -> (f64, [f64; 2]) {
    let of = (0..x.len()).filter(|&q| body[q] == b);
    let (mut total, mut m) = (0.0, [0.0; 2]);
    for q in of {
        total += v[q];
        (0..2).for_each(|d| m[d] += v[q] * x[q][d]);
    }
    (total, m.map(|c| c / total))
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn gmsh_rectangles_have_their_area_and_centroid_in_both_forms() {
    let dir = tempfile::tempdir().unwrap();
    // [0.5, 3.5] × [0, 2.2] (area 6.6, centroid (2, 1.1)); a lower-dimensional
    // block (lines) that the body passes over.
    for triangles in [true, false] {
        let (nodes, elements) = rectangle([0.5, 3.5], [0.0, 2.2], [7, 5], triangles);
        let lines = Block {
            dim: 1,
            entity: 1,
            kind: 1,
            elements: vec![vec![1, 2]],
        };
        let kind = if triangles { 2 } else { 3 };
        let blocks = [
            lines,
            Block {
                dim: 2,
                entity: 1,
                kind,
                elements,
            },
        ];
        let ascii = msh_ascii(&nodes, &blocks, &[(1, vec![])], &[]);
        std::fs::write(dir.path().join("a.msh"), ascii).unwrap();
        std::fs::write(
            dir.path().join("b.msh"),
            msh_binary(&nodes, &blocks[1..], &[(1, vec![])]),
        )
        .unwrap();
        let mut found = Vec::new();
        for (file, quadrature) in [("a.msh", "full"), ("b.msh", "full"), ("a.msh", "one")] {
            let body =
                format!("shape = \"mesh\"\nfile = \"{file}\"\nquadrature = \"{quadrature}\"");
            let m = model(dir.path(), &scene(&body, "")).unwrap();
            let p = &m.particles;
            let (v, c) = volume_and_centroid(&p.x, &p.volume, &p.body, 0);
            let per = match (triangles, quadrature) {
                (_, "one") => 1,
                (true, _) => 3,
                (false, _) => 4,
            };
            let cells = 35 * if triangles { 2 } else { 1 };
            assert_eq!(p.len(), per * cells, "{file} {quadrature}");
            eprintln!(
                "rectangle ({}, {quadrature}, {file}): {} particles, area {v:.17} (6.6), centroid {c:?}",
                if triangles { "triangles" } else { "quads" },
                p.len()
            );
            assert!(rel(v, 6.6) < 1e-12, "area {v}");
            assert!(
                (c[0] - 2.0).abs() < 1e-12 && (c[1] - 1.1).abs() < 1e-12,
                "{c:?}"
            );
            // Mass = density × volume; domains the squares of the volumes.
            let q = p.len() / 2;
            assert!(rel(p.mass[q], 2000.0 * p.volume[q]) < 1e-15);
            assert!(rel(p.half_length0[q][0], 0.5 * p.volume[q].sqrt()) < 1e-15);
            found.push((p.x.clone(), p.volume.clone()));
        }
        // ASCII and binary: the same particles, to the bit.
        assert_eq!(found[0], found[1]);
    }
}

#[test]
fn gmsh_slope_has_the_area_and_centroid_of_its_polygon() {
    // problems/slope_gmsh.msh: the polygon (0, 0), (35, 0), (15, 10), (0, 10).
    let scene = Scene::load(&problem("slope_gmsh.toml"), &[]).unwrap();
    let m = Model::<2>::build(&scene).unwrap();
    let p = &m.particles;
    let (v, c) = volume_and_centroid(&p.x, &p.volume, &p.body, 0);
    // Shoelace: A = Σ (x_k y_{k+1} − x_{k+1} y_k)/2, c = Σ (x_k + x_{k+1}) (…)/(6A).
    let poly = [[0.0, 0.0], [35.0, 0.0], [15.0, 10.0], [0.0, 10.0]];
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for k in 0..4 {
        let (p0, p1) = (poly[k], poly[(k + 1) % 4]);
        let cross = p0[0] * p1[1] - p1[0] * p0[1];
        a += cross / 2.0;
        cx += (p0[0] + p1[0]) * cross;
        cy += (p0[1] + p1[1]) * cross;
    }
    let (cx, cy) = (cx / (6.0 * a), cy / (6.0 * a));
    eprintln!(
        "slope mesh: {} particles, area {v:.15} ({a}), centroid {c:?} ({cx}, {cy})",
        p.len()
    );
    assert_eq!(p.len(), 16200);
    assert!(rel(v, a) < 1e-12, "area {v} against {a}");
    assert!(rel(c[0], cx) < 1e-12 && rel(c[1], cy) < 1e-12, "{c:?}");
    // The K0 depth is measured below the slope face, as for the polygon.
    let geostatic = scene.config.geostatic.as_ref().unwrap();
    let mut m = m;
    mpm::physics::geostatic::initialise(&mut m, geostatic);
    let k0 = 1.0 - 20f64.to_radians().sin();
    for q in 0..m.particles.len() {
        let (x, y) = (m.particles.x0[q][0], m.particles.x0[q][1]);
        let surface = if x <= 15.0 { 10.0 } else { (35.0 - x) / 2.0 };
        let s = m.particles.stress.get(q);
        assert!(
            (s[(1, 1)] + 20.0 * (surface - y)).abs() < 1e-9,
            "σ_v at ({x}, {y})"
        );
        assert!((s[(0, 0)] - k0 * s[(1, 1)]).abs() < 1e-9);
    }
}

/// Two zones of one file: [0.5, 2] × [0, 2] in surface 1 (group 1 "clay"),
/// [2, 3.5] × [0, 2] in surface 2 (group 2 "sand").
fn zones(dir: &Path) {
    let (mut nodes, left) = rectangle([0.5, 2.0], [0.0, 2.0], [3, 4], true);
    let (right_nodes, right) = rectangle([2.0, 3.5], [0.0, 2.0], [3, 4], false);
    let shift = nodes.len() as u64;
    nodes.extend(right_nodes);
    let right = right
        .into_iter()
        .map(|e| e.iter().map(|t| t + shift).collect())
        .collect();
    let blocks = [
        Block {
            dim: 2,
            entity: 1,
            kind: 2,
            elements: left,
        },
        Block {
            dim: 2,
            entity: 2,
            kind: 3,
            elements: right,
        },
    ];
    let text = msh_ascii(
        &nodes,
        &blocks,
        &[(1, vec![1]), (2, vec![2])],
        &[(2, 1, "clay"), (2, 2, "sand"), (1, 3, "base")],
    );
    std::fs::write(dir.join("zones.msh"), text).unwrap();
}

#[test]
fn gmsh_physical_groups_make_bodies_and_material_zones() {
    let dir = tempfile::tempdir().unwrap();
    zones(dir.path());
    let text = scene(
        "shape = \"mesh\"\nfile = \"zones.msh\"\nphysical = \"clay\"",
        "[[body]]\nmaterial = \"rock\"\nshape = \"mesh\"\nfile = \"zones.msh\"\nphysical = 2\n",
    );
    let m = model(dir.path(), &text).unwrap();
    let p = &m.particles;
    let (v0, c0) = volume_and_centroid(&p.x, &p.volume, &p.body, 0);
    let (v1, c1) = volume_and_centroid(&p.x, &p.volume, &p.body, 1);
    assert!(rel(v0, 3.0) < 1e-12 && rel(v1, 3.0) < 1e-12, "{v0} {v1}");
    assert!(
        (c0[0] - 1.25).abs() < 1e-12 && (c1[0] - 2.75).abs() < 1e-12,
        "{c0:?} {c1:?}"
    );
    assert!(
        (0..p.len()).all(|q| p.material[q] == p.body[q]),
        "body 1 is rock"
    );
    // Without `physical`: both zones.
    let m = model(
        dir.path(),
        &scene("shape = \"mesh\"\nfile = \"zones.msh\"", ""),
    )
    .unwrap();
    let (v, _) = volume_and_centroid(&m.particles.x, &m.particles.volume, &m.particles.body, 0);
    assert!(rel(v, 6.0) < 1e-12, "{v}");
}

/// The error building the model with `msh` as m.msh and `keys` for the body:
/// at `body.0.file`, holding every part and the scene file's line.
fn file_error(msh: &[u8], keys: &str, parts: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.msh"), msh).unwrap();
    zones(dir.path());
    let text = scene(&format!("shape = \"mesh\"\nfile = \"m.msh\"\n{keys}"), "");
    let Err(e) = model(dir.path(), &text) else {
        panic!("must be refused: {parts:?}")
    };
    assert_eq!(e.key.as_deref(), Some("body.0.file"), "{e}");
    let s = e.to_string();
    for part in parts {
        assert!(s.contains(part), "`{part}` not in: {s}");
    }
    assert!(s.contains("scene.toml:"), "{s}");
}

fn one_block(nodes: &[[f64; 3]], kind: u8, elements: Vec<Vec<u64>>) -> String {
    let blocks = [Block {
        dim: 2,
        entity: 1,
        kind,
        elements,
    }];
    msh_ascii(nodes, &blocks, &[(1, vec![1])], &[(2, 1, "soil")])
}

#[test]
fn every_gmsh_file_error_names_the_file_and_the_line_or_element() {
    let square = [
        [1.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
        [2.0, 2.0, 0.0],
        [1.0, 2.0, 0.0],
    ];
    let good = one_block(&square, 3, vec![vec![1, 2, 3, 4]]);
    // Not MSH; another version; a truncated file (the line where it stops).
    file_error(b"solid x\n", "", &["m.msh: not a Gmsh MSH file"]);
    file_error(
        good.replace("4.1 0 8", "2.2 0 8").as_bytes(),
        "",
        &["m.msh:2: MSH format version 2.2: only version 4.1 is read"],
    );
    file_error(
        good.replace("4.1 0 8", "4.1 1 3").as_bytes(),
        "",
        &["m.msh:2: `4.1 1 3`: the file type must be 0 (ASCII) or 1 (binary)"],
    );
    let cut = &good[..good.find("2.0 2.0 0.0").unwrap()];
    file_error(cut.as_bytes(), "", &["m.msh:", "node section"]);
    let bad_name = good.replace("2 1 \"soil\"", "2 x soil");
    file_error(
        bad_name.as_bytes(),
        "",
        &["m.msh:6: `2 x soil`: expected `dimension tag \"name\"`"],
    );
    // A quadratic triangle (Gmsh type 9) among the body's elements.
    let six = [square.to_vec(), vec![[1.5, 1.0, 0.0], [1.5, 1.5, 0.0]]].concat();
    let t6 = one_block(&six, 9, vec![vec![1, 2, 3, 5, 6, 4]]);
    file_error(
        t6.as_bytes(),
        "",
        &["m.msh: element 1: Gmsh element type 9 (Tri6) is not read: a 2D mesh body takes 3-node triangles and 4-node quadrilaterals"],
    );
    // Inverted (clockwise) and degenerate elements.
    let cw = one_block(&square, 3, vec![vec![1, 2, 3, 4], vec![1, 4, 3, 2]]);
    file_error(
        cw.as_bytes(),
        "",
        &[
            "m.msh: element 2 (quadrilateral) is inverted",
            "counter-clockwise",
        ],
    );
    let flat = one_block(&square, 2, vec![vec![1, 2, 3], vec![1, 3, 3]]);
    file_error(
        flat.as_bytes(),
        "",
        &["m.msh: element 2 (triangle) is degenerate: det J = 0"],
    );
    // A node outside the grid [0, 4] × [0, 3]; a node that is not in $Nodes.
    let far = one_block(
        &[square.to_vec(), vec![[5.0, 2.0, 0.0]]].concat(),
        2,
        vec![vec![1, 2, 3], vec![2, 5, 3]],
    );
    file_error(
        far.as_bytes(),
        "",
        &["m.msh: element 2 (triangle): its node at [5.0, 2.0] lies outside the grid"],
    );
    let lost = one_block(&square, 2, vec![vec![1, 2, 7]]);
    file_error(
        lost.as_bytes(),
        "",
        &["m.msh: element 1: its node 7 is not in the $Nodes section"],
    );
    // Physical groups: unknown by name and by number; a group with no element.
    file_error(
        good.as_bytes(),
        "physical = \"clay\"",
        &["m.msh: no physical group `clay` of dimension 2: its 2D groups are 1 `soil`"],
    );
    file_error(
        good.as_bytes(),
        "physical = 4",
        &["no physical group 4 of dimension 2"],
    );
    let lines = msh_ascii(
        &square,
        &[Block {
            dim: 1,
            entity: 1,
            kind: 1,
            elements: vec![vec![1, 2]],
        }],
        &[],
        &[],
    );
    file_error(
        lines.as_bytes(),
        "",
        &["m.msh: the file holds no 2D element"],
    );
    // A missing file.
    let dir = tempfile::tempdir().unwrap();
    let e = model(
        dir.path(),
        &scene("shape = \"mesh\"\nfile = \"none.msh\"", ""),
    )
    .err()
    .unwrap();
    assert_eq!(e.key.as_deref(), Some("body.0.file"), "{e}");
    assert!(
        e.to_string().contains("cannot read the Gmsh file") && e.to_string().contains("none.msh"),
        "{e}"
    );
}

#[test]
fn gmsh_keys_are_checked() {
    use crate::common::rejected_at;
    rejected_at(&scene("shape = \"mesh\"", ""), "body.0.file", &["required"]);
    rejected_at(
        &scene(
            "shape = \"rectangle\"\nmin = [0.5, 0.0]\nmax = [1.5, 1.0]\nphysical = 1",
            "",
        ),
        "body.0.physical",
        &["does not apply"],
    );
    rejected_at(
        &scene(
            "shape = \"rectangle\"\nmin = [0.5, 0.0]\nmax = [1.5, 1.0]\nquadrature = \"one\"",
            "",
        ),
        "body.0.quadrature",
        &["does not apply"],
    );
    rejected_at(
        &scene(
            "shape = \"mesh\"\nfile = \"m.msh\"\nquadrature = \"two\"",
            "",
        ),
        "body.0.quadrature",
        &["unknown variant"],
    );
    rejected_at(
        &scene("shape = \"mesh\"\nfile = \"m.msh\"\nphysical = 1.5", ""),
        "body.0.physical",
        &["physical group"],
    );
    rejected_at(
        &scene("shape = \"mesh\"\nfile = \"m.msh\"\nkind = \"rigid\"", ""),
        "body.0.kind",
        &["rigid body"],
    );
}

#[test]
fn gmsh_body_in_mpm_check() {
    let dir = tempfile::tempdir().unwrap();
    zones(dir.path());
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        scene(
            "name = \"clay\"\nshape = \"mesh\"\nfile = \"zones.msh\"\nphysical = \"clay\"",
            "",
        ),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("check")
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = String::from_utf8(out.stdout).unwrap();
    // 24 triangles × 3 points; volume 3 (to round-off, as printed).
    let line = out
        .lines()
        .find(|l| l.starts_with("  body 0 `clay` (mesh): 72 particles, volume "));
    let line = line.unwrap_or_else(|| panic!("{out}"));
    let volume: f64 = line
        .split("volume ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(rel(volume, 3.0) < 1e-12, "{line}");
}

/// A 3D scene on the grid [0, 2] × [0, 1] × [0, 1] (4 × 2 × 2 cells).
const SOLID: &str = r#"
dimension = 3
[grid]
min = [0.0, 0.0, 0.0]
max = [2.0, 1.0, 1.0]
cells = [4, 2, 2]

[[material]]
name = "soil"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25

[[body]]
material = "soil"
shape = "mesh"
file = "box.msh"
BODY

[solver]
kind = "explicit"
end_time = 0.01

[output]
frames = 0
"#;

#[test]
fn gmsh_3d_groups_pass_over_faces_and_refuse_prisms() {
    use crate::common::gmsh::box_mesh;
    let dir = tempfile::tempdir().unwrap();
    // [0, 1]³ as tetrahedra in volume 1 (group 5 "left"), [1, 2] × [0, 1]²
    // as hexahedra in volume 2 (group 6 "right"); a boundary face (2D, type 2).
    let (mut nodes, tets) = box_mesh([0.0; 3], [1.0; 3], [2, 2, 2], true);
    let (right_nodes, hexes) = box_mesh([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], [2, 2, 2], false);
    let shift = nodes.len() as u64;
    nodes.extend(right_nodes);
    let hexes: Vec<Vec<u64>> = hexes
        .iter()
        .map(|e| e.iter().map(|t| t + shift).collect())
        .collect();
    let face = Block {
        dim: 2,
        entity: 1,
        kind: 2,
        elements: vec![vec![1, 2, 4]],
    };
    let blocks = |prism: bool| {
        let mut right = hexes.clone();
        let kind = if prism { 6 } else { 5 };
        if prism {
            right = right.iter().map(|e| e[..6].to_vec()).collect();
        }
        [
            face.clone(),
            Block {
                dim: 3,
                entity: 1,
                kind: 4,
                elements: tets.clone(),
            },
            Block {
                dim: 3,
                entity: 2,
                kind,
                elements: right,
            },
        ]
    };
    let groups = [(1, vec![5]), (2, vec![6])];
    let names = [(3, 5, "left"), (3, 6, "right")];
    let build = |text: &str| {
        let scene = Scene::parse(dir.path().join("s.toml").to_str().unwrap(), text, &[])?;
        Model::<3>::build(&scene)
    };
    std::fs::write(
        dir.path().join("box.msh"),
        msh_ascii(&nodes, &blocks(false), &groups, &names),
    )
    .unwrap();
    for (keys, count, volume) in [
        ("physical = \"left\"", 48 * 4, 1.0),
        ("physical = 6", 64, 1.0),
        ("", 48 * 4 + 64, 2.0),
    ] {
        let m = build(&SOLID.replace("BODY", keys)).unwrap();
        let v: f64 = m.particles.volume.iter().sum();
        assert_eq!(m.particles.len(), count, "{keys}");
        assert!((v / volume - 1.0).abs() < 1e-12, "{keys}: {v}");
    }
    // Prisms (type 6) in the right half: refused by the first one's tag (the
    // tetrahedra are 48 elements after the face: tags 2..49, the prisms 50..).
    std::fs::write(
        dir.path().join("box.msh"),
        msh_ascii(&nodes, &blocks(true), &groups, &names),
    )
    .unwrap();
    let e = build(&SOLID.replace("BODY", "")).err().unwrap();
    assert_eq!(e.key.as_deref(), Some("body.0.file"), "{e}");
    let s = e.to_string();
    assert!(s.contains("box.msh: element 50: Gmsh element type 6 (Pri6) is not read: a 3D mesh body takes 4-node tetrahedra and 8-node hexahedra"), "{s}");
    // The left group alone has no prism.
    assert!(build(&SOLID.replace("BODY", "physical = \"left\"")).is_ok());
}
