//! Finite-element lower bound (Sloan 1988; Makrodimopoulos & Martin 2006 with
//! second-order cones): linear stress triangles, each with its own three nodes,
//! so that every edge is a statically admissible stress discontinuity.
//!
//! Unknowns: (σx, σy, τxy) at the three nodes of every triangle and the load
//! multiplier α. Constraints:
//! - equilibrium inside each triangle, ∂σx/∂x + ∂τxy/∂y = 0 and
//!   ∂τxy/∂x + ∂σy/∂y = α γ (gravity in −y, tension positive);
//! - equal normal and shear tractions on both sides of every interior edge, at
//!   both of its ends (the tractions are linear along the edge);
//! - prescribed tractions at both ends of every boundary edge (free: σn = τ = 0;
//!   smooth and footing: τ = 0; rigid: none);
//! - the footing's normal traction integrates to α times its width;
//! - Mohr–Coulomb at every node (a cone), hence everywhere, since the stress
//!   is linear and the yield set convex.
//!
//! Maximising α gives a multiplier that the exact collapse multiplier of the
//! same problem cannot be below.

use super::cone::{ConicProgram, Row, SolverFailure};
use super::model::{edge_geometry, BoundaryKind, Load, Model};
use super::Bound;

/// Index of σx at local node `k` of triangle `e` (σy and τxy follow).
fn stress(e: usize, k: usize) -> usize {
    9 * e + 3 * k
}

/// Normal and shear traction at a stress node on a plane of unit normal n:
/// σn = nx² σx + ny² σy + 2 nx ny τxy, τ = nx ny (σy − σx) + (nx² − ny²) τxy.
fn traction(s: usize, n: [f64; 2]) -> (Row, Row) {
    let [nx, ny] = n;
    (
        vec![(s, nx * nx), (s + 1, ny * ny), (s + 2, 2.0 * nx * ny)],
        vec![(s, -nx * ny), (s + 1, nx * ny), (s + 2, nx * nx - ny * ny)],
    )
}

fn minus(mut a: Row, b: Row) -> Row {
    a.extend(b.into_iter().map(|(j, v)| (j, -v)));
    a
}

/// The two equilibrium rows of a linear stress triangle (constant stress
/// gradient): Σ (b_i σx_i + c_i τ_i) / 2A = 0 and Σ (b_i τ_i + c_i σy_i) / 2A = α γ,
/// with b_i = y_j − y_k, c_i = x_k − x_j (Zienkiewicz's linear triangle).
pub fn equilibrium_rows(model: &Model, e: usize, alpha: usize) -> [(Row, f64); 2] {
    let t = model.mesh.triangles[e];
    let p = t.map(|i| model.mesh.nodes[i]);
    let two_a = 2.0 * model.mesh.signed_area(t);
    let mut rx = Row::new();
    let mut ry = Row::new();
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let b = (p[j][1] - p[k][1]) / two_a;
        let c = (p[k][0] - p[j][0]) / two_a;
        let s = stress(e, i);
        rx.extend([(s, b), (s + 2, c)]);
        ry.extend([(s + 2, b), (s + 1, c)]);
    }
    if let Load::Gravity { unit_weight } = model.load {
        ry.push((alpha, -unit_weight));
    }
    [(rx, 0.0), (ry, 0.0)]
}

/// Build the lower-bound program: variables, constraints and objective (−α).
pub fn program(model: &Model) -> ConicProgram {
    let mesh = &model.mesh;
    let ne = mesh.triangles.len();
    let alpha = 9 * ne;
    let mut p = ConicProgram::new(9 * ne + 1);
    p.objective = vec![(alpha, -1.0)];
    for e in 0..ne {
        for (row, rhs) in equilibrium_rows(model, e, alpha) {
            p.equal(row, rhs);
        }
    }
    let local = |e: usize, node: usize| {
        let t = mesh.triangles[e];
        stress(e, (0..3).find(|&k| t[k] == node).expect("node of triangle"))
    };
    let mut footing = Row::new();
    for (edge, kind) in model.edges.iter().zip(&model.boundary) {
        let (_, n, length) = edge_geometry(mesh, edge.nodes);
        let (e1, _) = edge.sides[0];
        match (kind, edge.sides.get(1)) {
            (None, Some(&(e2, _))) => {
                for node in edge.nodes {
                    let (n1, t1) = traction(local(e1, node), n);
                    let (n2, t2) = traction(local(e2, node), n);
                    p.equal(minus(n1, n2), 0.0);
                    p.equal(minus(t1, t2), 0.0);
                }
            }
            (Some(kind), None) => {
                for node in edge.nodes {
                    let (sn, tau) = traction(local(e1, node), n);
                    match kind {
                        BoundaryKind::Free => {
                            p.equal(sn, 0.0);
                            p.equal(tau, 0.0);
                        }
                        BoundaryKind::Smooth => {
                            p.equal(tau, 0.0);
                        }
                        BoundaryKind::Footing => {
                            p.equal(tau, 0.0);
                            // Pressure −σn, trapezoidal rule (exact for linear σn).
                            footing.extend(sn.into_iter().map(|(j, v)| (j, -0.5 * length * v)));
                        }
                        BoundaryKind::Rigid => {}
                    }
                }
            }
            _ => unreachable!("an edge is interior with two sides or boundary with one"),
        }
    }
    if let Load::FootingPressure { width } = model.load {
        footing.push((alpha, -width));
        p.equal(footing, 0.0);
    }
    for e in 0..ne {
        for k in 0..3 {
            p.yield_cone(stress(e, k), model.strength);
        }
    }
    p
}

