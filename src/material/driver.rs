//! Single-material-point driver.
//!
//! Drives one material point along a prescribed path of deformation gradients
//! F_0, F_1, …, F_n by feeding the increments ΔF_k = F_k F_{k−1}⁻¹ through
//! [`Material::update`], carrying stress and history from one increment to the next,
//! exactly as the MPM solvers do per particle. Used for verification against closed
//! forms and for inspecting a model's response. Also provides a finite-difference
//! tangent for checking [`Material::stress_derivative`].

use super::{Increment, Material, StressDerivative};
use crate::dim::Mat3;

/// States of a material point along a path (entry k belongs to F_k).
#[derive(Clone, Debug)]
pub struct Response {
    /// The deformation gradients F_0 … F_n that were applied.
    pub f: Vec<Mat3>,
    /// Cauchy stress after each F_k (entry 0 is the initial stress).
    pub stress: Vec<Mat3>,
    /// History variables after each F_k (entry 0 is the initial history).
    pub history: Vec<Vec<f64>>,
}

/// Drive `material` along `path` from zero stress and zero history.
pub fn run<M: Material + ?Sized>(material: &M, path: &[Mat3], dt: f64) -> Response {
    let history0 = vec![0.0; material.n_history()];
    run_from(material, path, dt, Mat3::zeros(), history0)
}

/// Drive `material` along `path` starting from the given stress and history at
/// `path[0]`. Panics if some F_{k−1} is singular.
pub fn run_from<M: Material + ?Sized>(
    material: &M,
    path: &[Mat3],
    dt: f64,
    stress0: Mat3,
    history0: Vec<f64>,
) -> Response {
    assert!(!path.is_empty(), "empty deformation path");
    assert_eq!(history0.len(), material.n_history(), "history length");
    let mut stress = vec![stress0];
    let mut history = vec![history0];
    for k in 1..path.len() {
        let f_inv = path[k - 1].try_inverse().expect("singular F in path");
        let mut h_new = vec![0.0; material.n_history()];
        let inc = Increment::new(
            path[k - 1],
            path[k] * f_inv,
            dt,
            stress[k - 1],
            &history[k - 1],
        );
        stress.push(material.update(&inc, &mut h_new));
        history.push(h_new);
    }
    Response {
        f: path.to_vec(),
        stress,
        history,
    }
}

/// A Cauchy stress component held at a target value by solving for one component
/// of ΔF (mixed control, e.g. a constant confining pressure).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StressControl {
    /// The controlled stress component (i, j).
    pub stress: (usize, usize),
    pub target: f64,
    /// The component (k, l) of ΔF that is solved for.
    pub free: (usize, usize),
    /// Another component of ΔF kept equal to the free one (axisymmetry: ΔF_yy =
    /// ΔF_xx in a triaxial test, where two separate controls would be singular on
    /// the Mohr–Coulomb edge σ_xx = σ_yy).
    pub mirror: Option<(usize, usize)>,
}

/// A mixed-control run: the response and, per increment, the scaled residual
/// max_m |σ_m − target_m| / scale of each Newton iterate.
#[derive(Clone, Debug)]
pub struct MixedResponse {
    pub response: Response,
    pub residuals: Vec<Vec<f64>>,
}

