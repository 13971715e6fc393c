//! Total-Lagrangian finite elements for the plane-strain Hencky cantilever of
//! problems/cantilever.toml: an independent discretisation of the same continuum,
//! written to verify the MPM result (not a product feature; no particles, no grid
//! transfer). Shared by `examples/cantilever_fe/main.rs` and tests/verification/cantilever.rs.
//!
//! - Mesh: nx × ny 9-node Lagrange quadrilaterals (biquadratic) on the reference
//!   rectangle [0, L] × [0, d], 3 × 3 Gauss points.
//! - Material: the project's `Hencky` through the `Material` trait, called with
//!   F_old = I and ΔF = F (its update depends on F = ΔF F_old only), so σ(F) and
//!   ∂σ/∂F come from the same code the MPM uses.
//! - Weak form (total Lagrangian): r_aI = ∫ P_iJ ∂N_a/∂X_J dV − f_ext,aI with the
//!   first Piola–Kirchhoff stress P = J σ F⁻ᵀ; tangent K = ∫ ∇N_a · A · ∇N_b with
//!   A_iJkL = ∂P_iJ/∂F_kL (Holzapfel 2000, (6.166) for P = J σ F⁻ᵀ).
//! - Clamp: every node on X = 0 fixed. Load: a vertical dead force P, either a
//!   uniform traction on the end section X = L or a uniform body force on the end
//!   strip X ≥ L − w (the MPM scene shares its force equally among the particles of
//!   its last column, i.e. a uniform load over the strip they fill).
//! - Output: the displacement averaged with the load's own weights (the
//!   work-conjugate tip displacement; the MPM test averages the loaded particles).
//! - Newton with the exact tangent, the sparse direct solver of the project.

use mpm::dim::Mat3;
use mpm::material::hencky::Hencky;
use mpm::material::{Increment, Material};
use mpm::solver::linear::direct::{DirectSolver, Structure};

/// The cantilever: length, depth, plane-strain Hencky constants.
#[derive(Clone, Copy, Debug)]
pub struct Beam {
    pub length: f64,
    pub depth: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
}

/// Where the vertical end force acts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipLoad {
    /// Uniform traction over the end section X = L.
    EndSection,
    /// Uniform body force over the strip L − width ≤ X ≤ L (the MPM scene's
    /// last particle column: width = h / ppc).
    Strip { width: f64 },
}

impl TipLoad {
    /// Arc length of the load's centroid (the length of the equivalent cantilever).
    pub fn arm(&self, length: f64) -> f64 {
        match self {
            TipLoad::EndSection => length,
            TipLoad::Strip { width } => length - 0.5 * width,
        }
    }
}

/// State at one converged load level.
#[derive(Clone, Copy, Debug)]
pub struct LoadLevel {
    /// Applied force magnitude (downwards).
    pub force: f64,
    /// Load-weighted mean deflection (down) and axial displacement (towards the clamp).
    pub v: f64,
    pub u: f64,
    /// The same at the tip node on the mid-line (X = L, Y = d/2).
    pub v_mid: f64,
    pub u_mid: f64,
    /// Newton iterations of this load step.
    pub iterations: usize,
}

/// 1D quadratic Lagrange basis at ξ ∈ {−1, 0, 1} and its derivative.
fn lagrange(xi: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)],
        [xi - 0.5, -2.0 * xi, xi + 0.5],
    )
}

/// 3-point Gauss–Legendre rule on [−1, 1].
const GAUSS: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// The structured Q9 mesh: node (i, j) at X = i hx/2, Y = j hy/2, numbered
/// i (2ny + 1) + j, so the clamped column i = 0 holds the first 2ny + 1 nodes.
struct Mesh {
    nx: usize,
    ny: usize,
    hx: f64,
    hy: f64,
}

