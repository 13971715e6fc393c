//! Displacement field against a reference run: the relative L2 error of the
//! particles' displacements u = x − X against a finer run's field u_ref,
//! e = √(Σ V0 |u − u_ref(X)|²) / √(Σ V0 |u_ref(X)|²), summed over the particles of
//! the run (V0 its reference volume). For problems without a closed form (a slope
//! under gravity), the reference is the same scene on a finer grid, its
//! `particles_final.csv` named by `[reference] file`.
//!
//! u_ref(X) is a weighted linear least-squares fit (moving least squares,
//! Lancaster & Salkauskas 1981) of the reference particles within a radius of two
//! reference spacings of X, weight (1 − r²/R²)²: exact for a linear field, second
//! order in the reference spacing otherwise, and it extrapolates across the last
//! half spacing at the body's surface. In a sharp corner (a slope's toe) where
//! the particles within that radius lie nearly on a line, the radius doubles, at
//! most twice. The fit is a (D + 1) × (D + 1) normal-equation
//! solve per particle; no crate does scattered-data interpolation on this small a
//! footing, so it is written here.

use super::measure::{ErrorMeasure, KeyError};
use crate::output::Table;
use crate::scene::SceneConfig;
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const REFERENCE: [&str; 3] = ["X0", "Y0", "Z0"];
const CURRENT: [&str; 3] = ["x", "y", "z"];

#[derive(Clone, Debug)]
pub struct DisplacementField {
    /// Spatial dimension of the positions compared.
    pub dim: usize,
    /// The reference run's `particles_final.csv`.
    pub file: PathBuf,
}

impl DisplacementField {
    /// From the scene: `[reference] file`, relative to the folder of the scene
    /// file `scene_file` (as given, if absolute). The file is read when the error
    /// is measured, so the reference run may come after the scene is written.
    pub fn from_scene(s: &SceneConfig, scene_file: &str) -> Result<DisplacementField, KeyError> {
        let file = s
            .reference
            .as_ref()
            .and_then(|r| r.file.as_deref())
            .ok_or((
                "reference.file".to_string(),
                "kind = \"displacement_field\" needs the reference run's particles_final.csv"
                    .to_string(),
            ))?;
        Ok(DisplacementField {
            dim: s.dimension.spatial(),
            file: crate::model::import::beside(scene_file, file),
        })
    }

    /// The relative L2 displacement error of `run` against `reference` (both
    /// particle tables with reference and current positions).
    pub fn error_of(&self, run: &Table, reference: &Table) -> Result<f64, String> {
        let field = Field::new(self.dim, reference)?;
        let (x0, x) = positions(self.dim, run)?;
        let v0 = run.column("volume0")?;
        let (mut diff, mut norm) = (0.0, 0.0);
        for p in 0..v0.len() {
            let at = &x0[p * self.dim..(p + 1) * self.dim];
            let u_ref = field.at(at)?;
            for d in 0..self.dim {
                let u = x[p * self.dim + d] - at[d];
                diff += v0[p] * (u - u_ref[d]).powi(2);
                norm += v0[p] * u_ref[d].powi(2);
            }
        }
        if norm == 0.0 {
            return Err("the reference field is zero: no relative error".into());
        }
        Ok((diff / norm).sqrt())
    }
}

/// Reference (X) and current (x) positions, D numbers per particle.
fn positions(dim: usize, t: &Table) -> Result<(Vec<f64>, Vec<f64>), String> {
    let cols = |names: &[&str]| -> Result<Vec<&[f64]>, String> {
        names[..dim].iter().map(|n| t.column(n)).collect()
    };
    let (big, small) = (cols(&REFERENCE)?, cols(&CURRENT)?);
    let interleave = |c: &[&[f64]]| {
        (0..t.len())
            .flat_map(|p| c.iter().map(move |c| c[p]))
            .collect()
    };
    Ok((interleave(&big), interleave(&small)))
}

/// The reference run's displacements, binned by reference position in cells of
/// the fit radius.
struct Field {
    dim: usize,
    radius: f64,
    x0: Vec<f64>,
    u: Vec<f64>,
    bins: HashMap<Vec<i64>, Vec<usize>>,
}

