//! The interface every constitutive model implements (`Material`), the state it
//! updates from (`Increment`) and the small helpers models share (Lamé constants,
//! reduced angles, the stress-derivative layout).

use crate::dim::{compose, Mat3};
use nalgebra::SMatrix;

/// ∂σ_ij/∂ΔF_kl with (i,j) and (k,l) flattened row-major (index 3i + j).
pub type StressDerivative = SMatrix<f64, 9, 9>;

/// The state at the start of an increment and the increment itself.
///
/// `f` is F_new = ΔF F_old, formed once by the constructors for the frame and
/// every model that reads it: build increments with `new` (or `with_df` from
/// another), not field by field, so that `f` follows `df`.
#[derive(Clone, Copy, Debug)]
pub struct Increment<'a> {
    /// Deformation gradient at the start of the increment.
    pub f_old: Mat3,
    /// Incremental deformation gradient: F_new = ΔF F_old.
    pub df: Mat3,
    /// Deformation gradient at the end of the increment, ΔF F_old (2-31).
    pub f: Mat3,
    /// Time increment (rate-dependent models; 0 for quasi-static calls).
    pub dt: f64,
    /// Cauchy stress at the start of the increment.
    pub stress_old: Mat3,
    /// History variables at the start of the increment (empty if the model has none).
    pub history_old: &'a [f64],
}

impl<'a> Increment<'a> {
    /// The increment ΔF from the state (F_old, σ_old, history) over `dt`.
    #[inline(always)]
    pub fn new(f_old: Mat3, df: Mat3, dt: f64, stress_old: Mat3, history_old: &'a [f64]) -> Self {
        Increment {
            f_old,
            df,
            f: compose(&df, &f_old),
            dt,
            stress_old,
            history_old,
        }
    }

    /// An increment ΔF from the undeformed, unstressed state.
    pub fn at_rest(df: Mat3, history_old: &'a [f64]) -> Self {
        Increment::new(Mat3::identity(), df, 0.0, Mat3::zeros(), history_old)
    }

    /// The same start state under another ΔF.
    pub fn with_df(&self, df: Mat3) -> Self {
        Increment::new(self.f_old, df, self.dt, self.stress_old, self.history_old)
    }
}

/// Cohesion, friction angle and dilation angle (radians), or their derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strength {
    pub cohesion: f64,
    pub friction_angle: f64,
    pub dilation_angle: f64,
}

/// What the flow between points needs of a point's pore water
/// (`Material::pore_fluid`; built by `material::undrained`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoreFluid {
    /// K_f = K_w/n.
    pub bulk_modulus: f64,
    /// k/γ_w (0: undrained).
    pub mobility: f64,
    /// The index of p_ex in the point's history; with mobility > 0 the next
    /// slot holds ln J at the last flow update (`physics::pore_flow`).
    pub slot: usize,
}

pub trait Material: CloneMaterial + Send + Sync + std::fmt::Debug {
    /// Model name as written in scene files.
    fn model(&self) -> &'static str;

    /// Reference mass density ρ0.
    fn density(&self) -> f64;

    /// Number of history variables per particle (0: none are allocated).
    fn n_history(&self) -> usize {
        0
    }

    /// Cauchy stress at the end of the increment; writes the new history.
    fn update(&self, inc: &Increment, history_new: &mut [f64]) -> Mat3;

    /// Small-strain P-wave modulus λ + 2G, for the CFL condition (2-45).
    fn p_wave_modulus(&self) -> f64;

    /// Stored (strain) energy per unit current volume at deformation `f` and stress
    /// `stress`.
    fn strain_energy_density(&self, f: &Mat3, stress: &Mat3, history: &[f64]) -> f64;

    /// Exact derivative ∂σ_new/∂ΔF of `update`, or `None` if the model has no
    /// analytic tangent (the matrix-free implicit path still serves it).
    fn stress_derivative(&self, _inc: &Increment) -> Option<StressDerivative> {
        None
    }

    /// Whether the model supplies `stress_derivative` (asked at rest), which the
    /// direct implicit solver needs; the Krylov solvers do not.
    fn has_analytic_tangent(&self) -> bool {
        let history = vec![0.0; self.n_history()];
        let at_rest = Increment::at_rest(Mat3::identity(), &history);
        self.stress_derivative(&at_rest).is_some()
    }

    /// Whether the update integrates from the stored stress (rate and
    /// return-mapping models), so that a prescribed initial stress (geostatic)
    /// persists; hyperelastic models compute the stress from F alone.
    fn integrates_from_stored_stress(&self) -> bool {
        false
    }

    /// Set the history of a point that starts at `stress` (its initial Cauchy
    /// stress at F = I: geostatic, or a particle file's), e.g. a
    /// pre-consolidation pressure from an over-consolidation ratio. The history
    /// is zero before; most models keep it so.
    fn initial_history(&self, _stress: &Mat3, _history: &mut [f64]) {}

