//! The geometry of a body: an axis-aligned box (rectangle in 2D), a ball (disk,
//! sphere), a cylinder along z (3D) or a simple polygon (2D), as given by the `[[body]]` keys. The model
//! fills it with particles (`contains`, within `BodyConfig::bounds`, which the
//! validation also uses) and measures the depth of a particle below its body's
//! top surface for geostatic stresses (`top`).

use crate::scene::{BodyConfig, BodyShape};

#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// Corners `min` and `max`.
    Box { min: Vec<f64>, max: Vec<f64> },
    /// `centre` and `radius`.
    Ball { centre: Vec<f64>, radius: f64 },
    /// Vertices in order.
    Polygon(Vec<Vec<f64>>),
    /// Axis along z from `base` (centre of the bottom face) up by `height`.
    Cylinder {
        base: Vec<f64>,
        radius: f64,
        height: f64,
    },
}

impl Geometry {
    /// The geometry of a validated `[[body]]` table.
    pub fn of(b: &BodyConfig) -> Geometry {
        match b.shape {
            BodyShape::Rectangle | BodyShape::Box => Geometry::Box {
                min: b.min.clone().expect("validated"),
                max: b.max.clone().expect("validated"),
            },
            BodyShape::Disk | BodyShape::Sphere => Geometry::Ball {
                centre: b.centre.clone().expect("validated"),
                radius: b.radius.expect("validated"),
            },
            BodyShape::Polygon => Geometry::Polygon(b.vertices.clone().expect("validated")),
            BodyShape::Cylinder => Geometry::Cylinder {
                base: b.centre.clone().expect("validated"),
                radius: b.radius.expect("validated"),
                height: b.height.expect("validated"),
            },
        }
    }

    /// Is the point x strictly inside?
    pub fn contains(&self, x: &[f64]) -> bool {
        match self {
            Geometry::Box { min, max } => (0..x.len()).all(|d| x[d] > min[d] && x[d] < max[d]),
            Geometry::Ball { centre, radius } => {
                let r2: f64 = (0..x.len()).map(|d| (x[d] - centre[d]).powi(2)).sum();
                r2 < radius.powi(2)
            }
            Geometry::Polygon(v) => point_in_polygon(x[0], x[1], v),
            Geometry::Cylinder {
                base,
                radius,
                height,
            } => {
                let r2 = (x[0] - base[0]).powi(2) + (x[1] - base[1]).powi(2);
                r2 < radius.powi(2) && x[2] > base[2] && x[2] < base[2] + height
            }
        }
    }

    /// Height (along `up` × axis v, `up` = ±1) of the top surface on the vertical
    /// line through x: the highest boundary point there.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        match self {
            Geometry::Box { min, max } => (up * min[v]).max(up * max[v]),
            Geometry::Ball { centre, radius } => {
                let r2: f64 = (0..x.len())
                    .filter(|&d| d != v)
                    .map(|d| (x[d] - centre[d]).powi(2))
                    .sum();
                up * centre[v] + (radius.powi(2) - r2).max(0.0).sqrt()
            }
            Geometry::Polygon(vertices) => polygon_top(vertices, x[1 - v], v, up),
            Geometry::Cylinder { base, height, .. } if v == 2 => {
                (up * base[2]).max(up * (base[2] + height))
            }
            Geometry::Cylinder { base, radius, .. } => {
                // Across the axis: the circle's top on the line through x.
                let w = 1 - v;
                let r2 = (x[w] - base[w]).powi(2);
                up * base[v] + (radius.powi(2) - r2).max(0.0).sqrt()
            }
        }
    }
}

/// Even-odd rule (ray crossing to +x).
fn point_in_polygon(x: f64, y: f64, v: &[Vec<f64>]) -> bool {
    let mut inside = false;
    let n = v.len();
    for k in 0..n {
        let (a, b) = (&v[k], &v[(k + 1) % n]);
        if (a[1] > y) != (b[1] > y) {
            let xc = a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x < xc {
                inside = !inside;
            }
        }
    }
    inside
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
    use super::*;

    #[test]
    fn polygon_membership() {
        let tri = vec![vec![0.0, 0.0], vec![2.0, 0.0], vec![0.0, 2.0]];
        assert!(point_in_polygon(0.5, 0.5, &tri));
        assert!(!point_in_polygon(1.5, 1.5, &tri));
    }

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
