//! What the contact of each pair of velocity fields did, summed between two
//! reads: impulse, frictional dissipation and nodes in contact (contact.csv),
//! for the explicit and the implicit contact alike.

use crate::dim::Vector;
use crate::scene::contact::ContactPlan;

/// What the contact of one field pair did since the totals were last taken.
#[derive(Clone, Debug, PartialEq)]
pub struct PairTotal<const D: usize> {
    /// The fields' first bodies (r < s).
    pub bodies: [u32; 2],
    /// Momentum the contact delivered to field r's particles (s got the opposite).
    pub impulse: Vector<D>,
    /// Energy dissipated by friction: the work of the tangential impulses on the
    /// slip, −J_t·(w_t + w_t')/2 per correction (w = v_r − v_s before and after).
    pub dissipation: f64,
    /// Nodes in contact in the last step.
    pub nodes: usize,
}

/// A zero total for every pair of fields i < j, in the order of
/// `field_split::pair_position` (contact.csv's rows).
pub fn pair_totals<const D: usize>(plan: &ContactPlan) -> Vec<PairTotal<D>> {
    let first_body = |field: usize| {
        (plan.field_of_body.iter())
            .position(|&x| x as usize == field)
            .unwrap() as u32
    };
    let f = plan.fields;
    (0..f)
        .flat_map(|i| (i + 1..f).map(move |j| (i, j)))
        .map(|(i, j)| PairTotal {
            bodies: [first_body(i), first_body(j)],
            impulse: Vector::<D>::zeros(),
            dissipation: 0.0,
            nodes: 0,
        })
        .collect()
}
