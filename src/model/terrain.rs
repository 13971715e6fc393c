//! A terrain body (`shape = "terrain"`, read by `model::import::esri_grid`):
//! the ground between a base elevation and a surface of elevations on a
//! regular plan grid (a raster), z up. The surface is bilinear between the
//! raster's points; the body's plan is the rectangle the points span.

/// Elevations on a regular grid of points in the x–y plane, and the base.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// The south-west (first) point's x and y.
    pub origin: [f64; 2],
    /// The spacing of the points along x and y.
    pub cell_size: f64,
    /// Points along x (columns) and y (rows), each at least 2.
    pub columns: usize,
    pub rows: usize,
    /// Elevation of point (column j, row i from the south) at i · columns + j.
    pub elevation: Vec<f64>,
    /// The body's bottom, below every elevation.
    pub base: f64,
}

impl Terrain {
    /// The plan's corners (min, max) in x and y.
    fn plan(&self) -> ([f64; 2], [f64; 2]) {
        let span = [self.columns - 1, self.rows - 1].map(|n| n as f64 * self.cell_size);
        let (o, s) = (self.origin, span);
        (o, [o[0] + s[0], o[1] + s[1]])
    }

    /// The interval k and the fraction t ∈ [0, 1] along it of coordinate x
    /// among n points from `start`.
    fn locate(&self, x: f64, start: f64, n: usize) -> (usize, f64) {
        let u = ((x - start) / self.cell_size).clamp(0.0, (n - 1) as f64);
        let k = (u.floor() as usize).min(n - 2);
        (k, u - k as f64)
    }

    /// The surface's elevation over (x, y), bilinear between the raster's
    /// points (the nearest edge's outside the plan).
    pub fn surface(&self, x: f64, y: f64) -> f64 {
        let (j, s) = self.locate(x, self.origin[0], self.columns);
        let (i, t) = self.locate(y, self.origin[1], self.rows);
        let z = |i: usize, j: usize| self.elevation[i * self.columns + j];
        let south = (1.0 - s) * z(i, j) + s * z(i, j + 1);
        let north = (1.0 - s) * z(i + 1, j) + s * z(i + 1, j + 1);
        (1.0 - t) * south + t * north
    }

    /// Is p strictly inside: over the plan, above the base, below the surface?
    pub fn contains(&self, p: &[f64]) -> bool {
        let (lo, hi) = self.plan();
        (0..2).all(|d| p[d] > lo[d] && p[d] < hi[d])
            && p[2] > self.base
            && p[2] < self.surface(p[0], p[1])
    }

    /// Height (along `up` × axis v) of the body's top on the line along axis
    /// v through x: the surface for z, the plan's edge across.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        let (lo, hi) = self.plan();
        match v {
            2 if up > 0.0 => self.surface(x[0], x[1]),
            2 => -self.base,
            _ => (up * lo[v]).max(up * hi[v]),
        }
    }

    /// The box (min, max) of the body.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let (lo, hi) = self.plan();
        let top = self
            .elevation
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        (vec![lo[0], lo[1], self.base], vec![hi[0], hi[1], top])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_is_its_own_bilinear_surface() {
        // z = 10 − 0.5 x + 0.25 y on 4 × 3 points 2 apart from (1, 0).
        let plane = |x: f64, y: f64| 10.0 - 0.5 * x + 0.25 * y;
        let (columns, rows) = (4, 3);
        let elevation = (0..rows)
            .flat_map(|i| (0..columns).map(move |j| plane(1.0 + 2.0 * j as f64, 2.0 * i as f64)))
            .collect();
        let t = Terrain {
            origin: [1.0, 0.0],
            cell_size: 2.0,
            columns,
            rows,
            elevation,
            base: 0.0,
        };
        for (x, y) in [(1.0, 0.0), (2.3, 1.1), (6.9, 3.99), (7.0, 4.0)] {
            assert!((t.surface(x, y) - plane(x, y)).abs() < 1e-14, "({x}, {y})");
        }
        assert_eq!(
            t.bounds(),
            (vec![1.0, 0.0, 0.0], vec![7.0, 4.0, plane(1.0, 4.0)])
        );
        assert!(t.contains(&[2.0, 2.0, 9.0]) && !t.contains(&[2.0, 2.0, 9.6]));
        assert!(!t.contains(&[0.5, 2.0, 1.0]) && !t.contains(&[2.0, 2.0, -0.1]));
        assert_eq!(t.top(&[2.0, 2.0, 1.0], 2, 1.0), plane(2.0, 2.0));
        assert_eq!(t.top(&[2.0, 2.0, 1.0], 0, -1.0), -1.0);
    }
}
