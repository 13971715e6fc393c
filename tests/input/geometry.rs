//! Geometry import (issue 55, item 1; docs/geometry.md): a particle file
//! (`shape = "particles"`) reads back the particles a run wrote and gives
//! the same run; its rows carry material zones, stresses and velocities; a
//! closed STL surface (`shape = "surface"`) is filled on the lattice; every
//! bad file is an error naming the file, the scene key and the line and
//! column (CSV) or the open edge (STL).

use crate::common::{assert_within, one_thread};
use mpm::model::Model;
use mpm::run::{run, RunOptions};
use mpm::scene::Scene;
use std::path::Path;

/// A gravity-loaded elastic block on a fixed base, cpGIMP (the particles'
/// domains matter), 2 × 2 particles per cell of 0.25 m: spacing 0.125 m and
/// volumes 1/64 m², both exact in binary, so the particle file holds them to
/// the bit. `BODY` is replaced by the body's shape keys.
const BLOCK: &str = r#"
dimension = 2
gravity = [0.0, -10.0]

[grid]
min = [0.0, 0.0]
max = [2.0, 2.0]
cells = [8, 8]
shape_function = "cpgimp"

[[material]]
name = "soil"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25

[[material]]
name = "stiff"
model = "linear_elastic"
density = 2500.0
youngs_modulus = 4.0e6
poisson_ratio = 0.2

[[body]]
material = "soil"
BODY

[[boundary]]
face = "ymin"
condition = "fixed"

[solver]
kind = "explicit"
end_time = 0.05

[output]
frames = 0
"#;

const RECTANGLE: &str = "shape = \"rectangle\"\nmin = [0.5, 0.0]\nmax = [1.5, 1.25]";

fn block(body: &str) -> String {
    BLOCK.replace("BODY", body)
}

fn particles_body(file: &Path) -> String {
    format!(
        "shape = \"particles\"\nfile = {:?}",
        file.display().to_string()
    )
}

/// Run scene text named `dir/scene.toml` (a particle file is found beside it).
fn run_in(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let out = dir.join(name);
    let scene = Scene::parse(dir.join("scene.toml").to_str().unwrap(), text, &[]).unwrap();
    one_thread(|| run(&scene, &out, &RunOptions::default())).unwrap();
    out
}

#[test]
fn a_run_from_its_own_particle_file_is_the_same_run() {
    let dir = tempfile::tempdir().unwrap();
    // The rectangle's particles at t = 0, as the run writes them.
    let first = block(RECTANGLE) + "particle_times = [0.0]\n";
    let a = run_in(dir.path(), "a", &first);
    let written = a.join("particles_0000.csv");
    let b = run_in(dir.path(), "b", &block(&particles_body(&written)));
    let (fa, fb) = (
        std::fs::read_to_string(a.join("particles_final.csv")).unwrap(),
        std::fs::read_to_string(b.join("particles_final.csv")).unwrap(),
    );
    assert!(
        fa.lines().count() == 8 * 10 + 1,
        "80 particles and the header"
    );
    // Bit for bit: the same particles (positions, volumes, domains) and so
    // the same 0.05 s of motion.
    assert!(fa == fb, "particles_final.csv differs");
    // The file's path relative to the scene file reads the same particles.
    std::fs::copy(&written, dir.path().join("block.csv")).unwrap();
    let relative = block("shape = \"particles\"\nfile = \"block.csv\"");
    let c = run_in(dir.path(), "c", &relative);
    let fc = std::fs::read_to_string(c.join("particles_final.csv")).unwrap();
    assert!(fa == fc, "relative path: particles_final.csv differs");
}

fn model(dir: &Path, text: &str) -> Result<Model<2>, mpm::scene::SceneError> {
    let scene = Scene::parse(dir.join("scene.toml").to_str().unwrap(), text, &[])?;
    Model::<2>::build(&scene)
}

