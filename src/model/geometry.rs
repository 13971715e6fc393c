//! The geometry of a body: an axis-aligned box (rectangle in 2D), a ball (disk,
//! sphere), a cylinder along z (3D), a simple polygon (2D) or a polygon extruded
//! along an axis (a prism, 3D), as given by the `[[body]]` keys; or read from
//! a file (`model::import`): the particles of a particle file, a closed
//! triangulated surface (3D), a raster's ground, finite elements. The model
//! fills it with particles (`contains`, within `BodyConfig::bounds`, which the
//! validation also uses) and measures the depth of a particle below its body's
//! top surface for geostatic stresses (`top`).

use crate::model::mesh::ElementMesh;
use crate::model::particle_set::ParticleSet;
use crate::model::terrain::Terrain;
use crate::model::triangles::TriangleSurface;
use crate::scene::{prism_bounds, prism_plane, BodyConfig, BodyShape};
use std::sync::Arc;

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
    /// The polygon `section` (coordinates along the other two axes,
    /// `prism_plane(axis)`) extruded over `from..to` along `axis`.
    Prism {
        section: Vec<Vec<f64>>,
        axis: usize,
        from: f64,
        to: f64,
    },
    /// The particles of a particle file, put in as they are: no lattice point
    /// is inside, and no face is surface (`nearest_surface` is `None`).
    Particles(Arc<ParticleSet>),
    /// A closed triangulated surface (3D); none of its faces is surface for
    /// `nearest_surface` (a rigid body does not take one, validation).
    Surface(Arc<TriangleSurface>),
    /// The ground under a raster's surface down to a base (3D, z up); none of
    /// its faces is surface for `nearest_surface`.
    Terrain(Arc<Terrain>),
    /// Finite elements with a particle at each Gauss point (`model::mesh`):
    /// no lattice point is inside, and no face is surface.
    Mesh(Arc<ElementMesh>),
}

