//! A body given as finite elements (`shape = "mesh"`, read from a Gmsh file by
//! `model::import::gmsh`): linear triangles and quadrilaterals (2D),
//! tetrahedra and hexahedra (3D), isoparametric, with a particle at each Gauss
//! point of the element's rule carrying the volume w_g |det J(ξ_g)|.
//!
//! Rules (reference coordinates and weights; Zienkiewicz, Taylor & Zhu, The
//! Finite Element Method, 7th ed., vol. 1, tables 5.3 and 5.4 for the simplices):
//! - triangle (0 ≤ ξ, η, ξ + η ≤ 1): 3 points (1/6, 1/6), (2/3, 1/6),
//!   (1/6, 2/3), weight 1/6 each (exact to degree 2);
//! - quadrilateral [−1, 1]²: 2 × 2 Gauss points ±1/√3, weight 1 (exact to
//!   degree 3 per direction);
//! - tetrahedron: 4 points, the permutations of (a, b, b) and (b, b, b) with
//!   a = (5 + 3√5)/20, b = (5 − √5)/20, weight 1/24 each (exact to degree 2);
//! - hexahedron [−1, 1]³: 2 × 2 × 2 Gauss points, weight 1.
//!
//! det J is constant on a simplex, linear on a quadrilateral and of degree 2
//! per direction on a hexahedron, so each rule integrates it, and x det J,
//! exactly: the particles' volumes sum to the mesh's volume and their first
//! moments to its first moments, to round-off. `Quadrature::One` puts one
//! particle per element at ξ = 0 of the quadrilateral and hexahedron, the
//! centroid of a simplex, with the element's volume (the full rule's sum).
//!
//! An element is refused where det J ≤ 0 (inverted, or degenerate to round-off)
//! at a corner or a Gauss point: linear elements run counter-clockwise in 2D,
//! and with a right-handed (positive) volume in 3D, as Gmsh writes them.

use crate::scene::Quadrature;
use std::sync::OnceLock;

/// The element types a mesh body takes (their Gmsh node orderings).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementKind {
    Triangle,
    Quadrilateral,
    Tetrahedron,
    Hexahedron,
}

impl ElementKind {
    pub fn dim(self) -> usize {
        match self {
            ElementKind::Triangle | ElementKind::Quadrilateral => 2,
            ElementKind::Tetrahedron | ElementKind::Hexahedron => 3,
        }
    }

    pub fn node_count(self) -> usize {
        match self {
            ElementKind::Triangle => 3,
            ElementKind::Quadrilateral | ElementKind::Tetrahedron => 4,
            ElementKind::Hexahedron => 8,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Triangle => "triangle",
            ElementKind::Quadrilateral => "quadrilateral",
            ElementKind::Tetrahedron => "tetrahedron",
            ElementKind::Hexahedron => "hexahedron",
        }
    }

    /// The reference coordinates of the corners, in node order.
    fn corners(self) -> Vec<[f64; 3]> {
        match self {
            ElementKind::Triangle => vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            ElementKind::Quadrilateral => (0..4).map(|a| square(a, 0.0)).collect(),
            ElementKind::Tetrahedron => vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            ElementKind::Hexahedron => (0..8).map(cube).collect(),
        }
    }

    /// The Gauss points (ξ, weight) of the full rule (module doc).
    fn gauss_points(self) -> Vec<([f64; 3], f64)> {
        let g = 1.0 / 3f64.sqrt();
        match self {
            ElementKind::Triangle => [[1.0, 1.0], [4.0, 1.0], [1.0, 4.0]]
                .map(|[a, b]| ([a / 6.0, b / 6.0, 0.0], 1.0 / 6.0))
                .to_vec(),
            ElementKind::Quadrilateral => (0..4)
                .map(|a| (square(a, 0.0).map(|c| c * g), 1.0))
                .collect(),
            ElementKind::Tetrahedron => {
                let a = (5.0 + 3.0 * 5f64.sqrt()) / 20.0;
                let b = (5.0 - 5f64.sqrt()) / 20.0;
                [[b, b, b], [a, b, b], [b, a, b], [b, b, a]]
                    .map(|p| (p, 1.0 / 24.0))
                    .to_vec()
            }
            ElementKind::Hexahedron => (0..8).map(|a| (cube(a).map(|c| c * g), 1.0)).collect(),
        }
    }

