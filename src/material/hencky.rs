//! Isotropic hyperelasticity in logarithmic (Hencky) strain.
//!
//! With b = F Fᵀ = Σ β_a n_a⊗n_a (β_a = λ_a², the squared principal stretches), the
//! Hencky strain is ε = ½ ln b = Σ ln λ_a n_a⊗n_a. The stored energy per reference
//! volume W = μ ε:ε + ½ λ (tr ε)² gives the Kirchhoff stress τ = λ tr(ε) I + 2μ ε and
//! the Cauchy stress σ = τ / J, J = det F. The stress depends only on
//! F_new = ΔF F_old (no history, path independent).
//!
//! The spectral decomposition is taken of b − I = H + Hᵀ + H Hᵀ (H = F − I) rather
//! than of b, so that ln β_a = ln_1p(β_a − 1) keeps full relative accuracy at small
//! strains.
//!
//! # Consistent tangent
//!
//! For dΔF = E_kl (the unit tensor e_k⊗e_l): dF = E_kl F_old, db = dF Fᵀ + F dFᵀ and
//! d ln J = tr(F⁻¹ dF) = (ΔF⁻¹)_lk. The derivative of the isotropic tensor function
//! ln b in the direction db is the Daleckii–Krein formula
//!
//!   d ln b = N (G ∘ (Nᵀ db N)) Nᵀ,  G_ab = (ln β_a − ln β_b)/(β_a − β_b) (a ≠ b
//!   eigenvalues), G_ab = 1/β_a (β_a = β_b),
//!
//! with N the matrix of eigenvectors and ∘ the entrywise product. The formula holds
//! for every multiplicity of the eigenvalues (within a repeated eigenvalue's
//! eigenspace G is constant, so the arbitrary choice of eigenvectors there cancels),
//! hence it is exact at F = I, under rigid rotations, uniaxial and hydrostatic
//! stretch alike. Then dε = ½ d ln b, dτ = λ tr(dε) I + 2μ dε and
//! dσ = dτ / J − σ d ln J.
//!
//! The only numerical hazard is the divided difference G_ab for close eigenvalues:
//! computing ln β_a − ln β_b and β_a − β_b separately divides one cancellation error
//! by another. Instead G_ab = ln_1p(r)/(β_hi − β_lo) with r = (β_hi − β_lo)/β_lo,
//! which uses the same computed difference in numerator and denominator; G is a
//! smooth function of the eigenvalues, so perturbations of the computed eigenvalues
//! only perturb G by the same relative amount. For r < 1e-4 the Taylor series
//! ln_1p(r)/r = 1 − r/2 + r²/3 − r³/4 + r⁴/5 − … (truncation error below r⁵/6 <
//! 2e-21) replaces the quotient and gives the limit 1/β_lo at r = 0. Both branches
//! are accurate to a few ulp, so there is no tolerance-dependent switch between an
//! approximate limit and the exact quotient.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{lame, Increment, Material, StressDerivative};
use crate::dim::Mat3;
use super::spectral::{from_principal, symmetric_eigen};
use nalgebra::Vector3;

/// Hencky (logarithmic-strain) hyperelastic solid with Lamé constants from (E, ν).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hencky {
    /// Reference mass density ρ0.
    pub density: f64,
    /// Young's modulus E (small-strain).
    pub youngs_modulus: f64,
    /// Poisson's ratio ν (small-strain).
    pub poisson_ratio: f64,
}

/// Spectral decomposition of b = F Fᵀ: eigenvectors (columns of `n`) and the
/// eigenvalues of b − I (`m`, so β_a = 1 + m_a).
pub(crate) struct Spectral {
    pub(crate) n: Mat3,
    pub(crate) m: Vector3<f64>,
}

impl Spectral {
    pub(crate) fn of(f: &Mat3) -> Self {
        let h = f - Mat3::identity();
        let b_minus_i = h + h.transpose() + h * h.transpose();
        let (m, n) = symmetric_eigen(&b_minus_i);
        Self { n, m }
    }