impl Geometry {
    /// The geometry of a validated `[[body]]` table whose shape is given by
    /// its keys (one read from a file: `model::import::body_geometry`).
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
            BodyShape::Prism => {
                let extent = b.extent.as_ref().expect("validated");
                Geometry::Prism {
                    section: b.vertices.clone().expect("validated"),
                    axis: b.prism_axis(),
                    from: extent[0],
                    to: extent[1],
                }
            }
            BodyShape::Particles | BodyShape::Surface | BodyShape::Terrain | BodyShape::Mesh => {
                unreachable!("read from the body's file by model::import::body_geometry")
            }
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
            Geometry::Prism {
                section,
                axis,
                from,
                to,
            } => {
                let plane = prism_plane(*axis);
                x[*axis] > *from
                    && x[*axis] < *to
                    && point_in_polygon(x[plane[0]], x[plane[1]], section)
            }
            Geometry::Particles(_) | Geometry::Mesh(_) => false,
            Geometry::Surface(s) => s.contains(x),
            Geometry::Terrain(t) => t.contains(x),
        }
    }

    /// Does the segment from a to b (points inside) stay inside? A peridynamic
    /// body's bonds must not cross a notch or a re-entrant corner
    /// (`model::build`). Convex shapes hold every such segment; a polygon (or a
    /// prism's section) holds it unless it crosses an edge, tested exactly; a
    /// closed surface or a terrain is sampled every `step` or closer (a slit
    /// thinner than about `step` can be missed there); the geometries without
    /// an inside (particle files, meshes) hold every segment.
    pub fn holds_segment(&self, a: &[f64], b: &[f64], step: f64) -> bool {
        match self {
            Geometry::Box { .. } | Geometry::Ball { .. } | Geometry::Cylinder { .. } => true,
            Geometry::Particles(_) | Geometry::Mesh(_) => true,
            Geometry::Polygon(v) => !crosses_an_edge([a[0], a[1]], [b[0], b[1]], v),
            Geometry::Prism { section, axis, .. } => {
                let plane = prism_plane(*axis);
                let on = |p: &[f64]| [p[plane[0]], p[plane[1]]];
                !crosses_an_edge(on(a), on(b), section)
            }
            Geometry::Surface(_) | Geometry::Terrain(_) => self.holds_sampled(a, b, step),
        }
    }

    /// Whether every point of the segment a–b at spacing `step` or closer is inside.
    fn holds_sampled(&self, a: &[f64], b: &[f64], step: f64) -> bool {
        let length: f64 = (0..a.len())
            .map(|d| (b[d] - a[d]).powi(2))
            .sum::<f64>()
            .sqrt();
        let n = (length / step).ceil().max(1.0) as usize;
        (1..n).all(|k| {
            let t = k as f64 / n as f64;
            let x: Vec<f64> = (0..a.len()).map(|d| a[d] + t * (b[d] - a[d])).collect();
            self.contains(&x)
        })
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
            Geometry::Prism { axis, from, to, .. } if v == *axis => (up * from).max(up * to),
            Geometry::Prism { section, axis, .. } => {
                // v is one of the section's axes: its top on the line through x.
                let plane = prism_plane(*axis);
                let k = usize::from(plane[1] == v);
                polygon_top(section, x[plane[1 - k]], k, up)
            }
            Geometry::Particles(set) => set.top(x, v, up),
            Geometry::Surface(s) => s.top(x, v, up),
            Geometry::Terrain(t) => t.top(x, v, up),
            Geometry::Mesh(m) => m.top(x, v, up),
        }
    }

    /// The axis-aligned bounds (min, max) of the body.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        match self {
            Geometry::Box { min, max } => (min.clone(), max.clone()),
            Geometry::Ball { centre, radius } => (
                centre.iter().map(|c| c - radius).collect(),
                centre.iter().map(|c| c + radius).collect(),
            ),
            Geometry::Polygon(v) => (
                (0..2)
                    .map(|d| v.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min))
                    .collect(),
                (0..2)
                    .map(|d| v.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max))
                    .collect(),
            ),
            Geometry::Cylinder {
                base,
                radius,
                height,
            } => (
                vec![base[0] - radius, base[1] - radius, base[2]],
                vec![base[0] + radius, base[1] + radius, base[2] + height],
            ),
            Geometry::Prism {
                section,
                axis,
                from,
                to,
            } => prism_bounds(section, *axis, [*from, *to]),
            Geometry::Particles(set) => set.bounds(),
            Geometry::Surface(s) => s.bounds(),
            Geometry::Terrain(t) => t.bounds(),
            Geometry::Mesh(m) => m.bounds(),
        }
    }

    /// The point of the body's surface nearest to x (a point inside the body) and
    /// the outward unit normal there. A face on a plane x_d = c for which
    /// `on_boundary(d, c)` holds (a symmetry plane, the axis) is not surface;
    /// `None` if no face is.
    pub fn nearest_surface(
        &self,
        x: &[f64],
        on_boundary: &dyn Fn(usize, f64) -> bool,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        (self.nearest_surface_point(x, on_boundary)).map(|s| (s.point, s.normal))
    }

    /// [`Self::nearest_surface`] with how the normal turns as x moves
    /// ([`Bend`]), for derivatives of the distance to the surface.
    pub fn nearest_surface_point(
        &self,
        x: &[f64],
        on_boundary: &dyn Fn(usize, f64) -> bool,
    ) -> Option<SurfacePoint> {
        let unit = |d: usize, sign: f64| -> Vec<f64> {
            (0..x.len())
                .map(|i| if i == d { sign } else { 0.0 })
                .collect()
        };
        let on_plane = |d: usize, c: f64, sign: f64| {
            let mut y = x.to_vec();
            y[d] = c;
            ((x[d] - c).abs(), y, unit(d, sign), Bend::Flat)
        };
        // Candidates (distance, point, normal, bend); the nearest wins.
        let mut faces: Vec<(f64, Vec<f64>, Vec<f64>, Bend)> = Vec::new();
        match self {
            Geometry::Box { min, max } => {
                for d in 0..x.len() {
                    if !on_boundary(d, min[d]) {
                        faces.push(on_plane(d, min[d], -1.0));
                    }
                    if !on_boundary(d, max[d]) {
                        faces.push(on_plane(d, max[d], 1.0));
                    }
                }
            }
            Geometry::Ball { centre, radius } => {
                let (d, s) = ball_point(x, centre, *radius);
                faces.push((-d, s.point, s.normal, s.bend));
            }
            Geometry::Polygon(v) => faces.extend(
                polygon_faces(v, x, on_boundary)
                    .into_iter()
                    .map(|(l, y, n)| (l, y, n, Bend::Flat)),
            ),
            Geometry::Cylinder {
                base,
                radius,
                height,
            } => {
                let r = [x[0] - base[0], x[1] - base[1], 0.0];
                let n = radial(&r);
                let y = vec![base[0] + radius * n[0], base[1] + radius * n[1], x[2]];
                let bend = Bend::About {
                    distance: norm(&r),
                    axis: Some(2),
                };
                faces.push((radius - norm(&r), y, n, bend));
                for (c, sign) in [(base[2], -1.0), (base[2] + height, 1.0)] {
                    if !on_boundary(2, c) {
                        faces.push(on_plane(2, c, sign));
                    }
                }
            }
            Geometry::Prism {
                section,
                axis,
                from,
                to,
            } => {
                // The section's edges, extruded: points and normals in the plane.
                let plane = prism_plane(*axis);
                let xs = [x[plane[0]], x[plane[1]]];
                let in_plane = |d: usize, c: f64| on_boundary(plane[d], c);
                for (l, y, n) in polygon_faces(section, &xs, &in_plane) {
                    let (mut point, mut normal) = (x.to_vec(), vec![0.0; 3]);
                    for k in 0..2 {
                        (point[plane[k]], normal[plane[k]]) = (y[k], n[k]);
                    }
                    faces.push((l, point, normal, Bend::Flat));
                }
                for (c, sign) in [(*from, -1.0), (*to, 1.0)] {
                    if !on_boundary(*axis, c) {
                        faces.push(on_plane(*axis, c, sign));
                    }
                }
            }
            Geometry::Particles(_)
            | Geometry::Surface(_)
            | Geometry::Terrain(_)
            | Geometry::Mesh(_) => {}
        }
        faces
            .into_iter()
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, point, normal, bend)| SurfacePoint {
                point,
                normal,
                bend,
            })
    }
}

