//! Closed surfaces from Wavefront OBJ (`shape = "surface"`, a `.obj` file;
//! docs/geometry.md): the same solid as STL gives the same particles, faces
//! with more than three corners are split, objects and groups are one
//! surface, and an open surface or an unreadable file names the file.

use crate::geometry::{cube, solid, sphere, volume_and_centroid, Facet};
use std::path::Path;

/// The facets as OBJ: one `v` line per corner (repeated; each coordinate the
/// shortest text of its single-precision value widened to double, which is
/// what the STL reader takes), one `f` line per facet.
fn write_obj(path: &Path, facets: &[Facet]) {
    let mut text = String::from("# test\no solid\n");
    for (k, f) in facets.iter().enumerate() {
        for v in f {
            let [x, y, z] = v.map(f64::from);
            text += &format!("v {x:e} {y:e} {z:e}\n");
        }
        text += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_sphere_and_a_cube_from_obj_are_the_stl_solids() {
    let dir = tempfile::tempdir().unwrap();
    for (name, facets) in [("sphere", sphere(3)), ("cube", cube([0.1, 0.05, 0.03]))] {
        write_obj(&dir.path().join(format!("{name}.obj")), &facets);
        crate::geometry::write_binary(&dir.path().join(format!("{name}.stl")), &facets);
        let obj = solid(dir.path(), &format!("{name}.obj")).unwrap();
        let stl = solid(dir.path(), &format!("{name}.stl")).unwrap();
        assert!(obj.particles.x == stl.particles.x, "{name}: OBJ ≠ STL");
        assert!(obj.particles.volume == stl.particles.volume, "{name}");
        println!("{name}: {} particles", obj.particles.len());
    }
    // The cube [−1, 1]³ with shared corners, quadrilateral faces and two
    // groups: 512 whole cells, exact.
    let text = "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\n\
                v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n\
                g bottom_and_sides\nf 1 3 4 2\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\n\
                g top_and_back\nf 5 6 8 7\nf 2 4 8 6\n";
    std::fs::write(dir.path().join("quads.obj"), text).unwrap();
    let m = solid(dir.path(), "quads.obj").unwrap();
    let (v, c) = volume_and_centroid(&m);
    assert_eq!((v, m.particles.len()), (8.0, 512));
    assert_eq!(c.map(f64::abs), [0.0; 3]);
}

#[test]
fn an_open_or_unreadable_obj_names_the_file_and_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    let mut open = cube([0.0; 3]);
    open.remove(3);
    write_obj(&dir.path().join("open.obj"), &open);
    let e = solid(dir.path(), "open.obj").err().unwrap();
    assert_eq!(e.key.as_deref(), Some("body.0.file"), "{e}");
    let s = e.to_string();
    for part in [
        "open.obj: the surface is not closed: the edge",
        "belongs to 1 triangle(s)",
    ] {
        assert!(s.contains(part), "`{part}` not in: {s}");
    }
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    let e = solid(dir.path(), "bad.obj").err().unwrap();
    assert!(e.to_string().contains("cannot read the OBJ file"), "{e}");
    assert!(e.to_string().contains("bad.obj"), "{e}");
    std::fs::write(dir.path().join("empty.obj"), "# nothing\n").unwrap();
    let e = solid(dir.path(), "empty.obj").err().unwrap();
    assert!(
        e.to_string()
            .contains("empty.obj: the OBJ file holds no triangle"),
        "{e}"
    );
}
