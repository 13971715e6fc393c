//! The seat of further nodal fields: a coupled system with D + 1 unknowns per
//! node (the D displacements and a scalar p) assembled through the step's
//! pattern, scatter, ties and Dirichlet elimination, its tangent checked
//! against central differences of its residual, and solved by Newton with the
//! direct solver and with GMRES preconditioned by the geometric multigrid.
//!
//! The system, on the particles and grid of a scene (Biot's consolidation in
//! one implicit step, small strain, with a pressure-dependent permeability so
//! that the tangent is not constant):
//!
//!   r_u,Ii = Σ_p V_p [σ'_ij(ε_p) ∂_j S_Ip − b p_p ∂_i S_Ip − S_Ip g_i],
//!   r_p,I  = Σ_p V_p [b S_Ip tr ε_p + c S_Ip p_p + k(p_p) ∇S_Ip · ∇p_p − S_Ip s],
//!
//! σ' = λ tr ε I + 2 μ ε, ε_p = sym Σ_J u_J ⊗ ∇S_Jp, p_p = Σ_J S_Jp p_J,
//! k(p) = k₀ (1 + κ p²): Biot's consolidation (Biot 1941, J. Appl. Phys.
//! 12:155–164) over one backward-Euler step, r_p the storage and Darcy flow
//! of the step, b the Biot coefficient, c the storage, k the permeability
//! times Δt (the pressure dependence only makes the tangent vary). Its
//! tangent has the blocks
//!
//!   K_uu = Σ V ∇S_I A ∇S_J (the stiffness term of `stiffness`, A elastic),
//!   K_up,(Ii)J = −Σ V b ∂_i S_I S_J,   K_pu,I(Jk) = Σ V b S_I ∂_k S_J,
//!   K_pp,IJ = Σ V [c S_I S_J + k(p) ∇S_I·∇S_J + k'(p) S_J ∇S_I·∇p],
//!
//! unsymmetric (K_up = −K_puᵀ, and the k' term).

use super::stiffness::{add_stiffness, ParticleTangents};
use super::{Components, Coupling, Dofs, Pattern, Storage, Tangent};
use crate::dim::Vector;
use crate::model::Model;
use crate::physics::boundary::conditions::implicit_node_constraint;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{stencils_and_nodes, NodeMap};
use crate::scene::{DirectOrdering, Scene};
use crate::solver::implicit::coarsening::hierarchy;
use crate::solver::implicit::ties::{nodal_support, ties};
use crate::solver::linear::direct::{DirectSolver, Ordering, Structure};
use crate::solver::linear::gmres::gmres;
use crate::solver::linear::iterative::{norm, Settings};
use crate::solver::linear::multigrid::{Csr, Fine, Multigrid};

/// The material and loading of the coupled system (module doc).
#[derive(Clone, Copy, Debug)]
struct Coefficients {
    lambda: f64,
    mu: f64,
    biot: f64,
    storage: f64,
    k0: f64,
    kappa: f64,
    gravity: f64,
    source: f64,
}

const COEFFICIENTS: Coefficients = Coefficients {
    lambda: 1.2,
    mu: 0.8,
    biot: 0.7,
    storage: 0.3,
    k0: 0.5,
    kappa: 2.0,
    gravity: -0.3,
    source: 0.2,
};

/// The prescribed pressure on the top of the body (drained).
const P_TOP: f64 = 0.25;

impl Coefficients {
    fn permeability(&self, p: f64) -> f64 {
        self.k0 * (1.0 + self.kappa * p * p)
    }

    fn permeability_slope(&self, p: f64) -> f64 {
        2.0 * self.k0 * self.kappa * p
    }
}

/// A body on a grid, its particles' stencils and the coupled unknowns.
struct Setup<const D: usize, const N: usize> {
    m: Model<D>,
    st: Stencils<D>,
    map: NodeMap,
    dofs: Dofs,
    /// Nodal values of the prescribed components (zero elsewhere).
    prescribed: Vec<Vector<N>>,
}

