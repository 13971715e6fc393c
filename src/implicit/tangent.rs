//! Internal force and consistent tangent of the implicit step, in the
//! configuration at the start of the step (updated Lagrangian).
//!
//! With ΔF_p = I + Σ_I u_I ⊗ ∇S_Ip (gradients at the step-start positions) and the
//! relative first Piola-Kirchhoff stress P = J σ ΔF⁻ᵀ (J = det ΔF), the internal
//! force is f_Ii = Σ_p V_p P_ij ∂S_Ip/∂X_j (thesis 2-21 pulled back), and its
//! derivative is K_(Ii)(Jk) = Σ_p V_p ∂S_Ip/∂X_j A_ijkl ∂S_Jp/∂X_l with
//! A = ∂P/∂ΔF. A holds both the material part (from the exact derivative of the
//! stress update, 2-41) and the geometric part (2-42).

use crate::dim::{restrict, Mat3, Tensor, Vector};
use crate::material::StressDerivative;
use crate::shape::Stencils;
use crate::transfer::{NodeMap, MIN_PARALLEL_LEN};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// ∂P_ij/∂ΔF_kl, row 3i + j, column 3k + l.
pub type Pk1Derivative = SMatrix<f64, 9, 9>;

/// P = J σ ΔF⁻ᵀ.
pub fn relative_pk1(df: &Mat3, sigma: &Mat3) -> Mat3 {
    let inv_t = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    sigma * inv_t * df.determinant()
}

/// A_ijkl = ∂P_ij/∂ΔF_kl = J [G_kl (σG)_ij + (∂σ_im/∂ΔF_kl) G_mj − (σG)_il G_kj],
/// G = ΔF⁻ᵀ (from ∂J/∂ΔF = J G and ∂G_mj/∂ΔF_kl = −G_ml G_kj).
pub fn pk1_derivative(df: &Mat3, sigma: &Mat3, dsigma: &StressDerivative) -> Pk1Derivative {
    let j = df.determinant();
    let g = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    let sg = sigma * g;
    Pk1Derivative::from_fn(|row, col| {
        let (i, jj, k, l) = (row / 3, row % 3, col / 3, col % 3);
        let material: f64 = (0..3).map(|m| dsigma[(3 * i + m, col)] * g[(m, jj)]).sum();
        j * (g[(k, l)] * sg[(i, jj)] + material - sg[(i, l)] * g[(k, jj)])
    })
}

/// Internal force at the active nodes: f_I = Σ_p V_p P_p ∇S_Ip.
pub fn internal_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    pk1: &[Mat3],
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        let p: Tensor<D> = restrict::<D>(&pk1[q]);
        p * st.grad[e] * volume[q]
    })
}

/// Global numbering of the unknowns: one per free component of each active node.
#[derive(Clone, Debug, Default)]
pub struct Dofs {
    /// index[a·D + d]: equation number, or `NONE` for a prescribed component.
    pub index: Vec<u32>,
    pub free: usize,
}

impl Dofs {
    pub const NONE: u32 = u32::MAX;

    pub fn new<const D: usize>(fixed: impl Iterator<Item = [bool; D]>) -> Dofs {
        let mut index = Vec::new();
        let mut free = 0;
        for f in fixed {
            for fixed_d in f {
                index.push(if fixed_d { Self::NONE } else { free as u32 });
                free += usize::from(!fixed_d);
            }
        }
        Dofs { index, free }
    }

    pub fn of(&self, a: usize, d: usize, dim: usize) -> Option<usize> {
        match self.index[a * dim + d] {
            Self::NONE => None,
            i => Some(i as usize),
        }
    }
}

/// (row, column, value) entries of a sparse matrix.
pub type Triplets = Vec<(usize, usize, f64)>;

/// Triplets of Σ_p V_p ∇S_I A_p ∇S_J over the free unknowns, particle by particle
/// in order (deterministic). Also reports whether every A_p has major symmetry
/// (A_ijkl = A_klij), i.e. whether the assembled matrix is symmetric.
pub fn stiffness_triplets<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    a: &[Pk1Derivative],
) -> (Triplets, bool) {
    let per_particle: Vec<(Triplets, bool)> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 8)
        .map(|q| {
            let ap = &a[q];
            let symmetric =
                (ap - ap.transpose()).amax() <= 1e-10 * ap.amax().max(f64::MIN_POSITIVE);
            let mut out = Vec::new();
            for e1 in st.range(q) {
                let n1 = map.local[st.node[e1] as usize] as usize;
                for e2 in st.range(q) {
                    let n2 = map.local[st.node[e2] as usize] as usize;
                    for i in 0..D {
                        let Some(r) = dofs.of(n1, i, D) else { continue };
                        for k in 0..D {
                            let Some(c) = dofs.of(n2, k, D) else { continue };
                            let mut v = 0.0;
                            for j in 0..D {
                                for l in 0..D {
                                    v += st.grad[e1][j]
                                        * ap[(3 * i + j, 3 * k + l)]
                                        * st.grad[e2][l];
                                }
                            }
                            out.push((r, c, v * volume[q]));
                        }
                    }
                }
            }
            (out, symmetric)
        })
        .collect();
    let symmetric = per_particle.iter().all(|(_, s)| *s);
    (
        per_particle.into_iter().flat_map(|(t, _)| t).collect(),
        symmetric,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Increment, Material, NeoHookean};

    /// A = ∂P/∂ΔF against central differences of P(ΔF) = J σ(ΔF) ΔF⁻ᵀ.
    #[test]
    fn pk1_derivative_matches_finite_differences() {
        let m = NeoHookean::new(1000.0, 1.0e6, 0.3);
        let f_old = Mat3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.02);
        let df = Mat3::new(1.02, 0.05, 0.01, -0.03, 0.97, 0.02, 0.01, -0.02, 1.01);
        let stress_old = m.cauchy(&f_old);
        let pk1 = |df: &Mat3| {
            let inc = Increment {
                f_old,
                df: *df,
                dt: 0.0,
                stress_old,
                history_old: &[],
            };
            relative_pk1(df, &m.update(&inc, &mut []))
        };
        let inc = Increment {
            f_old,
            df,
            dt: 0.0,
            stress_old,
            history_old: &[],
        };
        let a = pk1_derivative(
            &df,
            &m.update(&inc, &mut []),
            &m.stress_derivative(&inc).unwrap(),
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
