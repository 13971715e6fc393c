//! Matrix Market files (the NIST exchange format: `coordinate` for sparse
//! matrices, `array` for dense vectors), read by PETSc, SciPy, MATLAB, Julia and
//! SuiteSparse. The implicit solver writes its tangents and right-hand sides in
//! it (`[output] linear_systems`) for users who benchmark their own linear
//! solvers. Values are written in Rust's shortest round-trip form, so they read
//! back bit for bit.

use faer::sparse::SparseColMatRef;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `a` in coordinate format: `symmetric` when `a` holds the lower
/// triangle of a symmetric matrix (Matrix Market's convention), else `general`.
/// Any index type of faer's.
pub fn write_sparse<I: faer::Index>(
    path: &Path,
    a: SparseColMatRef<I, f64>,
    symmetric: bool,
) -> std::io::Result<()> {
    let mut f = BufWriter::new(File::create(path)?);
    let kind = if symmetric { "symmetric" } else { "general" };
    writeln!(f, "%%MatrixMarket matrix coordinate real {kind}")?;
    writeln!(f, "{} {} {}", a.nrows(), a.ncols(), a.compute_nnz())?;
    for c in 0..a.ncols() {
        for (&r, v) in a.row_idx_of_col_raw(c).iter().zip(a.val_of_col(c)) {
            writeln!(f, "{} {} {v:e}", r.zx() + 1, c + 1)?;
        }
    }
    f.flush()
}

/// Writes `v` as an n × 1 matrix in array format.
pub fn write_vector(path: &Path, v: &[f64]) -> std::io::Result<()> {
    let mut f = BufWriter::new(File::create(path)?);
    writeln!(f, "%%MatrixMarket matrix array real general")?;
    writeln!(f, "{} 1", v.len())?;
    for x in v {
        writeln!(f, "{x:e}")?;
    }
    f.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    #[test]
    fn files_carry_every_entry_one_based_and_round_trip() {
        let t = [
            Triplet::new(0, 0, 4.0),
            Triplet::new(2, 0, -1.0 / 3.0),
            Triplet::new(1, 1, 1e-300),
        ];
        let a = SparseColMat::<u32, f64>::try_new_from_triplets(3, 3, &t).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("k.mtx");
        write_sparse(&path, a.as_ref(), true).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "%%MatrixMarket matrix coordinate real symmetric");
        assert_eq!(lines[1], "3 3 3");
        let third: f64 = lines[3].split(' ').nth(2).unwrap().parse().unwrap();
        assert_eq!(lines[3].split(' ').take(2).collect::<Vec<_>>(), ["3", "1"]);
        assert_eq!(third, -1.0 / 3.0);
        let path = dir.path().join("b.mtx");
        write_vector(&path, &[1.5, -2.0]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "%%MatrixMarket matrix array real general\n2 1\n1.5e0\n-2e0\n"
        );
    }
}
