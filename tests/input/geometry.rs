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
    let e = model(dir.path(), &text).err().expect("must be refused");
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
