//! Geostatic initial stresses by the K0 procedure.
//!
//! Each particle gets the vertical stress of the soil column above it in its own
//! body, σ_v = −ρ g d (tension positive), and the horizontal stresses
//! σ_h = K0 σ_v (all horizontal directions, σ_zz in plane strain included); no
//! shear. The depth d is the vertical distance from the particle (reference
//! position) up to the top surface of its body at the particle's horizontal
//! position: the highest boundary point of the body on the vertical line through
//! the particle. On a sloping surface this is the depth below the slope face
//! directly above, so the K0 state is only exact under level ground; a
//! quasi-static stage with `gravity_ramp = false` then brings the slope to
//! equilibrium under full gravity. Bodies are independent: a body resting on
//! another does not load it (give layered ground as one body per material only
//! when the upper layers are thin, or load them by a gravity stage).
//! K0 is the scene's `k0`, else Jáky's 1 − sin φ of the body's material (as
//! given, before any strength reduction).
//!
//! With `[water]` K0 holds for the effective stress (Terzaghi, tension
//! positive: σ = σ′ − p I): σ_v = −ρ g d from the total (saturated) density as
//! before, σ′_v = σ_v + p with p of the water field at the particle
//! (`model::water`), σ′_h = K0 σ′_v, and the particle stores σ′. The water table
//! is taken to lie at or below the body's top (free water above it would load
//! the top surface, which this column does not count).

use crate::dim::Mat3;
use crate::model::Model;
use crate::scene::GeostaticConfig;

/// Set the K0 stresses of every particle, with the `[geostatic]` table's `k0`
/// if it has one. The model's gravity must point along one axis (validated).
pub fn initialise<const D: usize>(model: &mut Model<D>, g: &GeostaticConfig) {
    let v = (0..D)
        .position(|d| model.gravity[d] != 0.0)
        .expect("validated");
    let g_mag = model.gravity[v].abs();
    // +1 when the vertical axis points up (gravity along −axis).
    let up = -model.gravity[v].signum();
    let p = &mut model.particles;
    for q in 0..p.len() {
        let m = p.material[q] as usize;
        let body = &model.bodies[p.body[q] as usize];
        // A rigid body carries no stress.
        if !body.kind.carries_stress() {
            continue;
        }
        let k0 = g.k0.unwrap_or_else(|| {
            let phi = model.base_materials[m]
                .frictional_strength()
                .expect("validated");
            1.0 - phi.friction_angle.sin()
        });
        let depth = (body.geometry.top(p.x0[q].as_slice(), v, up) - up * p.x0[q][v]).max(0.0);
        let sigma_v = -model.materials[m].density() * g_mag * depth;
        // σ′_v = σ_v + p (Terzaghi), 0 without [water].
        let pore = (model.water.as_ref()).map_or(0.0, |w| w.pressure(p.x0[q].as_slice()));
        let effective_v = sigma_v + pore;
        let mut s = Mat3::from_diagonal_element(k0 * effective_v);
        s[(v, v)] = effective_v;
        p.stress.set(q, &s);
    }
}
