//! The hoop terms of the axisymmetric mode (`dimension = "axisymmetric"`, x = r,
//! y = z, quantities per radian: `model::axisymmetry`).
//!
//! Torsionless axisymmetric motion has u_θ = 0 and no θ-dependence, so the
//! deformation gradient is block diagonal: the r–z block from the in-plane
//! gradient and F_θθ = r / R, the hoop stretch. In an increment from radius r_p
//! the nodal displacements u_I give
//!
//!   ΔF_θθ = 1 + u_r(x_p) / r_p = 1 + Σ_I u_Ir S_Ip / r_p
//!
//! (the axisymmetric MPM of Sulsky & Schreyer 1996, CMAME 139, 409–429; the
//! GIMP form of Nairn & Guilkey 2015, IJNME 101, 127–147), and the virtual work
//! ∫ σ : δε r dr dz of a particle of volume V_p (per radian), with δε_θθ = δu_r / r,
//! adds the hoop stress to the radial internal force:
//!
//!   f_Ir = Σ_p V_p (σ_rr ∂S_I/∂r + σ_rz ∂S_I/∂z + σ_θθ S_Ip / r_p).
//!
//! The stencils carry S_Ip / r_p per entry (`Stencils::hoop`), the "hoop
//! gradient" of node I, from which the stress update, the internal force and
//! the tangent read it. Particles never sit on the axis (their centres start at
//! half a particle spacing from it and the axis nodes have zero radial
//! velocity; `solver::divergence` stops a run whose particle reaches r ≤ 0), so
//! S_Ip / r_p is finite at every entry, also of nodes on the axis, whose radial
//! force is a reaction.

use crate::dim::Vector;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::Stencils;
use rayon::prelude::*;

/// Fill `st.hoop` with S_Ip / r_p (r_p = x_p's first coordinate) for every
/// entry of the stencils computed at the positions `x`.
pub fn hoop_gradients<const D: usize>(st: &mut Stencils<D>, x: &[Vector<D>]) {
    let stride = st.stride;
    let mut hoop = std::mem::take(&mut st.hoop);
    hoop.resize(st.len(), 0.0);
    let values = &*st;
    hoop.par_chunks_mut(stride)
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .for_each(|(p, hoop)| {
            // S_Ip / r_p: the hoop gradient of node I.
            let r = x[p][0];
            for (h, e) in hoop.iter_mut().zip(values.range(p)) {
                *h = values.weight_at(p, e) / r;
            }
        });
    st.hoop = hoop;
}

/// ΔF_θθ = 1 + Σ_I u_Ir S_Ip / r_p from a particle's entries as pairs
/// (u_Ir, S_Ip / r_p): u_r(x_p) / r_p, the hoop strain of the increment.
pub fn hoop_stretch(entries: impl Iterator<Item = (f64, f64)>) -> f64 {
    1.0 + entries.map(|(u_r, hoop)| u_r * hoop).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Mat3;
    use crate::model::grid::Grid;
    use crate::model::tensors::{Layout, Tensors};
    use crate::physics::shape::ShapeFunction;
    use strum::IntoEnumIterator;

    /// A uniform radial expansion u_r = ε r is reproduced exactly by every
    /// family's hoop stretch (ΔF_θθ = 1 + ε), also next to the axis, since
    /// Σ_I S_Ip r_I = r_p (linear reproduction).
    #[test]
    fn uniform_expansion_gives_the_exact_hoop_stretch() {
        for shape in ShapeFunction::iter().filter(|&s| s != ShapeFunction::Cpdi) {
            let grid = Grid::<2>::new(
                Vector::<2>::new(0.0, 0.0),
                Vector::<2>::new(2.0, 1.0),
                [8, 4],
                shape.degree(),
            );
            let x: Vec<Vector<2>> = (0..16)
                .map(|k| Vector::<2>::new(0.0625 + 0.125 * k as f64, 0.3))
                .collect();
            let half = vec![Vector::<2>::new(0.0625, 0.125); x.len()];
            let f = Tensors::filled(Layout::gradient(2), x.len(), &Mat3::identity());
            let mut st = Stencils::<2>::default();
            st.compute(shape, &grid, &x, &half, &f);
            hoop_gradients(&mut st, &x);
            let eps = 1e-3;
            for (p, xp) in x.iter().enumerate() {
                let stretch = hoop_stretch(st.range(p).map(|e| {
                    let r_node = grid.node_position(grid.node_ijk(st.node[e] as usize))[0];
                    (eps * r_node, st.hoop[e])
                }));
                assert!(
                    (stretch - 1.0 - eps).abs() < 1e-14,
                    "{shape:?} at r = {}: ΔF_θθ − 1 = {:e}",
                    xp[0],
                    stretch - 1.0
                );
            }
        }
    }
}
