//! A terrain body (`shape = "terrain"`, read by `model::import::esri_grid` or
//! `model::import::geotiff`): the ground between a bottom and a surface of
//! elevations on a regular plan grid (a raster), z up. The bottom is a level
//! (`base`) or a second raster (`base_file`): a layer of layered ground. The
//! surfaces are bilinear between their rasters' points; the body's plan is
//! the rectangle the surface raster's points span.

/// Elevations on a regular grid of points in the x–y plane.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// The south-west (first) point's x and y.
    pub origin: [f64; 2],
    /// The spacing of the points along x and y.
    pub cell_size: f64,
    /// Points along x (columns) and y (rows), each at least 2.
    pub columns: usize,
    pub rows: usize,
    /// Elevation of point (column j, row i from the south) at i · columns + j.
    pub elevation: Vec<f64>,
}

/// The bottom of a terrain body.
#[derive(Clone, Debug, PartialEq)]
pub enum Bottom {
    /// A level: the body holds the points strictly above it.
    Level(f64),
    /// A surface (the top of the layer below): the body holds the points on
    /// it and above, so that layers sharing a surface share no particle and
    /// lose none.
    Surface(Raster),
}

/// A terrain body: a surface raster over a bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    pub surface: Raster,
    pub bottom: Bottom,
}

impl Raster {
    /// The plan's corners (min, max) in x and y.
    pub fn plan(&self) -> ([f64; 2], [f64; 2]) {
        let span = [self.columns - 1, self.rows - 1].map(|n| n as f64 * self.cell_size);
        let (o, s) = (self.origin, span);
        (o, [o[0] + s[0], o[1] + s[1]])
    }

    /// The position (x, y) of point (row i from the south, column j).
    pub fn point(&self, i: usize, j: usize) -> [f64; 2] {
        let h = self.cell_size;
        [self.origin[0] + j as f64 * h, self.origin[1] + i as f64 * h]
    }

    /// The interval k and the fraction t ∈ [0, 1] along it of coordinate x
    /// among n points from `start`.
    fn locate(&self, x: f64, start: f64, n: usize) -> (usize, f64) {
        let u = ((x - start) / self.cell_size).clamp(0.0, (n - 1) as f64);
        let k = (u.floor() as usize).min(n - 2);
        (k, u - k as f64)
    }

    /// The elevation over (x, y), bilinear between the points (the nearest
    /// edge's outside the plan).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let (j, s) = self.locate(x, self.origin[0], self.columns);
        let (i, t) = self.locate(y, self.origin[1], self.rows);
        let z = |i: usize, j: usize| self.elevation[i * self.columns + j];
        let south = (1.0 - s) * z(i, j) + s * z(i, j + 1);
        let north = (1.0 - s) * z(i + 1, j) + s * z(i + 1, j + 1);
        (1.0 - t) * south + t * north
    }

    /// Every point's position and elevation, from the south-west.
    pub fn points(&self) -> impl Iterator<Item = ([f64; 2], f64)> + '_ {
        (0..self.rows)
            .flat_map(move |i| (0..self.columns).map(move |j| (i, j)))
            .map(|(i, j)| (self.point(i, j), self.elevation[i * self.columns + j]))
    }

    /// Does (x, y) lie over the plan, its edges included?
    pub fn over_plan(&self, [x, y]: [f64; 2]) -> bool {
        let (lo, hi) = self.plan();
        x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1]
    }

    /// The first point not over `bottom` (`Bottom::refuses`), in the file's
    /// order: its row from the north, its column (both from 0) and the
    /// message naming its elevation and place.
    pub fn first_below(&self, bottom: &Bottom) -> Option<(usize, usize, String)> {
        let (row, column, m) = self.first_refused(|x, y, z| bottom.refuses(x, y, z))?;
        let z = self.elevation[(self.rows - 1 - row) * self.columns + column];
        let m = format!(
            "the elevation {z} at row {}, column {} {m}",
            row + 1,
            column + 1
        );
        Some((row, column, m))
    }

    /// The first point, in the file's order (the northernmost row first),
    /// for which `refuse(x, y, z)` gives a reason: its row from the north,
    /// its column (both from 0) and the reason.
    pub fn first_refused(
        &self,
        refuse: impl Fn(f64, f64, f64) -> Option<String>,
    ) -> Option<(usize, usize, String)> {
        (0..self.rows).rev().find_map(|i| {
            (0..self.columns).find_map(|j| {
                let [x, y] = self.point(i, j);
                let z = self.elevation[i * self.columns + j];
                refuse(x, y, z).map(|m| (self.rows - 1 - i, j, m))
            })
        })
    }
}