impl Mesh {
    fn rows(&self) -> usize {
        2 * self.ny + 1
    }
    fn n_nodes(&self) -> usize {
        (2 * self.nx + 1) * self.rows()
    }
    /// Free dofs: 2 per node off the clamp; dof of (node, c) is 2 (node − rows) + c.
    fn n_free(&self) -> usize {
        2 * (self.n_nodes() - self.rows())
    }
    fn node(&self, i: usize, j: usize) -> usize {
        i * self.rows() + j
    }
    /// The 9 nodes of element (ex, ey), local index 3p + q for ξ-node p, η-node q.
    fn element_nodes(&self, ex: usize, ey: usize) -> [usize; 9] {
        std::array::from_fn(|a| self.node(2 * ex + a / 3, 2 * ey + a % 3))
    }
    fn elements(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.nx).flat_map(move |ex| (0..self.ny).map(move |ey| (ex, ey)))
    }
    /// Free dof of (node, component), `None` on the clamp.
    fn dof(&self, node: usize, c: usize) -> Option<usize> {
        (node >= self.rows()).then(|| 2 * (node - self.rows()) + c)
    }
}

/// Shape functions and reference gradients at (ξ, η) of a hx × hy rectangle.
fn shape(xi: f64, eta: f64, hx: f64, hy: f64) -> ([f64; 9], [[f64; 2]; 9]) {
    let ((lx, dx), (ly, dy)) = (lagrange(xi), lagrange(eta));
    let n = std::array::from_fn(|a| lx[a / 3] * ly[a % 3]);
    let g = std::array::from_fn(|a| {
        [
            dx[a / 3] * ly[a % 3] * 2.0 / hx,
            lx[a / 3] * dy[a % 3] * 2.0 / hy,
        ]
    });
    (n, g)
}

/// Plane-strain deformation gradient F = I + Σ u_a ⊗ ∇N_a (F_33 = 1).
fn deformation_gradient(u: &[[f64; 2]; 9], grad: &[[f64; 2]; 9]) -> Mat3 {
    let mut f = Mat3::identity();
    for (ua, ga) in u.iter().zip(grad) {
        for i in 0..2 {
            for j in 0..2 {
                f[(i, j)] += ua[i] * ga[j];
            }
        }
    }
    f
}

fn increment(f: &Mat3) -> Increment<'static> {
    Increment::at_rest(*f, &[])
}

/// First Piola–Kirchhoff stress P = J σ F⁻ᵀ and, if asked, A_iJkL = ∂P_iJ/∂F_kL
/// (in-plane indices, stored as a[2i + J][2k + L]).
fn piola(mat: &Hencky, f: &Mat3, tangent: bool) -> (Mat3, Option<[[f64; 4]; 4]>) {
    let inc = increment(f);
    let sigma = mat.update(&inc, &mut []);
    let j = f.determinant();
    let finv = f.try_inverse().expect("det F > 0");
    let p = sigma * finv.transpose() * j;
    if !tangent {
        return (p, None);
    }
    let d = mat
        .stress_derivative(&inc)
        .expect("Hencky has an exact tangent");
    let mut a = [[0.0; 4]; 4];
    // dP_iJ = J [Finv_Lk σ_im Finv_Jm + dσ_im/dF_kL Finv_Jm − σ_im Finv_Jk Finv_Lm].
    for i in 0..2 {
        for jj in 0..2 {
            for k in 0..2 {
                for l in 0..2 {
                    let mut s = finv[(l, k)] * p[(i, jj)] / j;
                    for m in 0..3 {
                        s += d[(3 * i + m, 3 * k + l)] * finv[(jj, m)];
                        s -= sigma[(i, m)] * finv[(jj, k)] * finv[(l, m)];
                    }
                    a[2 * i + jj][2 * k + l] = j * s;
                }
            }
        }
    }
    (p, Some(a))
}

/// The assembled problem: mesh, material and the load's nodal weights.
pub struct Cantilever {
    mesh: Mesh,
    mat: Hencky,
    /// Nodal weights g_a = ∫ N_a dΓ or dA over the loaded set / its measure (Σ g_a = 1):
    /// f_ext = −P g e_y, and the load-weighted mean displacement is Σ g_a u_a.
    weights: Vec<f64>,
}

impl Cantilever {
    pub fn new(beam: &Beam, nx: usize, ny: usize, load: TipLoad) -> Self {
        let mesh = Mesh {
            nx,
            ny,
            hx: beam.length / nx as f64,
            hy: beam.depth / ny as f64,
        };
        let mat = Hencky::new(1000.0, beam.youngs_modulus, beam.poisson_ratio);
        let weights = load_weights(&mesh, beam, load);
        Self { mesh, mat, weights }
    }

