//! `particles_final.csv`: the particle state at the end of a run.
//!
//! The column names are a contract with users' post-processing scripts:
//! `id,body,X0,Y0[,Z0],x,y[,z],vx,vy[,vz],sxx,syy,szz,sxy[,syz,sxz],volume0,volume,mass`,
//! followed by extra columns only where the run has them (`eps_p`, the equivalent
//! plastic strain, when a material has one; `contact_fx,contact_fy[,contact_fz]`,
//! each particle's contact force, after an implicit stage with rigid contact;
//! `p_water`, the pore pressure, with `[water]`, when the stresses are the
//! effective ones).

use std::io;
use std::path::Path;

use super::csv_file::{CsvWriter, Field};
use super::text::AXES;
use crate::model::particles::Particles;

/// Stress components written for dimension `dim`, as (column name, row, column) of the
/// 3×3 Cauchy stress. Plane strain (2D) still carries σ_zz.
fn stress_columns(dim: usize) -> &'static [(&'static str, usize, usize)] {
    const ALL: [(&str, usize, usize); 6] = [
        ("sxx", 0, 0),
        ("syy", 1, 1),
        ("szz", 2, 2),
        ("sxy", 0, 1),
        ("syz", 1, 2),
        ("sxz", 0, 2),
    ];
    if dim == 3 {
        &ALL
    } else {
        &ALL[..4]
    }
}

/// The contract columns of `particles_final.csv` for dimension `dim`.
fn header(dim: usize) -> Vec<String> {
    let axes = &AXES[..dim];
    let mut cols: Vec<String> = vec!["id".into(), "body".into()];
    cols.extend(axes.iter().map(|a| format!("{}0", a.to_uppercase())));
    cols.extend(axes.iter().map(|a| a.to_string()));
    cols.extend(axes.iter().map(|a| format!("v{a}")));
    cols.extend(stress_columns(dim).iter().map(|c| c.0.to_string()));
    cols.extend(["volume0", "volume", "mass"].map(String::from));
    cols
}

/// Write every particle of `p` to `path` as CSV (columns in the module docs; `id` is the
/// particle index, floats with round-trip precision).
pub fn write_particles_csv<const D: usize>(path: &Path, p: &Particles<D>) -> io::Result<()> {
    write_particles_csv_with(path, p, &[])
}