/// A block on part of a grid (its right face inside cells, so that some nodes
/// are weakly supported and tied, those with support below `threshold`
/// cells), the base fixed; the scalar field prescribed (to `P_TOP`) at the
/// well-supported nodes of the top row of active nodes.
fn setup<const D: usize, const N: usize>(scene: &str, threshold: f64) -> Setup<D, N> {
    assert_eq!(N, D + 1, "D displacements and one scalar field");
    let scene = Scene::parse("coupled.toml", scene, &[]).unwrap();
    let m = Model::<D>::build(&scene).unwrap();
    let (mut st, mut map) = (Stencils::<D>::default(), NodeMap::default());
    stencils_and_nodes(&m, scene.config.grid.shape_function, &mut st, &mut map);
    let grid_ijk = |a: usize| m.grid.node_ijk(map.grid_node(a));
    let top = (0..map.len()).map(|a| grid_ijk(a)[D - 1]).max().unwrap();
    let support = nodal_support(&map, &st, &m.particles.volume, m.grid.cell_volume());
    let drained = |a: usize| grid_ijk(a)[D - 1] == top && support[a] >= threshold;
    let fixed: Vec<[bool; N]> = (0..map.len())
        .map(|a| {
            let c = implicit_node_constraint(&m.grid, &m.faces, &m.friction, map.grid_node(a));
            std::array::from_fn(|i| if i < D { c.fixed[i] } else { drained(a) })
        })
        .collect();
    let tied = ties(&m.grid, &map, None, &support, &fixed, threshold);
    let prescribed = fixed
        .iter()
        .map(|f| Vector::<N>::from_fn(|i, _| if i == D && f[D] { P_TOP } else { 0.0 }))
        .collect();
    let dofs = Dofs::with_ties(fixed.into_iter(), tied);
    Setup {
        m,
        st,
        map,
        dofs,
        prescribed,
    }
}

/// The displacement gradient (∇u)_ij = Σ_J u_Ji ∂_j S_J, p and ∇p of
/// particle q at the nodal values w.
fn particle_fields<const D: usize, const N: usize>(
    s: &Setup<D, N>,
    w: &[Vector<N>],
    q: usize,
) -> ([[f64; D]; D], f64, Vector<D>) {
    let (mut du, mut p, mut dp) = ([[0.0; D]; D], 0.0, Vector::<D>::zeros());
    for e in s.st.range(q) {
        let (wa, g) = (&w[s.map.local_of(&s.st, e)], s.st.grad(e));
        for i in 0..D {
            for j in 0..D {
                du[i][j] += wa[i] * g[j];
            }
        }
        p += s.st.weight(e) * wa[D];
        dp += g * wa[D];
    }
    (du, p, dp)
}

/// The nodal residual (module doc) at the nodal values w.
fn residual<const D: usize, const N: usize>(
    s: &Setup<D, N>,
    c: &Coefficients,
    w: &[Vector<N>],
) -> Vec<Vector<N>> {
    let mut r = vec![Vector::<N>::zeros(); w.len()];
    for q in 0..s.m.particles.len() {
        let v = s.m.particles.volume[q];
        let (du, p, dp) = particle_fields(s, w, q);
        let trace: f64 = (0..D).map(|i| du[i][i]).sum();
        let sigma = |i: usize, j: usize| {
            let strain = 0.5 * (du[i][j] + du[j][i]);
            2.0 * c.mu * strain + if i == j { c.lambda * trace } else { 0.0 }
        };
        for e in s.st.range(q) {
            let (ra, g, weight) = (
                &mut r[s.map.local_of(&s.st, e)],
                s.st.grad(e),
                s.st.weight(e),
            );
            for i in 0..D {
                let stress: f64 = (0..D).map(|j| sigma(i, j) * g[j]).sum();
                let load = if i == D - 1 { weight * c.gravity } else { 0.0 };
                ra[i] += v * (stress - c.biot * p * g[i] - load);
            }
            ra[D] += v
                * (weight * (c.biot * trace + c.storage * p - c.source)
                    + c.permeability(p) * g.dot(&dp));
        }
    }
    r
}

/// The particles' elastic A_ijkl = λ δ_ij δ_kl + μ (δ_ik δ_jl + δ_il δ_jk).
fn elastic_tangents<const D: usize>(particles: usize, c: &Coefficients) -> ParticleTangents<D> {
    let mut a = ParticleTangents::<D>::zeros(particles, false);
    let delta = |i: usize, j: usize| f64::from(u8::from(i == j));
    for a_q in a.values.chunks_mut(ParticleTangents::<D>::LEN) {
        for (n, (i, j, k, l)) in super::stiffness::indices::<D>().enumerate() {
            a_q[n] = c.lambda * delta(i, j) * delta(k, l)
                + c.mu * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k));
        }
    }
    a
}

