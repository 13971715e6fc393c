//! The stiffness of the implicit step: the particles' internal-force derivative.
//!
//! With ΔF_p = I + Σ_I u_I ⊗ ∇S_Ip (gradients at the step-start positions) and the
//! relative first Piola-Kirchhoff stress P = J σ ΔF⁻ᵀ (J = det ΔF), the internal
//! force is f_Ii = Σ_p V_p P_ij ∂S_Ip/∂X_j (thesis 2-21 pulled back,
//! `physics::transfer::internal_force`), and its derivative is
//! K_(Ii)(Jk) = Σ_p V_p ∂S_Ip/∂X_j A_ijkl ∂S_Jp/∂X_l with A = ∂P/∂ΔF. A holds both
//! the material part (from the exact derivative of the stress update, 2-41) and
//! the geometric part (2-42).
//!
//! Axisymmetric (`physics::shape::hoop`): ΔF_θθ = 1 + Σ_J u_Jr h_Jp with the hoop
//! gradient h_Jp = S_Jp / R_p (R_p the step-start radius) and f_Ir gains
//! V_p P_θθ h_Ip, so K gains the hoop couplings (θ = index 2 of A)
//!
//!   V_p [δ_i0 h_I A_θθkl ∂S_J/∂X_l + δ_k0 h_J ∂S_I/∂X_j A_ijθθ + δ_i0 δ_k0 h_I h_J A_θθθθ].

use super::{Components, Coupling, Dofs, Tangent};
use crate::dim::{Mat3, Vector};
use crate::material::driver::numerical_stress_derivative;
use crate::material::{Increment, StressDerivative};
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::kinematics::deformation::Trial;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::implicit::failure::Failure;
use nalgebra::SMatrix;
use rayon::prelude::*;

/// ∂P_ij/∂ΔF_kl, row 3i + j, column 3k + l.
pub type Pk1Derivative = SMatrix<f64, 9, 9>;

/// A_p = ∂P/∂ΔF of every particle, only the D⁴ components A_ijkl with
/// i, j, k, l < D that a D-dimensional tangent reads (16 numbers a particle in
/// 2D instead of 81), at [`ParticleTangents::at`]; in axisymmetric mode also the
/// hoop components (`hoop`).
#[derive(Clone, Debug)]
pub struct ParticleTangents<const D: usize> {
    pub values: Vec<f64>,
    /// Axisymmetric only (else empty): per particle A_θθkl (k, l < D), then
    /// A_ijθθ (i, j < D), then A_θθθθ ([`ParticleTangents::HOOP_LEN`] numbers).
    pub hoop: Vec<f64>,
}

impl<const D: usize> ParticleTangents<D> {
    /// Components per particle.
    pub const LEN: usize = D * D * D * D;

    /// Hoop components per particle (axisymmetric).
    pub const HOOP_LEN: usize = 2 * D * D + 1;

    /// Zero tangents of `n` particles (with hoop components if `axisymmetric`).
    pub fn zeros(n: usize, axisymmetric: bool) -> Self {
        ParticleTangents {
            values: vec![0.0; n * Self::LEN],
            hoop: vec![0.0; if axisymmetric { n * Self::HOOP_LEN } else { 0 }],
        }
    }

    /// The hoop components of particle q (empty unless axisymmetric).
    pub fn hoop_of(&self, q: usize) -> &[f64] {
        self.hoop
            .get(q * Self::HOOP_LEN..(q + 1) * Self::HOOP_LEN)
            .unwrap_or(&[])
    }

    /// The components of particle q.
    pub fn of(&self, q: usize) -> &[f64] {
        &self.values[q * Self::LEN..(q + 1) * Self::LEN]
    }

    /// Position of A_ijkl within a particle's components.
    pub const fn at(i: usize, j: usize, k: usize, l: usize) -> usize {
        ((i * D + j) * D + k) * D + l
    }
}

/// Central-difference step of the numerical stress derivative (preconditioners
/// of materials without an analytic tangent).
const NUMERICAL_STEP: f64 = 1e-6;

