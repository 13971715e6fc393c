//! A closed surface from an STL file (`shape = "surface"`), binary or ASCII,
//! read by the `stl_io` crate (both forms, no dependencies of its own). Vertices that are the same single-precision
//! numbers are one vertex (−0 and +0 alike); a triangle with two equal corners (a collapsed
//! facet, some exporters write them) is left out; then the surface must be
//! closed and consistently oriented (`TriangleSurface::check_closed`), else
//! the error names the first open edge by its two corners.

use crate::model::triangles::TriangleSurface;
use std::io::Cursor;
use std::path::Path;

/// Read and check the surface of `path` (`shown` names it in messages).
pub fn read(path: &Path, shown: &str) -> Result<TriangleSurface, String> {
    let bytes =
        std::fs::read(path).map_err(|e| format!("cannot read the STL file {shown}: {e}"))?;
    let facets = facets(&bytes).map_err(|e| format!("{shown}: {e}"))?;
    let corners: Vec<[[f64; 3]; 3]> = (facets.iter())
        .map(|f| f.map(|c| c.map(f64::from)))
        .collect();
    TriangleSurface::closed_from_facets(&corners, shown, "STL")
}

/// The facets (three corners each) of an STL file's bytes. A binary file
/// whose 80-byte header starts with "solid " (some exporters write one) fails
/// as ASCII; where its length is that of a binary file, it is read as binary.
fn facets(bytes: &[u8]) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let first = read_facets(bytes);
    if first.is_err() && binary_length(bytes) {
        let mut copy = bytes.to_vec();
        copy[..5].copy_from_slice(b"SOLID");
        return read_facets(&copy);
    }
    first
}

fn read_facets(bytes: &[u8]) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for (n, t) in reader.enumerate() {
        let t = t.map_err(|e| format!("facet {}: {e}", n + 1))?;
        if let Some(bad) = t
            .vertices
            .iter()
            .find(|v| v.0.iter().any(|x| !x.is_finite()))
        {
            return Err(format!(
                "facet {}: the corner {:?} is not finite",
                n + 1,
                bad.0
            ));
        }
        out.push(t.vertices.map(|v| v.0));
    }
    Ok(out)
}

/// Whether the length is a binary STL's: 84 bytes and 50 per triangle.
fn binary_length(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        bytes.len() as u64 == 84 + 50 * u64::from(n)
    }
}