/// The tangent of the coupled residual at w (stored whole: it is unsymmetric),
/// block by block through the step's scatter.
fn tangent<'p, const D: usize, const N: usize>(
    s: &Setup<D, N>,
    pattern: &'p Pattern,
    c: &Coefficients,
    w: &[Vector<N>],
) -> Tangent<'p> {
    let (map, st, dofs, volume) = (&s.map, &s.st, &s.dofs, &s.m.particles.volume);
    let storage = Storage::Full;
    let col_ptr = pattern.col_ptr(storage).unwrap();
    let mut k = Tangent {
        pattern,
        col_ptr,
        values: vec![0.0; col_ptr[col_ptr.len() - 1] as usize],
        storage,
    };
    // K_uu: the code's stiffness term, into the displacements' D×D block.
    let a = elastic_tangents::<D>(volume.len(), c);
    add_stiffness(&mut k, map, st, dofs, volume, &a);
    let fields: Vec<(f64, Vector<D>)> = (0..volume.len())
        .map(|q| {
            let (_, p, dp) = particle_fields(s, w, q);
            (p, dp)
        })
        .collect();
    // K_up (rows: the displacements, columns: the scalar field).
    let up = Coupling::<D, 1> {
        rows: 0,
        cols: D,
        components: Components::All,
    };
    k.add_terms(map, st, dofs, up, |q, e2, _, block| {
        for (local, e1) in st.range(q).enumerate() {
            let g1 = st.grad(e1);
            for i in 0..D {
                block[local * D + i] = -volume[q] * c.biot * g1[i] * st.weight(e2);
            }
        }
        true
    });
    // K_pu (rows: the scalar field, columns: the displacements).
    let pu = Coupling::<1, D> {
        rows: D,
        cols: 0,
        components: Components::All,
    };
    k.add_terms(map, st, dofs, pu, |q, e2, _, block| {
        let g2 = st.grad(e2);
        for (local, e1) in st.range(q).enumerate() {
            for kk in 0..D {
                block[local * D + kk] = volume[q] * c.biot * st.weight(e1) * g2[kk];
            }
        }
        true
    });
    // K_pp: storage and the nonlinear Darcy term.
    let pp = Coupling::<1, 1> {
        rows: D,
        cols: D,
        components: Components::Diagonal,
    };
    k.add_terms(map, st, dofs, pp, |q, e2, _, block| {
        let (p, dp) = &fields[q];
        let (g2, w2) = (st.grad(e2), st.weight(e2));
        for (local, e1) in st.range(q).enumerate() {
            let (g1, w1) = (st.grad(e1), st.weight(e1));
            block[local] = volume[q]
                * (c.storage * w1 * w2
                    + c.permeability(*p) * g1.dot(&g2)
                    + c.permeability_slope(*p) * w2 * g1.dot(dp));
        }
        true
    });
    k
}

/// A smooth iterate: displacements of a few per cent of the body, the scalar
/// field about `P_TOP`, the prescribed values kept, the tied nodes following
/// their masters.
fn iterate<const D: usize, const N: usize>(s: &Setup<D, N>) -> Vec<Vector<N>> {
    let mut w: Vec<Vector<N>> = (0..s.map.len())
        .map(|a| {
            let x =
                s.m.grid
                    .node_position(s.m.grid.node_ijk(s.map.grid_node(a)));
            Vector::<N>::from_fn(|i, _| match i {
                _ if s.dofs.of(a, i).is_none() => s.prescribed[a][i],
                _ if i == D => P_TOP + 0.3 * (0.8 * x[0]).sin() * x[D - 1],
                0 => 0.03 * (0.7 * x[D - 1]).sin() + 0.01 * x[0],
                _ => -0.02 * x[0] * x[i] / 4.0,
            })
        })
        .collect();
    s.dofs.follow_ties(&mut w);
    w
}

/// max |K − K_fd| / max |K| over the unknowns: the assembled tangent against
/// central differences of Tᵀ r (step 1e-6).
fn tangent_error<const D: usize, const N: usize>(s: &Setup<D, N>, c: &Coefficients) -> f64 {
    let pattern = Pattern::new(&s.map, &s.st, &s.dofs, None, None, &[]);
    let w = iterate(s);
    let k = tangent(s, &pattern, c, &w);
    let n = s.dofs.free;
    let mut dense = vec![0.0; n * n];
    let km = k.matrix();
    for col in 0..n {
        for (&r, &v) in km.row_idx_of_col_raw(col).iter().zip(km.val_of_col(col)) {
            dense[r as usize * n + col] += v;
        }
    }
    let scale = dense.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let h = 1e-6;
    let mut worst = 0.0f64;
    for col in 0..n {
        let (mut wp, mut wm) = (w.clone(), w.clone());
        let mut e = vec![0.0; n];
        e[col] = 1.0;
        s.dofs.apply_correction(&mut wp, &e, h);
        s.dofs.apply_correction(&mut wm, &e, -h);
        let (rp, rm) = (
            s.dofs.reduce(&residual(s, c, &wp)),
            s.dofs.reduce(&residual(s, c, &wm)),
        );
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * h);
            worst = worst.max((fd - dense[row * n + col]).abs());
        }
    }
    worst / scale
}

