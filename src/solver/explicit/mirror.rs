//! The mirror extension of B-splines at faces with prescribed velocities, for the
//! lumped-mass grid update of the explicit solver.
//!
//! A face with a prescribed velocity component v_w acts like a symmetry plane for
//! that component: the basis is extended across the face by ghost control points
//! c_−k = 2 v_w − c_k (odd about v_w), which is what image particles behind the
//! face would see. On the clamped knot vector this is the clamped space itself
//! for quadratic B-splines and the clamped space with u'' = 0 at the face for
//! cubic ones (the natural end condition, `solver::implicit::ties`). Along each
//! grid line normal to the face the first control points c₀ … c_{p−1} then carry
//! one unknown ṽ (the image problem's control point next to the face):
//!
//!   c_i = o_i ṽ + (1 − o_i) v_w,  o = (0, 1) for p = 2, (0, 1/3, 1) for p = 3.
//!
//! Its momentum and force are Σ o_i p_i and Σ o_i f_i (the odd combination
//! Σ o_i N_i of the clamped functions), and its lumped mass is that of the image
//! problem, Σ e_i m_i with the even combination e = (1, 1) for p = 2 and
//! (1/3, 1/3, 1) for p = 3 (the clamped expansion of N_k(y) + N_k(−y) of the uniform
//! functions). With the clamped masses alone the mass-weighted average of a
//! linear velocity field is wrong at the second control point (the centroid of its
//! function, 3/4 of a cell for p = 2, is not its Greville abscissa, 1/2), and the
//! MUSL/USF strain rate of the first particles is off by O(1) (docs/accuracy.md);
//! with the image mass the average reproduces linear fields next to the face.

use crate::dim::Vector;
use crate::model::conditions::FaceCondition;
use crate::model::grid::Grid;
use crate::physics::transfer::NodeMap;
use crate::scene::Face;
use std::collections::HashMap;

/// Odd coefficients o_i (momentum, force, unfolding) per degree 2 and 3.
const ODD: [[f64; 3]; 2] = [[0.0, 1.0, 0.0], [0.0, 1.0 / 3.0, 1.0]];
/// Even coefficients e_i (the image problem's lumped mass) per degree 2 and 3.
const EVEN: [[f64; 3]; 2] = [[1.0, 1.0, 0.0], [1.0 / 3.0, 1.0 / 3.0, 1.0]];

/// One grid line normal to a face, for one prescribed component.
#[derive(Clone, Debug)]
struct Line {
    /// Active indices of the first `layers` nodes from the face.
    nodes: [usize; 3],
    component: usize,
    wall: f64,
}

/// The mirrored lines of one step (empty for degree-1 shape functions).
#[derive(Clone, Debug, Default)]
pub struct Mirror {
    lines: Vec<Line>,
    degree: usize,
}

impl Mirror {
    /// The lines of every face condition's prescribed components, for B-spline
    /// grids (degree 2 or 3) along axes of at least `degree` cells. A node
    /// component that two lines would fold (a corner) is left to neither.
    pub fn build<const D: usize>(
        grid: &Grid<D>,
        faces: &[FaceCondition<D>],
        map: &NodeMap,
    ) -> Self {
        let p = grid.degree;
        if !(2..=3).contains(&p) {
            return Mirror::default();
        }
        let mut lines: Vec<Line> = Vec::new();
        let mut seen: HashMap<(usize, usize), usize> = HashMap::new();
        for fc in faces {
            let axis = fc.face.axis;
            if grid.cells[axis] < p {
                continue;
            }
            // Split nodes (contact) are left out: a line needs one field's nodes.
            for a in (0..map.len()).filter(|&a| !map.is_split(a)) {
                let ijk = grid.node_ijk(map.active[a] as usize);
                if !fc.acts_on(grid, ijk) {
                    continue;
                }
                let Some(nodes) = line_nodes(grid, map, ijk, fc.face, p) else {
                    continue;
                };
                for d in (0..D).filter(|&d| fc.constraint.fixed[d]) {
                    if seen.insert((nodes[0], d), lines.len()).is_none() {
                        lines.push(Line {
                            nodes,
                            component: d,
                            wall: fc.constraint.value[d],
                        });
                    }
                }
            }
        }
        // Node components folded by more than one line: drop those lines.
        let mut claims: HashMap<(usize, usize), usize> = HashMap::new();
        for l in &lines {
            for &n in &l.nodes[1..p] {
                *claims.entry((n, l.component)).or_default() += 1;
            }
        }
        lines.retain(|l| {
            l.nodes[1..p]
                .iter()
                .all(|&n| claims[&(n, l.component)] == 1)
        });
        Mirror { lines, degree: p }
    }