    /// ξ = 0 of a quadrilateral or hexahedron, the centroid of a simplex.
    fn centre(self) -> [f64; 3] {
        match self {
            ElementKind::Triangle => [1.0 / 3.0, 1.0 / 3.0, 0.0],
            ElementKind::Tetrahedron => [0.25; 3],
            ElementKind::Quadrilateral | ElementKind::Hexahedron => [0.0; 3],
        }
    }

    /// The shape functions N_a(ξ) and their derivatives ∂N_a/∂ξ_j.
    fn shape(self, xi: &[f64; 3]) -> (Vec<f64>, Vec<[f64; 3]>) {
        let [r, s, t] = *xi;
        match self {
            ElementKind::Triangle => (
                vec![1.0 - r - s, r, s],
                vec![[-1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            ),
            ElementKind::Tetrahedron => (
                vec![1.0 - r - s - t, r, s, t],
                vec![
                    [-1.0, -1.0, -1.0],
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, 1.0],
                ],
            ),
            // N_a = (1 + ξ ξ_a)(1 + η η_a)/4.
            ElementKind::Quadrilateral => (0..4)
                .map(|a| {
                    let [ra, sa, _] = square(a, 0.0);
                    let (fr, fs) = (1.0 + r * ra, 1.0 + s * sa);
                    (fr * fs / 4.0, [ra * fs / 4.0, fr * sa / 4.0, 0.0])
                })
                .unzip(),
            // N_a = (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a)/8.
            ElementKind::Hexahedron => (0..8)
                .map(|a| {
                    let [ra, sa, ta] = cube(a);
                    let (fr, fs, ft) = (1.0 + r * ra, 1.0 + s * sa, 1.0 + t * ta);
                    let d = [ra * fs * ft / 8.0, fr * sa * ft / 8.0, fr * fs * ta / 8.0];
                    (fr * fs * ft / 8.0, d)
                })
                .unzip(),
        }
    }

    /// The faces (corner indices, in order around each) of a 3D element.
    fn faces(self) -> Vec<Vec<usize>> {
        match self {
            ElementKind::Tetrahedron => {
                vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]]
            }
            ElementKind::Hexahedron => vec![
                vec![0, 3, 2, 1],
                vec![4, 5, 6, 7],
                vec![0, 1, 5, 4],
                vec![1, 2, 6, 5],
                vec![2, 3, 7, 6],
                vec![3, 0, 4, 7],
            ],
            ElementKind::Triangle | ElementKind::Quadrilateral => Vec::new(),
        }
    }
}

/// Corner a (0..4, counter-clockwise from (−1, −1)) of the square [−1, 1]² at ζ.
fn square(a: usize, z: f64) -> [f64; 3] {
    let [r, s] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]][a % 4];
    [r, s, z]
}

/// Corner a (0..8, Gmsh's order: the bottom face ζ = −1 counter-clockwise, then the top) of [−1, 1]³.
fn cube(a: usize) -> [f64; 3] {
    square(a, if a < 4 { -1.0 } else { 1.0 })
}

/// One element: its kind, its tag in the file (messages) and its nodes
/// (indices into `ElementMesh::nodes`, in the kind's order).
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    pub kind: ElementKind,
    pub tag: u64,
    pub nodes: Vec<usize>,
}

/// A body's elements and their nodes (x, y, z; z unused in 2D).
#[derive(Clone, Debug)]
pub struct ElementMesh {
    pub dim: usize,
    pub nodes: Vec<[f64; 3]>,
    pub elements: Vec<Element>,
    pub quadrature: Quadrature,
    /// Per vertical axis v, the elements binned by their extent across it
    /// (`top`), built on first use.
    columns: [OnceLock<Columns>; 3],
}

impl PartialEq for ElementMesh {
    fn eq(&self, o: &Self) -> bool {
        (self.dim, &self.nodes, &self.elements, self.quadrature)
            == (o.dim, &o.nodes, &o.elements, o.quadrature)
    }
}

