//! A stress gradient per particle, for a stress that is linear within each
//! particle domain instead of constant.
//!
//! With one stress per domain the internal force Σ_p V_p σ_p ∇S_Ip misses
//! −Σ_p ∫_Ωp σ'(y − x_p) ∇N_I, a boundary term ≈ (δ²/12) σ' [∇v] that leaves the
//! first and last particle of a body with an O(h) stress error and caps the
//! convergence rate at 1.5 (docs/accuracy.md). With σ(y) = σ_p + ∇σ_p (y − x_p)
//! in the domain the force gains Σ_p V_p Σ_k ∂_kσ_p M_Ip,k (`shape::gimp::moments`).
//!
//! The gradient is the least-squares fit of the neighbours' values about the
//! particle's own (a Taylor least-squares reconstruction; Wobbes et al. 2020,
//! Int. J. Numer. Meth. Eng. 121): ∇σ_p = argmin_G Σ_q |σ_q − σ_p − G (x_q − x_p)|²
//! over the particles q of the same body within 1.5 (ℓ_p + ℓ_q) per direction
//! (the first ring of contiguous domains, ℓ the half-lengths). It is exact for
//! linear fields, one-sided at the body's faces, and does not reach across
//! bodies (a material interface keeps its jump). A particle whose neighbours do
//! not span every direction gets no gradient.

use crate::dim::{embed_deformation, restrict, Mat3, Tensor, Vector};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::physics::shape::{contiguous_half_length, gradient_moments, ShapeFunction, Stencils};
use crate::physics::transfer::NodeMap;
use rayon::prelude::*;

/// The linear domain stress of one configuration: the least-squares weights of
/// the particles and the first moments M_Ip of their stencils' gradients.
#[derive(Clone, Debug, Default)]
pub struct LinearStress<const D: usize> {
    pub fit: LeastSquares<D>,
    /// M_Ip,kj = (1/|Ω_p|) ∫_Ωp (y − x_p)_k ∂_j N_I per stencil entry
    /// (`shape::gradient_moments`).
    pub moments: Vec<Tensor<D>>,
}

impl<const D: usize> LinearStress<D> {
    /// For the particles `p` at their stencils `st` (particles without nodes
    /// take no part). Panics for a family without domain moments (validation
    /// admits `cpgimp` and `cpbspline2` only).
    pub fn new(shape: ShapeFunction, grid: &Grid<D>, p: &Particles<D>, st: &Stencils<D>) -> Self {
        let half: Vec<Vector<D>> = (0..p.len())
            .map(|q| contiguous_half_length(grid, &p.half_length0[q], &p.f.get(q)))
            .collect();
        let active: Vec<bool> = st.count.iter().map(|c| *c > 0).collect();
        let mut moments = vec![Tensor::<D>::zeros(); st.node.len()];
        moments
            .par_chunks_mut(st.stride)
            .enumerate()
            .filter(|(q, _)| active[*q])
            .for_each(|(q, out)| {
                let n =
                    gradient_moments(shape, grid, &p.x[q], &p.half_length0[q], &p.f.get(q), out);
                assert_eq!(n, Some(st.count[q] as usize), "domain moments of {shape:?}");
            });
        LinearStress {
            fit: LeastSquares::new(&p.x, &half, &p.body, &active),
            moments,
        }
    }

    /// The internal force's linear part Σ_p V_p Σ_k ∂_kτ_p M_Ip,k· at every
    /// active node, τ the stress measure of `internal_force` and V its volumes.
    pub fn force(
        &self,
        map: &NodeMap,
        st: &Stencils<D>,
        volume: &[f64],
        stress: &[Mat3],
    ) -> Vec<Vector<D>> {
        let g = self.fit.gradients(stress);
        map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
            (0..D).fold(Vector::<D>::zeros(), |acc, k| {
                acc + restrict::<D>(&g[q][k]) * self.moments[e].row(k).transpose() * volume[q]
            })
        })
    }
}

/// The fixed least-squares weights c_pq of one configuration:
/// ∂_kσ_p = Σ_q c_pq,k (σ_q − σ_p).
#[derive(Clone, Debug, Default)]
pub struct LeastSquares<const D: usize> {
    /// Neighbours of particle p: `offset[p] .. offset[p + 1]`.
    offset: Vec<usize>,
    neighbour: Vec<u32>,
    coefficient: Vec<Vector<D>>,
}

/// Neighbour reach per direction over the centre distance, in units of ℓ_p + ℓ_q.
const REACH: f64 = 1.5;

impl<const D: usize> LeastSquares<D> {
    /// The weights for particles at `x` with half-lengths `half` in bodies `body`;
    /// particles with `active[p] == false` neither get nor give a gradient.
    pub fn new(x: &[Vector<D>], half: &[Vector<D>], body: &[u32], active: &[bool]) -> Self {
        let bins = Bins::new(x, half, active);
        let lists: Vec<Vec<(u32, Vector<D>)>> = (0..x.len())
            .into_par_iter()
            .map(|p| match active[p] {
                true => fit(p, &bins.near(p, x, half, body, active), x),
                false => Vec::new(),
            })
            .collect();
        let mut offset = Vec::with_capacity(x.len() + 1);
        offset.push(0);
        let (mut neighbour, mut coefficient) = (Vec::new(), Vec::new());
        for list in lists {
            for (q, c) in list {
                neighbour.push(q);
                coefficient.push(c);
            }
            offset.push(neighbour.len());
        }
        LeastSquares {
            offset,
            neighbour,
            coefficient,
        }
    }

