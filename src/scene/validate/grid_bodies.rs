//! The `[grid]` and `[[body]]` tables: the grid box and cells; each body's
//! material and kind, the keys of its shape, and its extent inside the grid.

use super::check::{ensure, forbidden, required, vector, Check};
use crate::material::rigid::Motion;
use crate::scene::{
    BodyConfig, BodyKindName, BodyShape, Condition, Fill, GridConfig, PerDirection, SceneConfig,
};

pub fn grid(g: &GridConfig, dim: usize) -> Check {
    vector(&g.min, dim, "grid.min")?;
    vector(&g.max, dim, "grid.max")?;
    ensure(
        g.cells.len() == dim,
        "grid.cells",
        format!("needs {dim} entries"),
    )?;
    ensure(
        g.cells.iter().all(|&c| c >= 1),
        "grid.cells",
        "every direction needs at least one cell",
    )?;
    let ok = (0..dim).all(|d| g.max[d] > g.min[d]);
    ensure(ok, "grid.max", "must exceed grid.min in every direction")?;
    for d in 0..dim {
        let extent = g.max[d] - g.min[d];
        ensure(
            extent.is_finite(),
            "grid.max",
            "the grid's extent must be a finite number",
        )?;
        // Cells must be resolved in floating point at the grid's coordinates.
        let h = extent / g.cells[d] as f64;
        let scale = g.min[d].abs().max(g.max[d].abs());
        ensure(
            h.is_normal() && h >= 1e-12 * scale,
            "grid.cells",
            format!(
                "the cell size {h:e} along axis {d} is too small to resolve at \
                 coordinates of {scale:e}"
            ),
        )?;
    }
    Ok(())
}

/// The grid's cell size along axis `d` (the grid validated).
fn cell_size(g: &GridConfig, d: usize) -> f64 {
    (g.max[d] - g.min[d]) / g.cells[d] as f64
}

pub fn body(b: &BodyConfig, i: usize, s: &SceneConfig) -> Check {
    let dim = s.dimension.spatial();
    let key = |k: &str| format!("body.{i}.{k}");
    let known = s.materials.iter().any(|m| m.name == b.material);
    ensure(
        known,
        key("material"),
        format!("no material is named `{}`", b.material),
    )?;
    kind(i, s)?;
    shape_keys(b, i, dim)?;
    // A body read from a file is checked against the grid once read
    // (`model::import`).
    if let Some((lo, hi)) = b.bounds() {
        inside_grid(&lo, &hi, i, s)?;
    }
    match &b.particles_per_cell {
        PerDirection::Same(n) => ensure(*n >= 1, key("particles_per_cell"), "must be at least 1")?,
        PerDirection::Each(v) => ensure(
            v.len() == dim && v.iter().all(|&n| n >= 1),
            key("particles_per_cell"),
            format!("needs {dim} entries, each at least 1"),
        )?,
    }
    // The particles' half-spacing (their domain's half-width) must be a normal
    // number: GIMP and CPDI divide by it.
    let spacing_ok = (0..dim)
        .all(|d| (cell_size(&s.grid, d) / b.particles_per_cell.get(d) as f64 / 2.0).is_normal());
    ensure(
        spacing_ok,
        key("particles_per_cell"),
        "the particle spacing is too small to represent",
    )?;
    if let Some(v) = &b.velocity {
        vector(v, dim, &key("velocity"))?;
    }
    if let Some(exprs) = &b.velocity_expr {
        ensure(
            exprs.len() == dim,
            key("velocity_expr"),
            format!("needs {dim} expressions"),
        )?;
        for (c, e) in exprs.iter().enumerate() {
            crate::scene::expr::eval(e, &[0.0; 3])
                .map_err(|m| (format!("body.{i}.velocity_expr.{c}"), m))?;
        }
    }
    Ok(())
}

/// A body's bounds [lo, hi] lie inside the grid, but across a face with a
/// roller condition (a symmetry plane: the model keeps the part inside).
pub fn inside_grid(lo: &[f64], hi: &[f64], i: usize, s: &SceneConfig) -> Check {
    let dim = s.dimension.spatial();
    let key = |k: &str| format!("body.{i}.{k}");
    let symmetry = |face: String| {
        s.boundaries
            .iter()
            .any(|c| c.face == face && c.condition == Condition::Roller)
    };
    let axis = ["x", "y", "z"];
    let inside = (0..dim).all(|d| {
        (lo[d] >= s.grid.min[d] || symmetry(format!("{}min", axis[d])) && hi[d] > s.grid.min[d])
            && (hi[d] <= s.grid.max[d]
                || symmetry(format!("{}max", axis[d])) && lo[d] < s.grid.max[d])
    });
    ensure(
        inside,
        key("shape"),
        format!(
            "the body spans {lo:?}..{hi:?}, outside the grid {:?}..{:?} (a body may cross \
             only a face with a roller condition, a symmetry plane)",
            s.grid.min, s.grid.max
        ),
    )
}