/// The elements binned on a uniform grid of the plane (line) across the
/// vertical axis: each bin lists the elements whose box reaches it.
#[derive(Clone, Debug, PartialEq)]
struct Columns {
    /// The axes across the vertical (one in 2D, two in 3D).
    axes: Vec<usize>,
    lo: Vec<f64>,
    width: Vec<f64>,
    bins: Vec<usize>,
    elements: Vec<Vec<usize>>,
}

impl Columns {
    fn new(mesh: &ElementMesh, v: usize) -> Columns {
        let axes: Vec<usize> = (0..mesh.dim).filter(|&d| d != v).collect();
        let (lo, hi) = mesh.bounds();
        let n = mesh.elements.len() as f64;
        // About one element per bin: n bins in 2D, √n × √n in 3D.
        let per = n.powf(1.0 / axes.len() as f64).ceil().max(1.0) as usize;
        let bins = vec![per; axes.len()];
        let width: Vec<f64> = (axes.iter())
            .map(|&d| (hi[d] - lo[d]).max(f64::MIN_POSITIVE) / per as f64)
            .collect();
        let lo: Vec<f64> = axes.iter().map(|&d| lo[d]).collect();
        let mut c = Columns {
            axes,
            lo,
            width,
            bins,
            elements: vec![Vec::new(); per.pow(mesh.dim as u32 - 1)],
        };
        for (k, e) in mesh.elements.iter().enumerate() {
            let corners = mesh.corners(e);
            let range = |a: usize| {
                let d = c.axes[a];
                let (min, max) = corners
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                        (l.min(x[d]), h.max(x[d]))
                    });
                (c.bin(a, min), c.bin(a, max))
            };
            let r0 = range(0);
            let r1 = if c.axes.len() == 2 { range(1) } else { (0, 0) };
            for i in r0.0..=r0.1 {
                for j in r1.0..=r1.1 {
                    c.elements[i + c.bins[0] * j].push(k);
                }
            }
        }
        c
    }

    /// The bin along the a-th axis across of the coordinate x (clamped).
    fn bin(&self, a: usize, x: f64) -> usize {
        let b = ((x - self.lo[a]) / self.width[a]).floor();
        (b.max(0.0) as usize).min(self.bins[a] - 1)
    }

    /// The elements whose box may reach the vertical line through x.
    fn at(&self, x: &[f64]) -> &[usize] {
        let i = self.bin(0, x[self.axes[0]]);
        let j = if self.axes.len() == 2 {
            self.bin(1, x[self.axes[1]])
        } else {
            0
        };
        &self.elements[i + self.bins[0] * j]
    }
}

/// A particle of the mesh: its position and volume.
pub type GaussPoint = ([f64; 3], f64);

impl ElementMesh {
    pub fn new(
        dim: usize,
        nodes: Vec<[f64; 3]>,
        elements: Vec<Element>,
        quadrature: Quadrature,
    ) -> Self {
        let columns = Default::default();
        ElementMesh {
            dim,
            nodes,
            elements,
            quadrature,
            columns,
        }
    }

    fn corners(&self, e: &Element) -> Vec<[f64; 3]> {
        e.nodes.iter().map(|&n| self.nodes[n]).collect()
    }

    /// x(ξ) and det J(ξ) of element e.
    fn map(&self, e: &Element, xi: &[f64; 3]) -> ([f64; 3], f64) {
        let (n, dn) = e.kind.shape(xi);
        let (mut x, mut j) = ([0.0; 3], [[0.0; 3]; 3]);
        for (a, &node) in e.nodes.iter().enumerate() {
            let xa = self.nodes[node];
            for i in 0..self.dim {
                x[i] += n[a] * xa[i];
                (0..self.dim).for_each(|k| j[i][k] += xa[i] * dn[a][k]);
            }
        }
        (x, determinant(&j, self.dim))
    }