#[test]
fn rows_carry_material_zones_stresses_and_velocities() {
    let dir = tempfile::tempdir().unwrap();
    let csv = "# two particles\n\
               x,y,volume,material,vx,vy,sxx,syy,szz,sxy,id\n\
               0.75,0.25,0.0625,,1.5,0,-10,-20,-5,2,7\n\
               1.25 , 0.5, 0.04 ,stiff,0,-2,0,0,0,0,8\n";
    std::fs::write(dir.path().join("p.csv"), csv).unwrap();
    let text = block("shape = \"particles\"\nfile = \"p.csv\"\nvelocity = [0.0, 0.5]");
    let m = model(dir.path(), &text).unwrap();
    let p = &m.particles;
    assert_eq!(p.len(), 2);
    assert_eq!((p.x[1][0], p.x[1][1]), (1.25, 0.5));
    assert_eq!((p.volume[0], p.volume[1]), (0.0625, 0.04));
    // The body's material and the row's zone; mass ρ V.
    assert_eq!((p.material[0], p.material[1]), (0, 1));
    assert_eq!((p.mass[0], p.mass[1]), (2000.0 * 0.0625, 2500.0 * 0.04));
    // The row's velocity plus the body's.
    assert_eq!((p.v[0][0], p.v[0][1], p.v[1][1]), (1.5, 0.5, -1.5));
    let s = p.stress.get(0);
    assert_eq!(
        (s[(0, 0)], s[(1, 1)], s[(2, 2)], s[(0, 1)], s[(1, 0)]),
        (-10.0, -20.0, -5.0, 2.0, 2.0)
    );
    // Domains: squares of the volume, 0.25 m and 0.2 m a side.
    assert_eq!(p.half_length0[0][0], 0.125);
    assert_within(
        "half-length of a 0.04 m² particle − 0.1 m",
        p.half_length0[1][1] - 0.1,
        1e-16,
    );
}

#[test]
fn body_id_takes_the_rows_of_one_body() {
    let dir = tempfile::tempdir().unwrap();
    let csv = "x,y,volume,body\n0.75,0.25,0.01,0\n0.8,0.3,0.01,1\n0.9,0.3,0.01,1\n";
    std::fs::write(dir.path().join("p.csv"), csv).unwrap();
    let text = block("shape = \"particles\"\nfile = \"p.csv\"\nbody_id = 1");
    let m = model(dir.path(), &text).unwrap();
    assert_eq!(m.particles.len(), 2);
    assert_eq!(m.particles.x[0][0], 0.8);
}

/// The error building the model of `body` with `csv` as p.csv: it is at the
/// key and holds every part.
fn file_error(csv: &str, body_keys: &str, key: &str, parts: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.csv"), csv).unwrap();
    let text = block(&format!(
        "shape = \"particles\"\nfile = \"p.csv\"\n{body_keys}"
    ));
    let Err(e) = model(dir.path(), &text) else {
        panic!("must be refused: {parts:?}")
    };
    assert_eq!(e.key.as_deref(), Some(key), "{e}");
    let s = e.to_string();
    for part in parts {
        assert!(s.contains(part), "`{part}` not in: {s}");
    }
    // The scene file at the key's line.
    assert!(s.contains("scene.toml:"), "{s}");
}

