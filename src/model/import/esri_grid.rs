//! A terrain raster in the ESRI ASCII grid format (`shape = "terrain"`): a
//! header of `key value` lines (`ncols`, `nrows`, `xllcorner` or
//! `xllcenter`, `yllcorner` or `yllcenter`, `cellsize`, optionally
//! `nodata_value`; keys in any case), then `nrows` rows of `ncols`
//! elevations, the northernmost row first, separated by any white space.
//! With `xllcorner` the values belong to the centres of the raster's cells,
//! half a cell in from the corner. Every error names the file and the line.

use crate::model::terrain::{Bottom, Raster};
use std::path::Path;

/// The header's values.
#[derive(Default)]
struct Header {
    columns: Option<usize>,
    rows: Option<usize>,
    /// The south-west corner or centre, and which.
    x: Option<(f64, bool)>,
    y: Option<(f64, bool)>,
    cell_size: Option<f64>,
    nodata: Option<f64>,
}

/// Read the raster of `path` (`shown` names it in messages): the surface of
/// a body over `bottom`, or a body's bottom surface (`None`).
pub fn read(path: &Path, shown: &str, bottom: Option<&Bottom>) -> Result<Raster, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the raster file {shown}: {e}"))?;
    let at = |line: usize, m: String| format!("{shown}:{line}: {m}");
    let mut header = Header::default();
    let mut values: Vec<(f64, usize)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(first) = words.first() else { continue };
        if values.is_empty() && first.starts_with(|c: char| c.is_ascii_alphabetic()) {
            header_line(&mut header, &words).map_err(|m| at(n + 1, m))?;
            continue;
        }
        for w in words {
            let v = w
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| at(n + 1, format!("`{w}` is not an elevation")))?;
            values.push((v, n + 1));
        }
    }
    raster(header, &values, bottom).map_err(|(line, m)| at(line, m))
}

/// One header line's key and value.
fn header_line(h: &mut Header, words: &[&str]) -> Result<(), String> {
    let key = words[0].to_ascii_lowercase();
    let [_, value] = words else {
        return Err(format!("`{}` needs one value", words[0]));
    };
    let number = || {
        value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{key}: `{value}` is not a number"))
    };
    let count = || {
        value
            .parse::<usize>()
            .ok()
            .filter(|&n| n >= 2)
            .ok_or_else(|| format!("{key}: `{value}` is not a count of at least 2"))
    };
    match key.as_str() {
        "ncols" => h.columns = Some(count()?),
        "nrows" => h.rows = Some(count()?),
        "xllcorner" | "xllcenter" => h.x = Some((number()?, key == "xllcenter")),
        "yllcorner" | "yllcenter" => h.y = Some((number()?, key == "yllcenter")),
        "cellsize" => {
            let c = number()?;
            if c <= 0.0 {
                return Err(format!("cellsize: {c} is not positive"));
            }
            h.cell_size = Some(c);
        }
        "nodata_value" => h.nodata = Some(number()?),
        _ => return Err(format!("unknown header key `{}`", words[0])),
    }
    Ok(())
}

/// The raster of a header and its values (each with its line), every
/// elevation over `bottom`; an error with the line it concerns.
fn raster(
    h: Header,
    values: &[(f64, usize)],
    bottom: Option<&Bottom>,
) -> Result<Raster, (usize, String)> {
    let missing = |k: &str| (1, format!("the header has no `{k}`"));
    let columns = h.columns.ok_or_else(|| missing("ncols"))?;
    let rows = h.rows.ok_or_else(|| missing("nrows"))?;
    let (x, x_centre) = h.x.ok_or_else(|| missing("xllcorner or xllcenter"))?;
    let (y, y_centre) = h.y.ok_or_else(|| missing("yllcorner or yllcenter"))?;
    let cell_size = h.cell_size.ok_or_else(|| missing("cellsize"))?;
    let last = values.last().map_or(1, |v| v.1);
    if values.len() != columns * rows {
        let m = format!(
            "the raster holds {} elevations, not ncols × nrows = {columns} × {rows}",
            values.len()
        );
        return Err((last, m));
    }
    let half = |centre: bool| if centre { 0.0 } else { 0.5 * cell_size };
    let mut elevation = vec![0.0; columns * rows];
    for (k, &(v, line)) in values.iter().enumerate() {
        let (row, column) = (k / columns, k % columns);
        if h.nodata == Some(v) {
            let m = format!(
                "no data at row {} (from the north), column {} (from 1): the body needs \
                 an elevation at every point",
                row + 1,
                column + 1
            );
            return Err((line, m));
        }
        // Stored from the south.
        elevation[(rows - 1 - row) * columns + column] = v;
    }
    let raster = Raster {
        origin: [x + half(x_centre), y + half(y_centre)],
        cell_size,
        columns,
        rows,
        elevation,
    };
    if let Some((row, column, m)) = bottom.and_then(|b| raster.first_below(b)) {
        return Err((values[row * columns + column].1, m));
    }
    Ok(raster)
}
