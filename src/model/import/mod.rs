//! Bodies whose geometry is read from a file (docs/geometry.md): a particle
//! file (`shape = "particles"`, CSV, `particle_file.rs`), a closed
//! triangulated surface (`shape = "surface"`, STL `stl.rs` or Wavefront OBJ
//! `obj.rs`), a terrain raster (`shape = "terrain"`, ESRI ASCII grid
//! `esri_grid.rs` or GeoTIFF `geotiff.rs`, over a level or a second raster)
//! and finite elements (`shape = "mesh"`, Gmsh MSH 4.1, `gmsh.rs`). The
//! `file` and `base_file` keys are paths relative to the scene file's folder.
//! A file error is a scene error at the body's key for the file, whose message
//! names the file and, where it can, the line and column (particle file,
//! ESRI grid, OBJ), the facet and edge (STL, OBJ), the element (Gmsh) or the
//! raster's row and column (GeoTIFF).
//! Nothing here runs for a scene without such a body.

pub(crate) mod esri_grid;
pub(crate) mod geotiff;
pub(crate) mod gmsh;
pub(crate) mod obj;
pub(crate) mod particle_file;
pub(crate) mod stl;

use crate::material::parameters::FromParameters;
use crate::material::rigid::Rigid;
use crate::model::geometry::Geometry;
use crate::model::terrain::{Bottom, Raster, Terrain};
use crate::scene::{validate, BodyKindName, BodyShape, Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The geometry of body i of a validated scene: from its keys, or read from
/// its file.
pub fn body_geometry(scene: &Scene, i: usize) -> Result<Geometry, SceneError> {
    let b = &scene.config.bodies[i];
    if !b.shape.from_file() {
        return Ok(Geometry::of(b));
    }
    let file = b.file.as_deref().expect("validated");
    let path = beside(&scene.file, file);
    let shown = path.display().to_string();
    let at_file = |m: String| scene.at_key(&format!("body.{i}.file"), m);
    let geometry = match b.shape {
        BodyShape::Particles => Geometry::Particles(Arc::new(
            particles(scene, i, &path, &shown).map_err(at_file)?,
        )),
        BodyShape::Terrain => Geometry::Terrain(Arc::new(terrain(scene, i, &path, &shown)?)),
        BodyShape::Mesh => {
            let c = &scene.config;
            let select = gmsh::Select {
                dim: c.dimension.spatial(),
                physical: b.physical.as_ref(),
                quadrature: b.quadrature.unwrap_or_default(),
                grid: (&c.grid.min, &c.grid.max),
            };
            Geometry::Mesh(Arc::new(
                gmsh::read(&path, &shown, &select).map_err(at_file)?,
            ))
        }
        _ if has_extension(&path, &["obj"]) => {
            Geometry::Surface(Arc::new(obj::read(&path, &shown).map_err(at_file)?))
        }
        _ => Geometry::Surface(Arc::new(stl::read(&path, &shown).map_err(at_file)?)),
    };
    // A particle file's and a mesh's rows and nodes were checked one by one.
    if !matches!(geometry, Geometry::Particles(_) | Geometry::Mesh(_)) {
        let (lo, hi) = geometry.bounds();
        validate::inside_grid(&lo, &hi, i, &scene.config)
            .map_err(|(key, m)| scene.at_key(&key, format!("{shown}: {m}")))?;
    }
    Ok(geometry)
}

/// A terrain body: its surface raster (`file`) over its level `base` or its
/// bottom raster (`base_file`), each checked against the other.
fn terrain(scene: &Scene, i: usize, path: &Path, shown: &str) -> Result<Terrain, SceneError> {
    let b = &scene.config.bodies[i];
    let at_base_file = |m: String| scene.at_key(&format!("body.{i}.base_file"), m);
    let base_path = b.base_file.as_deref().map(|f| beside(&scene.file, f));
    let base_shown = base_path.as_ref().map(|p| p.display().to_string());
    let bottom = match (&base_path, &base_shown) {
        (Some(p), Some(s)) => Bottom::Surface(raster(p, s, None).map_err(at_base_file)?),
        _ => Bottom::Level(b.base.expect("validated")),
    };
    let surface = raster(path, shown, Some(&bottom))
        .map_err(|m| scene.at_key(&format!("body.{i}.file"), m))?;
    let t = Terrain { surface, bottom };
    if let Some((row, column, m)) = t.bottom_above_surface() {
        let m = format!(
            "{}: the elevation at row {} (from the north), column {} {m} (`file`, {shown})",
            base_shown.as_deref().expect("only a raster bottom"),
            row + 1,
            column + 1
        );
        return Err(at_base_file(m));
    }
    Ok(t)
}

/// A raster file: GeoTIFF for `.tif` or `.tiff`, else an ESRI ASCII grid;
/// every elevation over `bottom` if one is given.
fn raster(path: &Path, shown: &str, bottom: Option<&Bottom>) -> Result<Raster, String> {
    match has_extension(path, &["tif", "tiff"]) {
        true => geotiff::read(path, shown, bottom),
        false => esri_grid::read(path, shown, bottom),
    }
}

/// Does the path end in one of these extensions (in any case)?
fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    let e = path.extension().and_then(|e| e.to_str());
    e.is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// `file` relative to the folder of the scene file `scene` (as given, if
/// absolute).
pub fn beside(scene: &str, file: &str) -> PathBuf {
    let p = Path::new(file);
    match p.is_absolute() {
        true => p.to_path_buf(),
        false => Path::new(scene).parent().unwrap_or(Path::new("")).join(p),
    }
}

fn particles(
    scene: &Scene,
    i: usize,
    path: &Path,
    shown: &str,
) -> Result<crate::model::particle_set::ParticleSet, String> {
    let c = &scene.config;
    let material = |name: &str| material_zone(scene, name);
    let expect = particle_file::Expect {
        dim: c.dimension.spatial(),
        per_radian: c.dimension.is_axisymmetric(),
        grid: (&c.grid.min, &c.grid.max),
        body_id: c.bodies[i].body_id,
        material: &material,
    };
    particle_file::read(path, shown, &expect)
}

/// The table index of the material a particle file's row names: a table of
/// the scene that no rigid body takes (a rigid body's table gives only its
/// density, `SceneConfig::particle_materials`).
fn material_zone(scene: &Scene, name: &str) -> Result<u32, String> {
    let c = &scene.config;
    let k = (c.materials.iter().position(|m| m.name == name))
        .ok_or_else(|| format!("no [[material]] is named `{name}`"))?;
    let rigid_body = (0..c.bodies.len())
        .any(|j| c.bodies[j].material == name && c.body_kind(j) == BodyKindName::Rigid);
    if c.materials[k].model == Rigid::NAME || rigid_body {
        return Err(format!(
            "material `{name}` is a rigid body's (model = \"rigid\" or the material of a \
             rigid body): a particle of a continuum body needs a constitutive model"
        ));
    }
    Ok(k as u32)
}