    fn odd(&self) -> &[f64] {
        &ODD[self.degree - 2][..self.degree]
    }

    fn even(&self) -> &[f64] {
        &EVEN[self.degree - 2][..self.degree]
    }

    /// Σ c_i x_i over a line's nodes, component d.
    fn fold<const D: usize>(c: &[f64], l: &Line, x: &[Vector<D>]) -> f64 {
        c.iter()
            .zip(&l.nodes)
            .map(|(c, &n)| c * x[n][l.component])
            .sum()
    }

    /// The image problem's lumped mass of a line's unknown, Σ e_i m_i.
    fn image_mass(&self, l: &Line, mass: &[f64]) -> f64 {
        self.even()
            .iter()
            .zip(&l.nodes)
            .map(|(e, &n)| e * mass[n])
            .sum()
    }

    /// Mass-weighted nodal velocities of the mirrored lines from the nodal masses
    /// and momenta: ṽ = v_w + (Σ o_i p_i − v_w Σ o_i m_i) / Σ e_i m_i, then
    /// c_i = o_i ṽ + (1 − o_i) v_w (module docs). Other nodes are left alone.
    pub fn velocity<const D: usize>(
        &self,
        mass: &[f64],
        momentum: &[Vector<D>],
        v: &mut [Vector<D>],
    ) {
        for l in &self.lines {
            let m_odd: f64 = self
                .odd()
                .iter()
                .zip(&l.nodes)
                .map(|(o, &n)| o * mass[n])
                .sum();
            let m_image = self.image_mass(l, mass);
            if m_image <= 0.0 {
                continue;
            }
            let v_line = l.wall + (Self::fold(self.odd(), l, momentum) - l.wall * m_odd) / m_image;
            for (o, &n) in self.odd().iter().zip(&l.nodes) {
                v[n][l.component] = o * v_line + (1.0 - o) * l.wall;
            }
        }
    }

    /// Nodal accelerations of the mirrored lines: ã = damped(Σ o_i f_i, ṽ) / Σ e_i m_i
    /// and a_i = o_i ã; `damped(f, v)` is the solver's damping law and ṽ the
    /// line's unknown (its last node's velocity).
    pub fn acceleration<const D: usize>(
        &self,
        mass: &[f64],
        force: &[Vector<D>],
        velocity: &[Vector<D>],
        damped: impl Fn(f64, f64) -> f64,
        accel: &mut [Vector<D>],
    ) {
        for l in &self.lines {
            let m_image = self.image_mass(l, mass);
            if m_image <= 0.0 {
                continue;
            }
            let last = l.nodes[self.degree - 1];
            let a_line = damped(
                Self::fold(self.odd(), l, force),
                velocity[last][l.component],
            ) / m_image;
            for (o, &n) in self.odd().iter().zip(&l.nodes) {
                accel[n][l.component] = o * a_line;
            }
        }
    }
}

