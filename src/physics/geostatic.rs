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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// A 2 × 4 m column of Modified Cam-Clay at OCR 2 with K0 = 1 − sin φ_cs
    /// (no `k0`): after the K0 stresses, `Model::initialise_history` gives every
    /// particle p_c0 = OCR (p′ + q²/(M² p′)) of its own stress.
    #[test]
    fn cam_clay_preconsolidation_follows_the_k0_stresses() {
        let text = "dimension = 2\ngravity = [0.0, -10.0]\n[grid]\nmin = [0.0, 0.0]\nmax = [2.0, 4.0]\ncells = [2, 4]\n\
            [[material]]\nname = \"clay\"\nmodel = \"modified_cam_clay\"\ndensity = 1800.0\nlambda = 0.2\nkappa = 0.04\n\
            critical_state_ratio = 1.2\npoisson_ratio = 0.3\ninitial_void_ratio = 1.0\nocr = 2.0\n\
            [[body]]\nname = \"column\"\nmaterial = \"clay\"\nshape = \"rectangle\"\nmin = [0.0, 0.0]\nmax = [2.0, 4.0]\n\
            [[boundary]]\nface = \"ymin\"\ncondition = \"fixed\"\n[geostatic]\n[solver]\nkind = \"explicit\"\nend_time = 0.1\n";
        let scene = Scene::parse("column.toml", text, &[]).unwrap();
        let mut model = Model::<2>::build(&scene).unwrap();
        initialise(&mut model, scene.config.geostatic.as_ref().unwrap());
        model.initialise_history();
        let m = 1.2f64;
        let sin = 3.0 * m / (6.0 + m);
        let p = &model.particles;
        for q in 0..p.len() {
            let s = p.stress.get(q);
            let (sv, sh) = (s[(1, 1)], s[(0, 0)]);
            assert!(
                (sh - (1.0 - sin) * sv).abs() < 1e-9 * sv.abs(),
                "Jáky's K0 of φ_cs"
            );
            let mean = -s.trace() / 3.0;
            let dev = s + Mat3::identity() * mean;
            let q2 = 1.5 * dev.norm_squared();
            let expect = 2.0 * (mean + q2 / (m * m * mean));
            let pc = p.history.get(q)[1];
            assert!(
                (pc - expect).abs() < 1e-12 * expect,
                "particle {q}: p_c = {pc}, expected {expect}"
            );
        }
    }
}
