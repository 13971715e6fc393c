//! The prescribed pore-water field of `[water]` (docs/pore_water.md): the one
//! place the pore pressure p of a particle is computed.
//!
//! Below the phreatic surface (Terzaghi's effective stress, tension positive:
//! σ = σ′ − p I, so p > 0 is compression of the water)
//!
//!   p = γ_w d_v cos²β,
//!
//! d_v the vertical depth below the surface, β its inclination to the
//! horizontal: cos²β = 1 for hydrostatic water (a piezometric line), and the
//! correction of flow parallel to a straight phreatic surface for
//! `seepage = "parallel"` (the flow net of an infinite slope: equipotentials
//! normal to the surface; e.g. Duncan, Wright & Brandon, *Soil Strength and
//! Slope Stability*, 2014, §6). Above the surface p = 0 (no suction).
//!
//! The surface is a level (the grid plane x_v = h, v the axis of gravity) or,
//! in 2D and axisymmetric mode, a polyline h(x_h) over the other axis, linear
//! between its points and level beyond its ends (β of the segment under the
//! particle). With parallel seepage below a level gravity may be tilted from the
//! axis v by β (an infinite slope in its slope-aligned frame): then
//! d_v = (h − x_v)/cos β and p = γ_w (h − x_v) cos β.
//!
//! p is evaluated at the particles' positions at the start of each step
//! (`Model::update_pore_pressure`, called by the run before every step), so it
//! is a constant of the step: the explicit internal force and the implicit
//! residual take σ′ − p I, and the implicit tangent is the derivative of that
//! at fixed p (`solver::implicit::assembly::stiffness`).

use crate::model::body::Body;
use crate::model::particles::Particles;
use crate::scene::{Seepage, WaterConfig};

/// The phreatic surface, as a height along the vertical axis.
#[derive(Clone, Debug, PartialEq)]
enum Surface {
    /// The plane x_v = h.
    Level(f64),
    /// h(x_h) through points [x_h, h], x_h increasing.
    Line {
        horizontal: usize,
        points: Vec<[f64; 2]>,
    },
}

/// A prescribed pore-water field, built from a validated `[water]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct Water {
    /// γ_w = ρ_w g.
    unit_weight: f64,
    /// The grid axis of elevations (the one gravity points along, or nearest to).
    vertical: usize,
    /// +1 when elevations grow along +vertical (gravity along −vertical).
    up: f64,
    /// cos of the angle between gravity and the vertical axis (1 unless tilted).
    tilt_cos: f64,
    surface: Surface,
    seepage: Seepage,
}

impl Water {
    /// The field of `w` under `gravity` (D components, validated).
    pub fn new(w: &WaterConfig, gravity: &[f64]) -> Water {
        let vertical = (0..gravity.len())
            .max_by(|&a, &b| gravity[a].abs().total_cmp(&gravity[b].abs()))
            .expect("validated: gravity has components");
        let g = gravity.iter().map(|x| x * x).sum::<f64>().sqrt();
        let surface = match (w.level, &w.phreatic_line) {
            (Some(h), _) => Surface::Level(h),
            (None, Some(line)) => Surface::Line {
                horizontal: 1 - vertical,
                points: line.iter().map(|p| [p[0], p[1]]).collect(),
            },
            (None, None) => unreachable!("validated"),
        };
        Water {
            unit_weight: w.unit_weight.expect("validated"),
            vertical,
            up: -gravity[vertical].signum(),
            tilt_cos: gravity[vertical].abs() / g,
            surface,
            seepage: w.seepage,
        }
    }

    /// p at position x (2-D or 3-D components): γ_w d_v cos²β below the
    /// surface, 0 above.
    pub fn pressure(&self, x: &[f64]) -> f64 {
        let (h, cos2) = self.surface_at(x);
        // The depth below the surface along the vertical axis.
        let depth = self.up * (h - x[self.vertical]);
        // d_v = depth / cos β_g, times cos²β_g: depth cos β_g (1 unless tilted).
        (self.unit_weight * depth * self.tilt_cos * cos2).max(0.0)
    }