/// Active indices of the first `layers` nodes along the face normal from the face
/// node ijk, if all are active.
fn line_nodes<const D: usize>(
    grid: &Grid<D>,
    map: &NodeMap,
    ijk: [usize; D],
    face: Face,
    layers: usize,
) -> Option<[usize; 3]> {
    let mut nodes = [usize::MAX; 3];
    for (k, slot) in nodes.iter_mut().enumerate().take(layers) {
        let mut n = ijk;
        n[face.axis] = if face.upper {
            ijk[face.axis] - k
        } else {
            ijk[face.axis] + k
        };
        match map.local[grid.node_index(n)] {
            NodeMap::NONE => return None,
            a => *slot = a as usize,
        }
    }
    Some(nodes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nodal masses and momenta of a continuum of unit density moving with v = a y
    /// over y ≥ 0 (cell units): m_i = ∫ N_i, p_i = a ∫ y N_i of the clamped
    /// functions next to the face. The mirrored average gives the Greville values
    /// a X_i (X = 0, 1/2 for p = 2; 0, 1/3, 1 for p = 3); the clamped average does not.
    #[test]
    fn image_mass_reproduces_linear_velocity() {
        let a = 0.7;
        // (degree, ∫ N_i, ∫ y N_i, Greville abscissae X_i) of the first p functions.
        type Case<'a> = (usize, &'a [f64], &'a [f64], &'a [f64]);
        let cases: [Case; 2] = [
            (2, &[1.0 / 3.0, 2.0 / 3.0], &[1.0 / 12.0, 0.5], &[0.0, 0.5]),
            (
                3,
                &[0.25, 0.5, 0.75],
                &[0.05, 0.3, 0.9],
                &[0.0, 1.0 / 3.0, 1.0],
            ),
        ];
        for (p, mass, moment, greville) in cases {
            let mirror = Mirror {
                lines: vec![Line {
                    nodes: [0, 1, 2],
                    component: 0,
                    wall: 0.0,
                }],
                degree: p,
            };
            let momentum: Vec<Vector<1>> = moment.iter().map(|m| Vector::<1>::new(a * m)).collect();
            let mut mass = mass.to_vec();
            mass.resize(3, 1.0);
            let mut momentum = momentum;
            momentum.resize(3, Vector::<1>::zeros());
            let clamped: Vec<f64> = (0..p).map(|i| momentum[i][0] / mass[i]).collect();
            let mut v = vec![Vector::<1>::new(f64::NAN); 3];
            mirror.velocity(&mass, &momentum, &mut v);
            for i in 0..p {
                assert!(
                    (v[i][0] - a * greville[i]).abs() < 1e-14,
                    "p {p} node {i}: {}",
                    v[i][0]
                );
            }
            assert!(
                (clamped[1] - a * greville[1]).abs() > 0.1 * a,
                "p {p}: clamped {clamped:?}"
            );
        }
    }

    /// A uniform velocity equal to the wall's is kept (constants are reproduced
    /// with a moving wall), and the acceleration unfolds with the odd coefficients.
    #[test]
    fn uniform_motion_with_the_wall_is_kept() {
        let mirror = Mirror {
            lines: vec![Line {
                nodes: [0, 1, 2],
                component: 0,
                wall: 2.5,
            }],
            degree: 3,
        };
        let mass = [0.25, 0.5, 0.75];
        let momentum: Vec<Vector<1>> = mass.iter().map(|m| Vector::<1>::new(2.5 * m)).collect();
        let mut v = vec![Vector::<1>::zeros(); 3];
        mirror.velocity(&mass, &momentum, &mut v);
        assert!(v.iter().all(|v| (v[0] - 2.5).abs() < 1e-14), "{v:?}");
        let force = [
            Vector::<1>::new(9.0),
            Vector::<1>::new(3.0),
            Vector::<1>::new(1.0),
        ];
        let mut accel = vec![Vector::<1>::zeros(); 3];
        mirror.acceleration(&mass, &force, &v, |f, _| f, &mut accel);
        // ã = (3/3 + 1) / (0.25/3 + 0.5/3 + 0.75) = 2; a = (0, ã/3, ã).
        assert!((accel[2][0] - 2.0).abs() < 1e-14 && (accel[1][0] - 2.0 / 3.0).abs() < 1e-14);
        assert_eq!(accel[0][0], 0.0);
    }
}
