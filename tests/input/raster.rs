//! Terrain rasters beyond the ESRI grid (issue 55, item 1; docs/geometry.md):
//! a GeoTIFF of the plane slope gives the ESRI raster's particles to the bit
//! (pixel-is-area and pixel-is-point, integer and floating samples), layers
//! between two rasters (`base_file`) hold every particle of the whole ground
//! once, and every bad file names the file, the key and the pixel.

use crate::geometry::{slope, slope_raster, TERRAIN};
use mpm::model::Model;
use std::path::Path;
use tiff::encoder::{colortype, TiffEncoder};
use tiff::tags::Tag;

/// GeoKeys: a projected model (1024 = 1) and the raster type (1025).
fn keys(model_type: u16, raster_type: u16) -> Vec<u16> {
    vec![1, 1, 0, 2, 1024, 0, 1, model_type, 1025, 0, 1, raster_type]
}

/// A single-band f32 GeoTIFF of `columns` values a row, the northern row
/// first, placed by a tie point and a pixel scale.
fn write_geotiff(path: &Path, columns: u32, values: &[f32], tie: [f64; 6], geo: &[u16]) {
    let rows = values.len() as u32 / columns;
    let mut file = std::fs::File::create(path).unwrap();
    let mut e = TiffEncoder::new(&mut file).unwrap();
    let mut image = e
        .new_image::<colortype::Gray32Float>(columns, rows)
        .unwrap();
    let d = image.encoder();
    d.write_tag(Tag::ModelPixelScaleTag, &[1.0f64, 1.0, 0.0][..])
        .unwrap();
    d.write_tag(Tag::ModelTiepointTag, &tie[..]).unwrap();
    d.write_tag(Tag::GeoKeyDirectoryTag, geo).unwrap();
    d.write_tag(Tag::GdalNodata, "-9999").unwrap();
    image.write_data(values).unwrap();
}

/// The slope z = 5 − x/2 on 9 × 3 pixels centred 1 m apart from (0, 0).
fn slope_values() -> Vec<f32> {
    (0..3)
        .flat_map(|_| (0..9).map(|j| 5.0 - 0.5 * j as f32))
        .collect()
}

/// Pixel-is-area: the tie point is the north-west corner of the first pixel.
const AREA_TIE: [f64; 6] = [0.0, 0.0, 0.0, -0.5, 2.5, 0.0];
/// Pixel-is-point: the tie point is the first pixel's centre.
const POINT_TIE: [f64; 6] = [0.0, 0.0, 0.0, 0.0, 2.0, 0.0];

fn geotiff_slope(dir: &Path, name: &str) -> Result<Model<3>, mpm::scene::SceneError> {
    slope(dir, &TERRAIN.replace("ground.asc", name))
}

#[test]
fn a_geotiff_of_the_plane_slope_is_the_esri_raster() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ground.asc"), slope_raster()).unwrap();
    let esri = slope(dir.path(), TERRAIN).unwrap();
    write_geotiff(
        &dir.path().join("area.tif"),
        9,
        &slope_values(),
        AREA_TIE,
        &keys(1, 1),
    );
    write_geotiff(
        &dir.path().join("point.TIFF"),
        9,
        &slope_values(),
        POINT_TIE,
        &keys(1, 2),
    );
    for name in ["area.tif", "point.TIFF"] {
        let g = geotiff_slope(dir.path(), name).unwrap();
        assert!(
            g.particles.x == esri.particles.x,
            "{name}: particles differ"
        );
        assert!(g.particles.volume == esri.particles.volume, "{name}");
    }
    println!("{} particles", esri.particles.len());
    // 16-bit integer samples: a stepped surface z = 5 − ⌊j/2⌋ against its
    // ESRI twin (corner-referenced, as pixel-is-area is).
    let steps: Vec<u16> = (0..3).flat_map(|_| (0..9).map(|j| 5 - j / 2)).collect();
    let mut file = std::fs::File::create(dir.path().join("steps.tif")).unwrap();
    let mut e = TiffEncoder::new(&mut file).unwrap();
    let mut image = e.new_image::<colortype::Gray16>(9, 3).unwrap();
    image
        .encoder()
        .write_tag(Tag::ModelPixelScaleTag, &[1.0f64, 1.0, 0.0][..])
        .unwrap();
    image
        .encoder()
        .write_tag(Tag::ModelTiepointTag, &AREA_TIE[..])
        .unwrap();
    image.write_data(&steps).unwrap();
    let mut asc = "ncols 9\nnrows 3\nxllcorner -0.5\nyllcorner -0.5\ncellsize 1\n".to_string();
    for _ in 0..3 {
        let row: Vec<String> = (0..9).map(|j| (5 - j / 2).to_string()).collect();
        asc += &(row.join(" ") + "\n");
    }
    std::fs::write(dir.path().join("steps.asc"), asc).unwrap();
    let (a, b) = (
        geotiff_slope(dir.path(), "steps.tif").unwrap(),
        geotiff_slope(dir.path(), "steps.asc").unwrap(),
    );
    assert!(a.particles.x == b.particles.x && !a.particles.is_empty());
}