    /// The peak frictional strength c, φ, ψ (radians; for Jáky's K0 = 1 − sin φ
    /// and the footing's cohesion), `None` for a model without one.
    fn frictional_strength(&self) -> Option<Strength> {
        None
    }

    /// The same model with its shear strength reduced by the factor F (strength
    /// reduction, Griffiths & Lane 1999): c/F, tan φ/F and tan ψ/F, residual values
    /// included. `None`: the model has no frictional strength to reduce.
    fn with_reduced_strength(&self, _factor: f64) -> Option<Box<dyn Material>> {
        None
    }

    /// The equivalent plastic strain held in `history` (`None`: the model has none).
    fn equivalent_plastic_strain(&self, _history: &[f64]) -> Option<f64> {
        None
    }

    /// The excess pore pressure held in `history` (compression positive) of an
    /// undrained material (`material::undrained`), `None` for the others.
    fn excess_pore_pressure(&self, _history: &[f64]) -> Option<f64> {
        None
    }

    /// The pore water of a saturated point (`material::undrained`: undrained
    /// or coupled), `None` for the others.
    fn pore_fluid(&self) -> Option<PoreFluid> {
        None
    }

    /// Whether the model erodes points at all (`material::erosion`).
    fn erodes(&self) -> bool {
        false
    }

    /// Whether the point with this history is eroded: left out of the
    /// particle–grid transfers (`material::erosion`).
    fn eroded(&self, _history: &[f64]) -> bool {
        false
    }

    /// Wave speed c = √(M/ρ) at the current Jacobian J (ρ = ρ0/J) and history.
    fn wave_speed(&self, j: f64, _history: &[f64]) -> f64 {
        (self.p_wave_modulus() * j / self.density()).sqrt()
    }
}

/// A copy of a material behind `Box<dyn Material>` (the model keeps the
/// materials as built to reduce their strength from them again).
pub trait CloneMaterial {
    fn clone_material(&self) -> Box<dyn Material>;
}

impl<T: Material + Clone + 'static> CloneMaterial for T {
    fn clone_material(&self) -> Box<dyn Material> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn Material> {
    fn clone(&self) -> Self {
        self.clone_material()
    }
}

/// Write ∂σ/∂ΔF_kl (a 3×3 tensor) into column 3k + l of the stress derivative.
pub fn set_derivative_column(d: &mut StressDerivative, k: usize, l: usize, ds: &Mat3) {
    for i in 0..3 {
        for j in 0..3 {
            d[(3 * i + j, 3 * k + l)] = ds[(i, j)];
        }
    }
}

/// Debug checks of the (ρ0, E, ν) constructors; the scene validation gives the
/// user-facing errors.
pub(crate) fn debug_check_elastic(density: f64, youngs_modulus: f64, poisson_ratio: f64) {
    debug_assert!(density > 0.0, "density must be positive");
    debug_assert!(youngs_modulus > 0.0, "Young's modulus must be positive");
    debug_assert!(
        poisson_ratio > -1.0 && poisson_ratio < 0.5,
        "Poisson's ratio must lie in (-1, 0.5)"
    );
}

/// A friction (or dilation) angle whose tangent is divided by `factor`:
/// atan(tan θ / F) (strength reduction).
pub fn reduced_angle(theta: f64, factor: f64) -> f64 {
    (theta.tan() / factor).atan()
}

/// Lamé constants from Young's modulus and Poisson's ratio.
pub fn lame(youngs_modulus: f64, poisson_ratio: f64) -> (f64, f64) {
    let g = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
    let lambda =
        youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
    (lambda, g)
}

/// Small-strain shear modulus of a material: ∂σ_xy/∂ΔF_xy at rest (unstressed,
/// undeformed), from its stress derivative, or by a central difference of its
/// stress update when it has none. For isotropic elasticity this is G.
pub fn shear_modulus(m: &dyn Material) -> f64 {
    let history = vec![0.0; m.n_history()];
    let at_rest = |df| Increment::at_rest(df, &history);
    if let Some(d) = m.stress_derivative(&at_rest(Mat3::identity())) {
        return d[(1, 1)];
    }
    let h = 1e-7;
    let sigma_xy = |s: f64| {
        let mut df = Mat3::identity();
        df[(0, 1)] = s;
        let mut scratch = history.clone();
        m.update(&at_rest(df), &mut scratch)[(0, 1)]
    };
    (sigma_xy(h) - sigma_xy(-h)) / (2.0 * h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::tests::plane;

    #[test]
    fn increments_keep_f_with_their_df() {
        let (f_old, df) = (plane(1), plane(2));
        let inc = Increment::new(f_old, df, 0.0, Mat3::zeros(), &[]);
        assert_eq!(inc.f, df * f_old);
        let other = inc.with_df(plane(5));
        assert_eq!(other.f, plane(5) * f_old);
        assert_eq!(Increment::at_rest(df, &[]).f, df);
    }
}