impl Geometry {
    /// The signed distance of x to the surface (negative inside) with the
    /// nearest surface point, for x inside (`nearest_surface_point`) or outside
    /// a box, a ball or a polygon; `None` outside a cylinder or where no face is
    /// surface. Outside a box's edge or corner, or a polygon's vertex, the
    /// nearest point is that edge or corner and the normal turns about it.
    pub fn signed_surface_point(
        &self,
        x: &[f64],
        on_boundary: &dyn Fn(usize, f64) -> bool,
    ) -> Option<(f64, SurfacePoint)> {
        if self.contains(x) {
            let s = self.nearest_surface_point(x, on_boundary)?;
            let depth: f64 = (0..x.len())
                .map(|d| (s.point[d] - x[d]) * s.normal[d])
                .sum();
            return Some((-depth, s));
        }
        let about = |y: Vec<f64>, axis: Option<usize>| {
            let r: Vec<f64> = (0..x.len()).map(|d| x[d] - y[d]).collect();
            let distance = norm(&r);
            let bend = Bend::About { distance, axis };
            (
                distance,
                SurfacePoint {
                    point: y,
                    normal: radial(&r),
                    bend,
                },
            )
        };
        match self {
            Geometry::Box { min, max } => {
                let y: Vec<f64> = (0..x.len()).map(|d| x[d].clamp(min[d], max[d])).collect();
                let outside: Vec<usize> = (0..x.len()).filter(|&d| y[d] != x[d]).collect();
                match outside[..] {
                    // On the boundary (`contains` is strict): as inside, the
                    // distance to the nearest face that is surface (zero unless
                    // the point's face lies on the grid's boundary).
                    [] => {
                        let s = self.nearest_surface_point(x, on_boundary)?;
                        let depth: f64 = (0..x.len())
                            .map(|d| (s.point[d] - x[d]) * s.normal[d])
                            .sum();
                        Some((-depth, s))
                    }
                    [d] => {
                        let sign = if x[d] > max[d] { 1.0 } else { -1.0 };
                        let normal = (0..x.len()).map(|i| if i == d { sign } else { 0.0 });
                        Some((
                            (x[d] - y[d]).abs(),
                            SurfacePoint {
                                point: y,
                                normal: normal.collect(),
                                bend: Bend::Flat,
                            },
                        ))
                    }
                    // An edge of a 3D box: the normal turns about its axis.
                    [a, b] if x.len() == 3 => Some(about(y, Some(3 - a - b))),
                    _ => Some(about(y, None)),
                }
            }
            Geometry::Ball { centre, radius } => Some(ball_point(x, centre, *radius)),
            Geometry::Polygon(v) => {
                let k = (0..v.len()).min_by(|&i, &j| {
                    let di = segment_distance(x, &v[i], &v[(i + 1) % v.len()]).0;
                    let dj = segment_distance(x, &v[j], &v[(j + 1) % v.len()]).0;
                    di.total_cmp(&dj)
                })?;
                let (a, b) = (&v[k], &v[(k + 1) % v.len()]);
                let (distance, t) = segment_distance(x, a, b);
                let y: Vec<f64> = (0..2).map(|d| a[d] + t * (b[d] - a[d])).collect();
                if t <= 0.0 || t >= 1.0 {
                    return Some(about(y, None));
                }
                let r: Vec<f64> = (0..2).map(|d| x[d] - y[d]).collect();
                Some((
                    distance,
                    SurfacePoint {
                        point: y,
                        normal: radial(&r),
                        bend: Bend::Flat,
                    },
                ))
            }
            Geometry::Cylinder { .. }
            | Geometry::Prism { .. }
            | Geometry::Particles(_)
            | Geometry::Surface(_)
            | Geometry::Terrain(_)
            | Geometry::Mesh(_) => None,
        }
    }
}