#[test]
fn every_particle_file_error_names_the_file_line_and_column() {
    let ok = "x,y,volume\n";
    file_error(
        "x,volume\n1,1\n",
        "",
        "body.0.file",
        &["p.csv:1: no column `y`", "the header names: x, volume"],
    );
    file_error(
        &format!("{ok}0.5,0.5,0.01\n0.5,abc,0.01\n"),
        "",
        "body.0.file",
        &["p.csv:3: column `y`: `abc` is not a finite number"],
    );
    file_error(
        &format!("{ok}0.5,0.5,-1\n"),
        "",
        "body.0.file",
        &["p.csv:2: column `volume`: -1 is not a positive volume"],
    );
    file_error(
        &format!("{ok}0.5,2.5,0.01\n"),
        "",
        "body.0.file",
        &["p.csv:2: column `y`: 2.5 lies outside the grid [0, 2)"],
    );
    file_error(
        &format!("{ok}0.5,0.5\n"),
        "",
        "body.0.file",
        &["p.csv", "line: 2", "found record with 2 fields"],
    );
    file_error(
        "x,y,volume,material\n0.5,0.5,0.01,clay\n",
        "",
        "body.0.file",
        &["p.csv:2: column `material`: no [[material]] is named `clay`"],
    );
    file_error(
        "x,y,volume,vx\n0.5,0.5,0.01,1\n",
        "",
        "body.0.file",
        &[
            "p.csv:1: no column `vy`",
            "an initial velocity needs all of vx, vy",
        ],
    );
    file_error(
        "x,y,volume,sxx,syy,sxy\n0.5,0.5,0.01,1,1,1\n",
        "",
        "body.0.file",
        &[
            "no column `szz`",
            "an initial stress needs all of sxx, syy, szz, sxy",
        ],
    );
    file_error(
        ok,
        "",
        "body.0.file",
        &["p.csv: the file holds no particle row"],
    );
    file_error(
        "x,y,volume\n0.5,0.5,0.01\n",
        "body_id = 0",
        "body.0.file",
        &["no column `body` (the key `body_id` selects rows by it)"],
    );
    file_error(
        "x,y,volume,body\n0.5,0.5,0.01,x\n",
        "body_id = 0",
        "body.0.file",
        &["p.csv:2: column `body`: `x` is not a body number"],
    );
    // A missing file.
    let dir = tempfile::tempdir().unwrap();
    let e = model(
        dir.path(),
        &block("shape = \"particles\"\nfile = \"none.csv\""),
    )
    .err()
    .unwrap();
    assert!(
        e.to_string().contains("cannot read the particle file")
            && e.to_string().contains("none.csv"),
        "{e}"
    );
}

#[test]
fn the_keys_of_a_file_body_are_checked() {
    use crate::common::rejected_at;
    rejected_at(
        &block("shape = \"particles\""),
        "body.0.file",
        &["is required for shape `particles`"],
    );
    rejected_at(
        &block("shape = \"particles\"\nfile = \"p.csv\"\nmin = [0.0, 0.0]"),
        "body.0.min",
        &["does not apply to shape `particles`"],
    );
    rejected_at(
        &block(&format!("{RECTANGLE}\nfile = \"p.csv\"")),
        "body.0.file",
        &["does not apply to shape `rectangle`"],
    );
    rejected_at(
        &block(&format!("{RECTANGLE}\nbody_id = 1")),
        "body.0.body_id",
        &["does not apply to shape `rectangle`"],
    );
    rejected_at(
        &block("shape = \"surface\"\nfile = \"s.stl\""),
        "body.0.shape",
        &["shape `surface` is a 3D shape but dimension = 2"],
    );
    rejected_at(
        &block("shape = \"particles\"\nfile = \"p.csv\"\nkind = \"rigid\""),
        "body.0.kind",
        &["a rigid body needs a surface of its own"],
    );
    let geostatic = block("shape = \"particles\"\nfile = \"p.csv\"")
        .replace("[solver]", "[geostatic]\nk0 = 0.5\n\n[solver]");
    rejected_at(
        &geostatic,
        "body.0.shape",
        &["[geostatic] measures depths below a body's top surface"],
    );
}

/// An elastic 3D scene on the grid [−1.5, 1.5]³ of 6 cells a side, 2
/// particles per cell: lattice spacing 0.25, the lattice symmetric about the
/// origin. `BODY` is replaced by the body's shape keys.
const SOLID: &str = r#"
dimension = 3

[grid]
min = [-1.5, -1.5, -1.5]
max = [1.5, 1.5, 1.5]
cells = [6, 6, 6]

[[material]]
name = "rock"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25

[[body]]
material = "rock"
BODY

[solver]
kind = "explicit"
end_time = 0.01

[output]
frames = 0
"#;

pub(crate) type Facet = [[f32; 3]; 3];

