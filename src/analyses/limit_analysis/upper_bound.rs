//! Finite-element upper bound with quadratic velocity triangles (six nodes,
//! linear strain rate), after Makrodimopoulos & Martin (2007), solved in its
//! dual ("static") form.
//!
//! The kinematic problem is: minimise the plastic dissipation
//! Σ_e (A_e/3) Σ_vertices D(ε̇) over continuous quadratic velocity fields that
//! satisfy the velocity boundary conditions, with the power of the reference
//! load equal to one. D(ε̇) = sup_{σ ∈ Y} σ : ε̇ is the support function of the
//! Mohr–Coulomb set, finite only where ε̇ obeys the associated flow rule. Its
//! conic dual is: maximise α subject to the weak equilibrium
//! Σ_e Σ_vertices (A_e/3) Bᵀ σ = α f at every free velocity degree of freedom,
//! with σ inside the yield cone at every vertex of every triangle. The two
//! optima coincide (strong duality), and the equality multipliers are the
//! collapse mechanism.
//!
//! The bound is rigorous: the strain rate is linear on a triangle, D is convex,
//! so the vertex rule (A/3) Σ D(ε̇_vertex) is not below the exact integral of D,
//! and the flow rule holds everywhere on the triangle once it holds at its
//! vertices (the cone is convex).

use super::cone::{ConicProgram, Row, SolverFailure};
use super::model::{edge_geometry, BoundaryKind, Load, Model};
use super::Bound;

/// Index of σx at vertex `k` of triangle `e` (σy and τxy follow).
fn stress(e: usize, k: usize) -> usize {
    9 * e + 3 * k
}

/// How a velocity component enters the equations.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Dof {
    Fixed,
    /// Its own equation.
    Free(usize),
    /// Tied to the footing's downward velocity V: u_y = −V.
    Footing,
}

/// The six nodes of each triangle: its vertices, then the midpoints of its local
/// edges 0-1, 1-2, 2-0 (numbered after the vertices, one per mesh edge).
pub fn quadratic_nodes(model: &Model) -> Vec<[usize; 6]> {
    let nv = model.mesh.nodes.len();
    let mut nodes: Vec<[usize; 6]> = model
        .mesh
        .triangles
        .iter()
        .map(|t| [t[0], t[1], t[2], 0, 0, 0])
        .collect();
    for (i, edge) in model.edges.iter().enumerate() {
        for &(e, k) in &edge.sides {
            nodes[e][3 + k] = nv + i;
        }
    }
    nodes
}

/// Gradients of the six quadratic shape functions at vertex q of a straight
/// triangle: vertex i, N_i = L_i (2L_i − 1); mid-node of edge k (k → k+1),
/// N = 4 L_k L_{k+1}.
pub fn shape_gradients(p: [[f64; 2]; 3], q: usize) -> [[f64; 2]; 6] {
    let two_a =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    let dl: Vec<[f64; 2]> = (0..3)
        .map(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            [(p[j][1] - p[k][1]) / two_a, (p[k][0] - p[j][0]) / two_a]
        })
        .collect();
    let l = |i: usize| if i == q { 1.0 } else { 0.0 };
    let mut g = [[0.0; 2]; 6];
    for i in 0..3 {
        for d in 0..2 {
            g[i][d] = (4.0 * l(i) - 1.0) * dl[i][d];
            let j = (i + 1) % 3;
            g[3 + i][d] = 4.0 * (l(i) * dl[j][d] + l(j) * dl[i][d]);
        }
    }
    g
}

fn dof_map(model: &Model, nnodes: usize) -> (Vec<[Dof; 2]>, usize, Option<usize>) {
    let nv = model.mesh.nodes.len();
    #[derive(Clone, Copy, Default)]
    struct Bc {
        fix: [bool; 2],
        footing: bool,
    }
    let mut bc = vec![Bc::default(); nnodes];
    for (i, (edge, kind)) in model.edges.iter().zip(&model.boundary).enumerate() {
        let Some(kind) = kind else { continue };
        let (_, n, _) = edge_geometry(&model.mesh, edge.nodes);
        for node in [edge.nodes[0], edge.nodes[1], nv + i] {
            let b = &mut bc[node];
            match kind {
                BoundaryKind::Free => {}
                BoundaryKind::Rigid => b.fix = [true, true],
                BoundaryKind::Smooth => {
                    assert!(
                        n[0].abs() < 1e-9 || n[1].abs() < 1e-9,
                        "smooth boundaries must be axis-aligned"
                    );
                    b.fix[if n[0].abs() > n[1].abs() { 0 } else { 1 }] = true;
                }
                BoundaryKind::Footing => b.footing = true,
            }
        }
    }
    let mut rows = 0;
    let footing_row = bc.iter().any(|b| b.footing && !b.fix[1]).then(|| {
        rows += 1;
        0
    });
    let dofs = bc
        .iter()
        .map(|b| {
            let mut d = [Dof::Fixed; 2];
            for (c, (dof, &fixed)) in d.iter_mut().zip(&b.fix).enumerate() {
                if fixed {
                    continue;
                }
                *dof = if c == 1 && b.footing {
                    Dof::Footing
                } else {
                    rows += 1;
                    Dof::Free(rows - 1)
                };
            }
            d
        })
        .collect();
    (dofs, rows, footing_row)
}