/// Drive `material` by the increments ΔF_k, except that the `free` components of
/// each ΔF are found by Newton's method (Jacobian from
/// [`Material::stress_derivative`], or central differences if it has none) so
/// that the controlled stress components equal their targets to `tolerance`
/// relative to max(|targets|, |σ|). Starts from `stress0`, `history0` at F = I.
/// Fails with a message naming the increment if Newton does not converge in 30
/// iterations.
pub fn run_mixed<M: Material + ?Sized>(
    material: &M,
    increments: &[Mat3],
    controls: &[StressControl],
    dt: f64,
    stress0: Mat3,
    history0: Vec<f64>,
    tolerance: f64,
) -> Result<MixedResponse, String> {
    assert_eq!(history0.len(), material.n_history(), "history length");
    let n = controls.len();
    let mut f = vec![Mat3::identity()];
    let mut stress = vec![stress0];
    let mut history = vec![history0];
    let mut residuals = Vec::new();
    for (k, increment) in increments.iter().enumerate() {
        let mut df = *increment;
        let mut h_new = vec![0.0; material.n_history()];
        let mut log = Vec::new();
        let converged = loop {
            let inc = Increment::new(f[k], df, dt, stress[k], &history[k]);
            let s = material.update(&inc, &mut h_new);
            let scale = controls
                .iter()
                .map(|c| c.target.abs())
                .fold(s.amax(), f64::max)
                .max(f64::MIN_POSITIVE);
            let r = nalgebra::DVector::from_fn(n, |m, _| {
                let c = controls[m];
                s[c.stress] - c.target
            });
            log.push(r.amax() / scale);
            if r.amax() <= tolerance * scale {
                break Some(s);
            }
            if log.len() > 30 {
                break None;
            }
            let d = material
                .stress_derivative(&inc)
                .unwrap_or_else(|| numerical_stress_derivative(material, &inc, 1e-7));
            let jac = nalgebra::DMatrix::from_fn(n, n, |m, j| {
                let (a, b) = controls[m].stress;
                let column = |(c, e): (usize, usize)| d[(3 * a + b, 3 * c + e)];
                column(controls[j].free) + controls[j].mirror.map_or(0.0, column)
            });
            let Some(dx) = jac.lu().solve(&(-r)) else {
                break None;
            };
            for (c, x) in controls.iter().zip(dx.iter()) {
                df[c.free] += x;
                if let Some(m) = c.mirror {
                    df[m] += x;
                }
            }
        };
        let Some(s) = converged else {
            return Err(format!(
                "mixed control did not converge in increment {} (residuals {log:?})",
                k + 1
            ));
        };
        f.push(df * f[k]);
        stress.push(s);
        history.push(h_new);
        residuals.push(log);
    }
    Ok(MixedResponse {
        response: Response { f, stress, history },
        residuals,
    })
}

/// Path F_k = f(k/steps), k = 0…steps; `f(0)` should be the identity.
pub fn from_fn(steps: usize, f: impl Fn(f64) -> Mat3) -> Vec<Mat3> {
    assert!(steps > 0, "a path needs at least one step");
    (0..=steps).map(|k| f(k as f64 / steps as f64)).collect()
}

/// Uniaxial strain along `axis`: F = I + t·ε e_a⊗e_a (stretch λ = 1 + ε at the end).
pub fn uniaxial_strain(axis: usize, total_strain: f64, steps: usize) -> Vec<Mat3> {
    assert!(axis < 3, "axis must be 0, 1 or 2");
    from_fn(steps, |t| {
        let mut f = Mat3::identity();
        f[(axis, axis)] += t * total_strain;
        f
    })
}

/// Simple shear: F = I + t·γ e1⊗e2 (x displaced in proportion to y).
pub fn simple_shear(gamma: f64, steps: usize) -> Vec<Mat3> {
    from_fn(steps, |t| {
        let mut f = Mat3::identity();
        f[(0, 1)] = t * gamma;
        f
    })
}

/// Hydrostatic stretch: F = (1 + t(s − 1)) I.
pub fn hydrostatic(stretch: f64, steps: usize) -> Vec<Mat3> {
    from_fn(steps, |t| Mat3::identity() * (1.0 + t * (stretch - 1.0)))
}

/// Rigid rotation of a pre-stretched state: `steps` increments ramping F linearly
/// from I to `stretch`, then `steps` increments F = R_z(t·angle)·stretch. The
/// returned path has 2·steps + 1 entries.
pub fn rotation(stretch: &Mat3, angle: f64, steps: usize) -> Vec<Mat3> {
    let load = from_fn(steps, |t| {
        Mat3::identity() + (stretch - Mat3::identity()) * t
    });
    let turn = from_fn(steps, |t| rotation_z(t * angle) * stretch);
    load.into_iter().chain(turn.into_iter().skip(1)).collect()
}

