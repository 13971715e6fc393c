//! Structured triangle meshes for plane-strain limit analysis.
//!
//! A domain is a set of mapped quadrilateral blocks (bilinear maps of the unit
//! square; two corners may coincide, which makes a fan of triangles at that
//! point). Every quadrilateral cell is split into four triangles through its
//! centre ("crossed diagonals"), which avoids the locking of a single diagonal in
//! the incompressible (φ = 0) upper bound. Nodes on shared block edges are merged
//! by position, so neighbouring blocks must use the same subdivision on the edge
//! they share.

use std::collections::HashMap;

pub type Point = [f64; 2];

/// A quadrilateral patch: corners at (ξ, η) = (0,0), (1,0), (1,1), (0,1),
/// counter-clockwise, and the cell boundaries in ξ and η (increasing from 0 to 1).
#[derive(Clone, Debug)]
pub struct Block {
    pub corners: [Point; 4],
    pub xi: Vec<f64>,
    pub eta: Vec<f64>,
}

impl Block {
    fn map(&self, xi: f64, eta: f64) -> Point {
        let [p0, p1, p2, p3] = self.corners;
        let w = [
            (1.0 - xi) * (1.0 - eta),
            xi * (1.0 - eta),
            xi * eta,
            (1.0 - xi) * eta,
        ];
        [
            w[0] * p0[0] + w[1] * p1[0] + w[2] * p2[0] + w[3] * p3[0],
            w[0] * p0[1] + w[1] * p1[1] + w[2] * p2[1] + w[3] * p3[1],
        ]
    }
}

/// A triangulation: node coordinates and counter-clockwise triangles.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub nodes: Vec<Point>,
    pub triangles: Vec<[usize; 3]>,
}

/// An edge of the triangulation: its end nodes (as in the first triangle's
/// counter-clockwise order) and the triangles on each side with the local edge
/// number (local edge `k` runs from local node `k` to `k + 1`).
#[derive(Clone, Debug)]
pub struct Edge {
    pub nodes: [usize; 2],
    pub sides: Vec<(usize, usize)>,
}

/// `n` cell boundaries on [0, 1] in geometric progression, the first cell `ratio`
/// times smaller than the last (ratio 1: uniform).
#[cfg(test)]
pub fn graded(n: usize, ratio: f64) -> Vec<f64> {
    assert!(n >= 1 && ratio > 0.0);
    let q = if n > 1 {
        ratio.powf(1.0 / (n as f64 - 1.0))
    } else {
        1.0
    };
    let mut x = vec![0.0];
    let mut h = 1.0;
    for _ in 0..n {
        let last = *x.last().unwrap();
        x.push(last + h);
        h *= q;
    }
    let total = *x.last().unwrap();
    x.iter().map(|v| v / total).collect()
}

/// Cell boundaries on [0, 1] for a segment of `length`: cells growing
/// geometrically by `growth` from `fine` at 0, capped at `max`, and scaled
/// together so that they fill the segment exactly.
pub fn spacing(length: f64, fine: f64, growth: f64, max: f64) -> Vec<f64> {
    assert!(length > 0.0 && fine > 0.0 && growth >= 1.0 && max >= fine);
    let mut cells = Vec::new();
    let (mut sum, mut h) = (0.0, fine);
    while sum < length {
        cells.push(h);
        sum += h;
        h = (h * growth).min(max);
    }
    // Drop the last cell if that brings the total closer to the length.
    if cells.len() > 1 {
        let last = *cells.last().unwrap();
        if (sum - last - length).abs() < (sum - length).abs() {
            cells.pop();
            sum -= last;
        }
    }
    let mut x = vec![0.0];
    for c in cells {
        let last = *x.last().unwrap();
        x.push(last + c / sum);
    }
    *x.last_mut().unwrap() = 1.0;
    x
}

/// Split every cell into 2^levels equal cells.
pub fn refine(x: &[f64], levels: u32) -> Vec<f64> {
    let m = 1usize << levels;
    let mut out = vec![x[0]];
    for w in x.windows(2) {
        for k in 1..=m {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / m as f64);
        }
    }
    out
}

/// Reverse a spacing: fine at 1 instead of 0.
pub fn reversed(x: &[f64]) -> Vec<f64> {
    x.iter().rev().map(|v| 1.0 - v).collect()
}

impl Mesh {
    /// Mesh the blocks: four triangles per cell, nodes merged by position, and
    /// triangles of zero area (at coincident block corners) dropped.
    pub fn from_blocks(blocks: &[Block]) -> Mesh {
        let scale = blocks
            .iter()
            .flat_map(|b| b.corners.iter())
            .flat_map(|p| p.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1.0);
        let mut mesh = Mesh::default();
        let mut index = NodeIndex::new(1e-9 * scale);
        for b in blocks {
            for j in 0..b.eta.len() - 1 {
                for i in 0..b.xi.len() - 1 {
                    let (x0, x1, y0, y1) = (b.xi[i], b.xi[i + 1], b.eta[j], b.eta[j + 1]);
                    let quad = [b.map(x0, y0), b.map(x1, y0), b.map(x1, y1), b.map(x0, y1)];
                    let centre = [
                        quad.iter().map(|p| p[0]).sum::<f64>() / 4.0,
                        quad.iter().map(|p| p[1]).sum::<f64>() / 4.0,
                    ];
                    let c = index.insert(&mut mesh.nodes, centre);
                    let q: Vec<usize> = quad
                        .iter()
                        .map(|&p| index.insert(&mut mesh.nodes, p))
                        .collect();
                    for k in 0..4 {
                        let t = [q[k], q[(k + 1) % 4], c];
                        if t[0] != t[1] && mesh.signed_area(t) > 1e-14 * scale * scale {
                            mesh.triangles.push(t);
                        }
                    }
                }
            }
        }
        mesh
    }