/// The signed distance of x to a ball's surface (negative inside) and the
/// nearest surface point, whose normal turns about the centre.
fn ball_point(x: &[f64], centre: &[f64], radius: f64) -> (f64, SurfacePoint) {
    let r: Vec<f64> = (0..x.len()).map(|d| x[d] - centre[d]).collect();
    let normal = radial(&r);
    let point = (0..x.len())
        .map(|d| centre[d] + radius * normal[d])
        .collect();
    let bend = Bend::About {
        distance: norm(&r),
        axis: None,
    };
    (
        norm(&r) - radius,
        SurfacePoint {
            point,
            normal,
            bend,
        },
    )
}

/// The distance of x to the segment ab and the parameter t ∈ [0, 1] of the
/// nearest point a + t (b − a).
fn segment_distance(x: &[f64], a: &[f64], b: &[f64]) -> (f64, f64) {
    let e = [b[0] - a[0], b[1] - a[1]];
    let l2 = e[0] * e[0] + e[1] * e[1];
    let t = match l2 > 0.0 {
        true => (((x[0] - a[0]) * e[0] + (x[1] - a[1]) * e[1]) / l2).clamp(0.0, 1.0),
        false => 0.0,
    };
    let y = [a[0] + t * e[0], a[1] + t * e[1]];
    (norm(&[x[0] - y[0], x[1] - y[1]]), t)
}

/// A point of a body's surface nearest to a point x inside it.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfacePoint {
    pub point: Vec<f64>,
    /// Outward unit normal.
    pub normal: Vec<f64>,
    pub bend: Bend,
}