    /// ∂_kσ_p, k = 0..D, of the particle values `value`.
    pub fn gradient(&self, p: usize, value: &[Mat3]) -> [Mat3; D] {
        let mut g = [Mat3::zeros(); D];
        for i in self.offset[p]..self.offset[p + 1] {
            let difference = value[self.neighbour[i] as usize] - value[p];
            for (k, gk) in g.iter_mut().enumerate() {
                *gk += difference * self.coefficient[i][k];
            }
        }
        g
    }

    /// The neighbours of particle p (ascending).
    pub fn neighbours(&self, p: usize) -> &[u32] {
        &self.neighbour[self.offset[p]..self.offset[p + 1]]
    }

    /// The weights c_pq of p's neighbours, in the order of `neighbours`.
    pub fn coefficients(&self, p: usize) -> &[Vector<D>] {
        &self.coefficient[self.offset[p]..self.offset[p + 1]]
    }

    /// The weight c_pq of neighbour q in p's fit (zero if q is none of them).
    pub fn coefficient(&self, p: usize, q: u32) -> Vector<D> {
        match self.neighbours(p).binary_search(&q) {
            Ok(i) => self.coefficients(p)[i],
            Err(_) => Vector::<D>::zeros(),
        }
    }

    /// The neighbour lists, to tell whether two configurations couple the same
    /// particles.
    pub fn lists(&self) -> (&[usize], &[u32]) {
        (&self.offset, &self.neighbour)
    }

    /// ∂_kσ_p of every particle.
    pub fn gradients(&self, value: &[Mat3]) -> Vec<[Mat3; D]> {
        (0..self.offset.len() - 1)
            .into_par_iter()
            .map(|p| self.gradient(p, value))
            .collect()
    }
}

/// The weights c_q = A⁻¹ Δx_q, A = Σ_q Δx_q Δx_qᵀ, of the neighbours `near` of p;
/// zero when A is singular (the neighbours lie on a line or a plane). Every
/// neighbour is listed, so that the lists are symmetric (q lists p when p
/// lists q).
fn fit<const D: usize>(p: usize, near: &[u32], x: &[Vector<D>]) -> Vec<(u32, Vector<D>)> {
    let a: Tensor<D> = near
        .iter()
        .map(|&q| {
            let dx = x[q as usize] - x[p];
            dx * dx.transpose()
        })
        .sum();
    // Scaled to unit diagonal, so that the singularity test does not depend on units.
    let scale = Vector::<D>::from_fn(|d, _| a[(d, d)].sqrt());
    let unit = Tensor::<D>::from_fn(|i, j| a[(i, j)] / (scale[i] * scale[j]));
    let inverse =
        match scale.iter().all(|s| *s > 0.0) && embed_deformation(&unit).determinant() > 1e-8 {
            true => unit
                .try_inverse()
                .map(|u| Tensor::<D>::from_fn(|i, j| u[(i, j)] / (scale[i] * scale[j]))),
            false => None,
        }
        .unwrap_or_else(Tensor::<D>::zeros);
    near.iter()
        .map(|&q| (q, inverse * (x[q as usize] - x[p])))
        .collect()
}

/// Particles sorted into boxes of the largest neighbour reach, so that the
/// neighbours of a particle lie in the 3^D boxes around its own.
struct Bins<const D: usize> {
    min: Vector<D>,
    width: Vector<D>,
    count: [usize; D],
    /// Particles of box b: `particle[start[b] .. start[b + 1]]`, in index order.
    start: Vec<usize>,
    particle: Vec<u32>,
}

impl<const D: usize> Bins<D> {
    fn new(x: &[Vector<D>], half: &[Vector<D>], active: &[bool]) -> Self {
        let live = || (0..x.len()).filter(|&p| active[p]);
        let mut min = Vector::<D>::repeat(f64::INFINITY);
        let mut max = Vector::<D>::repeat(f64::NEG_INFINITY);
        let mut width = Vector::<D>::repeat(f64::MIN_POSITIVE);
        for p in live() {
            min = min.inf(&x[p]);
            max = max.sup(&x[p]);
            width = width.sup(&(half[p] * (2.0 * REACH)));
        }
        if min[0] > max[0] {
            (min, max) = (Vector::<D>::zeros(), Vector::<D>::zeros());
        }
        let count: [usize; D] =
            std::array::from_fn(|d| ((max[d] - min[d]) / width[d]).floor() as usize + 1);
        let mut bins = Bins {
            min,
            width,
            count,
            start: vec![0; count.iter().product::<usize>() + 1],
            particle: Vec::new(),
        };
        let of: Vec<usize> = (0..x.len()).map(|p| bins.flat(bins.ijk(&x[p]))).collect();
        for p in live() {
            bins.start[of[p] + 1] += 1;
        }
        for b in 1..bins.start.len() {
            bins.start[b] += bins.start[b - 1];
        }
        let mut next = bins.start.clone();
        bins.particle = vec![0; bins.start[bins.start.len() - 1]];
        for p in live() {
            bins.particle[next[of[p]]] = p as u32;
            next[of[p]] += 1;
        }
        bins
    }