/// Solve the lower-bound problem.
pub fn lower_bound(model: &Model) -> Result<Bound, SolverFailure> {
    let p = program(model);
    let s = p.solve(model.max_iterations)?;
    let ne = model.mesh.triangles.len();
    Ok(Bound {
        multiplier: s.x[9 * ne] * model.multiplier_unit,
        elements: ne,
        variables: p.variables,
        equalities: p.equalities(),
        cones: p.cones(),
        iterations: s.iterations,
        seconds: s.seconds,
        field: (0..ne)
            .flat_map(|e| (0..3).map(move |k| stress(e, k)))
            .map(|i| [s.x[i], s.x[i + 1], s.x[i + 2]])
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyses::limit_analysis::cone::MohrCoulomb;
    use crate::analyses::limit_analysis::model::{MeshSize, SlopeGeometry};

    fn slope_patch() -> Model {
        let strength = MohrCoulomb {
            cohesion: 1.0,
            friction_angle: 0.3,
        };
        let geometry = SlopeGeometry {
            height: 1.0,
            gradient: 1.5,
            crest: 1.0,
            toe: 0.5,
            foundation_depth: 0.5,
        };
        let size = MeshSize {
            fine: 0.25,
            growth: 1.5,
            max: 0.5,
            refinements: 0,
        };
        Model::slope(strength, 1.0, geometry, size)
    }

    /// A field that is linear over the whole domain and in equilibrium with
    /// gravity α γ (γ = 1 in the model's units), put at every element node,
    /// satisfies every equilibrium and every continuity row exactly (only
    /// boundary rows may fail: the field ignores the boundary conditions); a
    /// change at one node of one triangle breaks its rows and no others.
    #[test]
    fn equilibrium_and_continuity_rows_hold_for_a_global_equilibrated_field() {
        let model = slope_patch();
        let p = program(&model);
        let ne = model.mesh.triangles.len();
        // σx = 0.3x − 0.2y + 1, σy = 0.6y + 0.5x, τ = 0.1x − 0.3y:
        // ∂σx/∂x + ∂τ/∂y = 0 and ∂τ/∂x + ∂σy/∂y = 0.7 = α γ.
        let field = |[x, y]: [f64; 2]| {
            [
                0.3 * x - 0.2 * y + 1.0,
                0.6 * y + 0.5 * x,
                0.1 * x - 0.3 * y,
            ]
        };
        let mut x = vec![0.0; p.variables];
        for (e, t) in model.mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let s = field(model.mesh.nodes[t[k]]);
                x[stress(e, k)..stress(e, k) + 3].copy_from_slice(&s);
            }
        }
        x[9 * ne] = 0.7;
        let r = p.equality_residuals(&x);
        assert!(r[..2 * ne].iter().all(|v| v.abs() < 1e-12), "equilibrium");
        let boundary_rows: usize = model
            .boundary
            .iter()
            .flatten()
            .map(|k| match k {
                BoundaryKind::Free => 4,
                BoundaryKind::Smooth | BoundaryKind::Footing => 2,
                BoundaryKind::Rigid => 0,
            })
            .sum();
        let violated = r.iter().filter(|v| v.abs() > 1e-12).count();
        assert!(
            violated > 0 && violated <= boundary_rows,
            "{violated} > {boundary_rows}"
        );
        // The wrong multiplier breaks every y-equilibrium row.
        let mut w = x.clone();
        w[9 * ne] = 0.8;
        let bad = p.equality_residuals(&w)[..2 * ne]
            .iter()
            .filter(|v| v.abs() > 1e-12)
            .count();
        assert_eq!(bad, ne);
        // Perturb σx at node 0 of a triangle with only interior edges: its
        // x-equilibrium row and the traction rows of its two edges through
        // that node change (σn and τ on each, where the normal makes them
        // depend on σx), nothing else.
        let e = (0..ne)
            .find(|&e| {
                model
                    .edges
                    .iter()
                    .filter(|ed| ed.sides.iter().any(|s| s.0 == e))
                    .all(|ed| ed.sides.len() == 2)
            })
            .unwrap();
        let mut y = x.clone();
        y[stress(e, 0)] += 1.0;
        let r2 = p.equality_residuals(&y);
        let changed = r
            .iter()
            .zip(&r2)
            .filter(|(a, b)| (*a - *b).abs() > 1e-12)
            .count();
        assert!((3..=5).contains(&changed), "{changed}");
    }

    /// The traction of a stress on a plane is the projection of σ·n.
    #[test]
    fn traction_rows_project_the_stress_vector() {
        let n = [0.6, 0.8];
        let s = [3.0, -2.0, 1.5];
        let (sn, tau) = traction(0, n);
        let eval = |row: &Row| row.iter().map(|&(j, a)| a * s[j]).sum::<f64>();
        let t = [s[0] * n[0] + s[2] * n[1], s[2] * n[0] + s[1] * n[1]];
        assert!((eval(&sn) - (t[0] * n[0] + t[1] * n[1])).abs() < 1e-14);
        assert!((eval(&tau) - (-t[0] * n[1] + t[1] * n[0])).abs() < 1e-14);
    }
}