    pub fn n_free(&self) -> usize {
        self.mesh.n_free()
    }

    /// Displacement of `node` from the free-dof vector (zero on the clamp).
    fn nodal(&self, x: &[f64], node: usize) -> [f64; 2] {
        std::array::from_fn(|c| self.mesh.dof(node, c).map_or(0.0, |d| x[d]))
    }

    /// Internal force vector and (if asked) the tangent as triplets, at free dofs `x`.
    pub fn internal(&self, x: &[f64], tangent: bool) -> (Vec<f64>, Vec<(usize, usize, f64)>) {
        let m = &self.mesh;
        let mut f = vec![0.0; m.n_free()];
        let mut k = Vec::new();
        let det = 0.25 * m.hx * m.hy;
        for (ex, ey) in m.elements() {
            let nodes = m.element_nodes(ex, ey);
            let u: [[f64; 2]; 9] = std::array::from_fn(|a| self.nodal(x, nodes[a]));
            let mut fe = [[0.0; 2]; 9];
            let mut ke = [[0.0; 18]; 18];
            for &(xi, wx) in &GAUSS {
                for &(eta, wy) in &GAUSS {
                    let (_, g) = shape(xi, eta, m.hx, m.hy);
                    let w = wx * wy * det;
                    let (p, a) = piola(&self.mat, &deformation_gradient(&u, &g), tangent);
                    for (fa, ga) in fe.iter_mut().zip(&g) {
                        for i in 0..2 {
                            fa[i] += w * (p[(i, 0)] * ga[0] + p[(i, 1)] * ga[1]);
                        }
                    }
                    if let Some(a) = a {
                        add_element_tangent(&mut ke, &a, &g, w);
                    }
                }
            }
            for (a, &na) in nodes.iter().enumerate() {
                for i in 0..2 {
                    let Some(r) = m.dof(na, i) else { continue };
                    f[r] += fe[a][i];
                    if !tangent {
                        continue;
                    }
                    for (b, &nb) in nodes.iter().enumerate() {
                        for kk in 0..2 {
                            if let Some(c) = m.dof(nb, kk) {
                                k.push((r, c, ke[2 * a + i][2 * b + kk]));
                            }
                        }
                    }
                }
            }
        }
        (f, k)
    }

    /// External force at load magnitude `force` (downwards).
    fn external(&self, force: f64) -> Vec<f64> {
        let mut f = vec![0.0; self.mesh.n_free()];
        for (node, &g) in self.weights.iter().enumerate() {
            if let Some(d) = self.mesh.dof(node, 1) {
                f[d] = -force * g;
            }
        }
        f
    }

    /// Load-weighted mean (v down, u towards the clamp) and the mid-line tip node's.
    fn tip(&self, x: &[f64]) -> (f64, f64, f64, f64) {
        let (mut v, mut u) = (0.0, 0.0);
        for (node, &g) in self.weights.iter().enumerate() {
            let d = self.nodal(x, node);
            v -= g * d[1];
            u -= g * d[0];
        }
        let mid = self.nodal(x, self.mesh.node(2 * self.mesh.nx, self.mesh.ny));
        (v, u, -mid[1], -mid[0])
    }