impl Field {
    fn new(dim: usize, t: &Table) -> Result<Field, String> {
        if t.is_empty() {
            return Err("the reference run has no particles".into());
        }
        let (x0, x) = positions(dim, t)?;
        let u = x.iter().zip(&x0).map(|(x, x0)| x - x0).collect();
        // Spacing from the median reference volume (V0 = h^D per particle).
        let mut v0 = t.column("volume0")?.to_vec();
        v0.sort_by(f64::total_cmp);
        let spacing = v0[v0.len() / 2].powf(1.0 / dim as f64);
        let radius = 2.0 * spacing;
        let mut bins: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
        for p in 0..t.len() {
            bins.entry(bin(&x0[p * dim..(p + 1) * dim], radius))
                .or_default()
                .push(p);
        }
        Ok(Field {
            dim,
            radius,
            x0,
            u,
            bins,
        })
    }

    /// u_ref at `at`: the weighted linear fit within the radius, or within two
    /// or four radii where the particles within one lie too close to a line
    /// (or plane) to fit a gradient to (in a sharp corner such as a slope's toe).
    fn at(&self, at: &[f64]) -> Result<Vec<f64>, String> {
        (0..3)
            .find_map(|k| self.fit(at, self.radius * f64::from(1 << k)))
            .ok_or_else(|| {
                format!(
                    "no reference particles around {at:?} to fit the displacement to (within {} of it)",
                    4.0 * self.radius
                )
            })
    }

    /// The weighted linear fit u(X) ≈ a + B (X − at) of the reference particles
    /// within `radius` of `at`, whose constant term a is the value; None when
    /// the normal equations are (nearly) singular.
    fn fit(&self, at: &[f64], radius: f64) -> Option<Vec<f64>> {
        let n = self.dim + 1;
        let (mut m, mut rhs) = (
            DMatrix::<f64>::zeros(n, n),
            DMatrix::<f64>::zeros(n, self.dim),
        );
        let reach = (radius / self.radius).round() as i64;
        let home = bin(at, self.radius);
        for offset in neighbour_offsets(self.dim, reach) {
            let key: Vec<i64> = home.iter().zip(&offset).map(|(h, o)| h + o).collect();
            for &q in self.bins.get(&key).into_iter().flatten() {
                let dx: Vec<f64> = (0..self.dim)
                    .map(|d| (self.x0[q * self.dim + d] - at[d]) / radius)
                    .collect();
                let r2 = dx.iter().map(|v| v * v).sum::<f64>();
                if r2 >= 1.0 {
                    continue;
                }
                let w = (1.0 - r2).powi(2);
                let basis = DVector::from_iterator(n, std::iter::once(1.0).chain(dx));
                m += w * &basis * basis.transpose();
                for d in 0..self.dim {
                    rhs.column_mut(d)
                        .axpy(w * self.u[q * self.dim + d], &basis, 1.0);
                }
            }
        }
        // Scaled offsets (|dx| < 1): a well-posed fit has every eigenvalue a
        // fair fraction of the weight sum m[0][0].
        if m[(0, 0)] == 0.0 || m.symmetric_eigenvalues().min() < 1e-6 * m[(0, 0)] {
            return None;
        }
        let s = m.cholesky()?.solve(&rhs);
        Some((0..self.dim).map(|d| s[(0, d)]).collect())
    }
}

fn bin(x: &[f64], size: f64) -> Vec<i64> {
    x.iter().map(|v| (v / size).floor() as i64).collect()
}

/// The (2 reach + 1)^D cell offsets around a cell (itself included).
fn neighbour_offsets(dim: usize, reach: i64) -> Vec<Vec<i64>> {
    let side = (2 * reach + 1) as usize;
    (0..side.pow(dim as u32))
        .map(|k| {
            (0..dim)
                .map(|d| (k / side.pow(d as u32) % side) as i64 - reach)
                .collect()
        })
        .collect()
}

impl ErrorMeasure for DisplacementField {
    fn description(&self) -> String {
        format!(
            "displacement field: relative L2 error of x − X against the reference run {}",
            self.file.display()
        )
    }

