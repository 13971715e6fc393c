//! A closed surface from a Wavefront OBJ file (`shape = "surface"`, a file
//! ending in `.obj`), read by the `tobj` crate in double precision with its
//! polygons split into triangles (fans). Every object and group of the file
//! is one surface: corners that are the same numbers are one vertex, a
//! collapsed triangle is left out, and the surface must be closed and
//! consistently oriented (`TriangleSurface::check_closed`), as for STL.
//! Materials (`mtllib`), texture coordinates and normals are ignored.

use crate::model::triangles::TriangleSurface;
use std::path::Path;

/// Read and check the surface of `path` (`shown` names it in messages).
pub fn read(path: &Path, shown: &str) -> Result<TriangleSurface, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Only the geometry: a missing material library is not an error here.
    let (models, _) = tobj::load_obj(path, &options)
        .map_err(|e| format!("cannot read the OBJ file {shown}: {e}"))?;
    let mut facets = Vec::new();
    for m in &models {
        let p = &m.mesh.positions;
        let corner = |k: u32| {
            let k = 3 * k as usize;
            [p[k], p[k + 1], p[k + 2]]
        };
        for (n, t) in m.mesh.indices.chunks_exact(3).enumerate() {
            let f = [corner(t[0]), corner(t[1]), corner(t[2])];
            if let Some(bad) = f.iter().find(|c| c.iter().any(|x| !x.is_finite())) {
                return Err(format!(
                    "{shown}: object `{}`, triangle {}: the corner {bad:?} is not finite",
                    m.name,
                    n + 1
                ));
            }
            facets.push(f);
        }
    }
    TriangleSurface::closed_from_facets(&facets, shown, "OBJ")
}