#[test]
fn every_geotiff_error_names_the_file_and_the_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |name: &str, key: &str, part: &str| {
        let Err(e) = geotiff_slope(dir.path(), name) else {
            panic!("must be refused: {part}")
        };
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
        assert!(e.to_string().contains(part), "`{part}` not in: {e}");
    };
    let p = |n: &str| dir.path().join(n);
    // A bad pixel (row 2, column 2): no data by GDAL's value or NaN, below base.
    for (name, value, part) in [
        (
            "nodata.tif",
            -9999.0,
            "no data at row 2 (from the north), column 2",
        ),
        (
            "nan.tif",
            f32::NAN,
            "no data at row 2 (from the north), column 2",
        ),
        (
            "low.tif",
            -1.0,
            "the elevation -1 at row 2, column 2 is not above the body's base 0",
        ),
    ] {
        let mut values = slope_values();
        values[10] = value;
        write_geotiff(&p(name), 9, &values, AREA_TIE, &keys(1, 1));
        refused(name, "body.0.file", &format!("{name}: {part}"));
    }
    write_geotiff(&p("degrees.tif"), 9, &slope_values(), AREA_TIE, &keys(2, 1));
    refused(
        "degrees.tif",
        "body.0.file",
        "degrees.tif: the raster is in geographic coordinates",
    );
    // No georeference at all.
    let mut file = std::fs::File::create(p("plain.tif")).unwrap();
    let mut e = TiffEncoder::new(&mut file).unwrap();
    e.write_image::<colortype::Gray32Float>(9, 3, &slope_values())
        .unwrap();
    refused(
        "plain.tif",
        "body.0.file",
        "plain.tif: the file has no ModelPixelScale tag",
    );
    std::fs::write(p("text.tif"), "not a tiff").unwrap();
    refused(
        "text.tif",
        "body.0.file",
        "text.tif: not a readable TIFF file",
    );
    refused(
        "missing.tif",
        "body.0.file",
        "missing.tif: cannot read the file",
    );
}

/// An ESRI grid of z = f(x, y) on `columns` × `rows` points `h` apart from
/// `origin`, the northern row first.
fn esri(
    f: impl Fn(f64, f64) -> f64,
    origin: [f64; 2],
    h: f64,
    (columns, rows): (usize, usize),
) -> String {
    let mut text = format!(
        "ncols {columns}\nnrows {rows}\nxllcenter {}\nyllcenter {}\ncellsize {h}\n",
        origin[0], origin[1]
    );
    for i in (0..rows).rev() {
        let row: Vec<String> = (0..columns)
            .map(|j| f(origin[0] + h * j as f64, origin[1] + h * i as f64).to_string())
            .collect();
        text += &(row.join(" ") + "\n");
    }
    text
}

/// The interface of two layers of the slope's ground: z = 0.375 + (x + y)/16
/// (exact in binary), on a coarser raster reaching beyond the plan, meeting
/// the ground at its corner x = 8, y = 2.
fn interface(x: f64, y: f64) -> f64 {
    0.375 + (x + y) / 16.0
}

fn interface_raster(lift: f64) -> String {
    esri(|x, y| interface(x, y) + lift, [-2.0, -2.0], 2.0, (7, 4))
}