    fn error(&self, out: &Path) -> Result<f64, String> {
        let reference = Table::read(&self.file)
            .map_err(|e| format!("reference run {}: {e}", self.file.display()))?;
        self.error_of(&Table::read(&out.join("particles_final.csv"))?, &reference)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A particle table on a lattice of spacing h over [0, 1] × [0, 0.5], its
    /// points displaced by u(X).
    fn lattice(h: f64, shift: f64, u: impl Fn(f64, f64) -> [f64; 2]) -> Table {
        let mut text = String::from("X0,Y0,x,y,volume0\n");
        let (nx, ny) = ((1.0 / h).round() as usize, (0.5 / h).round() as usize);
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = ((i as f64 + shift) * h, (j as f64 + shift) * h);
                let d = u(x, y);
                text += &format!("{x},{y},{},{},{}\n", x + d[0], y + d[1], h * h);
            }
        }
        Table::parse(&text).unwrap()
    }

    fn measure() -> DisplacementField {
        DisplacementField {
            dim: 2,
            file: PathBuf::new(),
        }
    }

    #[test]
    fn a_linear_field_is_fitted_exactly_from_an_offset_lattice() {
        let u = |x: f64, y: f64| [1e-3 * (1.0 + 2.0 * x - y), 1e-3 * (0.5 * x + 3.0 * y)];
        let reference = lattice(1.0 / 40.0, 0.5, u);
        let run = lattice(1.0 / 12.0, 0.5, u);
        let e = measure().error_of(&run, &reference).unwrap();
        assert!(e < 1e-12, "error of an exact field {e}");
    }

    #[test]
    fn the_fit_of_a_smooth_field_converges_at_second_order_in_the_reference_spacing() {
        // The run is exact; the whole error is the reference's interpolation.
        let u = |x: f64, y: f64| [(3.0 * x).sin() * (2.0 * y).cos(), (x * y).exp() - 1.0];
        let run = lattice(1.0 / 10.0, 0.37, u);
        let errors: Vec<f64> = [20.0, 40.0, 80.0]
            .iter()
            .map(|n| measure().error_of(&run, &lattice(1.0 / n, 0.5, u)).unwrap())
            .collect();
        let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        assert!(errors[2] < 1e-3, "errors {errors:?}");
        assert!(
            rates.iter().all(|r| *r > 1.8),
            "errors {errors:?}, rates {rates:?}"
        );
    }

    #[test]
    fn a_uniform_error_of_ten_percent_reads_ten_percent() {
        let u = |x: f64, y: f64| [1e-3 * (1.0 + x - 2.0 * y), -2e-3 * (1.0 + y)];
        let reference = lattice(1.0 / 40.0, 0.5, u);
        let run = lattice(1.0 / 12.0, 0.5, |x, y| u(x, y).map(|v| 1.1 * v));
        let e = measure().error_of(&run, &reference).unwrap();
        assert!((e - 0.1).abs() < 1e-9, "error {e}");
    }

    #[test]
    fn a_point_far_from_the_reference_body_is_an_error_not_a_guess() {
        let reference = lattice(1.0 / 40.0, 0.5, |_, _| [1e-3, 0.0]);
        let far = Table::parse("X0,Y0,x,y,volume0\n5,5,5.001,5,0.01\n").unwrap();
        let e = measure().error_of(&far, &reference).unwrap_err();
        assert!(e.contains("no reference particles"), "{e}");
    }

    #[test]
    fn the_tip_of_a_sharp_wedge_is_fitted_with_a_wider_radius() {
        // The reference lattice cut to the wedge y ≤ (1 − x)/2 (a 2:1 slope's
        // toe, 26.6°): near the tip the particles within two spacings lie in a
        // row.
        let u = |x: f64, y: f64| [1e-3 * (2.0 + x - y), 1e-3 * (x + 4.0 * y)];
        let h = 1.0 / 80.0;
        let mut text = String::from("X0,Y0,x,y,volume0\n");
        for j in 0..40 {
            for i in 0..80 {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                if y <= 0.5 * (1.0 - x) {
                    let d = u(x, y);
                    text += &format!("{x},{y},{},{},{}\n", x + d[0], y + d[1], h * h);
                }
            }
        }
        let reference = Table::parse(&text).unwrap();
        let tip = (0.985, 0.004);
        let d = u(tip.0, tip.1);
        let run = Table::parse(&format!(
            "X0,Y0,x,y,volume0\n{},{},{},{},1e-4\n",
            tip.0,
            tip.1,
            tip.0 + d[0],
            tip.1 + d[1]
        ))
        .unwrap();
        let e = measure().error_of(&run, &reference).unwrap();
        assert!(e < 1e-10, "error {e}");
    }
}
