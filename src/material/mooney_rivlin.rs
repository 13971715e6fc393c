//! Compressible Mooney–Rivlin hyperelasticity (LS-DYNA *MAT_MOONEY_RIVLIN_RUBBER),
//! thesis equations 3-2 … 3-18.
//!
//! Stored energy per reference volume (3-2)
//!   W = a(I − 3) + b(II − 3) + c(III⁻² − 1) + d(III − 1)²,
//! with I, II, III the invariants of C = FᵀF. PK2 stress (3-7)
//!   T = 2a 1 + 2b(I 1 − C) − 4c III⁻² C⁻¹ + 4d III(III − 1) C⁻¹,
//! Cauchy stress (3-18) σ = F T Fᵀ / J. The reference state is stress free when
//! c = a/2 + b (3-8); linearising at C = I gives λ = 4b + 16c + 8d (3-14) and
//! G = 4c − 2b (3-15), hence a + b = G/2 (3-16) and d from ν (3-17).
//!
//! Caution (checked in the tests): for ν below ν* = (2a + 5b)/(5a + 11b) ∈ [0.4, 0.455],
//! d < 0 and the response to hydrostatic tension has a limit point at small volume
//! change (for a = 4b, ν = 0.3: peak mean stress ≈ 0.054 G at J ≈ 1.05). The model is
//! meant for nearly incompressible rubber (ν → 0.5).

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material, StressDerivative};
use crate::dim::Mat3;
use nalgebra::SMatrix;

/// Fourth-order material tangent L_ABCD = ∂T_AB/∂E_CD, row 3A + B, column 3C + D.
pub type MaterialTangent = SMatrix<f64, 9, 9>;

/// Mooney–Rivlin solid with the LS-DYNA/thesis parameters a, b, c, d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MooneyRivlin {
    /// Reference mass density ρ0.
    pub density: f64,
    /// Coefficient of (I − 3).
    pub a: f64,
    /// Coefficient of (II − 3).
    pub b: f64,
    /// Coefficient of (III⁻² − 1).
    pub c: f64,
    /// Coefficient of (III − 1)².
    pub d: f64,
}

impl MooneyRivlin {
    /// Model with all four constants given. The reference state is stress free only
    /// if c = a/2 + b (3-8); [`MooneyRivlin::from_thesis`] enforces that.
    pub fn new(density: f64, a: f64, b: f64, c: f64, d: f64) -> Self {
        let m = Self {
            density,
            a,
            b,
            c,
            d,
        };
        debug_assert!(density > 0.0, "density must be positive");
        let (lambda, g) = m.small_strain_moduli();
        debug_assert!(
            g > 0.0,
            "small-strain shear modulus 4c − 2b must be positive"
        );
        debug_assert!(
            lambda + 2.0 * g / 3.0 > 0.0,
            "small-strain bulk modulus must be positive"
        );
        m
    }

    /// Constants as in LS-DYNA and the thesis: c = a/2 + b (3-8) and
    /// d = [a(5ν − 2) + b(11ν − 5)] / [2(1 − 2ν)] (3-17); then G = 2(a + b) (3-16).
    pub fn from_thesis(density: f64, a: f64, b: f64, poisson_ratio: f64) -> Self {
        let nu = poisson_ratio;
        debug_assert!(
            nu > -1.0 && nu < 0.5,
            "Poisson's ratio must lie in (-1, 0.5)"
        );
        debug_assert!(a + b > 0.0, "a + b = G/2 must be positive");
        let c = 0.5 * a + b;
        let d = (a * (5.0 * nu - 2.0) + b * (11.0 * nu - 5.0)) / (2.0 * (1.0 - 2.0 * nu));
        Self::new(density, a, b, c, d)
    }

    /// Small-strain Lamé constants (λ, G) from the tangent at C = I:
    /// λ = 4b + 16c + 8d (3-14), G = 4c − 2b (3-15).
    pub fn small_strain_moduli(&self) -> (f64, f64) {
        (
            4.0 * self.b + 16.0 * self.c + 8.0 * self.d,
            4.0 * self.c - 2.0 * self.b,
        )
    }