/// How the Newton corrections are solved.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Linear {
    Direct,
    /// GMRES(50) to 1e-10, the multigrid V-cycle as preconditioner.
    Multigrid,
}

/// What a Newton solve of the coupled system did.
#[derive(Debug)]
struct Solved<const N: usize> {
    w: Vec<Vector<N>>,
    newton_iterations: usize,
    /// ‖Tᵀ r‖ at the start and at the end.
    residuals: (f64, f64),
    /// The most GMRES iterations of one correction (multigrid).
    krylov: usize,
    /// The multigrid's levels (0 with the direct solver).
    levels: usize,
}

/// Newton from the prescribed values until ‖Tᵀ r‖ ≤ 1e-11 of its start.
fn solve<const D: usize, const N: usize>(
    s: &Setup<D, N>,
    c: &Coefficients,
    linear: Linear,
) -> Solved<N> {
    let pattern = Pattern::new(&s.map, &s.st, &s.dofs, None, None, &[]);
    let mut w = s.prescribed.clone();
    s.dofs.follow_ties(&mut w);
    let start = norm(&s.dofs.reduce(&residual(s, c, &w)));
    let (mut direct, mut krylov, mut levels) = (DirectSolver::new(), 0, 0);
    let mut multigrid = (linear == Linear::Multigrid).then(|| {
        let h = hierarchy(&s.m.grid, &s.map.active, &s.dofs, 60);
        assert!(h.levels.iter().all(|l| l.components == N));
        levels = h.levels.len();
        Multigrid::new(h.transfers)
    });
    for iteration in 0..20 {
        let r = s.dofs.reduce(&residual(s, c, &w));
        if norm(&r) <= 1e-11 * start {
            return Solved {
                w,
                newton_iterations: iteration,
                residuals: (start, norm(&r)),
                krylov,
                levels,
            };
        }
        let k = tangent(s, &pattern, c, &w);
        let rhs: Vec<f64> = r.iter().map(|v| -v).collect();
        let du = match multigrid.as_mut() {
            None => {
                let (_, du) = direct
                    .factorize_and_solve(k.matrix(), Structure::General, Ordering::Amd, &rhs)
                    .unwrap();
                du
            }
            Some(mg) => {
                mg.refresh(Fine::Rows(Csr::from_csc(k.matrix())), false)
                    .unwrap();
                let mut du = vec![0.0; rhs.len()];
                let settings = Settings {
                    tolerance: 1e-10,
                    max_iterations: 500,
                    restart: 50,
                };
                let apply = |v: &[f64], y: &mut [f64]| -> Result<(), ()> {
                    y.copy_from_slice(&k.apply(v));
                    Ok(())
                };
                let out = gmres(apply, &*mg, &rhs, &mut du, &settings).unwrap();
                assert!(out.converged, "{out:?}");
                krylov = krylov.max(out.iterations);
                du
            }
        };
        s.dofs.apply_correction(&mut w, &du, 1.0);
    }
    panic!("{linear:?}: Newton did not converge in 20 iterations");
}