impl Bottom {
    /// The bottom's elevation over (x, y).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        match self {
            Bottom::Level(z) => *z,
            Bottom::Surface(r) => r.at(x, y),
        }
    }

    /// Why a surface elevation z at (x, y) does not lie over this bottom, if
    /// it does not: above a level, on or above a surface (a layer may pinch
    /// out).
    pub fn refuses(&self, x: f64, y: f64, z: f64) -> Option<String> {
        match self {
            Bottom::Level(base) if z <= *base => {
                Some(format!("is not above the body's base {base}"))
            }
            Bottom::Surface(r) => {
                let below = r.at(x, y);
                (z < below).then(|| {
                    format!("is below the body's base surface (`base_file`), {below} there")
                })
            }
            Bottom::Level(_) => None,
        }
    }
}

impl Terrain {
    /// Is p inside: over the plan, above the bottom (or on a bottom
    /// surface), strictly below the surface?
    pub fn contains(&self, p: &[f64]) -> bool {
        let (lo, hi) = self.surface.plan();
        let bottom = self.bottom.at(p[0], p[1]);
        let above = match self.bottom {
            Bottom::Level(_) => p[2] > bottom,
            Bottom::Surface(_) => p[2] >= bottom,
        };
        (0..2).all(|d| p[d] > lo[d] && p[d] < hi[d]) && above && p[2] < self.surface.at(p[0], p[1])
    }