    /// The invariants (I, II, III) of a right Cauchy–Green tensor.
    fn invariants(c: &Mat3) -> (f64, f64, f64) {
        let i1 = c.trace();
        let i2 = 0.5 * (i1 * i1 - (c * c).trace());
        (i1, i2, c.determinant())
    }

    /// Stored energy per reference volume W(C), eq. 3-2.
    pub fn energy(&self, c: &Mat3) -> f64 {
        let (i1, i2, i3) = Self::invariants(c);
        self.a * (i1 - 3.0)
            + self.b * (i2 - 3.0)
            + self.c * (i3.powi(-2) - 1.0)
            + self.d * (i3 - 1.0).powi(2)
    }

    /// Second Piola–Kirchhoff stress T(C), eq. 3-7.
    pub fn pk2(&self, c: &Mat3) -> Mat3 {
        let (i1, _, i3) = Self::invariants(c);
        let c_inv = c.try_inverse().expect("C must be invertible");
        let id = Mat3::identity();
        id * (2.0 * self.a)
            + (id * i1 - c) * (2.0 * self.b)
            + c_inv * (-4.0 * self.c * i3.powi(-2) + 4.0 * self.d * i3 * (i3 - 1.0))
    }

    /// Material tangent L = ∂T/∂E = 2 ∂T/∂C (minor-symmetrised), eq. 3-12.
    pub fn material_tangent(&self, c: &Mat3) -> MaterialTangent {
        let (_, _, i3) = Self::invariants(c);
        let ci = c.try_inverse().expect("C must be invertible");
        let (b, cc, d) = (self.b, self.c, self.d);
        let k_outer = 16.0 * cc * i3.powi(-2) + 8.0 * d * (2.0 * i3 * i3 - i3);
        let k_sym = 4.0 * cc * i3.powi(-2) - 4.0 * d * (i3 * i3 - i3);
        let delta = |p: usize, q: usize| if p == q { 1.0 } else { 0.0 };
        MaterialTangent::from_fn(|r, s| {
            let (p, q, m, n) = (r / 3, r % 3, s / 3, s % 3);
            4.0 * b * delta(p, q) * delta(m, n)
                - 2.0 * b * (delta(p, m) * delta(q, n) + delta(p, n) * delta(q, m))
                + k_outer * ci[(p, q)] * ci[(m, n)]
                + k_sym * (ci[(p, m)] * ci[(q, n)] + ci[(p, n)] * ci[(q, m)])
        })
    }

    /// Cauchy stress σ = F T Fᵀ / J at total deformation gradient `f`, eq. 3-18.
    pub fn cauchy(&self, f: &Mat3) -> Mat3 {
        let j = f.determinant();
        debug_assert!(j > 0.0, "det F must be positive");
        f * self.pk2(&(f.transpose() * f)) * f.transpose() / j
    }
}

impl FromParameters for MooneyRivlin {
    const NAME: &'static str = "mooney_rivlin";
    const KEYS: &'static [&'static str] = &["a", "b", "poisson_ratio"];
    const EXAMPLE: &'static str = "a = 1.0e5\nb = 1.0e5\npoisson_ratio = 0.3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        let a: f64 = p.required("a")?;
        let b: f64 = p.required("b")?;
        let g = 2.0 * (a + b);
        p.ensure(
            g > 0.0 && g.is_finite(),
            "a",
            "a + b (= G/2, thesis 3-16) must be positive",
        )?;
        Ok(Self::from_thesis(density, a, b, p.poisson_ratio()?))
    }
}

impl Material for MooneyRivlin {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn update(&self, inc: &Increment, _history_new: &mut [f64]) -> Mat3 {
        self.cauchy(&inc.f)
    }

    /// λ + 2G from the small-strain relations 3-14, 3-15.
    fn p_wave_modulus(&self) -> f64 {
        let (lambda, g) = self.small_strain_moduli();
        lambda + 2.0 * g
    }

    /// W(C)/J.
    fn strain_energy_density(&self, f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        self.energy(&(f.transpose() * f)) / f.determinant()
    }