/// Rotation by `angle` (radians) about the z axis.
pub fn rotation_z(angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Central finite-difference approximation of ∂σ_new/∂ΔF (step `h` on each ΔF
/// component), in the layout of [`StressDerivative`].
pub fn numerical_stress_derivative<M: Material + ?Sized>(
    material: &M,
    inc: &Increment,
    h: f64,
) -> StressDerivative {
    let mut d = StressDerivative::zeros();
    let mut hist = vec![0.0; material.n_history()];
    for k in 0..3 {
        for l in 0..3 {
            let (mut plus, mut minus) = (inc.df, inc.df);
            plus[(k, l)] += h;
            minus[(k, l)] -= h;
            let (plus, minus) = (inc.with_df(plus), inc.with_df(minus));
            let ds = (material.update(&plus, &mut hist) - material.update(&minus, &mut hist))
                / (2.0 * h);
            crate::material::set_derivative_column(&mut d, k, l, &ds);
        }
    }
    d
}

/// Relative (Frobenius) difference between `material`'s exact stress derivative and
/// central differences of its update with step `h`.
pub fn tangent_error<M: Material + ?Sized>(material: &M, inc: &Increment, h: f64) -> f64 {
    let exact = material
        .stress_derivative(inc)
        .expect("the material has an exact stress derivative");
    let fd = numerical_stress_derivative(material, inc, h);
    (exact - fd).norm() / exact.norm().max(fd.norm())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_builders_start_at_identity_and_end_where_documented() {
        let i = Mat3::identity();
        let u = uniaxial_strain(1, 0.2, 4);
        assert_eq!(u.len(), 5);
        assert_eq!(u[0], i);
        assert!((u[4][(1, 1)] - 1.2).abs() < 1e-15, "uniaxial end stretch");
        let s = simple_shear(0.5, 2);
        assert_eq!(s[0], i);
        assert_eq!(s[2][(0, 1)], 0.5);
        let h = hydrostatic(0.9, 3);
        assert!((h[3] - i * 0.9).norm() < 1e-15, "hydrostatic end");
        let st = Mat3::new(1.1, 0.0, 0.0, 0.0, 0.9, 0.0, 0.0, 0.0, 1.0);
        let r = rotation(&st, 0.3, 5);
        assert_eq!(r.len(), 11);
        assert!((r[5] - st).norm() < 1e-15, "pre-stretch reached");
        assert!((r[10] - rotation_z(0.3) * st).norm() < 1e-15, "rotated end");
    }

    #[test]
    fn run_applies_multiplicative_increments() {
        // A trivial "material" whose stress is F_new − I: the driver must rebuild F_k.
        #[derive(Clone, Debug)]
        struct Probe;
        impl Material for Probe {
            fn model(&self) -> &'static str {
                "probe"
            }
            fn density(&self) -> f64 {
                1.0
            }
            fn n_history(&self) -> usize {
                1
            }
            fn update(&self, inc: &Increment, h: &mut [f64]) -> Mat3 {
                h[0] = inc.history_old[0] + inc.dt;
                inc.f - Mat3::identity()
            }
            fn p_wave_modulus(&self) -> f64 {
                1.0
            }
            fn strain_energy_density(&self, _: &Mat3, _: &Mat3, _: &[f64]) -> f64 {
                0.0
            }
        }
        let path = from_fn(7, |t| {
            Mat3::new(
                1.0 + t,
                0.3 * t,
                0.0,
                -0.2 * t,
                1.0 - 0.1 * t,
                0.0,
                0.0,
                0.0,
                1.0,
            )
        });
        let r = run(&Probe, &path, 0.5);
        for (f, s) in path.iter().zip(&r.stress) {
            assert!(
                (f - Mat3::identity() - s).norm() < 1e-14,
                "F_k reconstructed to 1e-14"
            );
        }
        assert!((r.history[7][0] - 3.5).abs() < 1e-14, "history carried");
    }
}