/// The checks of one dimension: the tangent against finite differences (to
/// `tangent_tolerance` of its largest entry), the two Newton solves, their
/// agreement (to 8 ε of the solution's largest value: round-off, measured 2–3
/// ε), and the pattern's node ordering.
fn check<const D: usize, const N: usize>(scene: &str, threshold: f64, tangent_tolerance: f64) {
    let s = setup::<D, N>(scene, threshold);
    let c = COEFFICIENTS;
    let tied = s.dofs.ties.iter().flatten().count();
    let free_scalar = (0..s.map.len())
        .filter(|&a| s.dofs.of(a, D).is_some())
        .count();
    assert!(tied > 0, "some nodes are tied");
    assert!(free_scalar > 0 && free_scalar < s.map.len() - tied);
    assert_eq!(s.dofs.per_node(), N);
    let error = tangent_error(&s, &c);
    let direct = solve(&s, &c, Linear::Direct);
    let multigrid = solve(&s, &c, Linear::Multigrid);
    let scale = (direct.w.iter()).fold(0.0f64, |m, v| m.max(v.amax()));
    let differ =
        (direct.w.iter().zip(&multigrid.w)).fold(0.0f64, |m, (a, b)| m.max((a - b).amax()));
    println!(
        "{D}D, {} unknowns ({} nodes, {tied} tied, {free_scalar} free scalars): \
         max |K − K_fd| / max |K| = {error:.2e}; direct: {} Newton iterations, \
         ‖r‖ {:.2e} → {:.2e}; multigrid ({} levels) + GMRES: {} Newton iterations, at most {} \
         GMRES iterations, ‖r‖ → {:.2e}; solutions differ by {:.2e} of {scale:.2e}",
        s.dofs.free,
        s.map.len(),
        direct.newton_iterations,
        direct.residuals.0,
        direct.residuals.1,
        multigrid.levels,
        multigrid.newton_iterations,
        multigrid.krylov,
        multigrid.residuals.1,
        differ,
    );
    assert!(
        error < tangent_tolerance,
        "tangent error {error:.2e} (tolerance {tangent_tolerance:.1e})"
    );
    assert!(direct.residuals.1 <= 1e-11 * direct.residuals.0);
    assert!(multigrid.residuals.1 <= 1e-11 * multigrid.residuals.0);
    assert!(multigrid.levels >= 2, "{} levels", multigrid.levels);
    assert!(
        differ <= 8.0 * f64::EPSILON * scale,
        "solutions differ by {differ:.2e} of {scale:.2e}"
    );
    // The fill-reducing orderings number whole nodes of N unknowns.
    let pattern = Pattern::new(&s.map, &s.st, &s.dofs, None, None, &[]);
    for kind in [DirectOrdering::Amd, DirectOrdering::Metis] {
        let perm = pattern.ordering::<D>(kind);
        let mut seen = vec![false; s.dofs.free];
        perm.iter().for_each(|&i| seen[i] = true);
        assert!(
            perm.len() == s.dofs.free && seen.iter().all(|&x| x),
            "{kind:?}"
        );
        let node = |i: usize| pattern.lists().node_of(i);
        for run in perm.chunk_by(|&a, &b| node(a) == node(b)) {
            assert_eq!(run.len(), pattern.columns(node(run[0])).len(), "{kind:?}");
        }
    }
}

/// The block of the coupled tests: uGIMP in 2D, 2 × 2 particles per cell;
/// the body ends inside the cells of its right face.
const BLOCK_2D: &str = r#"dimension = 2
[grid]
min = [0.0, 0.0]
max = [8.0, 8.0]
cells = [32, 32]
shape_function = "ugimp"
[[material]]
name = "m"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [5.1, 4.0]
[[boundary]]
face = "ymin"
condition = "fixed"
[solver]
kind = "implicit"
end_time = 1.0
dt = 1.0
"#;

/// D + 1 = 3 unknowns per node in 2D: the tangent matches central differences
/// of the residual to 3e-10 of its largest entry (measured 1.0e-10: the
/// differences' round-off, ε max|r| / h with h = 1e-6), and Newton with the
/// direct solver and with multigrid-preconditioned GMRES reach the same
/// solution with ‖Tᵀ r‖ below 1e-11 of its start.
#[test]
fn coupled_field_with_d_plus_one_unknowns_per_node_2d() {
    check::<2, 3>(BLOCK_2D, 0.3, 3e-10);
}

/// The same in 3D (4 unknowns per node), linear hats on 6 × 6 × 6 cells: the
/// tangent to 7e-11 (measured 2.3e-11).
#[test]
fn coupled_field_with_d_plus_one_unknowns_per_node_3d() {
    let scene = BLOCK_2D
        .replace("dimension = 2", "dimension = 3")
        .replace("min = [0.0, 0.0]", "min = [0.0, 0.0, 0.0]")
        .replace("max = [8.0, 8.0]", "max = [6.0, 6.0, 6.0]")
        .replace("cells = [32, 32]", "cells = [6, 6, 6]")
        .replace("\"ugimp\"", "\"linear\"")
        .replace("\"rectangle\"", "\"box\"")
        .replace("max = [5.1, 4.0]", "max = [4.2, 4.3, 3.0]")
        .replace("face = \"ymin\"", "face = \"zmin\"");
    check::<3, 4>(&scene, 0.3, 7e-11);
}