    /// Height (along `up` × axis v) of the body's top on the line along axis
    /// v through x: the surface for z, the plan's edge across.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        let (lo, hi) = self.surface.plan();
        match v {
            2 if up > 0.0 => self.surface.at(x[0], x[1]),
            2 => -self.bottom.at(x[0], x[1]),
            _ => (up * lo[v]).max(up * hi[v]),
        }
    }

    /// The box (min, max) of the body: the bottom's lowest point over the
    /// plan is at one of its raster's points in the plan or at the plan's
    /// edge, where the surface raster's points are.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let (lo, hi) = self.surface.plan();
        let high = (self.surface.elevation.iter()).fold(f64::NEG_INFINITY, |m, &z| m.max(z));
        let low = match &self.bottom {
            Bottom::Level(z) => *z,
            Bottom::Surface(r) => {
                let under_surface = self.surface.points().map(|([x, y], _)| r.at(x, y));
                let own = r.points().filter(|&(p, _)| self.surface.over_plan(p));
                (under_surface.chain(own.map(|(_, z)| z))).fold(f64::INFINITY, f64::min)
            }
        };
        (vec![lo[0], lo[1], low], vec![hi[0], hi[1], high])
    }

    /// The first point of a bottom surface's raster within the plan that lies
    /// above the surface: its row from the north, its column (from 0) and
    /// what is wrong; `None` for a level bottom.
    pub fn bottom_above_surface(&self) -> Option<(usize, usize, String)> {
        let Bottom::Surface(r) = &self.bottom else {
            return None;
        };
        r.first_refused(|x, y, z| {
            let top = self.surface.at(x, y);
            (self.surface.over_plan([x, y]) && z > top)
                .then(|| format!("is above the body's surface, {top} there"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The raster of z = f(x, y) on `columns` × `rows` points `h` apart from
    /// `origin`.
    fn raster(
        f: impl Fn(f64, f64) -> f64,
        origin: [f64; 2],
        h: f64,
        (columns, rows): (usize, usize),
    ) -> Raster {
        let elevation = (0..rows)
            .flat_map(|i| (0..columns).map(move |j| (i, j)))
            .map(|(i, j)| f(origin[0] + h * j as f64, origin[1] + h * i as f64))
            .collect();
        Raster {
            origin,
            cell_size: h,
            columns,
            rows,
            elevation,
        }
    }

    #[test]
    fn a_plane_is_its_own_bilinear_surface() {
        // z = 10 − 0.5 x + 0.25 y on 4 × 3 points 2 apart from (1, 0).
        let plane = |x: f64, y: f64| 10.0 - 0.5 * x + 0.25 * y;
        let t = Terrain {
            surface: raster(plane, [1.0, 0.0], 2.0, (4, 3)),
            bottom: Bottom::Level(0.0),
        };
        for (x, y) in [(1.0, 0.0), (2.3, 1.1), (6.9, 3.99), (7.0, 4.0)] {
            assert!(
                (t.surface.at(x, y) - plane(x, y)).abs() < 1e-14,
                "({x}, {y})"
            );
        }
        assert_eq!(
            t.bounds(),
            (vec![1.0, 0.0, 0.0], vec![7.0, 4.0, plane(1.0, 4.0)])
        );
        assert!(t.contains(&[2.0, 2.0, 9.0]) && !t.contains(&[2.0, 2.0, 9.6]));
        assert!(!t.contains(&[0.5, 2.0, 1.0]) && !t.contains(&[2.0, 2.0, -0.1]));
        assert!(!t.contains(&[2.0, 2.0, 0.0]), "a level bottom is outside");
        assert_eq!(t.top(&[2.0, 2.0, 1.0], 2, 1.0), plane(2.0, 2.0));
        assert_eq!(t.top(&[2.0, 2.0, 1.0], 0, -1.0), -1.0);
        assert_eq!(t.top(&[2.0, 2.0, 1.0], 2, -1.0), 0.0);
    }

    #[test]
    fn layers_on_a_shared_surface_hold_every_point_once() {
        // Ground z = 8 − 0.5 x; an interface z = 4 − 0.25 x + 0.1 y on a
        // coarser raster that reaches beyond the plan; a level base at 0.
        let ground = raster(|x, _| 8.0 - 0.5 * x, [0.0, 0.0], 1.0, (9, 4));
        let interface = raster(|x, y| 4.0 - 0.25 * x + 0.1 * y, [-2.0, -2.0], 2.0, (7, 5));
        let upper = Terrain {
            surface: ground,
            bottom: Bottom::Surface(interface.clone()),
        };
        let lower = Terrain {
            surface: interface.clone(),
            bottom: Bottom::Level(0.0),
        };
        // Points on the interface itself (z exactly its bilinear value), in it
        // and off it: each in exactly one layer.
        for (x, y) in [(0.5, 0.5), (3.25, 1.75), (6.0, 2.5), (7.9, 0.1)] {
            let z_i = interface.at(x, y);
            for z in [
                0.25,
                z_i - 1e-9,
                z_i,
                z_i + 1e-9,
                0.5 * (z_i + 8.0 - 0.5 * x),
            ] {
                let (a, b) = (upper.contains(&[x, y, z]), lower.contains(&[x, y, z]));
                assert!(a != b, "({x}, {y}, {z}): upper {a}, lower {b}");
            }
        }
        // The upper layer's bottom over the plan: the interface at x = 8, y = 0.
        assert_eq!(upper.bounds().0, vec![0.0, 0.0, 2.0]);
        assert!((upper.top(&[4.0, 1.0, 5.0], 2, -1.0) + 3.1).abs() < 1e-14);
        assert!(upper.bottom_above_surface().is_none());
        // An interface that rises above the ground at x = 8 (2 + 5 > 4).
        let crossing = Terrain {
            surface: upper.surface.clone(),
            bottom: Bottom::Surface(raster(|x, _| x - 1.0, [-2.0, -2.0], 2.0, (7, 5))),
        };
        let (row, column, m) = crossing.bottom_above_surface().unwrap();
        assert_eq!((row, column), (2, 5), "{m}");
        assert!(m.contains("is above the body's surface, 4 there"), "{m}");
    }

    #[test]
    fn a_bottom_refuses_a_surface_below_it() {
        let level = Bottom::Level(1.0);
        assert!(level.refuses(0.0, 0.0, 1.0).is_some() && level.refuses(0.0, 0.0, 1.5).is_none());
        let surface = Bottom::Surface(raster(|x, _| x, [0.0, 0.0], 1.0, (3, 2)));
        // On the surface (a pinched-out layer) is allowed, below it is not.
        assert!(surface.refuses(1.0, 0.5, 1.0).is_none());
        let m = surface.refuses(1.0, 0.5, 0.5).unwrap();
        assert!(
            m.contains("below the body's base surface (`base_file`), 1 there"),
            "{m}"
        );
    }
}