/// P = J σ ΔF⁻ᵀ.
pub fn relative_pk1(df: &Mat3, sigma: &Mat3) -> Mat3 {
    let inv_t = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    sigma * inv_t * df.determinant()
}

/// A_ijkl = ∂P_ij/∂ΔF_kl = J [G_kl (σG)_ij + (∂σ_im/∂ΔF_kl) G_mj − (σG)_il G_kj],
/// G = ΔF⁻ᵀ (from ∂J/∂ΔF = J G and ∂G_mj/∂ΔF_kl = −G_ml G_kj), for the indices
/// i, j, k, l < n that the tangent of a D-dimensional problem reads (zero
/// elsewhere; plane strain has no out-of-plane gradients): n = D, or n = 3 when
/// `hoop` (axisymmetric: ΔF_θθ varies too).
pub fn pk1_derivative<const D: usize>(
    df: &Mat3,
    sigma: &Mat3,
    dsigma: &StressDerivative,
    hoop: bool,
) -> Pk1Derivative {
    let j = df.determinant();
    let g = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    let sg = sigma * g;
    let mut a = Pk1Derivative::zeros();
    let n = if hoop { 3 } else { D };
    for i in 0..n {
        for jj in 0..n {
            for k in 0..n {
                for l in 0..n {
                    let col = 3 * k + l;
                    let material: f64 = (0..3).map(|m| dsigma[(3 * i + m, col)] * g[(m, jj)]).sum();
                    a[(3 * i + jj, col)] =
                        j * (g[(k, l)] * sg[(i, jj)] + material - sg[(i, l)] * g[(k, jj)]);
                }
            }
        }
    }
    a
}

/// A_p = ∂P/∂ΔF of every particle at the trial state: from the material's
/// exact stress derivative, or, when `numerical` (Krylov preconditioners
/// only), from central differences of its stress update if it has none.
pub fn particle_tangents<const D: usize>(
    m: &Model<D>,
    trial: &Trial<D>,
    st: &Stencils<D>,
    map: &NodeMap,
    numerical: bool,
) -> Result<ParticleTangents<D>, Failure> {
    let p = &m.particles;
    let history_old = p.history.slots(&p.history.data);
    let hoop = m.axisymmetric;
    let mut a = ParticleTangents::<D>::zeros(p.len(), hoop);
    let mut hoop_values = std::mem::take(&mut a.hoop);
    let hoop_slots: Vec<&mut [f64]> = if hoop {
        hoop_values
            .chunks_mut(ParticleTangents::<D>::HOOP_LEN)
            .collect()
    } else {
        (0..p.len()).map(|_| <&mut [f64]>::default()).collect()
    };
    // The first particle without a tangent (the same for any number of threads).
    let failed = a
        .values
        .par_chunks_mut(ParticleTangents::<D>::LEN)
        .zip(hoop_slots)
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .filter_map(|(q, (a_q, hoop_q))| {
            let df = trial.df(st, map, q);
            let inc = Increment::new(p.f.get(q), df, 0.0, p.stress.get(q), history_old[q]);
            let mat = m.materials[p.material[q] as usize].as_ref();
            mat.stress_derivative(&inc)
                .or_else(|| {
                    numerical.then(|| numerical_stress_derivative(mat, &inc, NUMERICAL_STEP))
                })
                .map(|ds| {
                    // ∂P/∂ΔF of the total stress σ′ − p I at fixed p (p of the step start).
                    let total = p.total_stress(q, &trial.stress.get(q));
                    let full = pk1_derivative::<D>(&df, &total, &ds, hoop);
                    compact::<D>(&full, a_q);
                    if hoop {
                        compact_hoop::<D>(&full, hoop_q);
                    }
                })
                .is_none()
                .then_some(q)
        })
        .min();
    a.hoop = hoop_values;
    match failed {
        None => Ok(a),
        Some(q) => {
            let model = m.materials[p.material[q] as usize].model();
            Err(Failure {
                particle: Some(q),
                message: format!(
                    "material model `{model}` has no analytic tangent, which the direct solver \
                 needs; choose a matrix-free solver: linear_solver = \"gmres\" (or \"cg\" \
                 for symmetric problems) in [solver] or the [[stage]]"
                ),
            })
        }
    }
}

