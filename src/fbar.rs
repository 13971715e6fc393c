//! F-bar against volumetric locking (Coombs, Charlton, Cortis & Augarde 2018,
//! "Overcoming volumetric locking in material point methods", CMAME 333).
//!
//! Linear interpolation with several particles per cell cannot represent an
//! isochoric flow field (plastic flow with ψ = 0, nearly incompressible
//! elasticity) without spurious volume changes at the particles: the
//! discretisation locks. F-bar relaxes the constraint to one per background cell:
//! each particle's incremental volume change is replaced by the average over the
//! particles whose centre lies in its cell,
//!
//!   ΔF̄_p = (ΔJ̄_c / ΔJ_p)^{1/n} ΔF_p,  ΔJ̄_c = Σ_{q∈c} V_q ΔJ_q / Σ_{q∈c} V_q,
//!
//! with V_q the step-start volumes and n = D (plane strain: the in-plane block is
//! scaled, ΔF_zz = 1 stays, so det ΔF̄_p = ΔJ̄_c). The particle then follows ΔF̄
//! throughout: stress σ(ΔF̄), F ← ΔF̄ F, V = det F V₀, and the implicit internal
//! force uses the relative first Piola-Kirchhoff stress P̄ = det ΔF̄ σ ΔF̄⁻ᵀ. Cells
//! are those of the particles' step-start positions.

use crate::dim::{Mat3, Vector};
use crate::grid::Grid;
use crate::implicit::tangent::{push_terms, stiffness_triplets, Dofs, Pk1Derivative, Triplets};
use crate::shape::Stencils;
use crate::transfer::{NodeMap, MIN_PARALLEL_LEN};
use rayon::prelude::*;

/// The occupied background cells and their particles.
#[derive(Clone, Debug, Default)]
pub struct Cells {
    /// Occupied cell (0..len) of each particle.
    pub of: Vec<u32>,
    /// CSR offsets into `members`, one range per occupied cell.
    start: Vec<u32>,
    /// Particles of each cell, in increasing order.
    members: Vec<u32>,
}

impl Cells {
    /// Group the particles by the grid cell containing their centre (a point on
    /// a cell face belongs to the cell above it, one on the max face of the grid
    /// to the last cell).
    pub fn locate<const D: usize>(grid: &Grid<D>, x: &[Vector<D>]) -> Cells {
        let cell = |x: &Vector<D>| {
            (0..D).rev().fold(0usize, |acc, d| {
                let xi = ((x[d] - grid.min[d]) / grid.h[d]).clamp(0.0, grid.cells[d] as f64);
                acc * grid.cells[d] + (xi.floor() as usize).min(grid.cells[d] - 1)
            })
        };
        let mut pairs: Vec<(usize, u32)> = x
            .par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .enumerate()
            .map(|(q, x)| (cell(x), q as u32))
            .collect();
        pairs.par_sort_unstable();
        let mut cells = Cells {
            of: vec![0; x.len()],
            start: vec![0],
            members: Vec::with_capacity(x.len()),
        };
        for (k, &(c, q)) in pairs.iter().enumerate() {
            if k > 0 && c != pairs[k - 1].0 {
                cells.start.push(k as u32);
            }
            cells.of[q as usize] = cells.start.len() as u32 - 1;
            cells.members.push(q);
        }
        cells.start.push(pairs.len() as u32);
        cells
    }

