//! Isotropic linear elasticity in rate form (hypoelasticity, thesis 3-19) with the
//! Jaumann stress rate (3-27), integrated with the Hughes–Winget algorithm.
//!
//! Over one increment the displacement gradient with respect to the midpoint
//! configuration x_{n+½} = ½(x_n + x_{n+1}) is G = 2(ΔF − I)(ΔF + I)⁻¹ (≈ L Δt to
//! second order). With Δε = sym G and Δω = skew G, the old stress is rotated by the
//! Cayley rotation Q = (I − Δω/2)⁻¹(I + Δω/2) and the elastic increment is added:
//! σ_new = Q σ_old Qᵀ + λ tr(Δε) I + 2G Δε.
//!
//! The midpoint gradient makes the update incrementally objective: for a rigid
//! rotation ΔF = R, G is skew, Δε = 0 and Q = R exactly. (With G = ΔF − I instead,
//! a rigid rotation would produce a spurious strain sym(R − I) = O(θ²).) Under
//! simple shear both choices coincide.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{lame, Increment, Material, StressDerivative};
use crate::dim::Mat3;

/// Hypoelastic isotropic solid, σ^∇J = λ tr(d) I + 2G d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearElastic {
    /// Reference mass density ρ0.
    pub density: f64,
    /// Young's modulus E.
    pub youngs_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
}

/// Kinematics of one increment: midpoint gradient G, (ΔF + I)⁻¹, Q and (I − Δω/2)⁻¹.
struct Kinematics {
    g: Mat3,
    m_inv: Mat3,
    q: Mat3,
    a_inv: Mat3,
}

impl LinearElastic {
    pub fn new(density: f64, youngs_modulus: f64, poisson_ratio: f64) -> Self {
        super::debug_check_elastic(density, youngs_modulus, poisson_ratio);
        Self {
            density,
            youngs_modulus,
            poisson_ratio,
        }
    }

    /// Lamé constants (λ, G).
    pub fn lame(&self) -> (f64, f64) {
        lame(self.youngs_modulus, self.poisson_ratio)
    }

    fn kinematics(df: &Mat3) -> Kinematics {
        let id = Mat3::identity();
        let m_inv = (df + id)
            .try_inverse()
            .expect("ΔF + I is singular (increment rotates by π)");
        let g = (df - id) * m_inv * 2.0;
        let half_w = (g - g.transpose()) * 0.25;
        // I − W with W skew has det 1 + |w|² > 0: always invertible.
        let a_inv = (id - half_w).try_inverse().expect("I − Δω/2 is invertible");
        let q = a_inv * (id + half_w);
        Kinematics { g, m_inv, q, a_inv }
    }

    /// C : ε for the isotropic stiffness.
    fn elastic(&self, eps: &Mat3) -> Mat3 {
        let (lambda, g) = self.lame();
        Mat3::identity() * (lambda * eps.trace()) + eps * (2.0 * g)
    }
}

impl FromParameters for LinearElastic {
    const NAME: &'static str = "linear_elastic";
    const KEYS: &'static [&'static str] = &["youngs_modulus", "poisson_ratio"];
    const EXAMPLE: &'static str = "youngs_modulus = 1.0e6\npoisson_ratio = 0.3";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        // E is checked before ν (arguments are evaluated in order).
        Ok(Self::new(density, p.youngs_modulus()?, p.poisson_ratio()?))
    }
}

impl Material for LinearElastic {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn update(&self, inc: &Increment, _history_new: &mut [f64]) -> Mat3 {
        // Hughes–Winget: incrementally objective integration of the Jaumann rate (3-27).
        let k = Self::kinematics(&inc.df);
        let eps = (k.g + k.g.transpose()) * 0.5;
        k.q * inc.stress_old * k.q.transpose() + self.elastic(&eps)
    }

    fn p_wave_modulus(&self) -> f64 {
        let (lambda, g) = self.lame();
        lambda + 2.0 * g
    }

    /// The Jaumann rate integrates from σ_old.
    fn integrates_from_stored_stress(&self) -> bool {
        true
    }

    /// Complementary energy ½ σ : C⁻¹ : σ = [(1 + ν) σ:σ − ν (tr σ)²] / (2E).
    fn strain_energy_density(&self, _f: &Mat3, stress: &Mat3, _history: &[f64]) -> f64 {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        ((1.0 + nu) * stress.norm_squared() - nu * stress.trace().powi(2)) / (2.0 * e)
    }