/// The components with indices < D of a 9×9 A, into `out` (`ParticleTangents`).
fn compact<const D: usize>(full: &Pk1Derivative, out: &mut [f64]) {
    for i in 0..D {
        for j in 0..D {
            for k in 0..D {
                for l in 0..D {
                    out[ParticleTangents::<D>::at(i, j, k, l)] = full[(3 * i + j, 3 * k + l)];
                }
            }
        }
    }
}

/// The hoop components of a 9×9 A (θ = 2), into `out` (`ParticleTangents::hoop`).
fn compact_hoop<const D: usize>(full: &Pk1Derivative, out: &mut [f64]) {
    for k in 0..D {
        for l in 0..D {
            out[k * D + l] = full[(8, 3 * k + l)];
            out[D * D + k * D + l] = full[(3 * k + l, 8)];
        }
    }
    out[2 * D * D] = full[(8, 8)];
}

/// The hoop part of K_(Ii)(Jk)/V_p for one particle (module doc):
/// δ_i0 h_I A_θθkl ∂S_J/∂X_l + δ_k0 h_J ∂S_I/∂X_j A_ijθθ + δ_i0 δ_k0 h_I h_J A_θθθθ,
/// with `hoop` the particle's hoop components (`ParticleTangents::hoop_of`)
/// and h_I, h_J the entries' hoop gradients S / R.
#[allow(clippy::too_many_arguments)]
pub fn hoop_coupling<const D: usize>(
    grad_i: &Vector<D>,
    h_i: f64,
    hoop: &[f64],
    grad_j: &Vector<D>,
    h_j: f64,
    i: usize,
    k: usize,
) -> f64 {
    let mut v = 0.0;
    if i == 0 {
        v += h_i * (0..D).map(|l| hoop[k * D + l] * grad_j[l]).sum::<f64>();
    }
    if k == 0 {
        v += h_j
            * (0..D)
                .map(|j| grad_i[j] * hoop[D * D + i * D + j])
                .sum::<f64>();
    }
    if i == 0 && k == 0 {
        v += h_i * h_j * hoop[2 * D * D];
    }
    v
}

/// Whether one particle's hoop components (`ParticleTangents::hoop_of`) have
/// the major symmetry A_θθkl = A_klθθ to round-off of the largest of them and
/// of its in-plane components `a`.
pub fn hoop_symmetric<const D: usize>(hoop: &[f64], a: &[f64]) -> bool {
    let size = (hoop.iter().chain(a)).fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    let asymmetry = (0..D * D).fold(0.0f64, |m, n| m.max((hoop[n] - hoop[D * D + n]).abs()));
    asymmetry <= 1e-10 * size
}

/// ∇S_I · A · ∇S_J for components (i, k): Σ_jl ∂S_I/∂X_j A_ijkl ∂S_J/∂X_l, with
/// `a` one particle's components (`ParticleTangents::of`).
pub fn coupling<const D: usize>(
    grad_i: &Vector<D>,
    a: &[f64],
    grad_j: &Vector<D>,
    i: usize,
    k: usize,
) -> f64 {
    let mut v = 0.0;
    for j in 0..D {
        for l in 0..D {
            v += grad_i[j] * a[ParticleTangents::<D>::at(i, j, k, l)] * grad_j[l];
        }
    }
    v
}

/// Whether one particle's A (`ParticleTangents::of`) has major symmetry
/// (A_ijkl = A_klij) to round-off, i.e. whether its term of the tangent is
/// symmetric.
pub fn major_symmetric<const D: usize>(a: &[f64]) -> bool {
    let at = ParticleTangents::<D>::at;
    let (mut asymmetry, mut size) = (0.0f64, f64::MIN_POSITIVE);
    for (i, j, k, l) in indices::<D>() {
        asymmetry = asymmetry.max((a[at(i, j, k, l)] - a[at(k, l, i, j)]).abs());
        size = size.max(a[at(i, j, k, l)].abs());
    }
    asymmetry <= 1e-10 * size
}

