//! The boundary value problems: a triangulated domain, its boundary conditions,
//! its strength and the load that the collapse multiplier scales.
//!
//! Both bounds solve the same problem, so their results bracket its exact
//! collapse multiplier. Each model is built in dimensionless units (lengths over
//! a reference length, stresses over a reference stress); `multiplier_unit`
//! converts the solver's multiplier back.

use super::cone::{MohrCoulomb, MAX_ITERATIONS};
use super::mesh::{refine, reversed, spacing, Block, Edge, Mesh, Point};

/// What a boundary edge imposes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundaryKind {
    /// Traction free (ground surface).
    Free,
    /// Zero shear traction and zero normal velocity: a line of symmetry or a
    /// smooth roller. Only axis-aligned smooth edges are supported.
    Smooth,
    /// Rigid and rough: zero velocity, any traction.
    Rigid,
    /// Under a rigid smooth footing: zero shear traction, vertical velocity equal
    /// to the footing's; the footing's normal traction resultant is the load.
    Footing,
}

/// The load scaled by the multiplier α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// Average pressure α on a smooth rigid footing of the given (half) width.
    /// The soil is weightless.
    FootingPressure { width: f64 },
    /// Gravity α γ acting in −y.
    Gravity { unit_weight: f64 },
}

/// A plane-strain limit analysis problem on a triangulation.
#[derive(Clone, Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub edges: Vec<Edge>,
    /// Boundary condition of each edge (None for interior edges).
    pub boundary: Vec<Option<BoundaryKind>>,
    pub strength: MohrCoulomb,
    pub load: Load,
    /// Physical value of a unit multiplier (a stress for a footing, 1 for gravity).
    pub multiplier_unit: f64,
    /// Clarabel's iteration limit for each bound (scene key
    /// `solver.max_iterations`).
    pub max_iterations: u32,
}

/// Mesh density: smallest cell at the singular point (footing edge, slope toe),
/// growth factor from cell to cell, largest cell, and the number of uniform
/// halvings applied on top.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSize {
    pub fine: f64,
    pub growth: f64,
    pub max: f64,
    pub refinements: u32,
}

impl MeshSize {
    /// Uniform cells of about the fine size (then refined).
    fn uniform(&self, length: f64) -> Vec<f64> {
        let n = (length / self.fine).round().max(1.0) as usize;
        refine(
            &(0..=n).map(|i| i as f64 / n as f64).collect::<Vec<_>>(),
            self.refinements,
        )
    }

    /// Cells growing from the fine size at 0 (then refined).
    fn spacing(&self, length: f64) -> Vec<f64> {
        let fine = self.fine.min(length);
        refine(
            &spacing(length, fine, self.growth, self.max.max(fine)),
            self.refinements,
        )
    }
}

impl Model {
    /// Classify every boundary edge by its midpoint and outward normal.
    fn new(
        mesh: Mesh,
        strength: MohrCoulomb,
        load: Load,
        multiplier_unit: f64,
        classify: impl Fn(Point, Point) -> BoundaryKind,
    ) -> Model {
        let edges = mesh.edges();
        let boundary = edges
            .iter()
            .map(|e| {
                (e.sides.len() == 1).then(|| {
                    let (mid, normal, _) = edge_geometry(&mesh, e.nodes);
                    classify(mid, normal)
                })
            })
            .collect();
        Model {
            mesh,
            edges,
            boundary,
            strength,
            load,
            multiplier_unit,
            max_iterations: MAX_ITERATIONS,
        }
    }

    /// Smooth rigid strip footing of width 2b on a weightless Mohr–Coulomb soil,
    /// half domain by symmetry: x ∈ [0, width], y ∈ [−depth, 0], footing on
    /// x ∈ [0, b] at y = 0, smooth symmetry line x = 0, rigid rough base and far
    /// side. Lengths in units of b, stresses in units of c; the multiplier is
    /// the average footing pressure.
    pub fn footing(
        strength: MohrCoulomb,
        half_width: f64,
        width: f64,
        depth: f64,
        size: MeshSize,
    ) -> Model {
        let (b, w, d) = (1.0, width / half_width, depth / half_width);
        let size = MeshSize {
            fine: size.fine / half_width,
            max: size.max / half_width,
            ..size
        };
        let under = reversed(&size.spacing(b));
        let outside = size.spacing(w - b);
        let down = reversed(&size.spacing(d));
        let blocks = [
            Block {
                corners: [[0.0, -d], [b, -d], [b, 0.0], [0.0, 0.0]],
                xi: under,
                eta: down.clone(),
            },
            Block {
                corners: [[b, -d], [w, -d], [w, 0.0], [b, 0.0]],
                xi: outside,
                eta: down,
            },
        ];
        let eps = 1e-9 * w;
        let unit = strength.cohesion;
        let scaled = MohrCoulomb {
            cohesion: 1.0,
            ..strength
        };
        Model::new(
            Mesh::from_blocks(&blocks),
            scaled,
            Load::FootingPressure { width: b },
            unit,
            |mid, normal| {
                if mid[1].abs() < eps && normal[1] > 0.5 {
                    if mid[0] < b {
                        BoundaryKind::Footing
                    } else {
                        BoundaryKind::Free
                    }
                } else if mid[0].abs() < eps {
                    BoundaryKind::Smooth
                } else {
                    BoundaryKind::Rigid
                }
            },
        )
    }