    /// Hencky strain ε = ½ ln b = Σ ½ ln β_a n_a⊗n_a.
    fn log_strain(&self) -> Mat3 {
        let half_ln = self.m.map(|m| 0.5 * m.ln_1p());
        from_principal(&self.n, &half_ln)
    }

    /// Principal Hencky strains ln λ_a = ½ ln β_a.
    pub(crate) fn principal_log_stretches(&self) -> Vector3<f64> {
        self.m.map(|m| 0.5 * m.ln_1p())
    }

    /// Daleckii–Krein matrix G_ab = divided difference of ln at (β_a, β_b).
    fn log_divided_differences(&self) -> Mat3 {
        Mat3::from_fn(|a, b| log_divided_difference(self.m[a], self.m[b]))
    }
}

/// Below this ratio r = β_hi/β_lo − 1 the divided difference uses the series.
const SERIES_BELOW: f64 = 1e-4;

/// ln(1 + r)/r by its Taylor series to r⁴ (Horner form); truncation error < r⁵/6.
fn ln_1p_over_r_series(r: f64) -> f64 {
    1.0 - r * (0.5 - r * (1.0 / 3.0 - r * (0.25 - r * 0.2)))
}

/// (ln(1 + x) − ln(1 + y)) / (x − y), with the limit 1/(1 + x) at x = y; x, y > −1 are
/// eigenvalues of b − I. See the module documentation for the evaluation.
pub(crate) fn log_divided_difference(x: f64, y: f64) -> f64 {
    let (hi, lo) = if x >= y { (x, y) } else { (y, x) };
    let d = hi - lo;
    let beta_lo = 1.0 + lo;
    let r = d / beta_lo;
    if r < SERIES_BELOW {
        ln_1p_over_r_series(r) / beta_lo
    } else {
        r.ln_1p() / d
    }
}

impl Hencky {
    pub fn new(density: f64, youngs_modulus: f64, poisson_ratio: f64) -> Self {
        super::debug_check_elastic(density, youngs_modulus, poisson_ratio);
        Self {
            density,
            youngs_modulus,
            poisson_ratio,
        }
    }

    /// Lamé constants (λ, μ).
    pub fn lame(&self) -> (f64, f64) {
        lame(self.youngs_modulus, self.poisson_ratio)
    }

    /// τ = λ tr(ε) I + 2μ ε for a (Hencky) strain ε.
    fn stress_of_strain(&self, eps: &Mat3) -> Mat3 {
        let (lambda, mu) = self.lame();
        Mat3::identity() * (lambda * eps.trace()) + eps * (2.0 * mu)
    }

    /// Hencky strain ε = ½ ln(F Fᵀ) at total deformation gradient `f`.
    pub fn log_strain(&self, f: &Mat3) -> Mat3 {
        Spectral::of(f).log_strain()
    }

    /// Kirchhoff stress τ = λ tr(ε) I + 2μ ε at total deformation gradient `f`.
    pub fn kirchhoff(&self, f: &Mat3) -> Mat3 {
        debug_assert!(f.determinant() > 0.0, "det F must be positive");
        self.stress_of_strain(&self.log_strain(f))
    }

    /// Cauchy stress σ = τ / det F at total deformation gradient `f`.
    pub fn cauchy(&self, f: &Mat3) -> Mat3 {
        let j = f.determinant();
        debug_assert!(j > 0.0, "det F must be positive");
        self.stress_of_strain(&self.log_strain(f)) / j
    }
}

impl FromParameters for Hencky {
    const NAME: &'static str = "hencky";
    const KEYS: &'static [&'static str] = &["youngs_modulus", "poisson_ratio"];
    const EXAMPLE: &'static str = "youngs_modulus = 1.0e6\npoisson_ratio = 0.3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        // E is checked before ν (arguments are evaluated in order).
        Ok(Self::new(density, p.youngs_modulus()?, p.poisson_ratio()?))
    }
}