/// How the outward normal n at the nearest surface point turns as x moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bend {
    /// A plane face (a polygon's edge): n is constant.
    Flat,
    /// A ball's surface (about its centre) or a cylinder's side (about its
    /// `axis`) at `distance` from x: ∂n/∂x = (I − a aᵀ − n nᵀ)/distance, a the
    /// axis (none for a ball).
    About { distance: f64, axis: Option<usize> },
}

fn norm(r: &[f64]) -> f64 {
    r.iter().map(|c| c * c).sum::<f64>().sqrt()
}

/// r/|r|, or the first axis for r = 0 (the centre of a ball: any direction).
fn radial(r: &[f64]) -> Vec<f64> {
    let l = norm(r);
    match l > 0.0 {
        true => r.iter().map(|c| c / l).collect(),
        false => (0..r.len())
            .map(|i| if i == 0 { 1.0 } else { 0.0 })
            .collect(),
    }
}

/// The nearest point of each edge of a polygon to x with the edge's outward
/// normal, leaving out edges on a boundary plane (both ends on it).
fn polygon_faces(
    v: &[Vec<f64>],
    x: &[f64],
    on_boundary: &dyn Fn(usize, f64) -> bool,
) -> Vec<(f64, Vec<f64>, Vec<f64>)> {
    let n = v.len();
    // Twice the signed area: > 0 for counter-clockwise vertices.
    let area: f64 = (0..n)
        .map(|k| v[k][0] * v[(k + 1) % n][1] - v[(k + 1) % n][0] * v[k][1])
        .sum();
    let out = area.signum();
    let mut faces = Vec::with_capacity(n);
    for k in 0..n {
        let (a, b) = (&v[k], &v[(k + 1) % n]);
        if (0..2).any(|d| a[d] == b[d] && on_boundary(d, a[d])) {
            continue;
        }
        let e = [b[0] - a[0], b[1] - a[1]];
        let l2 = e[0] * e[0] + e[1] * e[1];
        if l2 == 0.0 {
            continue;
        }
        let t = (((x[0] - a[0]) * e[0] + (x[1] - a[1]) * e[1]) / l2).clamp(0.0, 1.0);
        let y = vec![a[0] + t * e[0], a[1] + t * e[1]];
        let l = l2.sqrt();
        let normal = vec![out * e[1] / l, -out * e[0] / l];
        faces.push((norm(&[x[0] - y[0], x[1] - y[1]]), y, normal));
    }
    faces
}