    /// Refuse an element with det J ≤ 0 at a corner or a Gauss point (below
    /// 1e-12 of its box's size^dim: degenerate to round-off).
    pub fn check(&self) -> Result<(), String> {
        for e in &self.elements {
            let scale = box_size(&self.corners(e), self.dim).powi(self.dim as i32);
            let corners = e.kind.corners().into_iter().map(|xi| (xi, "corner"));
            let points = (e.kind.gauss_points().into_iter()).map(|(xi, _)| (xi, "Gauss point"));
            for (xi, what) in corners.chain(points) {
                let det = self.map(e, &xi).1;
                if det <= 1e-12 * scale {
                    return Err(format!(
                        "element {} ({}) is {}: det J = {det:.3e} at its {what} ξ = {:?}{}",
                        e.tag,
                        e.kind.name(),
                        if det < 0.0 { "inverted" } else { "degenerate" },
                        &xi[..self.dim],
                        if det < 0.0 && self.dim == 2 {
                            " (a 2D element's nodes run counter-clockwise)"
                        } else {
                            ""
                        },
                    ));
                }
            }
        }
        Ok(())
    }

    /// The particles: per element, its rule's points with w |det J| (module doc).
    pub fn gauss_points(&self) -> Vec<GaussPoint> {
        let mut out = Vec::new();
        for e in &self.elements {
            let full = e.kind.gauss_points();
            match self.quadrature {
                Quadrature::Full => out.extend(full.iter().map(|(xi, w)| {
                    let (x, det) = self.map(e, xi);
                    (x, w * det)
                })),
                Quadrature::One => {
                    let volume = full.iter().map(|(xi, w)| w * self.map(e, xi).1).sum();
                    out.push((self.map(e, &e.kind.centre()).0, volume));
                }
            }
        }
        out
    }

    /// The box (min, max) of the elements' nodes.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![f64::INFINITY; self.dim];
        let mut hi = vec![f64::NEG_INFINITY; self.dim];
        for x in self.elements.iter().flat_map(|e| self.corners(e)) {
            for d in 0..self.dim {
                lo[d] = lo[d].min(x[d]);
                hi[d] = hi[d].max(x[d]);
            }
        }
        (lo, hi)
    }

    /// Height (along `up` × axis v) of the highest point of the elements'
    /// boundaries on the vertical line through x: edges in 2D, faces in 3D
    /// (a hexahedron's as two triangles); −∞ where the line misses the mesh.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        let mut best = f64::NEG_INFINITY;
        let columns = self.columns[v].get_or_init(|| Columns::new(self, v));
        for e in columns.at(x).iter().map(|&k| &self.elements[k]) {
            let c = self.corners(e);
            if self.dim == 2 {
                let h = x[1 - v];
                for k in 0..c.len() {
                    let (a, b) = (&c[k], &c[(k + 1) % c.len()]);
                    best = best.max(edge_height(a, b, h, v, up));
                }
            } else {
                for face in e.kind.faces() {
                    for t in 1..face.len() - 1 {
                        let tri = [c[face[0]], c[face[t]], c[face[t + 1]]];
                        best = best.max(triangle_height(&tri, x, v, up));
                    }
                }
            }
        }
        best
    }
}

/// det J of the leading dim × dim block.
fn determinant(j: &[[f64; 3]; 3], dim: usize) -> f64 {
    match dim {
        2 => j[0][0] * j[1][1] - j[0][1] * j[1][0],
        _ => {
            j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
        }
    }
}