    /// The surface's height above x and the cos²β of parallel flow below it
    /// (1 for hydrostatic water and for a tilted frame's level, whose cos β is
    /// `tilt_cos`).
    fn surface_at(&self, x: &[f64]) -> (f64, f64) {
        match &self.surface {
            Surface::Level(h) => (*h, 1.0),
            Surface::Line { horizontal, points } => {
                let (h, slope) = interpolate(points, x[*horizontal]);
                let cos2 = match self.seepage {
                    Seepage::Hydrostatic => 1.0,
                    // cos²β = 1 / (1 + tan²β).
                    Seepage::Parallel => 1.0 / (1.0 + slope * slope),
                };
                (h, cos2)
            }
        }
    }

    /// Set every particle's pore pressure at its current position: p of the
    /// field on the particles of bodies that carry a stress (continua), 0 on
    /// the others (rigid and peridynamic bodies).
    pub fn assign<const D: usize>(&self, bodies: &[Body], p: &mut Particles<D>) {
        p.pore_pressure.resize(p.len(), 0.0);
        for q in 0..p.len() {
            let continuum = bodies[p.body[q] as usize].kind.carries_stress();
            p.pore_pressure[q] = match continuum {
                true => self.pressure(p.x[q].as_slice()),
                false => 0.0,
            };
        }
    }
}

/// The height h(s) of a polyline through `points` (s increasing) and its slope
/// dh/ds: linear between the points, level (slope 0) beyond its ends.
fn interpolate(points: &[[f64; 2]], s: f64) -> (f64, f64) {
    let (first, last) = (points[0], points[points.len() - 1]);
    if s <= first[0] {
        return (first[1], 0.0);
    }
    if s >= last[0] {
        return (last[1], 0.0);
    }
    let i = points.partition_point(|p| p[0] <= s) - 1;
    let (a, b) = (points[i], points[i + 1]);
    let slope = (b[1] - a[1]) / (b[0] - a[0]);
    (a[1] + slope * (s - a[0]), slope)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(level: Option<f64>, line: Option<Vec<Vec<f64>>>, seepage: Seepage) -> WaterConfig {
        WaterConfig {
            unit_weight: Some(10.0),
            level,
            phreatic_line: line,
            seepage,
        }
    }

    #[test]
    fn hydrostatic_below_a_level_zero_above() {
        let w = Water::new(&config(Some(4.0), None, Seepage::Hydrostatic), &[0.0, -9.0]);
        assert_eq!(w.pressure(&[3.0, 1.0]), 30.0);
        assert_eq!(w.pressure(&[3.0, 5.0]), 0.0);
        // Gravity along +y: elevations grow along −y.
        let w = Water::new(&config(Some(4.0), None, Seepage::Hydrostatic), &[0.0, 9.0]);
        assert_eq!(w.pressure(&[3.0, 6.0]), 20.0);
        assert_eq!(w.pressure(&[3.0, 1.0]), 0.0);
    }

    #[test]
    fn polyline_interpolates_and_holds_its_ends() {
        let line = vec![vec![0.0, 8.0], vec![10.0, 3.0], vec![20.0, 3.0]];
        let w = Water::new(
            &config(None, Some(line.clone()), Seepage::Hydrostatic),
            &[0.0, -9.0],
        );
        assert_eq!(w.pressure(&[5.0, 0.0]), 55.0);
        assert_eq!(w.pressure(&[-5.0, 0.0]), 80.0);
        assert_eq!(w.pressure(&[25.0, 1.0]), 20.0);
        // Parallel flow under the first segment, tan β = 1/2: cos²β = 0.8.
        let w = Water::new(&config(None, Some(line), Seepage::Parallel), &[0.0, -9.0]);
        assert!((w.pressure(&[5.0, 0.0]) - 55.0 * 0.8).abs() < 1e-12);
        assert_eq!(w.pressure(&[15.0, 0.0]), 30.0);
    }

    #[test]
    fn tilted_frame_gives_the_infinite_slope_pressure() {
        // Slope-aligned frame, β = atan(1/2): the surface y = 5 is the slope face,
        // a point at normal depth n has vertical depth n / cos β: p = γ_w n cos β.
        let beta = 0.5f64.atan();
        let g = [9.0 * beta.sin(), -9.0 * beta.cos()];
        let w = Water::new(&config(Some(5.0), None, Seepage::Parallel), &g);
        let p = w.pressure(&[40.0, 1.0]);
        let vertical_depth = 4.0 / beta.cos();
        assert!((p - 10.0 * vertical_depth * beta.cos().powi(2)).abs() < 1e-12);
    }
}
