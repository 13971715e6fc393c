//! A closed triangulated surface (`shape = "surface"`, read from STL by
//! `model::import::stl`): its vertices and triangles, the check that it is
//! closed, and what the model asks of a body's geometry.
//!
//! The model fills it cell by cell (`cell_parts`): the volume and centroid of
//! the solid inside each lattice cell, integrated exactly along vertical
//! lines (the method's doc). A point query (`contains`) is the generalised
//! winding number (Jacobson, Kavan and Sorkine-Hornung, "Robust inside-outside
//! segmentation using generalized winding numbers", SIGGRAPH 2013):
//! w(p) = Σ_t Ω_t(p) / 4π, Ω_t the signed solid angle of triangle t seen from
//! p (Van Oosterom and Strackee, IEEE Trans. Biomed. Eng. 30, 1983:
//! tan(Ω/2) = a·(b × c) / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|), with
//! a, b, c the corners less p). On a closed, consistently oriented surface w
//! is ±1 inside and 0 outside whichever way the triangles face; a point is
//! inside where |w| > ½.

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
    /// One vertex per distinct corner (−0 and +0 alike), and the triangles by
    /// vertex index; a collapsed triangle (two equal corners) is left out.
    pub fn from_facets(facets: &[[[f64; 3]; 3]]) -> TriangleSurface {
        let mut index: std::collections::HashMap<[u64; 3], usize> = Default::default();
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(facets.len());
        for f in facets {
            let t = f.map(|corner| {
                let key = corner.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
                *index.entry(key).or_insert_with(|| {
                    vertices.push(corner);
                    vertices.len() - 1
                })
            });
            if t[0] != t[1] && t[1] != t[2] && t[2] != t[0] {
                triangles.push(t);
            }
        }
        TriangleSurface {
            vertices,
            triangles,
        }
    }

    /// The surface of the facets of a file (`shown`, of kind `format`),
    /// checked: at least one triangle, closed and consistently oriented.
    pub fn closed_from_facets(
        facets: &[[[f64; 3]; 3]],
        shown: &str,
        format: &str,
    ) -> Result<TriangleSurface, String> {
        let surface = TriangleSurface::from_facets(facets);
        if surface.triangles.is_empty() {
            return Err(format!("{shown}: the {format} file holds no triangle"));
        }
        surface
            .check_closed()
            .map_err(|e| format!("{shown}: {e}"))?;
        Ok(surface)
    }

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

/// The part of the solid inside one cell of a lattice: the cell's index, the
/// part's volume and its centroid.
#[derive(Clone, Debug, PartialEq)]
pub struct CellPart {
    pub cell: [usize; 3],
    pub volume: f64,
    pub centroid: [f64; 3],
}

/// A lattice of cells: cell k spans origin + k·spacing … origin + (k + 1)·spacing
/// along each axis, for k in first..last.
#[derive(Clone, Copy, Debug)]
pub struct Cells {
    pub origin: [f64; 3],
    pub spacing: [f64; 3],
    pub first: [usize; 3],
    pub last: [usize; 3],
}

impl Cells {
    fn lower(&self, d: usize, k: usize) -> f64 {
        self.origin[d] + k as f64 * self.spacing[d]
    }

    fn count(&self, d: usize) -> usize {
        self.last[d].saturating_sub(self.first[d])
    }
}

