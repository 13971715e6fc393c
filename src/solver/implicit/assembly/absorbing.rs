//! The tangent of the absorbing faces' residual term (`AbsorbingStep::add_residual`,
//! thesis 2-63): the dashpots act through the end-of-step velocity
//! v(u) = v* + rate · u, the springs through u, so each layer particle adds
//! S_Ip S_Jp (rate C_p + K_p), diagonal in the components.

use super::{push_stencil_pairs, Components, Dofs, Triplets};
use crate::physics::absorbing::AbsorbingStep;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;

/// Adds Σ_p S_Ip S_Jp (rate C_p + K_p) over the layer particles onto the unknowns
/// (tied nodes through their masters; symmetric, positive semi-definite).
pub fn absorbing_triplets<const D: usize>(
    step: &AbsorbingStep<D>,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    out: &mut Triplets,
) {
    for lp in &step.layer {
        let coefficient = lp.damping * step.rate + lp.stiffness;
        push_stencil_pairs(
            out,
            map,
            st,
            dofs,
            lp.q,
            Components::Diagonal,
            |e1, e2, d, _| st.weight[e1] * st.weight[e2] * coefficient[d],
        );
    }
}
