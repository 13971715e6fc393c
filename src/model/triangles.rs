//! A closed triangulated surface (`shape = "surface"`, read from STL by
//! `model::import::stl`): its vertices and triangles, the check that it is
//! closed, and what the model asks of a body's geometry.
//!
//! Inside or outside is the generalised winding number (Jacobson, Kavan and
//! Sorkine-Hornung, "Robust inside-outside segmentation using generalized
//! winding numbers", SIGGRAPH 2013): w(p) = Σ_t Ω_t(p) / 4π, Ω_t the signed
//! solid angle of triangle t seen from p (Van Oosterom and Strackee, IEEE
//! Trans. Biomed. Eng. 30, 1983: tan(Ω/2) = a·(b × c) / (|a||b||c| + (a·b)|c|
//! + (b·c)|a| + (c·a)|b|), with a, b, c the corners less p). On a closed,
//! consistently oriented surface w is ±1 inside and 0 outside, whichever way
//! the triangles face and however a lattice point lines up with edges and
//! vertices (a ray-parity test miscounts a ray through an edge); a point is
//! inside where |w| > ½. It costs one atan2 per triangle and point.

/// Vertices and triangles (three vertex indices each, in the file's order).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleSurface {
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[usize; 3]>,
}

/// Why a surface does not bound a solid: an edge of one triangle only (or of
/// three or more), or two neighbours that face opposite ways.
#[derive(Clone, Debug, PartialEq)]
pub enum NotClosed {
    /// The edge's two vertices, and the triangle it belongs to (0-based).
    OpenEdge {
        edge: [[f64; 3]; 2],
        triangle: usize,
        triangles_at_edge: usize,
    },
    /// Two triangles run the edge the same way: their orientations disagree.
    Flipped {
        edge: [[f64; 3]; 2],
        triangles: [usize; 2],
    },
}

impl std::fmt::Display for NotClosed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = |v: &[f64; 3]| format!("({}, {}, {})", v[0], v[1], v[2]);
        match self {
            NotClosed::OpenEdge {
                edge,
                triangle,
                triangles_at_edge,
            } => write!(
                f,
                "the surface is not closed: the edge {} – {} of triangle {} (from 1, in \
                 the file's order) belongs to {triangles_at_edge} triangle(s), not 2",
                p(&edge[0]),
                p(&edge[1]),
                triangle + 1
            ),
            NotClosed::Flipped { edge, triangles } => write!(
                f,
                "triangles {} and {} (from 1) face opposite ways: both run the edge {} – {} \
                 in the same direction, so the surface has no consistent inside",
                triangles[0] + 1,
                triangles[1] + 1,
                p(&edge[0]),
                p(&edge[1])
            ),
        }
    }
}

type Edge = (usize, usize);

impl TriangleSurface {
    /// Whether every edge belongs to exactly two triangles that run it in
    /// opposite directions; else the first offending edge in the file's order.
    pub fn check_closed(&self) -> Result<(), NotClosed> {
        // Each undirected edge: the triangles that have it, with its direction.
        let mut uses: std::collections::HashMap<Edge, Vec<(usize, bool)>> = Default::default();
        for (t, tri) in self.triangles.iter().enumerate() {
            for (a, b) in edges(tri) {
                uses.entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((t, a < b));
            }
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            for (a, b) in edges(tri) {
                let at = &uses[&(a.min(b), a.max(b))];
                let edge = [self.vertices[a], self.vertices[b]];
                if at.len() != 2 {
                    return Err(NotClosed::OpenEdge {
                        edge,
                        triangle: t,
                        triangles_at_edge: at.len(),
                    });
                }
                if at[0].1 == at[1].1 {
                    return Err(NotClosed::Flipped {
                        edge,
                        triangles: [at[0].0, at[1].0],
                    });
                }
            }
        }
        Ok(())
    }

    fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.triangles[t].map(|k| self.vertices[k])
    }

    /// The generalised winding number at p (module doc).
    pub fn winding_number(&self, p: &[f64]) -> f64 {
        let mut omega = 0.0;
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t).map(|v| sub(&v, p));
            let (la, lb, lc) = (norm(&a), norm(&b), norm(&c));
            let numerator = dot(&a, &cross(&b, &c));
            let denominator = la * lb * lc + dot(&a, &b) * lc + dot(&b, &c) * la + dot(&c, &a) * lb;
            omega += 2.0 * numerator.atan2(denominator);
        }
        omega / (4.0 * std::f64::consts::PI)
    }

    /// Is p inside the surface (|w| > ½)?
    pub fn contains(&self, p: &[f64]) -> bool {
        self.winding_number(p).abs() > 0.5
    }

    /// The enclosed volume, Σ_t a·(b × c)/6 (positive for outward-facing
    /// triangles).
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(&a, &cross(&b, &c)) / 6.0
            })
            .sum()
    }

    /// The box (min, max) of the vertices.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![f64::INFINITY; 3];
        let mut hi = vec![f64::NEG_INFINITY; 3];
        for v in &self.vertices {
            for d in 0..3 {
                lo[d] = lo[d].min(v[d]);
                hi[d] = hi[d].max(v[d]);
            }
        }
        (lo, hi)
    }

    /// Height (along `up` × axis v) of the highest point of the surface on
    /// the line along axis v through x; −∞ where the line misses it.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        let [i, j] = match v {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        let mut best = f64::NEG_INFINITY;
        for t in 0..self.triangles.len() {
            let c = self.corners(t);
            if let Some(w) = barycentric([x[i], x[j]], c.map(|p| [p[i], p[j]])) {
                let height = w[0] * c[0][v] + w[1] * c[1][v] + w[2] * c[2][v];
                best = best.max(up * height);
            }
        }
        best
    }
}

/// The three directed edges of a triangle.
fn edges(t: &[usize; 3]) -> [Edge; 3] {
    [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
}

/// The barycentric coordinates of the point q in the plane triangle c, edges
/// included; `None` outside it or for a triangle seen edge-on.
fn barycentric(q: [f64; 2], c: [[f64; 2]; 3]) -> Option<[f64; 3]> {
    let area = |a: [f64; 2], b: [f64; 2], p: [f64; 2]| {
        (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    };
    let total = area(c[0], c[1], c[2]);
    if total == 0.0 {
        return None;
    }
    let w = [
        area(c[1], c[2], q) / total,
        area(c[2], c[0], q) / total,
        area(c[0], c[1], q) / total,
    ];
    w.iter().all(|&x| x >= 0.0).then_some(w)
}

fn sub(a: &[f64; 3], p: &[f64]) -> [f64; 3] {
    [a[0] - p[0], a[1] - p[1], a[2] - p[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube [0, 1]³, two triangles a face, facing out.
    pub(crate) fn cube() -> TriangleSurface {
        let vertices = (0..8)
            .map(|k| [(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64])
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = (quads.iter())
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriangleSurface {
            vertices,
            triangles,
        }
    }

    #[test]
    fn a_cube_is_closed_and_bounds_its_volume() {
        let c = cube();
        assert_eq!(c.check_closed(), Ok(()));
        assert!((c.signed_volume() - 1.0).abs() < 1e-15);
        // Inside, outside, and on the line of a face diagonal.
        assert!((c.winding_number(&[0.5, 0.5, 0.5]) - 1.0).abs() < 1e-12);
        assert!(c.winding_number(&[1.5, 0.5, 0.5]).abs() < 1e-12);
        assert!(c.contains(&[0.25, 0.25, 0.5]));
        assert!(!c.contains(&[0.25, 0.25, 1.5]));
        assert_eq!(c.top(&[0.3, 0.6, 0.1], 2, 1.0), 1.0);
        assert_eq!(c.top(&[0.3, 0.6, 0.1], 2, -1.0), 0.0);
        assert_eq!(c.top(&[1.3, 0.6, 0.1], 2, 1.0), f64::NEG_INFINITY);
    }

    #[test]
    fn an_open_or_flipped_surface_names_its_first_bad_edge() {
        let mut c = cube();
        c.triangles.remove(3);
        match c.check_closed() {
            Err(NotClosed::OpenEdge {
                edge,
                triangle,
                triangles_at_edge: 1,
            }) => {
                // Triangle [4, 5, 7] of the top face, its edge 7 – 4.
                assert_eq!(triangle, 2);
                assert_eq!(edge, [[1.0, 1.0, 1.0], [0.0, 0.0, 1.0]]);
            }
            other => panic!("{other:?}"),
        }
        let mut c = cube();
        c.triangles[0].swap(1, 2);
        assert!(matches!(c.check_closed(), Err(NotClosed::Flipped { .. })));
    }
}