/// Even-odd rule (ray crossing to +x).
/// Does the segment p–q cross an edge of the polygon `v` (a proper crossing,
/// or touching it: p and q inside, so a segment that only touches an edge
/// or a vertex grazes the boundary and is counted as leaving)?
fn crosses_an_edge(p: [f64; 2], q: [f64; 2], v: &[Vec<f64>]) -> bool {
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let n = v.len();
    (0..n).any(|k| {
        let (a, b) = ([v[k][0], v[k][1]], [v[(k + 1) % n][0], v[(k + 1) % n][1]]);
        let (d1, d2) = (cross(a, b, p), cross(a, b, q));
        let (d3, d4) = (cross(p, q, a), cross(p, q, b));
        d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && (d1 != d2 || d3 != d4)
    })
}

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
    fn nearest_surface_of_each_shape() {
        let none = |_: usize, _: f64| false;
        // A clockwise square: the normal still points out.
        let square = Geometry::Polygon(vec![
            vec![0.0, 0.0],
            vec![0.0, 2.0],
            vec![2.0, 2.0],
            vec![2.0, 0.0],
        ]);
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-15);
        let (y, n) = square.nearest_surface(&[1.9, 0.5], &none).unwrap();
        assert!(
            close(&y, &[2.0, 0.5]) && close(&n, &[1.0, 0.0]),
            "{y:?} {n:?}"
        );
        // The face on the axis x = 0 is not surface: the bottom is nearest.
        let axis = |d: usize, c: f64| d == 0 && c == 0.0;
        let (y, n) = square.nearest_surface(&[0.1, 0.5], &axis).unwrap();
        assert!(
            close(&y, &[0.1, 0.0]) && close(&n, &[0.0, -1.0]),
            "{y:?} {n:?}"
        );
        let disk = Geometry::Ball {
            centre: vec![1.0, 1.0],
            radius: 2.0,
        };
        let (y, n) = disk.nearest_surface(&[1.0, 2.5], &none).unwrap();
        assert!((y[1] - 3.0).abs() < 1e-15 && (n[1] - 1.0).abs() < 1e-15);
        let bx = Geometry::Box {
            min: vec![0.0, 0.0, 0.0],
            max: vec![1.0, 1.0, 4.0],
        };
        let (y, n) = bx.nearest_surface(&[0.5, 0.5, 3.8], &none).unwrap();
        assert_eq!((y, n), (vec![0.5, 0.5, 4.0], vec![0.0, 0.0, 1.0]));
        let cyl = Geometry::Cylinder {
            base: vec![0.0, 0.0, 0.0],
            radius: 1.0,
            height: 4.0,
        };
        let (y, n) = cyl.nearest_surface(&[0.0, 0.9, 2.0], &none).unwrap();
        assert_eq!((y, n), (vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.0]));
        assert_eq!(cyl.bounds(), (vec![-1.0, -1.0, 0.0], vec![1.0, 1.0, 4.0]));
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

    #[test]
    fn a_prism_is_its_section_extruded() {
        // The 2:1 slope in the x–z plane, extruded over 0 < y < 4 (axis y).
        let section: Vec<Vec<f64>> = [[0.0, 0.0], [35.0, 0.0], [15.0, 10.0], [0.0, 10.0]]
            .iter()
            .map(|p| p.to_vec())
            .collect();
        let prism = Geometry::Prism {
            section: section.clone(),
            axis: 1,
            from: 0.0,
            to: 4.0,
        };
        let slope = Geometry::Polygon(section);
        for (x, z) in [
            (5.0, 5.0),
            (25.0, 4.9),
            (25.0, 5.1),
            (36.0, 0.5),
            (10.0, 9.99),
        ] {
            for y in [-0.1, 0.1, 3.9, 4.1] {
                let inside = slope.contains(&[x, z]) && (0.0..4.0).contains(&y);
                assert_eq!(prism.contains(&[x, y, z]), inside, "({x}, {y}, {z})");
            }
            // Depth below the top along z (up = +1), and the extent along y.
            assert_eq!(prism.top(&[x, 2.0, z], 2, 1.0), slope.top(&[x, z], 1, 1.0));
            assert_eq!(prism.top(&[x, 2.0, z], 1, 1.0), 4.0);
            assert_eq!(prism.top(&[x, 2.0, z], 1, -1.0), 0.0);
        }
        assert_eq!(prism.bounds(), (vec![0.0, 0.0, 0.0], vec![35.0, 4.0, 10.0]));
        // Inside: the slope face (normal (1, 0, 2)/√5), an end face, or a face
        // on a boundary plane left out.
        let none = |_: usize, _: f64| false;
        let s = prism
            .nearest_surface_point(&[24.0, 2.0, 5.0], &none)
            .unwrap();
        let n = [1.0 / 5f64.sqrt(), 0.0, 2.0 / 5f64.sqrt()];
        assert!(
            (0..3).all(|d| (s.normal[d] - n[d]).abs() < 1e-12),
            "{:?}",
            s.normal
        );
        assert!((s.point[1] - 2.0).abs() < 1e-15);
        let s = prism
            .nearest_surface_point(&[5.0, 0.2, 5.0], &none)
            .unwrap();
        assert_eq!((s.normal.clone(), s.point[1]), (vec![0.0, -1.0, 0.0], 0.0));
        let symmetry = |d: usize, c: f64| d == 1 && c == 0.0;
        let s = prism
            .nearest_surface_point(&[5.0, 0.2, 9.0], &symmetry)
            .unwrap();
        assert_eq!(s.normal, vec![0.0, 0.0, 1.0]);
    }
}
