//! The regular Cartesian background grid.
//!
//! The grid is a box `[min, max]` cut into `cells[d]` equal cells per direction. Its
//! nodes are the degrees of freedom of the shape functions: for degree-1 families
//! (linear, GIMP, CPDI) they sit at the cell corners; for B-splines of degree `p`
//! with a clamped (open) knot vector there are `cells + p` control points per
//! direction, the first and last of which interpolate the faces, so conditions on a
//! face act on exactly one layer of nodes in every family.

use crate::dim::Vector;
use crate::scene::Face;

#[derive(Clone, Debug)]
pub struct Grid<const D: usize> {
    pub min: Vector<D>,
    pub max: Vector<D>,
    pub cells: [usize; D],
    /// Cell size per direction.
    pub h: Vector<D>,
    /// Polynomial degree of the shape functions (1, 2 or 3); sets the node layout.
    pub degree: usize,
    /// Nodes per direction: `cells + degree`.
    pub nodes: [usize; D],
}

impl<const D: usize> Grid<D> {
    pub fn new(min: Vector<D>, max: Vector<D>, cells: [usize; D], degree: usize) -> Self {
        let h = Vector::<D>::from_fn(|d, _| (max[d] - min[d]) / cells[d] as f64);
        let nodes = std::array::from_fn(|d| cells[d] + degree);
        Grid {
            min,
            max,
            cells,
            h,
            degree,
            nodes,
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.iter().product()
    }

    /// Flat node index from a multi-index (x fastest).
    pub fn node_index(&self, ijk: [usize; D]) -> usize {
        let mut idx = 0;
        for d in (0..D).rev() {
            idx = idx * self.nodes[d] + ijk[d];
        }
        idx
    }

    /// Multi-index of a flat node index.
    pub fn node_ijk(&self, mut idx: usize) -> [usize; D] {
        std::array::from_fn(|d| {
            let i = idx % self.nodes[d];
            idx /= self.nodes[d];
            i
        })
    }

    /// Position of a node: the cell corner for degree 1, the Greville abscissa of the
    /// control point for B-splines (the point it "belongs" to; Σ N_I x_I = x holds).
    pub fn node_position(&self, ijk: [usize; D]) -> Vector<D> {
        Vector::<D>::from_fn(|d, _| {
            self.min[d] + self.h[d] * greville(ijk[d], self.degree, self.cells[d])
        })
    }

    /// Is node `ijk` on `face`?
    pub fn on_face(&self, ijk: [usize; D], face: Face) -> bool {
        let i = ijk[face.axis];
        if face.upper {
            i == self.nodes[face.axis] - 1
        } else {
            i == 0
        }
    }

    /// Is `x` inside the closed grid box?
    pub fn contains(&self, x: &Vector<D>) -> bool {
        (0..D).all(|d| x[d] >= self.min[d] && x[d] <= self.max[d])
    }

    /// Smallest cell size (for the CFL condition).
    pub fn h_min(&self) -> f64 {
        self.h.min()
    }

    /// Is x in the outermost layer of cells of `face` (within one cell size of it)?
    pub fn in_outer_layer(&self, face: Face, x: &Vector<D>) -> bool {
        let a = face.axis;
        if face.upper {
            self.max[a] - x[a] < self.h[a]
        } else {
            x[a] - self.min[a] < self.h[a]
        }
    }

    pub fn cell_volume(&self) -> f64 {
        self.h.product()
    }
}

/// Greville abscissa, in cell units, of control point `i` of a clamped uniform
/// B-spline basis of degree `p` on `n` cells: the mean of knots i+1..=i+p.
pub fn greville(i: usize, p: usize, n: usize) -> f64 {
    if p == 1 {
        return i as f64;
    }
    let knot = |k: usize| (k as f64 - p as f64).clamp(0.0, n as f64);
    (1..=p).map(|k| knot(i + k)).sum::<f64>() / p as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn node_index_round_trip() {
        let g = Grid::<2>::new(Vector2::new(0.0, 0.0), Vector2::new(4.0, 2.0), [4, 2], 2);
        assert_eq!(g.nodes, [6, 4]);
        for idx in 0..g.node_count() {
            assert_eq!(g.node_index(g.node_ijk(idx)), idx);
        }
    }

    #[test]
    fn greville_ends_interpolate_the_faces() {
        for p in 1..=3 {
            assert_eq!(greville(0, p, 5), 0.0);
            assert_eq!(greville(5 + p - 1, p, 5), 5.0);
        }
        // Quadratic clamped on 5 cells: knots 0,0,0,1,2,3,4,5,5,5 -> 0, .5, 1.5, 2.5, 3.5, 4.5, 5
        let g: Vec<f64> = (0..7).map(|i| greville(i, 2, 5)).collect();
        assert_eq!(g, vec![0.0, 0.5, 1.5, 2.5, 3.5, 4.5, 5.0]);
    }
}
