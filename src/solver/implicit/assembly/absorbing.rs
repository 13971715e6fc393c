//! The tangent of the absorbing faces' residual term (`AbsorbingStep::add_residual`,
//! thesis 2-63): the dashpots act through the end-of-step velocity
//! v(u) = v* + rate · u, the springs through u, so each layer particle adds
//! S_Ip S_Jp (rate C_p + K_p), diagonal in the components.

use super::{Components, Coupling, Dofs, Tangent};
use crate::dim::Vector;
use crate::physics::boundary::absorbing::AbsorbingStep;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;

/// Adds Σ_p S_Ip S_Jp (rate C_p + K_p) over the layer particles (a particle in
/// the layers of several faces takes the sum; symmetric, positive semi-definite).
pub fn add_absorbing<const D: usize>(
    k: &mut Tangent,
    step: &AbsorbingStep<D>,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
) {
    if step.is_empty() {
        return;
    }
    let mut coefficient: Vec<Option<Vector<D>>> = vec![None; st.count.len()];
    for lp in &step.layer {
        let c = lp.damping * step.rate + lp.stiffness;
        *coefficient[lp.q].get_or_insert_with(Vector::<D>::zeros) += c;
    }
    k.add_terms(
        map,
        st,
        dofs,
        Coupling::<D, D>::displacements(Components::Diagonal),
        |q, e2, _needed, block| {
            let Some(c) = coefficient[q] else {
                return false;
            };
            for (local, e1) in st.range(q).enumerate() {
                let w = st.weight(e1) * st.weight(e2);
                for d in 0..D {
                    block[local * D * D + d * D + d] = w * c[d];
                }
            }
            true
        },
    );
}
