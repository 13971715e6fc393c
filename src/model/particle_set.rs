//! The particles of a body read from a particle file (`shape = "particles"`,
//! `model::import::particle_file`): each row's position and volume, and what it
//! may carry besides (a material zone, an initial stress and velocity). The
//! model puts them in as they are (`build.rs`); as a geometry the set has no
//! surface, only the box of its particles' domains.

use crate::dim::Mat3;

/// One row of a particle file.
#[derive(Clone, Debug, PartialEq)]
pub struct FileParticle {
    /// Position; the components past the dimension are zero.
    pub x: [f64; 3],
    /// Volume: area × unit thickness in 2D, per radian in an axisymmetric
    /// model (r × the r–z area), as `particles_final.csv` writes it.
    pub volume: f64,
    /// Index of its `[[material]]` table, where the row names one.
    pub material: Option<u32>,
    /// Initial Cauchy stress (tension positive), where the file gives one.
    pub stress: Option<Mat3>,
    /// Initial velocity, where the file gives one.
    pub velocity: Option<[f64; 3]>,
    /// The file's line of the row (1-based), for messages.
    pub line: u64,
}

/// The particles of one body read from a file, in the file's order.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleSet {
    /// The number of components of the positions.
    pub dim: usize,
    pub particles: Vec<FileParticle>,
    /// Whether the volumes are per radian (axisymmetric).
    pub per_radian: bool,
}

impl ParticleSet {
    /// Half-lengths of particle q's domain, a square (cube) of its volume
    /// (area in the r–z plane: V / r in an axisymmetric model).
    pub fn half_length(&self, q: usize) -> [f64; 3] {
        let p = &self.particles[q];
        let size = match self.per_radian {
            true => p.volume / p.x[0],
            false => p.volume,
        };
        let side = size.powf(1.0 / self.dim as f64);
        let mut h = [0.0; 3];
        h[..self.dim].fill(0.5 * side);
        h
    }

    /// The box (min, max) of the particles' domains.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![f64::INFINITY; self.dim];
        let mut hi = vec![f64::NEG_INFINITY; self.dim];
        for q in 0..self.particles.len() {
            let (x, h) = (self.particles[q].x, self.half_length(q));
            for d in 0..self.dim {
                lo[d] = lo[d].min(x[d] - h[d]);
                hi[d] = hi[d].max(x[d] + h[d]);
            }
        }
        (lo, hi)
    }

    /// Height (along `up` × axis v) of the highest domain top among the
    /// particles whose domain spans x across the vertical line; −∞ where none.
    pub fn top(&self, x: &[f64], v: usize, up: f64) -> f64 {
        let spans = |q: usize| {
            let (p, h) = (&self.particles[q].x, self.half_length(q));
            (0..self.dim).all(|d| d == v || (x[d] - p[d]).abs() <= h[d])
        };
        (0..self.particles.len())
            .filter(|&q| spans(q))
            .map(|q| up * self.particles[q].x[v] + self.half_length(q)[v])
            .fold(f64::NEG_INFINITY, f64::max)
    }
}