    /// Exact derivative of the Hughes–Winget update. For a perturbation dΔF = E_kl:
    /// dG = (2I − G) E_kl (ΔF + I)⁻¹, dQ = (I − Δω/2)⁻¹ (dΔω/2) (Q + I),
    /// dσ = dQ σ_old Qᵀ + Q σ_old dQᵀ + C : sym dG.
    fn stress_derivative(&self, inc: &Increment) -> Option<StressDerivative> {
        let k = Self::kinematics(&inc.df);
        let two_minus_g = Mat3::identity() * 2.0 - k.g;
        let q_plus_i = k.q + Mat3::identity();
        let s_qt = inc.stress_old * k.q.transpose();
        let q_s = k.q * inc.stress_old;
        let mut d = StressDerivative::zeros();
        for kk in 0..3 {
            for l in 0..3 {
                // (2I − G) E_kl M⁻¹ = column k of (2I − G) times row l of M⁻¹.
                let dg = two_minus_g.column(kk) * k.m_inv.row(l);
                let deps = (dg + dg.transpose()) * 0.5;
                let half_dw = (dg - dg.transpose()) * 0.25;
                let dq = k.a_inv * half_dw * q_plus_i;
                let ds = dq * s_qt + q_s * dq.transpose() + self.elastic(&deps);
                super::set_derivative_column(&mut d, kk, l, &ds);
            }
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::driver;
    use crate::material::testing::{increment, rel, rotation};

    fn model() -> LinearElastic {
        LinearElastic::new(2500.0, 2.0e9, 0.3)
    }

    fn prestress() -> Mat3 {
        Mat3::new(
            3.0e6, -1.2e6, 0.4e6, -1.2e6, -2.0e6, 0.7e6, 0.4e6, 0.7e6, 1.5e6,
        )
    }

    #[test]
    fn zero_increment_keeps_stress_and_identity_gives_zero() {
        let m = model();
        let s = m.update(
            &increment(Mat3::identity(), Mat3::identity(), Mat3::zeros(), &[]),
            &mut [],
        );
        assert_eq!(s, Mat3::zeros(), "zero stress at F = I exactly");
        let p = prestress();
        let s = m.update(
            &increment(Mat3::identity(), Mat3::identity(), p, &[]),
            &mut [],
        );
        assert!(rel(&s, &p) < 1e-15, "ΔF = I keeps the stress to 1e-15");
    }

    #[test]
    fn small_strain_limit_is_hooke() {
        let m = model();
        let (lambda, g) = m.lame();
        for scale in [1e-7, 1e-6] {
            let h = Mat3::new(1.0, 0.4, -0.3, 0.4, -0.6, 0.2, -0.3, 0.2, 0.5) * scale;
            let s = m.update(
                &increment(Mat3::identity(), Mat3::identity() + h, Mat3::zeros(), &[]),
                &mut [],
            );
            let hooke = Mat3::identity() * (lambda * h.trace()) + h * (2.0 * g);
            assert!(
                rel(&s, &hooke) < 1e-6,
                "Hooke's law to 1e-6 relative at strain {scale}"
            );
            assert!(
                (s - s.transpose()).norm() <= 1e-14 * s.norm(),
                "symmetric stress"
            );
        }
    }

    #[test]
    fn stress_is_symmetric_for_general_increment() {
        let m = model();
        let df = driver::rotation_z(0.2)
            * Mat3::new(1.05, 0.1, 0.02, -0.03, 0.97, 0.04, 0.01, -0.02, 1.01);
        let s = m.update(&increment(Mat3::identity(), df, prestress(), &[]), &mut []);
        assert!(
            (s - s.transpose()).norm() <= 1e-14 * s.norm(),
            "symmetric to 1e-14"
        );
    }

    #[test]
    fn stress_derivative_matches_finite_differences() {
        let m = model();
        let f_old = Mat3::new(1.1, 0.2, 0.0, 0.05, 0.95, 0.0, 0.0, 0.0, 1.02);
        let df = driver::rotation_z(0.15)
            * Mat3::new(1.02, 0.03, 0.01, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01);
        let i = increment(f_old, df, prestress(), &[]);
        let exact = m.stress_derivative(&i).unwrap();
        let fd = driver::numerical_stress_derivative(&m, &i, 1e-5);
        let err = (exact - fd).norm() / exact.norm();
        assert!(
            err < 1e-6,
            "tangent vs central FD: relative error {err:e} must be < 1e-6"
        );
    }

    #[test]
    fn rigid_rotation_increment_rotates_stress_exactly() {
        let m = model();
        let p = prestress();
        for angle in [0.1, 1.0, 2.5] {
            // A general rotation (about a skew axis), not only about z.
            let r = rotation(angle);
            let s = m.update(&increment(Mat3::identity(), r, p, &[]), &mut []);
            let expect = r * p * r.transpose();
            assert!(
                rel(&s, &expect) < 1e-12,
                "pure rotation rotates σ by R to 1e-12 (angle {angle})"
            );
        }
    }

    #[test]
    fn rotation_increment_after_stretch_rotates_stress_exactly() {
        // Stretch increment on a prestressed state, then a pure rotation increment
        // (the second half of `driver::rotation`): the rotation step must map σ to RσRᵀ.
        let m = model();
        let u = Mat3::new(1.01, 0.004, 0.0, 0.004, 0.995, 0.0, 0.0, 0.0, 1.0);
        let s1 = m.update(&increment(Mat3::identity(), u, prestress(), &[]), &mut []);
        let r = driver::rotation_z(0.7);
        let s2 = m.update(&increment(u, r, s1, &[]), &mut []);
        assert!(
            rel(&s2, &(r * s1 * r.transpose())) < 1e-13,
            "rotation after stretch rotates σ to 1e-13"
        );
        // Through the driver: 20 rotation increments of a pre-stretched state.
        let resp = driver::run(&m, &driver::rotation(&u, 1.3, 20), 1e-3);
        let r = driver::rotation_z(1.3);
        let s_u = resp.stress[20];
        assert!(
            rel(&resp.stress[40], &(r * s_u * r.transpose())) < 1e-12,
            "driver rotation to 1e-12"
        );
    }

    fn simple_shear_error(steps: usize) -> f64 {
        let m = model();
        let (_, g) = m.lame();
        let gamma = 1.0;
        let r = driver::run(&m, &driver::simple_shear(gamma, steps), 1e-3);
        let s = r.stress.last().unwrap();
        let exact = Mat3::new(
            g * (1.0 - gamma.cos()),
            g * gamma.sin(),
            0.0,
            g * gamma.sin(),
            -g * (1.0 - gamma.cos()),
            0.0,
            0.0,
            0.0,
            0.0,
        );
        rel(s, &exact)
    }

    #[test]
    fn simple_shear_converges_to_jaumann_closed_form() {
        // Exact Jaumann hypoelastic simple shear: σ12 = G sin γ, σ11 = −σ22 = G(1 − cos γ).
        let e500 = simple_shear_error(500);
        let e2000 = simple_shear_error(2000);
        let e8000 = simple_shear_error(8000);
        assert!(e2000 < 1e-3, "2000 steps: relative error {e2000:e} < 1e-3");
        assert!(
            e2000 < e500 && e8000 < e2000,
            "error decreases: {e500:e}, {e2000:e}, {e8000:e}"
        );
        // Observed order of convergence (at least first order).
        let order = (e500 / e8000).log2() / 4.0;
        assert!(order > 0.9, "convergence order {order} > 0.9");
    }

    #[test]
    fn energy_is_quadratic_strain_energy_at_small_strain_and_handles_nu_zero() {
        for nu in [0.0, 0.3, 0.45] {
            let m = LinearElastic::new(1000.0, 1.0e7, nu);
            let (lambda, g) = m.lame();
            let eps = Mat3::new(1.0, 0.3, 0.0, 0.3, -0.4, 0.1, 0.0, 0.1, 0.2) * 1e-4;
            let s = m.elastic(&eps);
            let w = m.strain_energy_density(&(Mat3::identity() + eps), &s, &[]);
            let exact = 0.5 * lambda * eps.trace().powi(2) + g * eps.norm_squared();
            assert!(
                (w - exact).abs() < 1e-12 * exact,
                "½σ:C⁻¹:σ = ½ε:C:ε to 1e-12 (ν = {nu})"
            );
            assert!(w > 0.0, "positive energy");
        }
    }

    #[test]
    fn p_wave_modulus_is_lambda_plus_two_g() {
        let m = model();
        let (lambda, g) = m.lame();
        assert!(
            (m.p_wave_modulus() - (lambda + 2.0 * g)).abs() < 1e-6,
            "M = λ + 2G"
        );
    }
}
