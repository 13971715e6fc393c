//! `history.csv`: energies and per-body centres of mass over time.

use std::io;
use std::path::Path;
use std::time::{Duration, Instant};

use super::csv_file::{CsvWriter, Field};
use super::text::AXES;
use crate::dim::Vector;
use crate::model::particles::Particles;

/// Rows are flushed to disk at least this often even if the caller never calls `flush`.
const AUTO_FLUSH: Duration = Duration::from_secs(1);

/// Writer of `history.csv`: one row per call of [`HistoryWriter::write_row`] with time,
/// energies and each body's centre of mass and its velocity.
///
/// Rows are buffered and reach the disk on [`HistoryWriter::flush`], at least once a
/// second during `write_row`, and on drop, so a run killed midway keeps (almost) all rows.
pub struct HistoryWriter {
    w: CsvWriter,
    dim: usize,
    n_bodies: usize,
    /// Columns after `external_work` that only some scenes have.
    extra: usize,
    last_flush: Instant,
}

impl HistoryWriter {
    /// Create (truncate) `path` and write the header
    /// `t,kinetic,strain,external_work[,extra…],body0_x,body0_y[,body0_z],body0_vx,body0_vy[,body0_vz],…`.
    pub fn create(path: &Path, dim: usize, n_bodies: usize, extra: &[&str]) -> io::Result<Self> {
        if !(2..=3).contains(&dim) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("history: dimension must be 2 or 3, got {dim}"),
            ));
        }
        let mut w = CsvWriter::create(path, &header(dim, n_bodies, extra))?;
        w.flush()?;
        Ok(Self {
            w,
            dim,
            n_bodies,
            extra: extra.len(),
            last_flush: Instant::now(),
        })
    }

    /// Write on after `text`, the file as an earlier run had written it (header
    /// and rows, from a checkpoint).
    pub fn resume(
        path: &Path,
        dim: usize,
        n_bodies: usize,
        extra: usize,
        text: &str,
    ) -> io::Result<Self> {
        let mut w = CsvWriter::resume(path, text)?;
        w.flush()?;
        Ok(Self {
            w,
            dim,
            n_bodies,
            extra,
            last_flush: Instant::now(),
        })
    }

    /// Append one row; `extra` holds the values of the extra columns, `com` and
    /// `com_velocity` one entry per body (see [`body_centres`]).
    #[allow(clippy::too_many_arguments)]
    pub fn write_row<const D: usize>(
        &mut self,
        t: f64,
        kinetic: f64,
        strain: f64,
        external_work: f64,
        extra: &[f64],
        com: &[Vector<D>],
        com_velocity: &[Vector<D>],
    ) -> io::Result<()> {
        if D != self.dim
            || com.len() != self.n_bodies
            || com_velocity.len() != self.n_bodies
            || extra.len() != self.extra
        {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "history: row for D = {D} with {} / {} bodies, header for D = {} with {} bodies",
                    com.len(),
                    com_velocity.len(),
                    self.dim,
                    self.n_bodies
                ),
            ));
        }
        let energies = [t, kinetic, strain, external_work];
        let centres = com
            .iter()
            .zip(com_velocity)
            .flat_map(|(c, v)| c.iter().chain(v.iter()).copied());
        self.w.row(
            energies
                .into_iter()
                .chain(extra.iter().copied())
                .chain(centres)
                .map(Field::Number),
        )?;
        if self.last_flush.elapsed() >= AUTO_FLUSH {
            self.flush()?;
        }
        Ok(())
    }

    /// Push buffered rows to the file.
    pub fn flush(&mut self) -> io::Result<()> {
        self.last_flush = Instant::now();
        self.w.flush()
    }
}

impl Drop for HistoryWriter {
    /// Flush remaining rows (errors cannot be reported here; call `flush` to see them).
    fn drop(&mut self) {
        let _ = self.w.flush();
    }
}

/// The columns of `history.csv`.
fn header(dim: usize, n_bodies: usize, extra: &[&str]) -> Vec<String> {
    let mut h: Vec<String> = ["t", "kinetic", "strain", "external_work"]
        .map(String::from)
        .into();
    h.extend(extra.iter().map(|c| c.to_string()));
    for i in 0..n_bodies {
        for prefix in ["", "v"] {
            for a in &AXES[..dim] {
                h.push(format!("body{i}_{prefix}{a}"));
            }
        }
    }
    h
}