const LAYERS: &str =
    "shape = \"terrain\"\nfile = \"ground.asc\"\nbase_file = \"interface.asc\"\n\n\
                      [[body]]\nmaterial = \"soil\"\nshape = \"terrain\"\n\
                      file = \"interface.asc\"\nbase = 0.0";

#[test]
fn layers_between_rasters_hold_every_particle_of_the_ground_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ground.asc"), slope_raster()).unwrap();
    std::fs::write(dir.path().join("interface.asc"), interface_raster(0.0)).unwrap();
    let whole = slope(dir.path(), TERRAIN).unwrap();
    let layered = slope(dir.path(), LAYERS).unwrap();
    let key = |m: &Model<3>, q: usize| -> [u64; 3] {
        std::array::from_fn(|d| m.particles.x[q][d].to_bits())
    };
    let mut a: Vec<_> = (0..whole.particles.len()).map(|q| key(&whole, q)).collect();
    let mut b: Vec<_> = (0..layered.particles.len())
        .map(|q| key(&layered, q))
        .collect();
    a.sort();
    b.sort();
    assert!(a == b, "the layers' particles are not the ground's");
    let volume = |m: &Model<3>| m.particles.volume.iter().sum::<f64>();
    assert_eq!(volume(&whole), volume(&layered));
    // Each in its layer; those exactly on the interface in the upper one.
    let p = &layered.particles;
    let (mut upper, mut on) = (0, 0);
    for q in 0..p.len() {
        let (x, z) = (p.x[q], p.x[q][2]);
        let zi = interface(x[0], x[1]);
        match p.body[q] {
            0 => assert!(z >= zi, "upper particle {q} at {x:?} under the interface"),
            _ => assert!(z < zi, "lower particle {q} at {x:?} over the interface"),
        }
        upper += usize::from(p.body[q] == 0);
        on += usize::from(z == zi);
    }
    println!(
        "{} particles: {upper} upper, {on} on the interface",
        p.len()
    );
    assert!(on > 0 && upper > 0 && upper < p.len());
}

#[test]
fn a_base_raster_is_checked_against_the_surface() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ground.asc"), slope_raster()).unwrap();
    let body = "shape = \"terrain\"\nfile = \"ground.asc\"\nbase_file = \"interface.asc\"";
    let refused = |interface: &str, key: &str, part: &str| {
        std::fs::write(dir.path().join("interface.asc"), interface).unwrap();
        let Err(e) = slope(dir.path(), body) else {
            panic!("must be refused: {part}")
        };
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
        assert!(e.to_string().contains(part), "`{part}` not in: {e}");
    };
    // Raised by 0.25 m: above the ground at the corner (8, 2), a point of
    // both rasters; the ground's point is named first.
    refused(
        &interface_raster(0.25),
        "body.0.file",
        "ground.asc:7: the elevation 1 at row 1, column 9 is below the body's base surface \
         (`base_file`), 1.25 there",
    );
    // A bottom raster point inside the plan above the surface where the
    // ground's points do not see it: a spike at (4.25, 0.25) on a raster of
    // points between the ground's.
    let spike = |x: f64, y: f64| match (x, y) == (4.25, 0.25) {
        true => 9.0,
        false => interface(x, y),
    };
    refused(
        &esri(spike, [-0.25, -0.25], 0.5, (18, 6)),
        "body.0.base_file",
        "interface.asc: the elevation at row 5 (from the north), column 10 is above the \
         body's surface, 2.875 there (`file`,",
    );
    refused(
        "ncols 2\n",
        "body.0.base_file",
        "interface.asc:1: the header has no `nrows`",
    );
    crate::common::rejected_at(
        &crate::geometry::SLOPE.replace("BODY", &format!("{body}\nbase = 0.0")),
        "body.0.base",
        &["does not apply to a body with `base_file`"],
    );
    crate::common::rejected_at(
        &crate::geometry::SLOPE.replace(
            "BODY",
            "shape = \"box\"\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\nbase_file = \"a.asc\"",
        ),
        "body.0.base_file",
        &["does not apply to shape `box`"],
    );
}
