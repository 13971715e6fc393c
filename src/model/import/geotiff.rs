//! A terrain raster in GeoTIFF (`shape = "terrain"`, a file ending in `.tif`
//! or `.tiff`), decoded by the `tiff` crate: the first image, one band of
//! any integer or floating-point sample type, placed in the plan by the
//! GeoTIFF tags ModelPixelScale (33550) and ModelTiepoint (33922), square
//! pixels, no rotation (a ModelTransformation tag is refused). The
//! elevations belong to the pixels' centres (GTRasterTypeGeoKey
//! PixelIsArea, the default) or to the tie point's lattice (PixelIsPoint);
//! the plan is in the model space's units, so a geographic (degrees) raster
//! is refused. Pixels equal to GDAL's no-data value (tag 42113) or NaN are no
//! data, which the body does not take. Every error names the file and, for a
//! pixel, its row (from the north) and column.

use crate::model::terrain::{Bottom, Raster};
use std::path::Path;
use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::Tag;

/// GeoKeys (GeoTIFF 1.1, 7.1): the model type and the raster type.
const MODEL_TYPE_KEY: u16 = 1024;
const RASTER_TYPE_KEY: u16 = 1025;
const MODEL_TYPE_GEOGRAPHIC: u16 = 2;
const RASTER_PIXEL_IS_POINT: u16 = 2;

/// Read the raster of `path` (`shown` names it in messages): the surface of
/// a body over `bottom`, or a body's bottom surface (`None`).
pub fn read(path: &Path, shown: &str, bottom: Option<&Bottom>) -> Result<Raster, String> {
    let raster = decode(path).map_err(|m| format!("{shown}: {m}"))?;
    if let Some((_, _, m)) = bottom.and_then(|b| raster.first_below(b)) {
        return Err(format!("{shown}: {m}"));
    }
    Ok(raster)
}

/// The raster of a GeoTIFF file.
fn decode(path: &Path) -> Result<Raster, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read the file: {e}"))?;
    let bad = |e: tiff::TiffError| format!("not a readable TIFF file: {e}");
    let mut d = Decoder::new(std::io::BufReader::new(file)).map_err(bad)?;
    let (columns, rows) = d.dimensions().map_err(bad)?;
    let (columns, rows) = (columns as usize, rows as usize);
    if columns < 2 || rows < 2 {
        return Err(format!(
            "the raster has {columns} × {rows} pixels: the body needs at least 2 × 2"
        ));
    }
    match d.colortype().map_err(bad)? {
        tiff::ColorType::Gray(_) => {}
        other => {
            return Err(format!(
                "the raster is {other:?}: an elevation needs one band"
            ))
        }
    }
    let f64_tag = |d: &mut Decoder<_>, tag: Tag| -> Result<Option<Vec<f64>>, String> {
        (d.find_tag(tag).map_err(bad)?)
            .map(|v| v.into_f64_vec().map_err(bad))
            .transpose()
    };
    if f64_tag(&mut d, Tag::ModelTransformationTag)?.is_some() {
        return Err(
            "the raster is placed by a ModelTransformation tag (rotated or sheared): \
             only ModelPixelScale with ModelTiepoint is read; resample it to a north-up grid"
                .into(),
        );
    }
    let scale = f64_tag(&mut d, Tag::ModelPixelScaleTag)?
        .ok_or("the file has no ModelPixelScale tag (33550): it is not georeferenced")?;
    let tie = f64_tag(&mut d, Tag::ModelTiepointTag)?
        .ok_or("the file has no ModelTiepoint tag (33922): it is not georeferenced")?;
    if scale.len() < 2 || tie.len() < 6 {
        return Err("ModelPixelScale needs 3 values and ModelTiepoint 6".into());
    }
    let (sx, sy) = (scale[0], scale[1]);
    if !(sx > 0.0 && sx.is_finite()) || (sx - sy).abs() > 1e-9 * sx {
        return Err(format!(
            "the pixels are {sx} × {sy}: the body needs square pixels (resample the raster)"
        ));
    }
    let keys = geo_keys(&mut d)?;
    if keys(MODEL_TYPE_KEY) == Some(MODEL_TYPE_GEOGRAPHIC) {
        return Err(
            "the raster is in geographic coordinates (degrees): the plan needs \
                    lengths; reproject it (e.g. gdalwarp -t_srs EPSG:…) to a projected system"
                .into(),
        );
    }
    let nodata = (d.find_tag(Tag::GdalNodata).map_err(bad)?)
        .map(|v| v.into_string().map_err(bad))
        .transpose()?
        .and_then(|s| s.trim().trim_end_matches('\0').parse::<f64>().ok());
    let values = samples(d.read_image().map_err(bad)?);
    // Raster coordinates of pixel (c, r)'s value: its centre, or its corner.
    let o = match keys(RASTER_TYPE_KEY) == Some(RASTER_PIXEL_IS_POINT) {
        true => 0.0,
        false => 0.5,
    };
    let x = |c: f64| tie[3] + (c + o - tie[0]) * sx;
    let y = |r: f64| tie[4] - (r + o - tie[1]) * sx;
    if values.len() < columns * rows {
        return Err(format!(
            "the image holds {} samples, not {columns} × {rows}",
            values.len()
        ));
    }
    let mut elevation = vec![0.0; columns * rows];
    for (k, &v) in values.iter().enumerate().take(columns * rows) {
        let (row, column) = (k / columns, k % columns);
        if !v.is_finite() || nodata == Some(v) {
            return Err(format!(
                "no data at row {} (from the north), column {} (from 1): the body needs an \
                 elevation at every point",
                row + 1,
                column + 1
            ));
        }
        // Stored from the south.
        elevation[(rows - 1 - row) * columns + column] = v;
    }
    Ok(Raster {
        origin: [x(0.0), y((rows - 1) as f64)],
        cell_size: sx,
        columns,
        rows,
        elevation,
    })
}