impl TriangleSurface {
    /// The volume and centroid of the solid inside each cell it reaches, in
    /// the order of the cells (x fastest, then y, then z), exact for the
    /// triangulated solid to round-off.
    ///
    /// Along a vertical line (z) the solid is the union of intervals
    /// [a_k, b_k] between a downward-facing (entry) and an upward-facing
    /// (exit) crossing, so its length within [z0, z1] is Σ_k c(b_k) − c(a_k),
    /// c(z) = clamp(z, z0, z1). Over a cell's xy-rectangle R, then,
    /// V = Σ_t s_t ∫_{P_t} (c(z_t) − z0) dA, with P_t the projection of
    /// triangle t clipped to R, z_t its height over it (linear) and s_t = ±1
    /// as it faces up or down; the first moments are ∫ x (c − z0), ∫ y (c − z0)
    /// and ∫ ½ (c² − z0²) likewise. Each P_t is cut at z0 and z1 (nothing
    /// below z0; c = z1 above z1) and each piece integrated by the edge-midpoint
    /// rule, exact for these quadratics.
    pub fn cell_parts(&self, cells: &Cells) -> Vec<CellPart> {
        let orientation = self.signed_volume().signum();
        let (nx, ny, nz) = (cells.count(0), cells.count(1), cells.count(2));
        let columns = self.columns(cells);
        let mut parts = Vec::new();
        let mut sums = vec![[0.0; 4]; nx * ny * nz];
        for (c, column) in columns.iter().enumerate() {
            let (i, j) = (c % nx, c / nx);
            let rect = [
                cells.lower(0, cells.first[0] + i),
                cells.lower(0, cells.first[0] + i + 1),
                cells.lower(1, cells.first[1] + j),
                cells.lower(1, cells.first[1] + j + 1),
            ];
            for &t in column {
                let corners = self.corners(t);
                let facing = orientation * projected_area(&corners).signum();
                let mut p = corners.to_vec();
                for (d, bound, keep_above) in [
                    (0, rect[0], true),
                    (0, rect[1], false),
                    (1, rect[2], true),
                    (1, rect[3], false),
                ] {
                    p = clip(&p, d, bound, keep_above);
                }
                for k in 0..nz {
                    let z0 = cells.lower(2, cells.first[2] + k);
                    let z1 = z0 + cells.spacing[2];
                    let above = clip(&p, 2, z0, true);
                    if above.len() < 3 {
                        break;
                    }
                    let piece = column_integrals(&above, z0, z1);
                    let sum = &mut sums[c + nx * ny * k];
                    (0..4).for_each(|m| sum[m] += facing * piece[m]);
                }
            }
        }
        let cell_volume = cells.spacing.iter().product::<f64>();
        for k in 0..nz {
            for c in 0..nx * ny {
                let sum = sums[c + nx * ny * k];
                // Round-off of the cancelling column sums, not solid.
                if sum[0] <= 1e-12 * cell_volume {
                    continue;
                }
                parts.push(CellPart {
                    cell: [
                        cells.first[0] + c % nx,
                        cells.first[1] + c / nx,
                        cells.first[2] + k,
                    ],
                    volume: sum[0],
                    centroid: [sum[1] / sum[0], sum[2] / sum[0], sum[3] / sum[0]],
                });
            }
        }
        parts
    }

    /// For each xy-column of the cells (x fastest), the triangles whose
    /// projection's box reaches it; triangles seen edge-on from above are
    /// left out (they bound no vertical interval).
    fn columns(&self, cells: &Cells) -> Vec<Vec<usize>> {
        let (nx, ny) = (cells.count(0), cells.count(1));
        let mut columns = vec![Vec::new(); nx * ny];
        let index = |d: usize, x: f64, n: usize| {
            let k = ((x - cells.origin[d]) / cells.spacing[d]).floor() - cells.first[d] as f64;
            k.clamp(0.0, n as f64 - 1.0) as usize
        };
        for t in 0..self.triangles.len() {
            let c = self.corners(t);
            if projected_area(&c) == 0.0 || nx == 0 || ny == 0 {
                continue;
            }
            let lo = |d: usize| c.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min);
            let hi = |d: usize| c.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max);
            for j in index(1, lo(1), ny)..=index(1, hi(1), ny) {
                for i in index(0, lo(0), nx)..=index(0, hi(0), nx) {
                    columns[i + nx * j].push(t);
                }
            }
        }
        columns
    }
}