/// The body's kind and what it asks of the other keys: a continuum body needs
/// a material with a constitutive model and has no `motion`; a rigid body's
/// motion is given once (on the body or, in the old form, on its material), and
/// its material is no continuum body's (the particles of a rigid body carry the
/// zero-stress `material::rigid::Rigid` with the table's density,
/// `SceneConfig::particle_materials`).
fn kind(i: usize, s: &SceneConfig) -> Check {
    let (b, key) = (&s.bodies[i], |k: &str| format!("body.{i}.{k}"));
    let old_form = s.old_form_rigid(i);
    if s.body_kind(i) != BodyKindName::Peridynamic {
        super::peridynamic::not_peridynamic(i, s)?;
    }
    match s.body_kind(i) {
        BodyKindName::Peridynamic => {
            ensure(
                old_form.is_none(),
                key("material"),
                format!(
                    "`{}` is a rigid material: a peridynamic body needs E and ν (bond-based) or \
                     a continuum model (correspondence)",
                    b.material
                ),
            )?;
            super::peridynamic::body(i, s)
        }
        BodyKindName::Continuum => {
            ensure(
                old_form.is_none(),
                key("kind"),
                format!(
                    "a continuum body needs a material with a constitutive model, and `{}` \
                     has model = \"rigid\" (the old form of a rigid body): give kind = \
                     \"rigid\" or another material",
                    b.material
                ),
            )?;
            forbidden(
                &b.motion,
                key("motion"),
                "a continuum body (kind = \"rigid\" has one)",
            )
        }
        BodyKindName::Rigid => {
            ensure(
                !b.shape.from_file(),
                key("kind"),
                format!(
                    "a rigid body needs a surface of its own for contact, which the model \
                     does not yet take from a file (shape `{}`): give a rigid body a \
                     built-in shape",
                    b.shape.name()
                ),
            )?;
            let twice =
                b.motion.is_some() && old_form.and_then(|m| Motion::of(&m.parameters)).is_some();
            ensure(
                !twice,
                key("motion"),
                format!(
                    "material `{}` gives the motion too (its `motion`, the old form): give \
                     it once",
                    b.material
                ),
            )?;
            let shared = (0..s.bodies.len()).find(|&j| {
                s.bodies[j].material == b.material && s.body_kind(j) != BodyKindName::Rigid
            });
            match shared {
                Some(j) => Err((
                    key("material"),
                    format!(
                        "material `{}` is also the material of continuum body {j}: a rigid \
                         body takes only the density of its material, so give it a \
                         [[material]] table of its own",
                        b.material
                    ),
                )),
                None => Ok(()),
            }
        }
    }
}