/// The GeoKey directory's short values by key (GeoTIFF 1.1, 7.1: a header of
/// four shorts, then key, location, count, value; location 0 is a value in
/// place).
fn geo_keys<R: std::io::Read + std::io::Seek>(
    d: &mut Decoder<R>,
) -> Result<impl Fn(u16) -> Option<u16>, String> {
    let bad = |e: tiff::TiffError| format!("the GeoKey directory: {e}");
    let dir = (d.find_tag(Tag::GeoKeyDirectoryTag).map_err(bad)?)
        .map(|v| v.into_u16_vec().map_err(bad))
        .transpose()?
        .unwrap_or_default();
    let entries: Vec<[u16; 4]> = (dir.get(4..).unwrap_or(&[]).chunks_exact(4))
        .map(|e| [e[0], e[1], e[2], e[3]])
        .collect();
    Ok(move |key: u16| {
        (entries.iter())
            .find(|e| e[0] == key && e[1] == 0)
            .map(|e| e[3])
    })
}

/// The samples as elevations, in the file's order (rows from the north).
fn samples(image: DecodingResult) -> Vec<f64> {
    fn all<T: Copy + Into<f64>>(v: Vec<T>) -> Vec<f64> {
        v.into_iter().map(Into::into).collect()
    }
    match image {
        DecodingResult::U8(v) => all(v),
        DecodingResult::U16(v) => all(v),
        DecodingResult::U32(v) => all(v),
        DecodingResult::U64(v) => v.into_iter().map(|s| s as f64).collect(),
        DecodingResult::I8(v) => all(v),
        DecodingResult::I16(v) => all(v),
        DecodingResult::I32(v) => all(v),
        DecodingResult::I64(v) => v.into_iter().map(|s| s as f64).collect(),
        DecodingResult::F16(v) => all(v),
        DecodingResult::F32(v) => all(v),
        DecodingResult::F64(v) => v,
    }
}