/// The largest side of the points' box.
fn box_size(points: &[[f64; 3]], dim: usize) -> f64 {
    (0..dim)
        .map(|d| {
            let lo = points.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min);
            let hi = points
                .iter()
                .map(|p| p[d])
                .fold(f64::NEG_INFINITY, f64::max);
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// up × the height along v of the edge a–b at the coordinate h across it;
/// −∞ if the edge does not reach h.
fn edge_height(a: &[f64; 3], b: &[f64; 3], h: f64, v: usize, up: f64) -> f64 {
    let (ah, bh) = (a[1 - v], b[1 - v]);
    if h < ah.min(bh) || h > ah.max(bh) {
        return f64::NEG_INFINITY;
    }
    if ah == bh {
        return (up * a[v]).max(up * b[v]);
    }
    up * (a[v] + (h - ah) / (bh - ah) * (b[v] - a[v]))
}

/// up × the height along v of the triangle on the vertical line through x;
/// −∞ if the line misses it (a vertical triangle: its highest corner if the
/// line touches it, else −∞).
fn triangle_height(t: &[[f64; 3]; 3], x: &[f64], v: usize, up: f64) -> f64 {
    let (p, q) = match v {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    // Barycentric coordinates of (x_p, x_q) in the triangle's projection.
    let area =
        (t[1][p] - t[0][p]) * (t[2][q] - t[0][q]) - (t[2][p] - t[0][p]) * (t[1][q] - t[0][q]);
    if area == 0.0 {
        return f64::NEG_INFINITY;
    }
    let l1 =
        ((x[p] - t[0][p]) * (t[2][q] - t[0][q]) - (t[2][p] - t[0][p]) * (x[q] - t[0][q])) / area;
    let l2 =
        ((t[1][p] - t[0][p]) * (x[q] - t[0][q]) - (x[p] - t[0][p]) * (t[1][q] - t[0][q])) / area;
    let l0 = 1.0 - l1 - l2;
    let tol = -1e-12;
    if l0 < tol || l1 < tol || l2 < tol {
        return f64::NEG_INFINITY;
    }
    up * (l0 * t[0][v] + l1 * t[1][v] + l2 * t[2][v])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(dim: usize, nodes: Vec<[f64; 3]>, kind: ElementKind) -> ElementMesh {
        let n = nodes.len();
        let elements = vec![Element {
            kind,
            tag: 7,
            nodes: (0..n).collect(),
        }];
        ElementMesh::new(dim, nodes, elements, Quadrature::Full)
    }

    #[test]
    fn a_distorted_element_has_its_volume_and_centroid() {
        // A quadrilateral (0,0), (3,0), (2,2), (0,1): area 4 (shoelace).
        let q = vec![
            [0.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let m = mesh(2, q, ElementKind::Quadrilateral);
        m.check().unwrap();
        let p = m.gauss_points();
        assert_eq!(p.len(), 4);
        let v: f64 = p.iter().map(|g| g.1).sum();
        assert!((v - 4.0).abs() < 1e-14, "{v}");
        // Centroid of the polygon (shoelace moments / 6A): x = 34/24, y = 18/24.
        let cx: f64 = p.iter().map(|g| g.0[0] * g.1).sum::<f64>() / v;
        let cy: f64 = p.iter().map(|g| g.0[1] * g.1).sum::<f64>() / v;
        assert!(
            (cx - 17.0 / 12.0).abs() < 1e-14 && (cy - 0.75).abs() < 1e-14,
            "{cx} {cy}"
        );
        // A hexahedron: the unit cube with its top corner 6 raised by 1.
        let mut h: Vec<[f64; 3]> = (0..8).map(|a| cube(a).map(|c| 0.5 * (c + 1.0))).collect();
        h[6][2] = 2.0;
        let m = mesh(3, h, ElementKind::Hexahedron);
        m.check().unwrap();
        let v: f64 = m.gauss_points().iter().map(|g| g.1).sum();
        // Its top face is bilinear over the unit square with heights
        // (1, 1, 2, 1): volume = their mean, 1.25.
        assert!((v - 1.25).abs() < 1e-14, "{v}");
    }

    #[test]
    fn an_inverted_element_is_named() {
        let t = vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
        let e = mesh(2, t, ElementKind::Triangle).check().unwrap_err();
        assert!(e.contains("element 7 (triangle) is inverted"), "{e}");
        let t = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let e = mesh(2, t, ElementKind::Triangle).check().unwrap_err();
        assert!(e.contains("element 7 (triangle) is degenerate"), "{e}");
    }

    #[test]
    fn the_top_of_a_tetrahedron_is_its_upper_face() {
        let t = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let m = mesh(3, t, ElementKind::Tetrahedron);
        let top = m.top(&[0.25, 0.25, 0.1], 2, 1.0);
        assert!((top - 0.5).abs() < 1e-15, "{top}");
        assert_eq!(m.top(&[2.0, 2.0, 0.0], 2, 1.0), f64::NEG_INFINITY);
    }
}
