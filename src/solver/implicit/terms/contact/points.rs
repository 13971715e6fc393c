//! The particles' contact points against rigid bodies (`super::rigid`).
//!
//! With linear hats or a particle-domain basis (uGIMP, cpGIMP, CPDI,
//! cpbspline2) the point of a particle that touches a rigid body is not its
//! centre but its contact point: the point c of its domain that faces the
//! nearest body when it first comes within two cells of it, moved by the point
//! basis N_I of the family, x_c(u) = c + Σ_I N_I(c) u_I, in contact when
//! inside the body; the particle's force and motion there go with the weights
//! N_I(c) instead of S_Ip. The next step starts from where the converged step
//! left it (it moves with the grid, as the body's surface does), while the
//! particle faces the same body. The load then enters at the body's surface,
//! not half a particle inside it.

use super::state::CarriedPoint;
use crate::dim::{Mat3, Vector};
use crate::model::grid::Grid;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::{
    contiguous_half_length, deformation_for, evaluate, ShapeFunction, Stencils,
};
use crate::physics::transfer::NodeMap;
use rayon::prelude::*;

/// How far a contact point carried from the last step may stray from the
/// point of the particle's domain that faces the body, as a fraction of its
/// largest half-length, before it is set back there. Carried, the point rides
/// on the soil's surface and its gap stays continuous from step to step; set
/// anew from x_p − s every step the point left the footing of
/// `problems/contact_footing_implicit.toml` where the soil flows (F of a
/// plastic particle does not move its domain's edge with the grid: gaps of up
/// to 1.4e-4 m grew under the footing's edge), and the points under the
/// footing chattered in and out of contact (1,662 Newton rows, 66 cut-backs,
/// against 576 and 2 carried). Carried, they strayed at most 0.14 of a
/// half-length in that run.
const CARRIED_POINT_STRAY: f64 = 0.5;

/// The contact points of the current step and those carried to the next.
#[derive(Clone, Debug, Default)]
pub struct ContactPoints<const D: usize> {
    /// Per stencil entry (stride of the step's stencils) of each particle: the
    /// weight with which its contact point moves and takes its force; empty
    /// when the particles' own weights serve.
    weights: Vec<f64>,
    /// Each particle's contact point at the step start and the rigid body it
    /// faces, where it has one.
    point: Vec<CarriedPoint<D>>,
    /// Where the last converged step left them: the next step's contact points.
    pub carried: Vec<CarriedPoint<D>>,
}

impl<const D: usize> ContactPoints<D> {
    /// Each particle's contact point at the step start and the weight of each
    /// of its stencil entries there: c = x_p − s, s the point of its domain
    /// (`domain_support`) that faces the nearest rigid surface (outward normal
    /// n, at the end of the step), with the point basis of the family (linear
    /// hats for linear, uGIMP, cpGIMP and CPDI, quadratic B-splines for
    /// cpbspline2) over the particle's own nodes, renormalised. A point that
    /// faced the same body in the last step goes on from where that step's
    /// motion took it (`carried`), unless it strayed from x_p − s by more than
    /// `CARRIED_POINT_STRAY` of the particle's half-length. None (and the
    /// particle keeps its own weights) where no rigid body is within two cells
    /// or the basis is a B-spline: such a particle is a point with its reach.
    /// Linear hats take the point of their reference domain, as uGIMP does:
    /// the explicit contact supports a body's nodes, and where the implicit
    /// penalty acted at the centres a block handed from an implicit stage to
    /// an explicit one on a rigid base rang (kinetic energy 1.6e-2 of the
    /// strain energy; at the contact points 7.6e-10).
    ///
    /// `nearest(q, reach)` is the rigid body particle q is in contact with
    /// that it reaches deepest with the half-lengths `reach`, and the body's
    /// outward normal there (None for a particle in contact with none).
    pub fn place(
        &mut self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &Stencils<D>,
        map: &NodeMap,
        nearest: impl Fn(usize, &Vector<D>) -> Option<(usize, Vector<D>)> + Sync,
    ) {
        let point = match shape {
            ShapeFunction::Linear
            | ShapeFunction::Ugimp
            | ShapeFunction::Cpgimp
            | ShapeFunction::Cpdi => ShapeFunction::Linear,
            ShapeFunction::Cpbspline2 => ShapeFunction::Bspline2,
            _ => {
                (self.weights, self.point) = (Vec::new(), Vec::new());
                return;
            }
        };
        let p = &m.particles;
        let h = m.grid.h_min();
        let stride = st.stride;
        let mut out = vec![0.0; p.len() * stride];
        let mut points = vec![None; p.len()];
        let carried = &self.carried;
        out.par_chunks_mut(stride)
            .zip(points.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(q, (w, point_of))| {
                // A particle without a contact point keeps its own weights
                // (`Touch::at_point` false): its row here is not read.
                if st.count[q] == 0 {
                    return;
                }
                let ell = &p.half_length0[q];
                let near = ell.add_scalar(2.0 * h);
                let Some((body, normal)) = nearest(q, &near) else {
                    return;
                };
                let f = deformation_for(shape, || p.f.get(q));
                let offset = domain_support(shape, &m.grid, ell, &f, &normal);
                let on_domain = p.x[q] - offset;
                let c = match carried.get(q).copied().flatten() {
                    Some((k, c))
                        if k == body
                            && (c - on_domain).norm() <= CARRIED_POINT_STRAY * ell.max() =>
                    {
                        c
                    }
                    _ => on_domain,
                };
                let c = c.sup(&m.grid.min).inf(&m.grid.max);
                let one = Vector::<D>::zeros();
                let (mut node, mut nw, mut grad) =
                    ([0u32; 64], [0.0; 64], [Vector::<D>::zeros(); 64]);
                let count = evaluate(
                    point,
                    &m.grid,
                    &c,
                    &one,
                    &Mat3::identity(),
                    &mut node,
                    &mut nw,
                    &mut grad,
                );
                let mut total = 0.0;
                for (k, e) in st.range(q).enumerate() {
                    let g = map.grid_node(map.local_of(st, e)) as u32;
                    w[k] = (0..count).find(|&i| node[i] == g).map_or(0.0, |i| nw[i]);
                    total += w[k];
                }
                if total < 0.5 {
                    return;
                }
                w.iter_mut().for_each(|x| *x /= total);
                *point_of = Some((body, c));
            });
        (self.weights, self.point) = (out, points);
    }