/// The keys a body's shape needs, and no others.
fn shape_keys(b: &BodyConfig, i: usize, dim: usize) -> Check {
    let key = |k: &str| format!("body.{i}.{k}");
    let what = format!("shape `{}`", b.shape.name());
    ensure(
        b.fill == Fill::Lattice || matches!(b.shape, BodyShape::Disk | BodyShape::Cylinder),
        key("fill"),
        format!("`polar` fills a disk or a cylinder only, not {what}"),
    )?;
    let shape_dim = match b.shape {
        BodyShape::Rectangle | BodyShape::Disk | BodyShape::Polygon => 2,
        BodyShape::Box
        | BodyShape::Sphere
        | BodyShape::Cylinder
        | BodyShape::Prism
        | BodyShape::Surface
        | BodyShape::Terrain => 3,
        BodyShape::Particles | BodyShape::Mesh => dim,
    };
    if b.shape != BodyShape::Prism {
        forbidden(&b.axis, key("axis"), &what)?;
        forbidden(&b.extent, key("extent"), &what)?;
    }
    if !b.shape.from_file() {
        forbidden(&b.file, key("file"), &what)?;
    }
    if b.shape != BodyShape::Particles {
        forbidden(&b.body_id, key("body_id"), &what)?;
    }
    if b.shape != BodyShape::Mesh {
        forbidden(&b.physical, key("physical"), &what)?;
        forbidden(&b.quadrature, key("quadrature"), &what)?;
    }
    if b.shape != BodyShape::Terrain {
        forbidden(&b.base, key("base"), &what)?;
        forbidden(&b.base_file, key("base_file"), &what)?;
    } else if let Some(f) = &b.base_file {
        forbidden(&b.base, key("base"), "a body with `base_file`")?;
        ensure(
            !f.trim().is_empty(),
            key("base_file"),
            "needs the path of a raster file",
        )?;
    } else {
        ensure(
            b.base.is_some(),
            key("base"),
            format!("is required for {what} (a level; or give `base_file`, a raster)"),
        )?;
        ensure(
            b.base.unwrap().is_finite(),
            key("base"),
            "must be a finite elevation",
        )?;
    }
    ensure(
        shape_dim == dim,
        key("shape"),
        format!("{what} is a {shape_dim}D shape but dimension = {dim}"),
    )?;
    match b.shape {
        BodyShape::Rectangle | BodyShape::Box => {
            required(&b.min, key("min"), &what)?;
            required(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            forbidden(&b.height, key("height"), &what)?;
            let (lo, hi) = (b.min.clone().unwrap(), b.max.clone().unwrap());
            vector(&lo, dim, &key("min"))?;
            vector(&hi, dim, &key("max"))?;
            ensure(
                (0..dim).all(|d| hi[d] > lo[d]),
                key("max"),
                "must exceed min in every direction",
            )
        }
        BodyShape::Disk | BodyShape::Sphere => {
            required(&b.centre, key("centre"), &what)?;
            required(&b.radius, key("radius"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            forbidden(&b.height, key("height"), &what)?;
            let c = b.centre.clone().unwrap();
            vector(&c, dim, &key("centre"))?;
            let r = b.radius.unwrap();
            ensure(
                r > 0.0 && r.is_finite(),
                key("radius"),
                "must be a positive number",
            )
        }
        BodyShape::Polygon => {
            required(&b.vertices, key("vertices"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            forbidden(&b.height, key("height"), &what)?;
            polygon_vertices(b, i)
        }
        BodyShape::Prism => {
            required(&b.vertices, key("vertices"), &what)?;
            required(&b.extent, key("extent"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            forbidden(&b.height, key("height"), &what)?;
            if let Some(a) = &b.axis {
                ensure(
                    crate::scene::grid::axis(a).is_some(),
                    key("axis"),
                    format!("unknown axis `{a}`: expected \"x\", \"y\" or \"z\""),
                )?;
            }
            polygon_vertices(b, i)?;
            let e = b.extent.as_ref().unwrap();
            ensure(
                e.len() == 2 && e.iter().all(|x| x.is_finite()) && e[1] > e[0],
                key("extent"),
                "needs [from, to] along the axis, finite, with to > from",
            )
        }
        BodyShape::Particles | BodyShape::Surface | BodyShape::Terrain | BodyShape::Mesh => {
            required(&b.file, key("file"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.centre, key("centre"), &what)?;
            forbidden(&b.radius, key("radius"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            forbidden(&b.height, key("height"), &what)?;
            ensure(
                !b.file.as_ref().unwrap().trim().is_empty(),
                key("file"),
                "needs the path of a file",
            )
        }
        BodyShape::Cylinder => {
            required(&b.centre, key("centre"), &what)?;
            required(&b.radius, key("radius"), &what)?;
            required(&b.height, key("height"), &what)?;
            forbidden(&b.min, key("min"), &what)?;
            forbidden(&b.max, key("max"), &what)?;
            forbidden(&b.vertices, key("vertices"), &what)?;
            vector(b.centre.as_ref().unwrap(), dim, &key("centre"))?;
            for (k, v) in [("radius", b.radius.unwrap()), ("height", b.height.unwrap())] {
                ensure(
                    v > 0.0 && v.is_finite(),
                    key(k),
                    "must be a positive number",
                )?;
            }
            Ok(())
        }
    }
}

/// A polygon's (or a prism's cross-section's) vertices: at least 3 points in
/// the plane.
fn polygon_vertices(b: &BodyConfig, i: usize) -> Check {
    let v = b.vertices.as_ref().unwrap();
    ensure(
        v.len() >= 3,
        format!("body.{i}.vertices"),
        "a polygon needs at least 3 vertices",
    )?;
    for (k, p) in v.iter().enumerate() {
        ensure(
            p.len() == 2 && p.iter().all(|x| x.is_finite()),
            format!("body.{i}.vertices.{k}"),
            format!("needs 2 finite coordinates in the polygon's plane, has {p:?}"),
        )?;
    }
    Ok(())
}