    pub fn signed_area(&self, t: [usize; 3]) -> f64 {
        let [a, b, c] = t.map(|i| self.nodes[i]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
    }

    /// Every edge once, in order of first appearance.
    pub fn edges(&self) -> Vec<Edge> {
        let mut at: HashMap<(usize, usize), usize> = HashMap::new();
        let mut edges: Vec<Edge> = Vec::new();
        for (e, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                match at.get(&key) {
                    Some(&i) => edges[i].sides.push((e, k)),
                    None => {
                        at.insert(key, edges.len());
                        edges.push(Edge {
                            nodes: [a, b],
                            sides: vec![(e, k)],
                        });
                    }
                }
            }
        }
        edges
    }

    /// Area of the domain.
    pub fn area(&self) -> f64 {
        self.triangles.iter().map(|&t| self.signed_area(t)).sum()
    }
}

/// Merges nodes closer than `tol` (looks in the neighbouring hash cells).
struct NodeIndex {
    tol: f64,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl NodeIndex {
    fn new(tol: f64) -> Self {
        NodeIndex {
            tol,
            cells: HashMap::new(),
        }
    }

    fn insert(&mut self, nodes: &mut Vec<Point>, p: Point) -> usize {
        let key = (
            (p[0] / self.tol).floor() as i64,
            (p[1] / self.tol).floor() as i64,
        );
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(list) = self.cells.get(&(key.0 + dx, key.1 + dy)) {
                    for &i in list {
                        let q = nodes[i];
                        if (q[0] - p[0]).abs() <= self.tol && (q[1] - p[1]).abs() <= self.tol {
                            return i;
                        }
                    }
                }
            }
        }
        nodes.push(p);
        self.cells.entry(key).or_default().push(nodes.len() - 1);
        nodes.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grading_spans_the_unit_interval_with_the_given_ratio() {
        let x = graded(5, 4.0);
        assert_eq!(x.len(), 6);
        assert!((x[5] - 1.0).abs() < 1e-15 && x[0] == 0.0);
        let first = x[1] - x[0];
        let last = x[5] - x[4];
        assert!((last / first - 4.0).abs() < 1e-12);
        let y = reversed(&graded(5, 4.0));
        assert!(((y[5] - y[4]) * 4.0 - (y[1] - y[0])).abs() < 1e-12);
    }

    #[test]
    fn spacing_grows_from_the_fine_end_and_refinement_halves_cells() {
        let x = spacing(10.0, 0.5, 1.5, 2.0);
        assert_eq!(x[0], 0.0);
        assert_eq!(*x.last().unwrap(), 1.0);
        let h: Vec<f64> = x.windows(2).map(|w| 10.0 * (w[1] - w[0])).collect();
        assert!(h
            .windows(2)
            .all(|w| w[1] >= w[0] - 1e-12 && w[1] <= 1.5 * w[0] + 1e-12));
        assert!(
            h[0] > 0.4 && h[0] < 0.6 && *h.last().unwrap() < 2.4,
            "{h:?}"
        );
        let r = refine(&x, 2);
        assert_eq!(r.len(), 4 * (x.len() - 1) + 1);
        assert!((r[4] - x[1]).abs() < 1e-15 && (r[2] - 0.5 * x[1]).abs() < 1e-15);
    }

    #[test]
    fn two_blocks_share_their_edge_and_a_fan_block_covers_a_triangle() {
        let xi = graded(3, 2.0);
        let eta = vec![0.0, 0.5, 1.0];
        let a = Block {
            corners: [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            xi: xi.clone(),
            eta: eta.clone(),
        };
        let b = Block {
            corners: [[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]],
            xi: xi.clone(),
            eta: eta.clone(),
        };
        // A triangle with a fan at (0, 1): corners 0 and 3 coincide.
        let c = Block {
            corners: [[0.0, 1.0], [1.0, 1.0], [1.0, 1.5], [0.0, 1.0]],
            xi,
            eta,
        };
        let mesh = Mesh::from_blocks(&[a, b, c]);
        assert!((mesh.area() - 2.25).abs() < 1e-12);
        // 12 cells in the rectangles, 6 in the fan of which 2 lose a triangle.
        assert_eq!(mesh.triangles.len(), 4 * 12 + 4 * 6 - 2);
        let edges = mesh.edges();
        let boundary: f64 = edges
            .iter()
            .filter(|e| e.sides.len() == 1)
            .map(|e| {
                let [p, q] = e.nodes.map(|i| mesh.nodes[i]);
                ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt()
            })
            .sum();
        let perimeter = 2.0 + 1.0 + 1.0 + 0.5 + 0.5f64.hypot(1.0) + 1.0;
        assert!(
            (boundary - perimeter).abs() < 1e-12,
            "{boundary} vs {perimeter}"
        );
        assert!(edges.iter().all(|e| e.sides.len() <= 2));
    }
}