/// Mass-weighted centre of position and of velocity of each body `0..n_bodies`, summed
/// in particle order (deterministic). A body without mass gets NaN components. Particles
/// with `body >= n_bodies` are a caller bug: debug builds panic, release builds skip them.
pub fn body_centres<const D: usize>(
    p: &Particles<D>,
    n_bodies: usize,
) -> (Vec<Vector<D>>, Vec<Vector<D>>) {
    let mut mass = vec![0.0; n_bodies];
    let mut mx = vec![Vector::<D>::zeros(); n_bodies];
    let mut mv = vec![Vector::<D>::zeros(); n_bodies];
    for i in 0..p.len() {
        let b = p.body[i] as usize;
        debug_assert!(b < n_bodies, "particle {i} has body {b} >= {n_bodies}");
        if b >= n_bodies {
            continue;
        }
        let m = p.mass[i];
        mass[b] += m;
        mx[b] += p.x[i] * m;
        mv[b] += p.v[i] * m;
    }
    for b in 0..n_bodies {
        // 0/0 = NaN for a body without mass, as documented.
        mx[b] /= mass[b];
        mv[b] /= mass[b];
    }
    (mx, mv)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_rows(text: &str) -> Vec<Vec<f64>> {
        text.lines()
            .skip(1)
            .map(|l| l.split(',').map(|s| s.parse().unwrap()).collect())
            .collect()
    }

    #[test]
    fn header_2d() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        drop(HistoryWriter::create(&path, 2, 2, &[]).unwrap());
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "t,kinetic,strain,external_work,\
             body0_x,body0_y,body0_vx,body0_vy,\
             body1_x,body1_y,body1_vx,body1_vy\n"
        );
    }

    #[test]
    fn header_3d() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        drop(HistoryWriter::create(&path, 3, 1, &[]).unwrap());
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "t,kinetic,strain,external_work,body0_x,body0_y,body0_z,body0_vx,body0_vy,body0_vz\n"
        );
    }

    #[test]
    fn header_without_bodies() {
        assert_eq!(
            header(3, 0, &[]).join(","),
            "t,kinetic,strain,external_work"
        );
        assert_eq!(
            header(2, 0, &["eroded_mass"]).join(","),
            "t,kinetic,strain,external_work,eroded_mass"
        );
    }

    #[test]
    fn rows_count_and_values() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        let mut h = HistoryWriter::create(&path, 2, 2, &[]).unwrap();
        let com = [Vector::<2>::new(0.1, 0.2), Vector::<2>::new(-3.0, 1e-9)];
        let vel = [
            Vector::<2>::new(1.0 / 3.0, 0.0),
            Vector::<2>::new(2.0, -4.5),
        ];
        for k in 0..5 {
            let t = k as f64 * 0.1;
            h.write_row(t, 0.5 * t, 1e-12 * t, -t, &[], &com, &vel)
                .unwrap();
        }
        h.flush().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let rows = parse_rows(&text);
        assert_eq!(rows.len(), 5);
        for (k, r) in rows.iter().enumerate() {
            let t = k as f64 * 0.1;
            assert_eq!(r.len(), 4 + 2 * 4);
            // Exact: numbers are written with round-trip precision.
            assert_eq!(
                r,
                &[
                    t,
                    0.5 * t,
                    1e-12 * t,
                    -t,
                    0.1,
                    0.2,
                    1.0 / 3.0,
                    0.0,
                    -3.0,
                    1e-9,
                    2.0,
                    -4.5
                ]
            );
        }
        // Rows written after the explicit flush reach the file on drop.
        h.write_row(9.0, 0.0, 0.0, 0.0, &[], &com, &vel).unwrap();
        drop(h);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(parse_rows(&text).len(), 6);
    }

    #[test]
    fn row_with_wrong_shape_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        let mut h = HistoryWriter::create(&path, 3, 2, &[]).unwrap();
        let one = [Vector::<3>::zeros()];
        assert!(h.write_row(0.0, 0.0, 0.0, 0.0, &[], &one, &one).is_err());
        let two2 = [Vector::<2>::zeros(); 2];
        assert!(h.write_row(0.0, 0.0, 0.0, 0.0, &[], &two2, &two2).is_err());
        assert!(HistoryWriter::create(&path, 1, 1, &[]).is_err());
    }

    #[test]
    fn centres_of_two_bodies() {
        let mut p = Particles::<2>::default();
        let h = Vector::<2>::new(0.5, 0.5);
        // Body 0: masses 1 and 3 at x = 0 and x = 4 -> centre x = 3.
        p.push(
            Vector::<2>::new(0.0, 0.0),
            Vector::<2>::new(1.0, 0.0),
            1.0,
            1.0,
            h,
            0,
            0,
            0,
        );
        p.push(
            Vector::<2>::new(4.0, 2.0),
            Vector::<2>::new(-1.0, 2.0),
            3.0,
            1.0,
            h,
            0,
            0,
            0,
        );
        // Body 1: a single particle of mass 2, interleaved.
        p.push(
            Vector::<2>::new(10.0, -1.0),
            Vector::<2>::new(0.0, 5.0),
            2.0,
            1.0,
            h,
            1,
            0,
            0,
        );
        let (c, v) = body_centres(&p, 2);
        assert_eq!(c.len(), 2);
        assert!((c[0] - Vector::<2>::new(3.0, 1.5)).norm() < 1e-15);
        assert!((v[0] - Vector::<2>::new(-0.5, 1.5)).norm() < 1e-15);
        assert_eq!(c[1], Vector::<2>::new(10.0, -1.0));
        assert_eq!(v[1], Vector::<2>::new(0.0, 5.0));
    }

    #[test]
    fn centres_in_3d_and_empty_body() {
        let mut p = Particles::<3>::default();
        let h = Vector::<3>::repeat(0.5);
        p.push(
            Vector::<3>::new(1.0, 2.0, 3.0),
            Vector::<3>::new(0.0, 0.0, -1.0),
            2.0,
            1.0,
            h,
            0,
            0,
            0,
        );
        p.push(
            Vector::<3>::new(3.0, 2.0, 1.0),
            Vector::<3>::new(0.0, 0.0, 1.0),
            2.0,
            1.0,
            h,
            0,
            0,
            0,
        );
        let (c, v) = body_centres(&p, 2);
        assert_eq!(c[0], Vector::<3>::new(2.0, 2.0, 2.0));
        assert_eq!(v[0], Vector::<3>::zeros());
        assert!(c[1].iter().all(|x| x.is_nan()));
        assert!(v[1].iter().all(|x| x.is_nan()));
    }
}