    /// Number of occupied cells.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles of occupied cell c, in increasing order.
    pub fn members(&self, c: usize) -> &[u32] {
        &self.members[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// ΔJ̄_c = Σ V_q ΔJ_q / Σ V_q of every occupied cell, each sum taken in
    /// increasing particle order (the same for any number of threads).
    pub fn mean_dilatation(&self, volume: &[f64], dj: &[f64]) -> Vec<f64> {
        (0..self.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN / 4)
            .map(|c| {
                let (mut v, mut vj) = (0.0, 0.0);
                for &q in self.members(c) {
                    v += volume[q as usize];
                    vj += volume[q as usize] * dj[q as usize];
                }
                vj / v
            })
            .collect()
    }
}

/// β = (ΔJ̄ / ΔJ)^{1/D}, the factor that gives ΔF_p the cell's volume change.
pub fn scale_factor<const D: usize>(dj_bar: f64, dj: f64) -> f64 {
    (dj_bar / dj).powf(1.0 / D as f64)
}

/// β ΔF on the D×D block (plane strain: ΔF_zz = 1 stays).
pub fn scaled<const D: usize>(df: &Mat3, beta: f64) -> Mat3 {
    let mut out = *df;
    for i in 0..D {
        for j in 0..D {
            out[(i, j)] *= beta;
        }
    }
    out
}

/// The F-bar state of a trial: ΔF_p before the modification, the cells and the
/// cells' mean dilatation.
#[derive(Clone, Debug, Default)]
pub struct FBarState {
    pub cells: Cells,
    /// ΔF_p = I + Σ u_I ⊗ ∇S_Ip (before F-bar).
    pub df: Vec<Mat3>,
    /// ΔJ̄_c of every occupied cell.
    pub dj_bar: Vec<f64>,
}

/// Consistent tangent of the F-bar internal force f_Ii = Σ_p V_p P̄_ij(ΔF̄_p) ∂S_Ip/∂X_j
/// over the free unknowns (particles in order, then cells in order: deterministic).
///
/// With g_q^J = ΔF_q⁻ᵀ ∇S_Jq (so ∂ΔJ_q/∂u_Jk = ΔJ_q g_qk^J) and w_q = V_q / Σ_{c} V,
///   ∂ΔF̄_p,ab/∂u_Jk = β_p [δ_ak ∇S_Jp,b − ΔF_p,ab g_pk^J / n]
///                   + β_p ΔF_p,ab / (n ΔJ̄_c) Σ_{q∈c} w_q ΔJ_q g_qk^J,
/// so with M_p = A_p : ΔF_p (A = ∂P/∂ΔF at ΔF̄_p) the tangent is the standard
/// one with Ã_p,ijkl = β_p (A_p,ijkl − M_p,ij (ΔF_p⁻ᵀ)_kl / n), plus, per cell, the
/// outer product a_c ⊗ h_c of
///   a_c(I)_i = Σ_{p∈c} V_p β_p / (n ΔJ̄_c) ∇S_Ip,j M_p,ij,
///   h_c(J)_k = Σ_{q∈c} w_q ΔJ_q g_qk^J,
/// which couples each particle to the nodes of every particle in its cell.
pub fn tangent_triplets<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    state: &FBarState,
    a: &[Pk1Derivative],
) -> Triplets {
    let n = D as f64;
    let cells = &state.cells;
    let dj: Vec<f64> = state.df.iter().map(|f| f.determinant()).collect();
    let beta: Vec<f64> = (0..volume.len())
        .map(|q| scale_factor::<D>(state.dj_bar[cells.of[q] as usize], dj[q]))
        .collect();
    let inv_t: Vec<Mat3> = state
        .df
        .iter()
        .map(|f| f.try_inverse().unwrap_or_else(Mat3::zeros).transpose())
        .collect();
    // M_p,ij = Σ_{a,b<D} A_p,ijab ΔF_p,ab.
    let m: Vec<Mat3> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            Mat3::from_fn(|i, j| {
                let mut s = 0.0;
                for a2 in 0..D {
                    for b in 0..D {
                        s += a[q][(3 * i + j, 3 * a2 + b)] * state.df[q][(a2, b)];
                    }
                }
                s
            })
        })
        .collect();
    let a_tilde: Vec<Pk1Derivative> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            Pk1Derivative::from_fn(|row, col| {
                let (i, j, k, l) = (row / 3, row % 3, col / 3, col % 3);
                let local = if k < D && l < D {
                    m[q][(i, j)] * inv_t[q][(k, l)] / n
                } else {
                    0.0
                };
                beta[q] * (a[q][(row, col)] - local)
            })
        })
        .collect();
    let (mut triplets, _) = stiffness_triplets(map, st, dofs, volume, &a_tilde);

    let node = |e: usize| map.local[st.node[e] as usize] as usize;
    // Adds v at `node` of a short list of (node, vector) pairs.
    fn add<const D: usize>(list: &mut Vec<(usize, Vector<D>)>, node: usize, v: Vector<D>) {
        match list.iter_mut().find(|(a, _)| *a == node) {
            Some((_, x)) => *x += v,
            None => list.push((node, v)),
        }
    }
    let per_cell: Vec<Triplets> = (0..cells.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 16)
        .map(|c| {
            let members = cells.members(c);
            let v_cell: f64 = members.iter().map(|&q| volume[q as usize]).sum();
            let dj_bar = state.dj_bar[c];
            let mut a_c: Vec<(usize, Vector<D>)> = Vec::new();
            let mut h_c: Vec<(usize, Vector<D>)> = Vec::new();
            for &q in members {
                let q = q as usize;
                let coef_a = volume[q] * beta[q] / (n * dj_bar);
                let coef_h = volume[q] / v_cell * dj[q];
                for e in st.range(q) {
                    let grad = &st.grad[e];
                    let av = Vector::<D>::from_fn(|i, _| {
                        (0..D).map(|j| grad[j] * m[q][(i, j)]).sum::<f64>() * coef_a
                    });
                    let hv = Vector::<D>::from_fn(|k, _| {
                        (0..D).map(|l| inv_t[q][(k, l)] * grad[l]).sum::<f64>() * coef_h
                    });
                    add(&mut a_c, node(e), av);
                    add(&mut h_c, node(e), hv);
                }
            }
            let mut out = Triplets::new();
            for (n1, av) in &a_c {
                for i in 0..D {
                    let rows = dofs.terms(*n1, i, D);
                    if rows.as_slice().is_empty() {
                        continue;
                    }
                    for (n2, hv) in &h_c {
                        for k in 0..D {
                            let cols = dofs.terms(*n2, k, D);
                            push_terms(&mut out, &rows, &cols, av[i] * hv[k]);
                        }
                    }
                }
            }
            out
        })
        .collect();
    triplets.extend(per_cell.into_iter().flatten());
    triplets
}
