//! The inertia of the implicit step's tangent, M/(βΔt²) (thesis 2-40), with the
//! lumped nodal mass m_I (2-24) or the consistent mass M_IJ = Σ_p m_p S_Ip S_Jp,
//! diagonal in the components.

use super::{push_stencil_pairs, push_terms, Components, Dofs, Triplets};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;

/// Adds m_I · inertia on the diagonal of every node's components.
pub fn lumped_mass_triplets<const D: usize>(
    dofs: &Dofs,
    mass: &[f64],
    inertia: f64,
    out: &mut Triplets,
) {
    for (node, m_i) in mass.iter().enumerate() {
        for d in 0..D {
            let t = dofs.terms(node, d, D);
            push_terms(out, &t, &t, m_i * inertia);
        }
    }
}

/// Adds Σ_p m_p S_Ip S_Jp · inertia, particle by particle in order.
pub fn consistent_mass_triplets<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    particle_mass: &[f64],
    inertia: f64,
    out: &mut Triplets,
) {
    for (q, m_q) in particle_mass.iter().enumerate() {
        push_stencil_pairs(
            out,
            map,
            st,
            dofs,
            q,
            Components::Diagonal,
            |e1, e2, _, _| m_q * st.weight[e1] * st.weight[e2] * inertia,
        );
    }
}