/// Every (i, j, k, l) with indices < D, in the order of `ParticleTangents`.
pub fn indices<const D: usize>() -> impl Iterator<Item = (usize, usize, usize, usize)> {
    (0..ParticleTangents::<D>::LEN).map(|n| (n / (D * D * D), n / (D * D) % D, n / D % D, n % D))
}

/// Adds Σ_p V_p ∇S_I A_p ∇S_J (2-41, 2-42), with the hoop couplings in
/// axisymmetric mode, to the tangent `k`.
pub fn add_stiffness<const D: usize>(
    k: &mut Tangent,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    a: &ParticleTangents<D>,
) {
    let at = ParticleTangents::<D>::at;
    k.add_terms(
        map,
        st,
        dofs,
        Coupling::<D, D>::displacements(Components::All),
        |q, e2, needed, block| {
            // b_ijk = Σ_l A_ijkl ∂S_J/∂X_l, then V Σ_j ∂S_I/∂X_j b_ijk for each node I.
            let (ap, g2) = (a.of(q), &st.grad(e2));
            let mut b = [[[0.0; D]; D]; D];
            for (i, bi) in b.iter_mut().enumerate() {
                for (j, bij) in bi.iter_mut().enumerate() {
                    for (kk, bijk) in bij.iter_mut().enumerate() {
                        *bijk = (0..D).map(|l| ap[at(i, j, kk, l)] * g2[l]).sum();
                    }
                }
            }
            let hoop = a.hoop_of(q);
            for (local, e1) in st.range(q).enumerate().filter(|&(l, _)| needed[l]) {
                let g1 = &st.grad(e1);
                let out = &mut block[local * D * D..(local + 1) * D * D];
                for i in 0..D {
                    for kk in 0..D {
                        let mut v: f64 = (0..D).map(|j| g1[j] * b[i][j][kk]).sum();
                        if !hoop.is_empty() {
                            let (h1, h2) = (st.hoop[e1], st.hoop[e2]);
                            v += hoop_coupling(g1, h1, hoop, g2, h2, i, kk);
                        }
                        out[i * D + kk] = v * volume[q];
                    }
                }
            }
            true
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::neo_hookean::NeoHookean;
    use crate::material::{Increment, Material};

    /// A = ∂P/∂ΔF against central differences of P(ΔF) = J σ(ΔF) ΔF⁻ᵀ.
    #[test]
    fn pk1_derivative_matches_finite_differences() {
        let m = NeoHookean::new(1000.0, 1.0e6, 0.3);
        let f_old = Mat3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.02);
        let df = Mat3::new(1.02, 0.05, 0.01, -0.03, 0.97, 0.02, 0.01, -0.02, 1.01);
        let stress_old = m.cauchy(&f_old);
        let pk1 = |df: &Mat3| {
            let inc = Increment::new(f_old, *df, 0.0, stress_old, &[]);
            relative_pk1(df, &m.update(&inc, &mut []))
        };
        let inc = Increment::new(f_old, df, 0.0, stress_old, &[]);
        let a = pk1_derivative::<3>(
            &df,
            &m.update(&inc, &mut []),
            &m.stress_derivative(&inc).unwrap(),
            false,
        );
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for col in 0..9 {
            let mut dp = df;
            let mut dm = df;
            dp[(col / 3, col % 3)] += h;
            dm[(col / 3, col % 3)] -= h;
            let fd = (pk1(&dp) - pk1(&dm)) / (2.0 * h);
            for row in 0..9 {
                worst = worst.max((fd[(row / 3, row % 3)] - a[(row, col)]).abs());
            }
        }
        assert!(
            worst < 1e-6 * a.amax(),
            "max |A − A_fd| = {worst:.3e} (scale {:.3e})",
            a.amax()
        );
    }
}