/// As `write_particles_csv`, with extra named columns (one value per particle)
/// after the contract columns.
pub fn write_particles_csv_with<const D: usize>(
    path: &Path,
    p: &Particles<D>,
    extra: &[(&str, &[f64])],
) -> io::Result<()> {
    let mut head = header(D);
    for (name, values) in extra {
        assert_eq!(values.len(), p.len(), "extra column {name}");
        head.push(name.to_string());
    }
    // Replaced atomically: a run killed while writing leaves the old file whole.
    super::atomic::replace(path, |tmp| {
        let mut w = CsvWriter::create(tmp, &head)?;
        let stress = stress_columns(D);
        for i in 0..p.len() {
            let ids = [Field::from(i), Field::from(p.body[i])];
            let kinematics = p.x0[i].iter().chain(p.x[i].iter()).chain(p.v[i].iter());
            let s = p.stress.get(i);
            let sigma = stress.iter().map(|&(_, r, c)| s[(r, c)]);
            let sizes = [p.volume0[i], p.volume[i], p.mass[i]];
            let more = extra.iter().map(|(_, values)| values[i]);
            let numbers = kinematics.copied().chain(sigma).chain(sizes).chain(more);
            w.row(ids.into_iter().chain(numbers.map(Field::Number)))?;
        }
        w.flush()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{Mat3, Vector};
    use std::collections::HashMap;

    /// Parse a CSV file into its header and rows keyed by column name.
    fn read_csv(path: &Path) -> (Vec<String>, Vec<HashMap<String, f64>>) {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| {
                let vals: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
                assert_eq!(vals.len(), head.len(), "{l}");
                head.iter().cloned().zip(vals).collect()
            })
            .collect();
        (head, rows)
    }

    fn stressed() -> Mat3 {
        // Symmetric, every component distinct.
        Mat3::new(
            11.0, 12.5, 13.25, //
            12.5, 22.0, 23.125, //
            13.25, 23.125, -33.0,
        )
    }

    #[test]
    fn round_trip_2d() {
        let mut p = Particles::<2>::default();
        let h = Vector::<2>::repeat(0.25);
        p.push(
            Vector::<2>::new(0.0, 0.0),
            Vector::zeros(),
            1.0,
            0.5,
            h,
            0,
            0,
            0,
        );
        p.push(
            Vector::<2>::new(1.0, 2.0),
            Vector::<2>::new(0.1, -0.2),
            3.0,
            0.5,
            h,
            7,
            1,
            0,
        );
        p.x[1] = Vector::<2>::new(1.5, 2.0 / 3.0);
        p.stress.set(1, &stressed());
        p.volume[1] = 0.625;

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("particles_final.csv");
        write_particles_csv(&path, &p).unwrap();
        let (head, rows) = read_csv(&path);
        assert_eq!(
            head.join(","),
            "id,body,X0,Y0,x,y,vx,vy,sxx,syy,szz,sxy,volume0,volume,mass"
        );
        assert_eq!(rows.len(), 2);
        let r = &rows[1];
        let expect = [
            ("id", 1.0),
            ("body", 7.0),
            ("X0", 1.0),
            ("Y0", 2.0),
            ("x", 1.5),
            ("y", 2.0 / 3.0),
            ("vx", 0.1),
            ("vy", -0.2),
            ("sxx", 11.0),
            ("syy", 22.0),
            ("szz", -33.0),
            ("sxy", 12.5),
            ("volume0", 0.5),
            ("volume", 0.625),
            ("mass", 3.0),
        ];
        for (k, v) in expect {
            assert_eq!(r[k], v, "column {k}");
        }
        assert_eq!(rows[0]["id"], 0.0);
        assert_eq!(rows[0]["sxx"], 0.0);
    }

    #[test]
    fn round_trip_3d() {
        let mut p = Particles::<3>::default();
        let h = Vector::<3>::repeat(0.25);
        p.push(
            Vector::<3>::new(1.0, 2.0, 3.0),
            Vector::<3>::new(4.0, 5.0, 6.0),
            2.0,
            0.125,
            h,
            1,
            0,
            0,
        );
        p.x[0] = Vector::<3>::new(1.1, 2.2, 3.3);
        p.stress.set(0, &stressed());

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("particles_final.csv");
        write_particles_csv(&path, &p).unwrap();
        let (head, rows) = read_csv(&path);
        assert_eq!(
            head.join(","),
            "id,body,X0,Y0,Z0,x,y,z,vx,vy,vz,sxx,syy,szz,sxy,syz,sxz,volume0,volume,mass"
        );
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        let expect = [
            ("id", 0.0),
            ("body", 1.0),
            ("X0", 1.0),
            ("Y0", 2.0),
            ("Z0", 3.0),
            ("x", 1.1),
            ("y", 2.2),
            ("z", 3.3),
            ("vx", 4.0),
            ("vy", 5.0),
            ("vz", 6.0),
            ("sxx", 11.0),
            ("syy", 22.0),
            ("szz", -33.0),
            ("sxy", 12.5),
            ("syz", 23.125),
            ("sxz", 13.25),
            ("volume0", 0.125),
            ("volume", 0.125),
            ("mass", 2.0),
        ];
        for (k, v) in expect {
            assert_eq!(r[k], v, "column {k}");
        }
    }

    #[test]
    fn empty_particles_write_header_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        write_particles_csv(&path, &Particles::<2>::default()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().count(), 1);
    }
}