    /// Dead end force rising to `force` in `steps` equal load steps, Newton with the
    /// exact tangent; converged when ‖Δu‖ ≤ 1e-10 ‖u‖ with ‖r‖ ≤ 1e-6 P before it
    /// (the residual itself stalls at round-off, ~1e-10 P on fine meshes).
    pub fn solve(&self, force: f64, steps: usize) -> Result<Vec<LoadLevel>, String> {
        let n = self.n_free();
        let mut x = vec![0.0; n];
        let mut solver = DirectSolver::new();
        let mut levels = Vec::with_capacity(steps);
        for step in 1..=steps {
            let p = force * step as f64 / steps as f64;
            let f_ext = self.external(p);
            let mut iterations = 0;
            loop {
                let (f_int, k) = self.internal(&x, true);
                let r: Vec<f64> = f_int.iter().zip(&f_ext).map(|(a, b)| b - a).collect();
                let r_norm = norm(&r);
                if iterations >= 30 {
                    return Err(format!(
                        "load step {step} (P = {p:.4e}): no convergence in 30 iterations, ‖r‖ = {r_norm:.3e}"
                    ));
                }
                solver
                    .factorize_triplets(n, &k, Structure::Symmetric)
                    .map_err(|e| format!("load step {step}: {e}"))?;
                let du = solver
                    .solve(&r)
                    .map_err(|e| format!("load step {step}: {e}"))?;
                if std::env::var("FE_DEBUG").is_ok() {
                    eprintln!(
                        "step {step} it {iterations}: r {r_norm:.3e} du {:.3e}",
                        norm(&du)
                    );
                }
                x.iter_mut().zip(&du).for_each(|(a, b)| *a += b);
                iterations += 1;
                if norm(&du) <= 1e-10 * norm(&x) && r_norm <= 1e-6 * force {
                    break;
                }
            }
            let (v, u, v_mid, u_mid) = self.tip(&x);
            levels.push(LoadLevel {
                force: p,
                v,
                u,
                v_mid,
                u_mid,
                iterations,
            });
        }
        Ok(levels)
    }
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// K_(a i)(b k) += w Σ_JL ∂N_a/∂X_J A_iJkL ∂N_b/∂X_L.
fn add_element_tangent(ke: &mut [[f64; 18]; 18], a: &[[f64; 4]; 4], g: &[[f64; 2]; 9], w: f64) {
    for (na, ga) in g.iter().enumerate() {
        for (nb, gb) in g.iter().enumerate() {
            for i in 0..2 {
                for k in 0..2 {
                    let mut s = 0.0;
                    for jj in 0..2 {
                        for l in 0..2 {
                            s += ga[jj] * a[2 * i + jj][2 * k + l] * gb[l];
                        }
                    }
                    ke[2 * na + i][2 * nb + k] += w * s;
                }
            }
        }
    }
}

/// Nodal weights of the uniform end load (module documentation), exact: the
/// loaded set is a union of rectangles in each element's (affine) reference
/// coordinates, integrated with 3 × 3 Gauss points (N is biquadratic).
fn load_weights(mesh: &Mesh, beam: &Beam, load: TipLoad) -> Vec<f64> {
    let mut g = vec![0.0; mesh.n_nodes()];
    let ex = mesh.nx - 1;
    match load {
        TipLoad::EndSection => {
            // Edge ξ = 1 of the last element column: ∫ N dY / d.
            for ey in 0..mesh.ny {
                let nodes = mesh.element_nodes(ex, ey);
                for &(eta, w) in &GAUSS {
                    let (n, _) = shape(1.0, eta, mesh.hx, mesh.hy);
                    for (a, &na) in nodes.iter().enumerate() {
                        g[na] += w * 0.5 * mesh.hy * n[a] / beam.depth;
                    }
                }
            }
        }
        TipLoad::Strip { width } => {
            let x_lo = beam.length - width;
            for (ex, ey) in mesh.elements() {
                let x0 = ex as f64 * mesh.hx;
                let lo = x_lo.max(x0);
                if lo >= x0 + mesh.hx {
                    continue;
                }
                // The part [lo, x0 + hx] in ξ: [ξ_lo, 1].
                let xi_lo = 2.0 * (lo - x0) / mesh.hx - 1.0;
                let (c, half) = (0.5 * (xi_lo + 1.0), 0.5 * (1.0 - xi_lo));
                let nodes = mesh.element_nodes(ex, ey);
                for &(s, wx) in &GAUSS {
                    for &(eta, wy) in &GAUSS {
                        let (n, _) = shape(c + half * s, eta, mesh.hx, mesh.hy);
                        let w = wx * wy * half * 0.25 * mesh.hx * mesh.hy;
                        for (a, &na) in nodes.iter().enumerate() {
                            g[na] += w * n[a] / (width * beam.depth);
                        }
                    }
                }
            }
        }
    }
    g
}