impl Material for Hencky {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn update(&self, inc: &Increment, _history_new: &mut [f64]) -> Mat3 {
        self.cauchy(&inc.f)
    }

    fn p_wave_modulus(&self) -> f64 {
        let (lambda, mu) = self.lame();
        lambda + 2.0 * mu
    }

    /// W / J with W = μ ε:ε + ½ λ (tr ε)².
    fn strain_energy_density(&self, f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        let (lambda, mu) = self.lame();
        let e = Spectral::of(f).principal_log_stretches();
        let tr = e.sum();
        (mu * e.norm_squared() + 0.5 * lambda * tr * tr) / f.determinant()
    }

    /// Chain rule through b = ΔF b_old ΔFᵀ and J = det ΔF det F_old, with the
    /// Daleckii–Krein derivative of ln b (module documentation).
    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let (lambda, mu) = self.lame();
        let f = inc.f;
        let j = f.determinant();
        let df_inv = inc.df.try_inverse()?;
        let sp = Spectral::of(&f);
        let n = sp.n;
        let g = sp.log_divided_differences();
        let sigma = self.stress_of_strain(&sp.log_strain()) / j;
        // dF Fᵀ = E_kl F_old Fᵀ: row k equals row l of F_old Fᵀ.
        let a = inc.f_old * f.transpose();
        let mut d = StressDerivative::zeros();
        for k in 0..3 {
            for l in 0..3 {
                let mut dff = Mat3::zeros();
                dff.set_row(k, &a.row(l));
                let db = dff + dff.transpose();
                let dlog_hat = g.component_mul(&(n.transpose() * db * n));
                let deps = n * dlog_hat * n.transpose() * 0.5;
                let dtau = Mat3::identity() * (lambda * deps.trace()) + deps * (2.0 * mu);
                let dlnj = df_inv[(l, k)];
                let ds = dtau / j - sigma * dlnj;
                super::set_derivative_column(&mut d, k, l, &ds);
            }
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::testing::{general_f, prestressed, rel, rotation};

    fn model() -> Hencky {
        Hencky::new(1100.0, 3.0e6, 0.35)
    }

    fn diag(a: f64, b: f64, c: f64) -> Mat3 {
        Mat3::from_diagonal(&Vector3::new(a, b, c))
    }

    fn hooke(lambda: f64, mu: f64, eps: &Mat3) -> Mat3 {
        Mat3::identity() * (lambda * eps.trace()) + eps * (2.0 * mu)
    }

    #[test]
    fn zero_stress_at_identity() {
        let m = model();
        let s = m.update(&prestressed(Mat3::identity(), Mat3::identity()), &mut []);
        assert!(s.norm() == 0.0, "σ(I) = 0 exactly");
        assert!(
            m.strain_energy_density(&Mat3::identity(), &Mat3::zeros(), &[]) == 0.0,
            "W(I) = 0 exactly"
        );
        assert_eq!(m.model(), "hencky");
        let (lambda, mu) = m.lame();
        assert_eq!(m.p_wave_modulus(), lambda + 2.0 * mu);
    }

    #[test]
    fn small_strain_limit_is_hooke() {
        let m = model();
        let (lambda, mu) = m.lame();
        for (scale, tol) in [(1e-7, 1e-6), (1e-6, 1e-5)] {
            let h = Mat3::new(1.0, 0.4, -0.3, 0.4, -0.6, 0.2, -0.3, 0.2, 0.5) * scale;
            let s = m.update(
                &prestressed(Mat3::identity(), Mat3::identity() + h),
                &mut [],
            );
            let e = rel(&s, &hooke(lambda, mu, &h));
            eprintln!("Hooke at strain {scale:e}: {e:e}");
            assert!(
                e < tol,
                "Hooke's law at strain {scale}: relative error {e:e} < {tol:e}"
            );
        }
    }

    #[test]
    fn stress_is_symmetric() {
        let s = model().update(&prestressed(general_f(), driver::rotation_z(0.3)), &mut []);
        assert!(
            (s - s.transpose()).norm() <= 1e-14 * s.norm(),
            "symmetric to 1e-14"
        );
    }

    #[test]
    fn uniaxial_stretch_closed_form() {
        let m = model();
        let (lambda, mu) = m.lame();
        for s in [0.5, 0.8, 0.999, 1.001, 1.3, 2.5] {
            let tau = m.kirchhoff(&diag(s, 1.0, 1.0));
            let ln_s: f64 = f64::ln(s);
            let t11 = (lambda + 2.0 * mu) * ln_s;
            let t22 = lambda * ln_s;
            let scale = t11.abs();
            assert!(
                (tau[(0, 0)] - t11).abs() < 1e-12 * scale,
                "τ11 = (λ + 2μ) ln s to 1e-12 (s = {s})"
            );
            assert!(
                (tau[(1, 1)] - t22).abs() < 1e-12 * scale,
                "τ22 = λ ln s to 1e-12 (s = {s})"
            );
            assert!(
                (tau[(2, 2)] - t22).abs() < 1e-12 * scale,
                "τ33 = λ ln s to 1e-12 (s = {s})"
            );
            assert!(
                tau[(0, 1)].abs() + tau[(0, 2)].abs() + tau[(1, 2)].abs() < 1e-12 * scale,
                "no shear (s = {s})"
            );
        }
        // The same through the driver (multiplicative increments), Cauchy = τ / s.
        let resp = driver::run(&m, &driver::uniaxial_strain(0, 0.5, 50), 1e-3);
        for (f, s) in resp.f.iter().zip(&resp.stress).skip(1) {
            let l1: f64 = f[(0, 0)];
            let s11 = (lambda + 2.0 * mu) * l1.ln() / l1;
            let s22 = lambda * l1.ln() / l1;
            assert!(
                (s[(0, 0)] - s11).abs() < 1e-12 * s11.abs(),
                "driver σ11 to 1e-12"
            );
            assert!(
                (s[(1, 1)] - s22).abs() < 1e-12 * s11.abs(),
                "driver σ22 to 1e-12"
            );
        }
    }

    #[test]
    fn one_dimensional_column_law_with_zero_poisson_ratio() {
        // The project's 1D column verification: σ_yy = E ln s / s for F = diag(1, s, 1).
        let e_mod = 1.0e6;
        let m = Hencky::new(1000.0, e_mod, 0.0);
        for s in [0.3, 0.7, 0.95, 0.9999, 1.0001, 1.2, 3.0] {
            let sigma = m.cauchy(&diag(1.0, s, 1.0));
            let expect = e_mod * f64::ln(s) / s;
            assert!(
                (sigma[(1, 1)] - expect).abs() < 1e-12 * expect.abs(),
                "σ_yy = E ln s / s to 1e-12 (s = {s})"
            );
            let others = sigma[(0, 0)].abs()
                + sigma[(2, 2)].abs()
                + sigma[(0, 1)].abs()
                + sigma[(0, 2)].abs()
                + sigma[(1, 2)].abs();
            assert!(
                others < 1e-12 * expect.abs(),
                "no lateral stress at ν = 0 (s = {s})"
            );
        }
    }

    #[test]
    fn superposed_rotation_rotates_stress() {
        let m = model();
        let r = rotation(0.8);
        for f in [general_f(), diag(1.3, 1.0, 1.0), Mat3::identity() * 0.8] {
            let s = m.cauchy(&f);
            let sr = m.cauchy(&(r * f));
            let err = (sr - r * s * r.transpose()).norm() / s.norm();
            assert!(err < 1e-12, "σ(QF) = QσQᵀ: relative error {err:e} < 1e-12");
        }
        let f_old = general_f();
        let df = Mat3::new(1.03, 0.02, 0.0, -0.01, 0.98, 0.01, 0.0, 0.0, 1.0);
        let s = m.update(&prestressed(f_old, df), &mut []);
        let sr = m.update(&prestressed(f_old, r * df), &mut []);
        assert!(
            rel(&sr, &(r * s * r.transpose())) < 1e-12,
            "update: σ(Q ΔF F_old) = QσQᵀ to 1e-12"
        );
        // Through the driver: rotating a pre-stretched state.
        let u = Mat3::new(1.2, 0.1, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0, 1.0);
        let resp = driver::run(&m, &driver::rotation(&u, 1.3, 20), 1e-3);
        let rz = driver::rotation_z(1.3);
        let s_u = resp.stress[20];
        assert!(
            rel(&resp.stress[40], &(rz * s_u * rz.transpose())) < 1e-12,
            "driver rotation to 1e-12"
        );
    }

    #[test]
    fn energy_derivative_is_first_piola() {
        for nu in [0.0, 0.35, 0.49] {
            let m = Hencky::new(1100.0, 3.0e6, nu);
            for f in [general_f(), rotation(0.8) * diag(1.3, 1.0, 1.0)] {
                let h = 1e-6;
                let w =
                    |f: &Mat3| f.determinant() * m.strain_energy_density(f, &Mat3::zeros(), &[]);
                let p_num = Mat3::from_fn(|k, l| {
                    let mut fp = f;
                    let mut fm = f;
                    fp[(k, l)] += h;
                    fm[(k, l)] -= h;
                    (w(&fp) - w(&fm)) / (2.0 * h)
                });
                let p = m.cauchy(&f) * f.determinant() * f.try_inverse().unwrap().transpose();
                let e = rel(&p_num, &p);
                eprintln!("∂W/∂F vs τF⁻ᵀ, ν = {nu}: {e:e}");
                assert!(
                    e < 1e-6,
                    "∂W/∂F = Jσ F⁻ᵀ (ν = {nu}): relative error {e:e} < 1e-6"
                );
            }
        }
    }

    #[test]
    fn log_divided_difference_is_continuous_and_accurate() {
        // Limit at coincidence.
        for x in [-0.5, 0.0, 1e-9, 0.7] {
            let g = log_divided_difference(x, x);
            assert!(
                (g - 1.0 / (1.0 + x)).abs() <= 1e-15 / (1.0 + x),
                "limit 1/β at x = y to 1e-15"
            );
        }
        // Both branches agree with the plain quotient where it is well conditioned, and
        // with each other across the switch at r = 1e-4.
        let y: f64 = 0.3;
        for r in [1e-2, 2e-4, 1.0001e-4, 0.9999e-4, 5e-5] {
            let x = (1.0 + y) * (1.0 + r) - 1.0;
            let g = log_divided_difference(x, y);
            let g_sym = log_divided_difference(y, x);
            assert!(g == g_sym, "symmetric in its arguments");
            let plain = (x.ln_1p() - y.ln_1p()) / (x - y);
            let tol = if r > 1e-3 { 1e-13 } else { 1e-10 };
            assert!(
                (g - plain).abs() < tol * plain,
                "divided difference at r = {r:e} to {tol:e}"
            );
        }
        // The series and the quotient agree at the switch.
        let r = SERIES_BELOW;
        let jump = (ln_1p_over_r_series(r) - r.ln_1p() / r).abs();
        eprintln!("series vs ln_1p(r)/r at r = {r:e}: {jump:e}");
        assert!(jump < 1e-15, "no jump across the series switch (1e-15)");
    }

    #[test]
    fn tangent_at_identity_is_isotropic_stiffness() {
        let m = model();
        let (lambda, mu) = m.lame();
        let d = m
            .stress_derivative(&prestressed(Mat3::identity(), Mat3::identity()))
            .unwrap();
        let delta = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
        let c = StressDerivative::from_fn(|r, c| {
            let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
            lambda * delta(i, j) * delta(k, l)
                + mu * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k))
        });
        let err = (d - c).norm() / c.norm();
        assert!(
            err < 1e-15,
            "∂σ/∂ΔF at I = ℂ: relative error {err:e} < 1e-15"
        );
    }

    /// Relative error of the exact tangent against central differences of `update`.
    fn tangent_error(m: &Hencky, f_old: Mat3, df: Mat3) -> f64 {
        let i = prestressed(f_old, df);
        let exact = m.stress_derivative(&i).unwrap();
        // ΔF entries are O(1): an absolute step 1e-6 balances the O(h²) truncation
        // against the O(ulp/h) round-off, both ~1e-10 relative here.
        let h = 1e-6 * df.norm() / 3f64.sqrt();
        let fd = driver::numerical_stress_derivative(m, &i, h);
        (exact - fd).norm() / exact.norm()
    }

    #[test]
    fn stress_derivative_matches_finite_differences() {
        let r = rotation(0.8);
        let id = Mat3::identity();
        let generic_df = driver::rotation_z(0.15)
            * Mat3::new(1.02, 0.03, 0.01, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01);
        let near = |eps: f64| r * diag(1.2, 1.2 * (1.0 + eps), 0.9) * r.transpose();
        let cases: [(&str, Mat3, Mat3); 15] = [
            ("generic", general_f(), generic_df),
            ("generic F_old, ΔF = I", general_f(), id),
            ("F_old = I, ΔF = I", id, id),
            ("F_old = I, ΔF = rotation", id, r),
            ("generic F_old, ΔF = rotation", general_f(), r),
            ("uniaxial F_old, ΔF = I", diag(1.3, 1.0, 1.0), id),
            (
                "uniaxial F_old, uniaxial ΔF",
                diag(1.3, 1.0, 1.0),
                diag(1.05, 1.0, 1.0),
            ),
            (
                "uniaxial, rotated ΔF",
                diag(1.3, 1.0, 1.0),
                r * diag(1.05, 1.0, 1.0),
            ),
            ("rotated uniaxial F_old", r * diag(0.7, 1.0, 1.0), id),
            ("hydrostatic F_old, ΔF = I", id * 1.2, id),
            ("hydrostatic F_old, hydrostatic ΔF", id * 1.2, id * 0.9),
            ("hydrostatic, ΔF = rotation", id * 1.2, r * 0.9),
            ("near-coincident 1e-12", near(1e-12), id),
            ("near-coincident 1e-8", near(1e-8), generic_df),
            ("near-coincident 1e-4", near(1e-4), id),
        ];
        for nu in [0.0, 0.35, 0.49] {
            let m = Hencky::new(1100.0, 3.0e6, nu);
            for (name, f_old, df) in cases {
                let err = tangent_error(&m, f_old, df);
                eprintln!("tangent vs FD, {name}, ν = {nu}: {err:e}");
                assert!(
                    err < 1e-6,
                    "tangent vs central FD at {name} (ν = {nu}): relative error {err:e} < 1e-6"
                );
            }
        }
    }

    #[test]
    fn loading_unloading_loop_is_path_independent() {
        let m = Hencky::new(1100.0, 3.0e6, 0.49);
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
        // A closed loop (out and back to the identity) returns to zero stress.
        let loop_path = driver::from_fn(100, |t| {
            Mat3::identity() + h * (std::f64::consts::PI * t).sin()
        });
        let resp = driver::run(&m, &loop_path, 1e-3);
        let peak = resp.stress[50].norm();
        let last = resp.stress.last().unwrap().norm();
        assert!(last < 1e-12 * peak, "closed loop returns to σ = 0 to 1e-12");
    }
}