    /// Particle q's contact point at the step start and the body it faces.
    pub fn of(&self, q: usize) -> CarriedPoint<D> {
        self.point.get(q).copied().flatten()
    }

    /// How far each contact point has moved under u, Σ N_I(c) u_I (None for a
    /// particle without one).
    pub fn motion(
        &self,
        st: &Stencils<D>,
        map: &NodeMap,
        u: &[Vector<D>],
    ) -> Vec<Option<Vector<D>>> {
        (self.point.par_iter().enumerate())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(q, point)| {
                point.map(|_| {
                    st.range(q).fold(Vector::<D>::zeros(), |acc, e| {
                        acc + u[map.local_of(st, e)] * self.weights[e]
                    })
                })
            })
            .collect()
    }

    /// The weight of stencil entry e of a particle in contact (`at_point`:
    /// at its contact point, else at its centre).
    pub fn weight(&self, at_point: bool, st: &Stencils<D>, e: usize) -> f64 {
        match at_point {
            true => self.weights[e],
            false => st.weight(e),
        }
    }

    /// The converged step: the points moved by `motion` (`motion` at the
    /// converged u) are the next step's.
    pub fn carry(&mut self, motion: &[Option<Vector<D>>]) {
        self.carried = (self.point.iter().zip(motion))
            .map(|(c, dx)| Some((c.as_ref()?.0, c.as_ref()?.1 + (*dx)?)))
            .collect();
    }
}

/// The point of a particle's domain that faces a surface of outward normal n,
/// relative to the particle: the support point of its reach ellipse as the
/// family shapes the domain. Linear and uGIMP: the reference half-lengths L,
/// L² n / |L n|;
/// cpGIMP and cpbspline2: the same with the contiguous half-lengths (L stretched
/// by F_dd, axis-aligned, `contiguous_half_length`); CPDI: the ellipse carried by
/// F, F L² Fᵀ n / |L Fᵀ n|.
fn domain_support<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
    n: &Vector<D>,
) -> Vector<D> {
    let support = |l: &Vector<D>, n: &Vector<D>| {
        let l2n = l.component_mul(l).component_mul(n);
        l2n / l2n.dot(n).sqrt()
    };
    match shape {
        ShapeFunction::Cpgimp | ShapeFunction::Cpbspline2 => {
            support(&contiguous_half_length(grid, half_length0, f), n)
        }
        ShapeFunction::Cpdi => {
            let f = crate::dim::restrict::<D>(f);
            let ftn = f.transpose() * n;
            let l2ftn = half_length0.component_mul(half_length0).component_mul(&ftn);
            f * l2ftn / half_length0.component_mul(&ftn).norm()
        }
        _ => support(half_length0, n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// The contact point faces the surface on the domain as each family shapes
    /// it: CPDI's ellipse turns with F, cpGIMP's box stretches along the axes.
    #[test]
    fn a_domain_s_support_point_follows_its_family() {
        let grid = Grid::<2>::new(Vector2::zeros(), Vector2::new(4.0, 4.0), [4, 4], 1);
        let up = Vector2::new(0.0, 1.0);
        // Turned by 90°: the long half-axis 0.2 now points along y.
        let turn = Mat3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let ell = Vector2::new(0.2, 0.1);
        let cpdi = domain_support(ShapeFunction::Cpdi, &grid, &ell, &turn, &up);
        assert!((cpdi - Vector2::new(0.0, 0.2)).norm() < 1e-15, "{cpdi}");
        // Squashed to half along y (and stretched along x).
        let squash = Mat3::new(1.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0);
        let round = Vector2::new(0.1, 0.1);
        let cp = domain_support(ShapeFunction::Cpgimp, &grid, &round, &squash, &up);
        assert!((cp - Vector2::new(0.0, 0.05)).norm() < 1e-15, "{cp}");
        // uGIMP's domain does not deform; a tilted normal meets the ellipse
        // where its outward normal is n.
        let n = Vector2::new(0.6, 0.8);
        let u = domain_support(ShapeFunction::Ugimp, &grid, &ell, &squash, &n);
        let on_ellipse = (u[0] / ell[0]).powi(2) + (u[1] / ell[1]).powi(2);
        let normal = Vector2::new(u[0] / ell[0].powi(2), u[1] / ell[1].powi(2)).normalize();
        assert!((on_ellipse - 1.0).abs() < 1e-14 && (normal - n).norm() < 1e-14);
    }
}