/// For each node and velocity component: the equation it belongs to and the
/// sign of its velocity relative to that equation's multiplier.
pub type VelocityMap = Vec<[Option<(usize, f64)>; 2]>;

/// Build the upper-bound program; also returns where each velocity component
/// sits and each equation's load coefficient (its share of the load power).
pub fn program(model: &Model) -> (ConicProgram, VelocityMap, Vec<f64>) {
    let mesh = &model.mesh;
    let ne = mesh.triangles.len();
    let alpha = 9 * ne;
    let six = quadratic_nodes(model);
    let nnodes = mesh.nodes.len() + model.edges.len();
    let (dofs, nrows, footing_row) = dof_map(model, nnodes);
    let mut rows: Vec<Row> = vec![Row::new(); nrows];
    let target = |d: Dof| match d {
        Dof::Fixed => None,
        Dof::Free(r) => Some((r, 1.0)),
        Dof::Footing => footing_row.map(|r| (r, -1.0)),
    };
    let map: VelocityMap = dofs.iter().map(|d| [target(d[0]), target(d[1])]).collect();
    let mut load = vec![0.0; nrows];
    for (e, t) in mesh.triangles.iter().enumerate() {
        let p = t.map(|i| mesh.nodes[i]);
        let w = mesh.signed_area(*t) / 3.0;
        for q in 0..3 {
            let g = shape_gradients(p, q);
            let s = stress(e, q);
            for (a, &node) in six[e].iter().enumerate() {
                let [gx, gy] = g[a];
                // (Bᵀσ) at this node: (∂N/∂x σx + ∂N/∂y τ, ∂N/∂y σy + ∂N/∂x τ).
                let parts = [[(s, gx), (s + 2, gy)], [(s + 1, gy), (s + 2, gx)]];
                for (c, part) in parts.iter().enumerate() {
                    if let Some((r, sign)) = target(dofs[node][c]) {
                        rows[r].extend(part.iter().map(|&(j, v)| (j, sign * w * v)));
                    }
                }
            }
        }
        if let Load::Gravity { unit_weight } = model.load {
            // Consistent nodal loads of a constant body force on a six-node
            // triangle: nothing at the vertices, A/3 at each mid-side node.
            for &node in &six[e][3..] {
                if let Some((r, sign)) = target(dofs[node][1]) {
                    load[r] -= sign * unit_weight * w;
                }
            }
        }
    }
    if let (Load::FootingPressure { width }, Some(r)) = (model.load, footing_row) {
        load[r] += width;
    }
    let mut p = ConicProgram::new(9 * ne + 1);
    p.objective = vec![(alpha, -1.0)];
    for (mut row, f) in rows.into_iter().zip(&load) {
        // Internal power of the vertex stresses = α × load power.
        if *f != 0.0 {
            row.push((alpha, -f));
        }
        p.equal(row, 0.0);
    }
    for e in 0..ne {
        for k in 0..3 {
            p.yield_cone(stress(e, k), model.strength);
        }
    }
    (p, map, load)
}