/// Twice the signed area of a triangle's projection on the xy-plane.
fn projected_area(c: &[[f64; 3]; 3]) -> f64 {
    (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0])
}

/// The part of the convex polygon p (corners in order) with coordinate d ≥
/// bound (`keep_above`) or ≤ bound, its corners interpolated linearly.
fn clip(p: &[[f64; 3]], d: usize, bound: f64, keep_above: bool) -> Vec<[f64; 3]> {
    let inside = |q: &[f64; 3]| match keep_above {
        true => q[d] >= bound,
        false => q[d] <= bound,
    };
    let mut out = Vec::with_capacity(p.len() + 1);
    for k in 0..p.len() {
        let (a, b) = (&p[k], &p[(k + 1) % p.len()]);
        if inside(a) {
            out.push(*a);
        }
        if inside(a) != inside(b) {
            let t = (bound - a[d]) / (b[d] - a[d]);
            let mut q = [0.0; 3];
            (0..3).for_each(|e| q[e] = a[e] + t * (b[e] - a[e]));
            q[d] = bound;
            out.push(q);
        }
    }
    out
}

/// ∫ (c − z0), ∫ x (c − z0), ∫ y (c − z0) and ∫ ½ (c² − z0²) over the xy
/// projection of the polygon p (all above z0), c = min(z, z1): the piece
/// below z1 with its heights, the piece above at z1.
fn column_integrals(p: &[[f64; 3]], z0: f64, z1: f64) -> [f64; 4] {
    let mut total = [0.0; 4];
    let mut top = clip(p, 2, z1, true);
    top.iter_mut().for_each(|q| q[2] = z1);
    for piece in [clip(p, 2, z1, false), top] {
        for k in 1..piece.len().saturating_sub(1) {
            let tri = [piece[0], piece[k], piece[k + 1]];
            let area = 0.5 * projected_area(&tri).abs();
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let m: [f64; 3] = std::array::from_fn(|e| 0.5 * (tri[a][e] + tri[b][e]));
                let h = m[2] - z0;
                let w = area / 3.0;
                total[0] += w * h;
                total[1] += w * m[0] * h;
                total[2] += w * m[1] * h;
                total[3] += w * 0.5 * (m[2] * m[2] - z0 * z0);
            }
        }
    }
    total
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

    /// The cube moved by `shift`.
    fn moved(shift: [f64; 3]) -> TriangleSurface {
        let mut c = cube();
        for v in &mut c.vertices {
            (0..3).for_each(|d| v[d] += shift[d]);
        }
        c
    }

    #[test]
    fn the_parts_of_cells_sum_to_the_solid_and_its_centroid() {
        // A unit cube off the lattice of 0.25 spacing, and turned inside out.
        let shift = [0.1, 0.05, 0.03];
        let cells = Cells {
            origin: [0.0; 3],
            spacing: [0.25; 3],
            first: [0; 3],
            last: [5; 3],
        };
        for flip in [false, true] {
            let mut c = moved(shift);
            if flip {
                c.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            let parts = c.cell_parts(&cells);
            let volume: f64 = parts.iter().map(|p| p.volume).sum();
            assert!((volume - 1.0).abs() < 1e-13, "{volume}");
            for (d, s) in shift.iter().enumerate() {
                let m: f64 = parts.iter().map(|p| p.volume * p.centroid[d]).sum();
                assert!((m - (0.5 + s)).abs() < 1e-13, "{d}: {m}");
            }
            // 3 × 3 × 3 whole cells inside, the rest cut: 5³ cells reached.
            assert_eq!(parts.len(), 125);
            let whole = parts.iter().filter(|p| p.volume > 0.25f64.powi(3) - 1e-15);
            assert_eq!(whole.count(), 27);
            // The corner cell holds (0.25 − shift) per axis of the cube.
            let corner: f64 = shift.iter().map(|s| 0.25 - s).product();
            assert!((parts[0].volume - corner).abs() < 1e-15);
        }
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
