//! The inertia of the implicit step's tangent, M/(βΔt²) (thesis 2-40), with the
//! lumped nodal mass m_I (2-24) or the consistent mass M_IJ = Σ_p m_p S_Ip S_Jp,
//! diagonal in the components.

use super::{Components, Coupling, Dofs, Storage, Tangent};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;

/// Adds m_I · inertia on the diagonal of every node's components (a tied node's
/// mass spread onto its masters, T_rowᵀ m T_col).
pub fn add_lumped_mass<const D: usize>(k: &mut Tangent, dofs: &Dofs, mass: &[f64], inertia: f64) {
    for (node, m_i) in mass.iter().enumerate() {
        for d in 0..D {
            let t = dofs.terms(node, d);
            for &(r, cr) in t.as_slice() {
                for &(c, cc) in t.as_slice() {
                    if k.storage == Storage::Full || r >= c {
                        let s = k.slot(r, c).expect("mass entry in the pattern");
                        k.values[s] += m_i * inertia * cr * cc;
                    }
                }
            }
        }
    }
}

/// Adds Σ_p m_p S_Ip S_Jp · inertia.
pub fn add_consistent_mass<const D: usize>(
    k: &mut Tangent,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    particle_mass: &[f64],
    inertia: f64,
) {
    k.add_terms(
        map,
        st,
        dofs,
        Coupling::<D, D>::displacements(Components::Diagonal),
        |q, e2, _needed, block| {
            for (local, e1) in st.range(q).enumerate() {
                let v = particle_mass[q] * st.weight(e1) * st.weight(e2) * inertia;
                for i in 0..D {
                    block[local * D * D + i * D + i] = v;
                }
            }
            true
        },
    );
}