    /// Slope of height H and gradient G (horizontal : vertical) with its toe at
    /// the origin, a crest plateau of length `crest` behind it, and a foundation
    /// layer of depth D extending `toe` in front of the toe (no foundation layer
    /// when D = 0: the toe then stands on the rigid base). Smooth rollers on both
    /// vertical sides, a rigid rough base. Lengths in units of H, stresses in
    /// units of γH; the multiplier scales gravity.
    pub fn slope(
        strength: MohrCoulomb,
        unit_weight: f64,
        geometry: SlopeGeometry,
        size: MeshSize,
    ) -> Model {
        let h = geometry.height;
        let (g, lc, lt, d) = (
            geometry.gradient,
            geometry.crest / h,
            geometry.toe / h,
            geometry.foundation_depth / h,
        );
        let size = MeshSize {
            fine: size.fine / h,
            max: size.max / h,
            ..size
        };
        let right = g + lc;
        // Above the toe level: one trapezoid whose left side is the slope face,
        // with uniform cells (the slip surface, the face and the crest all need
        // resolving); the foundation and the ground in front of the toe grade
        // away from it.
        let along = size.uniform(right);
        let up = size.uniform(1.0);
        let mut blocks = vec![Block {
            corners: [[0.0, 0.0], [right, 0.0], [right, 1.0], [g, 1.0]],
            xi: along.clone(),
            eta: up,
        }];
        let left = if d > 0.0 { -lt } else { 0.0 };
        if d > 0.0 {
            let down = reversed(&size.spacing(d));
            blocks.push(Block {
                corners: [[0.0, -d], [right, -d], [right, 0.0], [0.0, 0.0]],
                xi: along,
                eta: down.clone(),
            });
            if lt > 0.0 {
                blocks.push(Block {
                    corners: [[-lt, -d], [0.0, -d], [0.0, 0.0], [-lt, 0.0]],
                    xi: reversed(&size.spacing(lt)),
                    eta: down,
                });
            }
        }
        let eps = 1e-9 * (right - left);
        let unit = unit_weight * h;
        let scaled = MohrCoulomb {
            cohesion: strength.cohesion / unit,
            ..strength
        };
        Model::new(
            Mesh::from_blocks(&blocks),
            scaled,
            Load::Gravity { unit_weight: 1.0 },
            1.0,
            |mid, _| {
                let on_left = d > 0.0 && (mid[0] - left).abs() < eps;
                if on_left || (mid[0] - right).abs() < eps {
                    BoundaryKind::Smooth
                } else if (mid[1] + d).abs() < eps {
                    BoundaryKind::Rigid
                } else {
                    BoundaryKind::Free
                }
            },
        )
    }

    /// The same problem with the strength reduced by F (c/F, atan(tan φ/F)).
    pub fn with_strength(&self, strength: MohrCoulomb) -> Model {
        Model {
            strength,
            ..self.clone()
        }
    }
}

/// Slope geometry (physical lengths).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeGeometry {
    pub height: f64,
    pub gradient: f64,
    pub crest: f64,
    pub toe: f64,
    pub foundation_depth: f64,
}

/// Midpoint, unit normal pointing to the right of a → b (outward for a
/// counter-clockwise triangle) and length of the edge a → b.
pub fn edge_geometry(mesh: &Mesh, nodes: [usize; 2]) -> (Point, Point, f64) {
    let [a, b] = nodes.map(|i| mesh.nodes[i]);
    let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
    let length = tx.hypot(ty);
    (
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
        [ty / length, -tx / length],
        length,
    )
}