/// Solve the upper-bound problem. The field is the collapse velocity at every
/// node (vertices, then mid-side nodes), normalised by its largest component.
pub fn upper_bound(model: &Model) -> Result<Bound, SolverFailure> {
    let (p, map, load) = program(model);
    let s = p.solve(model.max_iterations)?;
    let ne = model.mesh.triangles.len();
    let y = &s.equality_duals;
    // Orient the mechanism so that the load does positive work on it.
    let power: f64 = load.iter().zip(y).map(|(f, u)| f * u).sum();
    let orient = if power < 0.0 { -1.0 } else { 1.0 };
    let velocity: Vec<[f64; 3]> = map
        .iter()
        .map(|m| {
            let v = |c: usize| m[c].map_or(0.0, |(r, sign)| orient * sign * y[r]);
            [v(0), v(1), 0.0]
        })
        .collect();
    let mut velocity = velocity;
    let vmax = velocity
        .iter()
        .flat_map(|v| v.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if vmax > 0.0 {
        velocity.iter_mut().flatten().for_each(|v| *v /= vmax);
    }
    // The dual objective is the dissipation of the (dual-feasible) mechanism:
    // the kinematic bound itself, never below the primal optimum.
    Ok(Bound {
        multiplier: -s.dual_objective * model.multiplier_unit,
        elements: ne,
        variables: p.variables,
        equalities: p.equalities(),
        cones: p.cones(),
        iterations: s.iterations,
        seconds: s.seconds,
        field: velocity,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyses::limit_analysis::cone::MohrCoulomb;
    use crate::analyses::limit_analysis::model::MeshSize;

    /// The quadratic shape functions reproduce linear and quadratic fields:
    /// Σ ∇N_a x_a = (1, 0), Σ ∇N_a = 0, and ∇(x²) at a vertex is (2x, 0).
    #[test]
    fn shape_gradients_reproduce_quadratic_fields() {
        let p = [[0.2, 0.1], [1.3, 0.4], [0.5, 1.1]];
        let mid = |i: usize, j: usize| [0.5 * (p[i][0] + p[j][0]), 0.5 * (p[i][1] + p[j][1])];
        let x = [p[0], p[1], p[2], mid(0, 1), mid(1, 2), mid(2, 0)];
        for q in 0..3 {
            let g = shape_gradients(p, q);
            for d in 0..2 {
                let sum: f64 = g.iter().map(|v| v[d]).sum();
                let lin: f64 = g.iter().zip(&x).map(|(v, xa)| v[d] * xa[0]).sum();
                let quad: f64 = g.iter().zip(&x).map(|(v, xa)| v[d] * xa[0] * xa[1]).sum();
                assert!(sum.abs() < 1e-12);
                assert!((lin - if d == 0 { 1.0 } else { 0.0 }).abs() < 1e-12);
                // ∇(xy) = (y, x) at vertex q.
                let exact = if d == 0 { p[q][1] } else { p[q][0] };
                assert!((quad - exact).abs() < 1e-12);
            }
        }
    }

    /// Patch test of the weak equilibrium: a constant stress gives zero
    /// internal force at every node away from the boundary, and the footing
    /// equation alone carries the load (the footing's width).
    #[test]
    fn constant_stress_is_in_weak_equilibrium_and_only_the_footing_is_loaded() {
        let strength = MohrCoulomb {
            cohesion: 1.0,
            friction_angle: 0.0,
        };
        let size = MeshSize {
            fine: 0.3,
            growth: 1.4,
            max: 0.6,
            refinements: 0,
        };
        let model = Model::footing(strength, 1.0, 2.5, 1.5, size);
        let (p, map, load) = program(&model);
        let ne = model.mesh.triangles.len();
        let mut x = vec![0.0; p.variables];
        for e in 0..ne {
            for k in 0..3 {
                x[stress(e, k)..stress(e, k) + 3].copy_from_slice(&[-1.3, 0.4, 0.7]);
            }
        }
        let r = p.equality_residuals(&x);
        // Rows of nodes with no boundary edge: internal force zero.
        let nv = model.mesh.nodes.len();
        let mut on_boundary = vec![false; nv + model.edges.len()];
        for (i, (e, k)) in model.edges.iter().zip(&model.boundary).enumerate() {
            if k.is_some() {
                on_boundary[e.nodes[0]] = true;
                on_boundary[e.nodes[1]] = true;
                on_boundary[nv + i] = true;
            }
        }
        let mut checked = 0;
        for (node, m) in map.iter().enumerate() {
            for &(row, _) in m.iter().flatten() {
                if !on_boundary[node] {
                    assert!(r[row].abs() < 1e-12, "node {node}: {}", r[row]);
                    checked += 1;
                }
            }
        }
        assert!(checked > 50);
        // The footing row carries the load (its width); nothing else does.
        assert_eq!(load.iter().filter(|f| **f != 0.0).count(), 1);
        assert!((load.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