/// The unit sphere as an icosahedron subdivided `levels` times, the new
/// corners pushed out to the sphere (20 · 4^levels facets, each facing out).
/// Each corner is computed from its edge's ends alone, so the facets are
/// symmetric about the three coordinate planes to the bit.
pub(crate) fn sphere(levels: usize) -> Vec<Facet> {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    let corners: Vec<[f64; 3]> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .into_iter()
    .map(unit)
    .collect();
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[[f64; 3]; 3]> = faces.iter().map(|f| f.map(|k| corners[k])).collect();
    for _ in 0..levels {
        let mid = |a: [f64; 3], b: [f64; 3]| unit([a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        tris = (tris.iter())
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    (tris.iter())
        .map(|t| {
            // Facing out: the normal along the facet's centre.
            let e = |k: usize, d: usize| t[k][d] - t[0][d];
            let n = [
                e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1),
                e(1, 2) * e(2, 0) - e(1, 0) * e(2, 2),
                e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0),
            ];
            let out: f64 = (0..3).map(|d| n[d] * (t[0][d] + t[1][d] + t[2][d])).sum();
            let f = t.map(|v| v.map(|c| c as f32));
            match out > 0.0 {
                true => f,
                false => [f[0], f[2], f[1]],
            }
        })
        .collect()
}

/// The cube [−1, 1]³ moved by `shift`, two facets a face, facing out.
pub(crate) fn cube(shift: [f32; 3]) -> Vec<Facet> {
    let v = |k: usize| -> [f32; 3] {
        std::array::from_fn(|d| if (k >> d) & 1 == 1 { 1.0 } else { -1.0 } + shift[d])
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    (quads.iter())
        .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
        .collect()
}

pub(crate) fn write_binary(path: &Path, facets: &[Facet]) {
    let mesh: Vec<stl_io::Triangle> = (facets.iter())
        .map(|f| stl_io::Triangle {
            normal: stl_io::Normal::new([0.0; 3]),
            vertices: f.map(stl_io::Vertex::new),
        })
        .collect();
    let mut file = std::fs::File::create(path).unwrap();
    stl_io::write_stl(&mut file, mesh.iter()).unwrap();
}

/// ASCII STL, each coordinate as the shortest text that reads back to its f32.
fn write_ascii(path: &Path, facets: &[Facet]) {
    let mut text = String::from("solid test\n");
    for f in facets {
        text += "facet normal 0 0 0\nouter loop\n";
        for v in f {
            text += &format!("vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
        }
        text += "endloop\nendfacet\n";
    }
    text += "endsolid test\n";
    std::fs::write(path, text).unwrap();
}

pub(crate) fn solid(dir: &Path, file: &str) -> Result<Model<3>, mpm::scene::SceneError> {
    let body = format!("shape = \"surface\"\nfile = \"{file}\"");
    let text = SOLID.replace("BODY", &body);
    let scene = Scene::parse(dir.join("scene.toml").to_str().unwrap(), &text, &[])?;
    Model::<3>::build(&scene)
}

/// The particles' total volume and volume-weighted centroid.
pub(crate) fn volume_and_centroid(m: &Model<3>) -> (f64, [f64; 3]) {
    let p = &m.particles;
    let v: f64 = p.volume.iter().sum();
    let c = std::array::from_fn(|d| (0..p.len()).map(|q| p.volume[q] * p.x[q][d]).sum::<f64>() / v);
    (v, c)
}

/// Both forms of one surface give the same particles; their volume and
/// centroid.
fn both_forms(dir: &Path, name: &str, facets: &[Facet]) -> (f64, [f64; 3], usize) {
    write_binary(&dir.join(format!("{name}.stl")), facets);
    write_ascii(&dir.join(format!("{name}_ascii.stl")), facets);
    let binary = solid(dir, &format!("{name}.stl")).unwrap();
    let ascii = solid(dir, &format!("{name}_ascii.stl")).unwrap();
    assert!(
        binary.particles.x == ascii.particles.x,
        "{name}: ASCII ≠ binary"
    );
    assert!(binary.particles.volume == ascii.particles.volume);
    let (v, c) = volume_and_centroid(&binary);
    (v, c, binary.particles.len())
}

#[test]
fn a_sphere_and_a_cube_from_stl_have_their_volume_and_centroid() {
    let dir = tempfile::tempdir().unwrap();
    // The unit sphere at 8 particles across (spacing 0.25), 5120 facets.
    let (v, c, n) = both_forms(dir.path(), "sphere", &sphere(4));
    let exact = 4.0 / 3.0 * std::f64::consts::PI;
    println!("sphere: {n} particles");
    // The issue's bound; measured −0.22 %, the facets' own volume deficit
    // (the fill is exact for the triangulated solid, below).
    assert_within("sphere volume / (4π/3) − 1", v / exact - 1.0, 5e-3);
    // The fill is exact for the facets' solid (measured 1e-16 or so).
    let facets_volume: f64 = (sphere(4).iter())
        .map(|f| {
            let [a, b, c] = f.map(|v| v.map(f64::from));
            let bc = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0
        })
        .sum();
    assert_within(
        "sphere volume / the facets' − 1",
        v / facets_volume - 1.0,
        1e-12,
    );
    // Round-off: measured ≤ 3.1e-17.
    for (d, x) in c.iter().enumerate() {
        assert_within(&format!("sphere centroid {d}"), *x, 1e-14);
    }
    // The cube [−1, 1]³ on the lattice: 512 whole cells, exact.
    let (v, c, n) = both_forms(dir.path(), "cube", &cube([0.0; 3]));
    assert_eq!((v, n), (8.0, 512));
    assert_eq!(c.map(f64::abs), [0.0; 3]);
    // Moved off the lattice: cut cells, their parts' volumes and centroids,
    // against the box of the file's single-precision corners.
    let shift = [0.1f32, 0.05, 0.03];
    let (v, c, _) = both_forms(dir.path(), "moved", &cube(shift));
    let (lo, hi) = (
        shift.map(|s| f64::from(s - 1.0)),
        shift.map(|s| f64::from(s + 1.0)),
    );
    let exact: f64 = (0..3).map(|d| hi[d] - lo[d]).product();
    // Measured 0 and ≤ 1.2e-16.
    assert_within("moved cube volume / exact − 1", v / exact - 1.0, 1e-13);
    for d in 0..3 {
        let centre = 0.5 * (lo[d] + hi[d]);
        assert_within(&format!("moved cube centroid {d}"), c[d] - centre, 1e-13);
    }
}

#[test]
fn an_open_or_unreadable_stl_names_the_file_and_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    let mut open = cube([0.0; 3]);
    open.remove(3);
    write_ascii(&dir.path().join("open.stl"), &open);
    let e = solid(dir.path(), "open.stl").err().unwrap();
    assert_eq!(e.key.as_deref(), Some("body.0.file"), "{e}");
    let s = e.to_string();
    for part in [
        "open.stl: the surface is not closed: the edge (1, 1, 1) – (-1, -1, 1) of triangle 3",
        "belongs to 1 triangle(s)",
    ] {
        assert!(s.contains(part), "`{part}` not in: {s}");
    }
    std::fs::write(
        dir.path().join("bad.stl"),
        "solid x\nfacet normal 0 0 0\nouter loop\nvertex 1 2\n",
    )
    .unwrap();
    let e = solid(dir.path(), "bad.stl").err().unwrap().to_string();
    assert!(e.contains("bad.stl: facet 1:"), "{e}");
    let e = solid(dir.path(), "none.stl").err().unwrap().to_string();
    assert!(
        e.contains("cannot read the STL file") && e.contains("none.stl"),
        "{e}"
    );
    // A surface outside the grid.
    write_binary(&dir.path().join("far.stl"), &cube([1.0, 0.0, 0.0]));
    let e = solid(dir.path(), "far.stl").err().unwrap();
    assert_eq!(e.key.as_deref(), Some("body.0.shape"), "{e}");
    assert!(e.to_string().contains("far.stl: the body spans"), "{e}");
}

/// `mpm check DIR/scene.toml` through the program: its standard output.
fn check(dir: &Path, text: &str) -> String {
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("check")
        .arg(&scene)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "mpm check: {stderr}");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn check_prints_each_bodys_particles_volume_and_box() {
    let dir = tempfile::tempdir().unwrap();
    // The rectangle [0.5, 1.5] × [0, 1.25] at spacing 0.125: 8 × 10
    // particles whose domains tile it exactly.
    let out = check(dir.path(), &block(RECTANGLE));
    let line = "  body 0 (rectangle): 80 particles, volume 1.25 per unit thickness, \
                box (0.5, 0) – (1.5, 1.25)";
    assert!(out.lines().any(|l| l == line), "{out}");
    // A particle file: its rows, their volumes and domains (0.2 m squares).
    let csv = "x,y,volume\n0.75,0.25,0.04\n1.25,0.5,0.04\n";
    std::fs::write(dir.path().join("p.csv"), csv).unwrap();
    let out = check(
        dir.path(),
        &block("name = \"fill\"\nshape = \"particles\"\nfile = \"p.csv\""),
    );
    let line = "  body 0 `fill` (particles): 2 particles, volume 0.08 per unit thickness, \
                box (0.65, 0.15) – (1.35, 0.6)";
    assert!(out.lines().any(|l| l == line), "{out}");
    // A cube from STL in 3D: 512 whole cells of the lattice.
    write_binary(&dir.path().join("cube.stl"), &cube([0.0; 3]));
    let out = check(
        dir.path(),
        &SOLID.replace("BODY", "shape = \"surface\"\nfile = \"cube.stl\""),
    );
    let line = "  body 0 (surface): 512 particles, volume 8, box (-1, -1, -1) – (1, 1, 1)";
    assert!(out.lines().any(|l| l == line), "{out}");
}

/// A 3D slope z = 5 − x/2 over 0 < x < 8, 0 < y < 2, down to z = 0, on a
/// grid of 1 m cells with 2 particles per cell: side faces on rollers, base
/// fixed, K0 stresses, 0.05 s of explicit motion under gravity. `BODY` is
/// replaced by the body's shape keys.
pub(crate) const SLOPE: &str = r#"
dimension = 3
gravity = [0.0, 0.0, -10.0]

[grid]
min = [0.0, 0.0, 0.0]
max = [8.0, 2.0, 6.0]
cells = [8, 2, 6]

[[material]]
name = "soil"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 2.0e7
poisson_ratio = 0.3

[[body]]
material = "soil"
BODY

[[boundary]]
face = "xmin"
condition = "roller"

[[boundary]]
face = "xmax"
condition = "roller"

[[boundary]]
face = "ymin"
condition = "roller"

[[boundary]]
face = "ymax"
condition = "roller"

[[boundary]]
face = "zmin"
condition = "fixed"

[geostatic]
k0 = 0.5

[solver]
kind = "explicit"
end_time = 0.05

[output]
frames = 0
"#;

const PRISM: &str = "shape = \"prism\"\naxis = \"y\"\nextent = [0.0, 2.0]\n\
                     vertices = [[0.0, 0.0], [8.0, 0.0], [8.0, 1.0], [0.0, 5.0]]";

/// The slope's surface as an ESRI ASCII grid: 9 × 3 points 1 m apart from
/// (0, 0), the northern row first.
pub(crate) fn slope_raster() -> String {
    let mut text =
        "ncols 9\nnrows 3\nxllcenter 0\nyllcenter 0\ncellsize 1\nNODATA_value -9999\n".to_string();
    for _ in 0..3 {
        let row: Vec<String> = (0..9)
            .map(|j| format!("{}", 5.0 - 0.5 * j as f64))
            .collect();
        text += &(row.join(" ") + "\n");
    }
    text
}

pub(crate) fn slope(dir: &Path, body: &str) -> Result<Model<3>, mpm::scene::SceneError> {
    let scene = Scene::parse(
        dir.join("scene.toml").to_str().unwrap(),
        &SLOPE.replace("BODY", body),
        &[],
    )?;
    Model::<3>::build(&scene)
}

pub(crate) const TERRAIN: &str = "shape = \"terrain\"\nfile = \"ground.asc\"\nbase = 0.0";

#[test]
fn a_raster_of_a_plane_slope_is_the_prism_of_the_same_slope() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ground.asc"), slope_raster()).unwrap();
    let (terrain, prism) = (
        slope(dir.path(), TERRAIN).unwrap(),
        slope(dir.path(), PRISM).unwrap(),
    );
    // The same particles, in the same order.
    assert!(terrain.particles.x == prism.particles.x);
    assert!(terrain.particles.volume == prism.particles.volume);
    println!("{} particles", terrain.particles.len());
    // The same run: K0 stresses below the slope face, then 0.05 s under
    // gravity. The two tops could differ in round-off (a bilinear surface, a
    // polygon's edge): measured 0 (bit for bit) in stress and position, held
    // to the round-off floor.
    let run_of = |name: &str, body: &str| {
        let text = SLOPE.replace("BODY", body);
        let scene = Scene::parse(dir.path().join("scene.toml").to_str().unwrap(), &text, &[]);
        let out = dir.path().join(name);
        one_thread(|| run(&scene.unwrap(), &out, &RunOptions::default())).unwrap();
        mpm::output::Table::read(&out.join("particles_final.csv")).unwrap()
    };
    let (a, b) = (run_of("terrain", TERRAIN), run_of("prism", PRISM));
    for column in ["x", "z", "szz", "sxx", "sxz"] {
        let (ca, cb) = (a.col(column), b.col(column));
        let scale = cb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = (ca.iter().zip(cb)).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert_within(
            &format!("{column}: terrain − prism, relative"),
            worst / scale,
            1e-12,
        );
    }
}

#[test]
fn every_raster_error_names_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |raster: &str, key: &str, part: &str| {
        std::fs::write(dir.path().join("ground.asc"), raster).unwrap();
        let Err(e) = slope(dir.path(), TERRAIN) else {
            panic!("must be refused: {part}")
        };
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
        assert!(e.to_string().contains(part), "`{part}` not in: {e}");
    };
    let good = slope_raster();
    refused(
        &good.replace("cellsize 1", "cellsize x"),
        "body.0.file",
        "ground.asc:5: cellsize: `x` is not a number",
    );
    refused(
        &good.replace("nrows 3", "rows 3"),
        "body.0.file",
        "ground.asc:2: unknown header key `rows`",
    );
    refused(
        &good.replacen("5 4.5 4", "5 -9999 4", 1),
        "body.0.file",
        "ground.asc:7: no data at row 1 (from the north), column 2",
    );
    refused(
        &good.replacen("5 4.5 4", "5 4.5", 1),
        "body.0.file",
        "ground.asc:9: the raster holds 26 elevations, not ncols × nrows = 9 × 3",
    );
    refused(
        &good.replacen("5 4.5 4", "5 4.5 a", 1),
        "body.0.file",
        "ground.asc:7: `a` is not an elevation",
    );
    refused(
        &good.replacen("5 4.5 4", "5 4.5 -1", 1),
        "body.0.file",
        "ground.asc:7: the elevation -1 at row 1, column 3 is not above the body's base 0",
    );
    // Above the grid's top (z = 6, no roller there).
    refused(
        &good.replacen("5 4.5 4", "7 4.5 4", 1),
        "body.0.shape",
        "ground.asc: the body spans",
    );
    crate::common::rejected_at(
        &SLOPE.replace("BODY", "shape = \"terrain\"\nfile = \"ground.asc\""),
        "body.0.base",
        &["is required for shape `terrain`"],
    );
}