    fn ijk(&self, x: &Vector<D>) -> [usize; D] {
        std::array::from_fn(|d| {
            (((x[d] - self.min[d]) / self.width[d]).floor().max(0.0) as usize)
                .min(self.count[d] - 1)
        })
    }

    fn flat(&self, ijk: [usize; D]) -> usize {
        (0..D).rev().fold(0, |acc, d| acc * self.count[d] + ijk[d])
    }

    /// The active particles of p's body within the reach of p, in index order.
    fn near(
        &self,
        p: usize,
        x: &[Vector<D>],
        half: &[Vector<D>],
        body: &[u32],
        active: &[bool],
    ) -> Vec<u32> {
        let centre = self.ijk(&x[p]);
        let mut near = Vec::new();
        for offset in 0..3usize.pow(D as u32) {
            let mut ijk = centre;
            let mut inside = true;
            let mut rest = offset;
            for (d, i) in ijk.iter_mut().enumerate() {
                let step = rest % 3;
                rest /= 3;
                match (*i + step).checked_sub(1) {
                    Some(j) if j < self.count[d] => *i = j,
                    _ => inside = false,
                }
            }
            if !inside {
                continue;
            }
            let b = self.flat(ijk);
            near.extend(
                self.particle[self.start[b]..self.start[b + 1]]
                    .iter()
                    .copied()
                    .filter(|&q| {
                        let q = q as usize;
                        q != p
                            && active[q]
                            && body[q] == body[p]
                            && (0..D).all(|d| {
                                (x[q][d] - x[p][d]).abs() <= REACH * (half[p][d] + half[q][d])
                            })
                    }),
            );
        }
        near.sort_unstable();
        near
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lattice of particles with spacing 2ℓ, two bodies side by side.
    fn lattice<const D: usize>(n: usize, l: f64) -> (Vec<Vector<D>>, Vec<Vector<D>>, Vec<u32>) {
        let total = n.pow(D as u32);
        let x: Vec<Vector<D>> = (0..total)
            .map(|i| {
                Vector::<D>::from_fn(|d, _| {
                    let k = (i / n.pow(d as u32)) % n;
                    (2 * k + 1) as f64 * l + 0.01 * (d as f64 + 1.0) * (i % 3) as f64 * l
                })
            })
            .collect();
        let half = vec![Vector::<D>::repeat(l); total];
        let body = x.iter().map(|y| (y[0] > n as f64 * l) as u32).collect();
        (x, half, body)
    }

    /// Linear fields are reproduced at every particle, inside and at the faces;
    /// a jump between two bodies is not smeared.
    fn exact_for_linear_fields<const D: usize>() {
        let (x, half, body) = lattice::<D>(6, 0.25);
        let active = vec![true; x.len()];
        let ls = LeastSquares::new(&x, &half, &body, &active);
        let slope: [Mat3; D] =
            std::array::from_fn(|k| Mat3::from_fn(|i, j| (1 + i + 2 * j + 5 * k) as f64));
        let value: Vec<Mat3> = (0..x.len())
            .map(|p| {
                let jump = Mat3::repeat(100.0 * body[p] as f64);
                (0..D).fold(jump, |acc, k| acc + slope[k] * x[p][k])
            })
            .collect();
        for (p, g) in ls.gradients(&value).iter().enumerate() {
            for k in 0..D {
                assert!(
                    (g[k] - slope[k]).norm() < 1e-9 * slope[k].norm(),
                    "particle {p} direction {k}: {}",
                    g[k]
                );
            }
        }
    }

    #[test]
    fn exact_for_linear_fields_2d() {
        exact_for_linear_fields::<2>();
    }

    #[test]
    fn exact_for_linear_fields_3d() {
        exact_for_linear_fields::<3>();
    }

    /// A row of particles (no neighbour across) gets no gradient; inactive
    /// particles are neither fitted nor used.
    #[test]
    fn degenerate_neighbourhoods_get_no_gradient() {
        let x: Vec<Vector<2>> = (0..5)
            .map(|i| Vector::<2>::new(0.5 * i as f64, 1.0))
            .collect();
        let half = vec![Vector::<2>::repeat(0.25); 5];
        let body = vec![0; 5];
        let value: Vec<Mat3> = (0..5).map(|i| Mat3::repeat(i as f64)).collect();
        let ls = LeastSquares::new(&x, &half, &body, &[true; 5]);
        assert!(ls
            .gradients(&value)
            .iter()
            .all(|g| g.iter().all(|m| m.norm() == 0.0)));
    }
}
