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
//! K0 is the scene's `k0`, else Jáky's 1 − sin φ of the body's material.

use crate::dim::Mat3;
use crate::model::Model;
use crate::scene::{BodyConfig, SceneConfig, Shape};

/// Set the K0 stresses of every particle (`c.geostatic` must be present).
pub fn initialise<const D: usize>(model: &mut Model<D>, c: &SceneConfig) {
    let g = c.geostatic.as_ref().expect("caller checks [geostatic]");
    let gravity = c.gravity.as_deref().expect("validated");
    let v = gravity.iter().position(|&x| x != 0.0).expect("validated");
    let g_mag = gravity[v].abs();
    // +1 when the vertical axis points up (gravity along −axis).
    let up = -gravity[v].signum();
    let p = &mut model.particles;
    for q in 0..p.len() {
        let body = &c.bodies[p.body[q] as usize];
        let material = c
            .materials
            .iter()
            .find(|m| m.name == body.material)
            .expect("validated");
        let k0 =
            g.k0.unwrap_or_else(|| 1.0 - material.friction_angle.unwrap().to_radians().sin());
        let mut x = [0.0; 3];
        (0..D).for_each(|d| x[d] = p.x0[q][d]);
        let depth = (top(body, &x[..D], v, up) - up * x[v]).max(0.0);
        let sigma_v = -model.materials[p.material[q] as usize].density() * g_mag * depth;
        let mut s = Mat3::from_diagonal_element(k0 * sigma_v);
        s[(v, v)] = sigma_v;
        p.stress[q] = s;
    }
}

/// Height (along `up` × axis v) of the body's top surface on the vertical line
/// through x.
fn top(b: &BodyConfig, x: &[f64], v: usize, up: f64) -> f64 {
    match b.shape {
        Shape::Rectangle | Shape::Box => {
            let (lo, hi) = (b.min.as_ref().unwrap(), b.max.as_ref().unwrap());
            (up * lo[v]).max(up * hi[v])
        }
        Shape::Disk | Shape::Sphere => {
            let c = b.centre.as_ref().unwrap();
            let r2: f64 = (0..x.len())
                .filter(|&d| d != v)
                .map(|d| (x[d] - c[d]).powi(2))
                .sum();
            up * c[v] + (b.radius.unwrap().powi(2) - r2).max(0.0).sqrt()
        }
        Shape::Polygon => polygon_top(b.vertices.as_ref().unwrap(), x[1 - v], v, up),
    }
}

/// Highest crossing of the vertical line (horizontal coordinate `h`) with the
/// polygon's edges (2D; `v` is the vertical axis).
fn polygon_top(vertices: &[Vec<f64>], h: f64, v: usize, up: f64) -> f64 {
    let n = vertices.len();
    let mut best = f64::NEG_INFINITY;
    for k in 0..n {
        let (a, b) = (&vertices[k], &vertices[(k + 1) % n]);
        let (ah, bh) = (a[1 - v], b[1 - v]);
        if h < ah.min(bh) || h > ah.max(bh) {
            continue;
        }
        let height = if ah == bh {
            (up * a[v]).max(up * b[v])
        } else {
            up * (a[v] + (h - ah) / (bh - ah) * (b[v] - a[v]))
        };
        best = best.max(height);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::polygon_top;

    #[test]
    fn top_of_a_slope_polygon() {
        // 2:1 slope, crest at x = 15, toe at x = 35, height 10.
        let v: Vec<Vec<f64>> = [[0.0, 0.0], [35.0, 0.0], [15.0, 10.0], [0.0, 10.0]]
            .iter()
            .map(|p| p.to_vec())
            .collect();
        assert_eq!(polygon_top(&v, 5.0, 1, 1.0), 10.0);
        assert!((polygon_top(&v, 25.0, 1, 1.0) - 5.0).abs() < 1e-12);
        assert!((polygon_top(&v, 35.0, 1, 1.0) - 0.0).abs() < 1e-12);
    }
}