    /// Through the PK2 tangent: for dΔF = E_kl, dF = E_kl F_old, dC = dFᵀF + FᵀdF,
    /// dT = ½ L : dC (3-12), d ln J = tr(F⁻¹ dF) and
    /// dσ = (dF T Fᵀ + F T dFᵀ + F dT Fᵀ)/J − σ d ln J.
    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let f = inc.f;
        let j = f.determinant();
        let f_inv = f.try_inverse()?;
        let c = f.transpose() * f;
        let t = self.pk2(&c);
        let l = self.material_tangent(&c);
        let sigma = f * t * f.transpose() / j;
        let t_ft = t * f.transpose();
        let mut out = StressDerivative::zeros();
        for k in 0..3 {
            for m in 0..3 {
                let mut df = Mat3::zeros();
                df.set_row(k, &inc.f_old.row(m));
                let ftdf = f.transpose() * df;
                let dc = ftdf + ftdf.transpose();
                let dc_flat = SMatrix::<f64, 9, 1>::from_fn(|r, _| dc[(r / 3, r % 3)]);
                let dt_flat = l * dc_flat * 0.5;
                let dt = Mat3::from_fn(|p, q| dt_flat[3 * p + q]);
                let dlnj = (f_inv * df).trace();
                let x = df * t_ft;
                let ds = (x + x.transpose() + f * dt * f.transpose()) / j - sigma * dlnj;
                for i in 0..3 {
                    for jj in 0..3 {
                        out[(3 * i + jj, 3 * k + m)] = ds[(i, jj)];
                    }
                }
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::testing::{prestressed, rel};

    const A: f64 = 0.4e6;
    const B: f64 = 0.1e6;

    fn model(nu: f64) -> MooneyRivlin {
        MooneyRivlin::from_thesis(1200.0, A, B, nu)
    }

    fn general_f() -> Mat3 {
        Mat3::new(1.08, 0.12, -0.04, 0.03, 0.95, 0.06, 0.01, -0.05, 1.03)
    }

    #[test]
    fn thesis_constants_3_8_and_3_17() {
        let m = model(0.3);
        assert_eq!(m.c, 0.5 * A + B, "c = a/2 + b (3-8)");
        // d = [0.4(−0.5) + 0.1(−1.7)] / 0.8 · 1e6 = −0.4625e6.
        assert!((m.d + 0.4625e6).abs() < 1e-6, "d from 3-17: {}", m.d);
    }

    #[test]
    fn zero_stress_at_identity() {
        for nu in [0.0, 0.3, 0.45, 0.499] {
            let m = model(nu);
            let s = m.update(&prestressed(Mat3::identity(), Mat3::identity()), &mut []);
            assert!(
                s.norm() < 1e-9 * (A + B),
                "σ(I) = 0 via 3-8 to 1e-9·G (ν = {nu}): {s}"
            );
            let w = m.strain_energy_density(&Mat3::identity(), &s, &[]);
            assert!(w.abs() < 1e-9 * (A + B), "W(I) = 0");
        }
    }

    #[test]
    fn small_strain_limit_is_hooke_with_3_16_and_3_17() {
        // 3-14 … 3-17 checked numerically: G = 2(a + b), λ = 2Gν/(1 − 2ν).
        for nu in [0.0, 0.25, 0.3, 0.45, 0.49] {
            let m = model(nu);
            let g = 2.0 * (A + B);
            let lambda = 2.0 * g * nu / (1.0 - 2.0 * nu);
            let (l_m, g_m) = m.small_strain_moduli();
            assert!((g_m - g).abs() < 1e-9 * g, "4c − 2b = 2(a + b) (ν = {nu})");
            assert!(
                (l_m - lambda).abs() < 1e-9 * g,
                "4b + 16c + 8d = 2Gν/(1−2ν) (ν = {nu})"
            );
            assert!(
                (m.p_wave_modulus() - (lambda + 2.0 * g)).abs() < 1e-9 * g,
                "M = λ + 2G"
            );
            let shape = Mat3::new(1.0, 0.4, -0.3, 0.4, -0.6, 0.2, -0.3, 0.2, 0.5);
            for scale in [1e-7, 1e-6] {
                let h = shape * scale;
                let sp = m.update(
                    &prestressed(Mat3::identity(), Mat3::identity() + h),
                    &mut [],
                );
                let sm = m.update(
                    &prestressed(Mat3::identity(), Mat3::identity() - h),
                    &mut [],
                );
                let hooke = Mat3::identity() * (lambda * h.trace()) + h * (2.0 * g);
                // Odd part ½(σ(h) − σ(−h)): the linear response, O(h²) relative error.
                let e_lin = rel(&((sp - sm) * 0.5), &hooke);
                assert!(
                    e_lin < 1e-6,
                    "linear part = Hooke to 1e-6 (ν = {nu}, strain {scale}): {e_lin:e}"
                );
                // Raw stress: the quadratic term of this model is large (≈ 12·strain
                // relative at ν = 0), so the bound is 20·strain.
                let e = rel(&sp, &hooke);
                assert!(
                    e < 20.0 * scale,
                    "Hooke to 20·strain (ν = {nu}, strain {scale}): {e:e}"
                );
            }
            assert!(
                (sym_err(&m, shape * 1e-3)) < 1e-14,
                "symmetric stress to 1e-14"
            );
        }
    }

    fn sym_err(m: &MooneyRivlin, h: Mat3) -> f64 {
        let s = m.update(
            &prestressed(Mat3::identity(), Mat3::identity() + h),
            &mut [],
        );
        (s - s.transpose()).norm() / s.norm()
    }

    #[test]
    fn tangent_3_12_matches_finite_differences_of_pk2() {
        let m = model(0.45);
        let f = general_f();
        let c = f.transpose() * f;
        let l = m.material_tangent(&c);
        let h = 1e-6;
        let mut l_fd = MaterialTangent::zeros();
        for p in 0..3 {
            for q in 0..3 {
                // Symmetric perturbation of C_pq and C_qp, dE = dC/2.
                let mut dc = Mat3::zeros();
                dc[(p, q)] += 0.5 * h;
                dc[(q, p)] += 0.5 * h;
                let dt = (m.pk2(&(c + dc)) - m.pk2(&(c - dc))) / (2.0 * h) * 2.0;
                for r in 0..9 {
                    l_fd[(r, 3 * p + q)] = dt[(r / 3, r % 3)];
                }
            }
        }
        let e = (l - l_fd).norm() / l.norm();
        assert!(
            e < 1e-6,
            "L (3-12) vs FD of 2∂T/∂C: relative error {e:e} < 1e-6"
        );
    }

    #[test]
    fn stress_is_symmetric() {
        let s = model(0.45).update(&prestressed(general_f(), driver::rotation_z(0.3)), &mut []);
        assert!(
            (s - s.transpose()).norm() <= 1e-12 * s.norm(),
            "symmetric to 1e-12"
        );
    }

    #[test]
    fn stress_derivative_matches_finite_differences() {
        for nu in [0.3, 0.49] {
            let m = model(nu);
            let f_old = Mat3::new(1.1, 0.2, 0.0, 0.05, 0.95, 0.0, 0.0, 0.0, 1.02);
            let df = driver::rotation_z(0.15)
                * Mat3::new(1.02, 0.03, 0.01, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01);
            let i = prestressed(f_old, df);
            let exact = m.stress_derivative(&i).unwrap();
            let fd = driver::numerical_stress_derivative(&m, &i, 1e-6);
            let err = (exact - fd).norm() / exact.norm();
            assert!(
                err < 1e-6,
                "tangent vs central FD (ν = {nu}): relative error {err:e} < 1e-6"
            );
        }
    }

    #[test]
    fn superposed_rotation_rotates_stress() {
        let m = model(0.45);
        let f_old = general_f();
        let df = Mat3::new(1.03, 0.02, 0.0, -0.01, 0.98, 0.01, 0.0, 0.0, 1.0);
        let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(0.3, -0.5, 0.8));
        let r = *nalgebra::Rotation3::from_axis_angle(&axis, 0.8).matrix();
        let s = m.update(&prestressed(f_old, df), &mut []);
        let sr = m.update(&prestressed(f_old, r * df), &mut []);
        assert!(
            rel(&sr, &(r * s * r.transpose())) < 1e-12,
            "σ(RF) = RσRᵀ to 1e-12"
        );
    }

    #[test]
    fn loading_unloading_loop_is_path_independent() {
        let m = model(0.49);
        let h = Mat3::new(0.3, 0.4, 0.0, -0.1, -0.15, 0.0, 0.0, 0.0, 0.0);
        // Load to I + H, unload to I + H/4 while rotating by 0.6 rad about z.
        let path = driver::from_fn(200, |t| {
            let amp = (std::f64::consts::PI * t).sin() * (1.0 - t) + 0.25 * t;
            driver::rotation_z(0.6 * t) * (Mat3::identity() + h * amp)
        });
        let resp = driver::run(&m, &path, 1e-3);
        for (f, s) in resp.f.iter().zip(&resp.stress).skip(1) {
            let direct = m.cauchy(f);
            assert!(
                rel(s, &direct) < 1e-12,
                "driver stress = σ(F_total) to 1e-12"
            );
        }
        let end = Mat3::identity() + h * 0.25;
        let r = driver::rotation_z(0.6);
        let expect = r * m.cauchy(&end) * r.transpose();
        assert!(
            rel(resp.stress.last().unwrap(), &expect) < 1e-12,
            "end state to 1e-12"
        );
    }

    #[test]
    fn energy_derivative_is_first_piola() {
        for nu in [0.3, 0.49] {
            let m = model(nu);
            let f = general_f();
            let h = 1e-6;
            let w = |f: &Mat3| f.determinant() * m.strain_energy_density(f, &Mat3::zeros(), &[]);
            let p_num = Mat3::from_fn(|k, l| {
                let mut fp = f;
                let mut fm = f;
                fp[(k, l)] += h;
                fm[(k, l)] -= h;
                (w(&fp) - w(&fm)) / (2.0 * h)
            });
            let p = m.cauchy(&f) * f.determinant() * f.try_inverse().unwrap().transpose();
            let e = rel(&p_num, &p);
            assert!(
                e < 1e-6,
                "∂W/∂F = Jσ F⁻ᵀ (ν = {nu}): relative error {e:e} < 1e-6"
            );
        }
    }

    #[test]
    fn low_poisson_ratio_gives_hydrostatic_limit_point() {
        // Documented finding: for ν < ν* = (2a + 5b)/(5a + 11b) the constant d is
        // negative and the mean stress under hydrostatic tension peaks early.
        let nu_star = (2.0 * A + 5.0 * B) / (5.0 * A + 11.0 * B);
        assert!(
            model(nu_star - 1e-3).d < 0.0 && model(nu_star + 1e-3).d > 0.0,
            "sign change of d at ν*"
        );
        let m = model(0.3);
        let g = 2.0 * (A + B);
        let resp = driver::run(&m, &driver::hydrostatic(1.04, 400), 1e-3);
        let p: Vec<f64> = resp.stress.iter().map(|s| s.trace() / 3.0).collect();
        let (k_max, p_max) = p
            .iter()
            .cloned()
            .enumerate()
            .fold((0, f64::MIN), |b, (k, v)| if v > b.1 { (k, v) } else { b });
        let j_peak = resp.f[k_max].determinant();
        assert!(k_max > 0 && k_max < 400, "interior maximum of mean stress");
        assert!(
            (p_max / g - 0.0544).abs() < 1e-3,
            "peak mean stress ≈ 0.054 G: {}",
            p_max / g
        );
        assert!((j_peak - 1.052).abs() < 2e-3, "at J ≈ 1.052: {j_peak}");
        // With ν = 0.49 the same path is monotone.
        let resp = driver::run(&model(0.49), &driver::hydrostatic(1.04, 400), 1e-3);
        assert!(
            resp.stress.windows(2).all(|w| w[1].trace() > w[0].trace()),
            "monotone for ν = 0.49"
        );
    }
}
