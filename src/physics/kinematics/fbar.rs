//! F-bar against volumetric locking (Coombs, Charlton, Cortis & Augarde 2018,
//! "Overcoming volumetric locking in material point methods", CMAME 333).
//!
//! Linear interpolation with several particles per cell cannot represent an
//! isochoric flow field (plastic flow with ψ = 0, nearly incompressible
//! elasticity) without spurious volume changes at the particles: the
//! discretisation locks. F-bar relaxes the constraint to one per background cell:
//! each particle's incremental volume change is replaced by the average over the
//! particles whose centre lies in its cell,
//!
//!   ΔF̄_p = (ΔJ̄_c / ΔJ_p)^{1/n} ΔF_p,  ΔJ̄_c = Σ_{q∈c} V_q ΔJ_q / Σ_{q∈c} V_q,
//!
//! with V_q the step-start volumes and n = D (plane strain: the in-plane block is
//! scaled, ΔF_zz = 1 stays, so det ΔF̄_p = ΔJ̄_c), or n = 3 in axisymmetric mode
//! (ΔF_θθ, the hoop stretch, is scaled with the r–z block; the volumes are per
//! radian, so the average is over the cell's ring). The particle then follows ΔF̄
//! throughout: stress σ(ΔF̄), F ← ΔF̄ F, V = det F V₀, and the implicit internal
//! force uses the relative first Piola-Kirchhoff stress P̄ = det ΔF̄ σ ΔF̄⁻ᵀ. Cells
//! are those of the particles' step-start positions.

use crate::dim::{Mat3, Vector};
use crate::model::grid::Grid;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::linear::{cell_coordinate, cell_index};
use rayon::prelude::*;

/// The occupied background cells and their particles.
#[derive(Clone, Debug, Default)]
pub struct Cells {
    /// Occupied cell (0..len) of each particle.
    pub of: Vec<u32>,
    /// CSR offsets into `members`, one range per occupied cell.
    start: Vec<u32>,
    /// Particles of each cell, in increasing order.
    members: Vec<u32>,
}

impl Cells {
    /// Group the particles by the grid cell containing their centre (a point on
    /// a cell face belongs to the cell above it, one on the max face of the grid
    /// to the last cell).
    pub fn locate<const D: usize>(grid: &Grid<D>, x: &[Vector<D>]) -> Cells {
        let cell = |x: &Vector<D>| {
            (0..D).rev().fold(0usize, |acc, d| {
                acc * grid.cells[d] + cell_index(cell_coordinate(grid, x, d), grid.cells[d])
            })
        };
        let mut pairs: Vec<(usize, u32)> = x
            .par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .enumerate()
            .map(|(q, x)| (cell(x), q as u32))
            .collect();
        pairs.par_sort_unstable();
        let mut cells = Cells {
            of: vec![0; x.len()],
            start: vec![0],
            members: Vec::with_capacity(x.len()),
        };
        for (k, &(c, q)) in pairs.iter().enumerate() {
            if k > 0 && c != pairs[k - 1].0 {
                cells.start.push(k as u32);
            }
            cells.of[q as usize] = cells.start.len() as u32 - 1;
            cells.members.push(q);
        }
        cells.start.push(pairs.len() as u32);
        cells
    }

    /// Number of occupied cells.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The particles of occupied cell c, in increasing order.
    pub fn members(&self, c: usize) -> &[u32] {
        &self.members[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// ΔJ̄_c = Σ V_q ΔJ_q / Σ V_q of every occupied cell, each sum taken in
    /// increasing particle order (the same for any number of threads).
    pub fn mean_dilatation(&self, volume: &[f64], dj: &[f64]) -> Vec<f64> {
        (0..self.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN / 4)
            .map(|c| {
                let (mut v, mut vj) = (0.0, 0.0);
                for &q in self.members(c) {
                    v += volume[q as usize];
                    vj += volume[q as usize] * dj[q as usize];
                }
                vj / v
            })
            .collect()
    }
}

/// β = (ΔJ̄ / ΔJ)^{1/D}, the factor that gives ΔF_p the cell's volume change.
pub fn scale_factor<const D: usize>(dj_bar: f64, dj: f64) -> f64 {
    (dj_bar / dj).powf(1.0 / D as f64)
}

/// β ΔF on the D×D block (plane strain: ΔF_zz = 1 stays).
pub fn scaled<const D: usize>(df: &Mat3, beta: f64) -> Mat3 {
    let mut out = *df;
    for i in 0..D {
        for j in 0..D {
            out[(i, j)] *= beta;
        }
    }
    out
}

/// The F-bar state of a trial: ΔF_p before the modification and its determinant,
/// the cells and the cells' mean dilatation.
#[derive(Clone, Debug, Default)]
pub struct FBarState {
    pub cells: Cells,
    /// ΔF_p = I + Σ u_I ⊗ ∇S_Ip (before F-bar).
    pub df: Vec<Mat3>,
    /// ΔJ_p = det ΔF_p.
    pub dj: Vec<f64>,
    /// ΔJ̄_c of every occupied cell.
    pub dj_bar: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use crate::dim::{Mat3, Tensor, Vector};
    use crate::model::Model;
    use crate::physics::kinematics::deformation::Trial;
    use crate::physics::shape::Stencils;
    use crate::physics::transfer::NodeMap;
    use crate::scene::Scene;
    use strum::IntoEnumIterator;

    /// A Hencky block whose edges cut the cells anywhere, 4 × 4 particles per cell.
    const BLOCK: &str = r#"dimension = 2
[grid]
min = [0.0, 0.0]
max = [4.0, 4.0]
cells = [12, 12]
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.45
[[body]]
material = "m"
shape = "rectangle"
min = [0.31, 0.27]
max = [3.73, 3.58]
particles_per_cell = 4
[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 1
"#;

    /// A trial state with the ΔF of every particle.
    struct Evaluated {
        df: Vec<Mat3>,
        stress: Vec<Mat3>,
        volume: Vec<f64>,
        fbar: Option<super::FBarState>,
    }

    impl Evaluated {
        fn of(t: Trial<2>, st: &Stencils<2>, map: &NodeMap) -> Evaluated {
            Evaluated {
                df: (0..t.stress.len()).map(|q| t.df(st, map, q)).collect(),
                stress: t.stress.iter().collect(),
                volume: t.volume,
                fbar: t.fbar,
            }
        }
    }

    /// Trial states without and with F-bar under nodal displacements u(x).
    fn trials(shape: &str, u: impl Fn(&Vector<2>) -> Vector<2>) -> (Evaluated, Evaluated) {
        let overrides = vec![format!("grid.shape_function={shape}")];
        let scene = Scene::parse("block.toml", BLOCK, &overrides).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let p = &m.particles;
        let (mut st, mut map) = (Stencils::default(), NodeMap::default());
        crate::physics::transfer::stencils_and_nodes(
            &m,
            scene.config.grid.shape_function,
            &mut st,
            &mut map,
        );
        let nodal: Vec<Vector<2>> = map
            .active
            .iter()
            .map(|&g| u(&m.grid.node_position(m.grid.node_ijk(g as usize))))
            .collect();
        let (mut plain, mut fbar) = (Trial::default(), Trial::default());
        assert!(plain
            .evaluate(p, &m.materials, &st, &map, &nodal, 1.0)
            .is_none());
        fbar.use_fbar(&m.grid, &p.x);
        assert!(fbar
            .evaluate(p, &m.materials, &st, &map, &nodal, 1.0)
            .is_none());
        (
            Evaluated::of(plain, &st, &map),
            Evaluated::of(fbar, &st, &map),
        )
    }

    fn max_difference(a: &[Mat3], b: &[Mat3]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max)
    }

    /// Under a homogeneous deformation every particle has ΔJ_p = ΔJ̄_c, so F-bar
    /// changes nothing: ΔF, σ and V agree with the plain update to round-off, for
    /// every shape function (each reproduces linear fields).
    #[test]
    fn homogeneous_deformation_is_unchanged() {
        let a = Tensor::<2>::new(0.03, -0.02, 0.015, -0.04);
        for shape in crate::scene::ShapeFunction::iter().map(|s| s.name()) {
            let (plain, fbar) = trials(shape, |x| a * x + Vector::<2>::new(0.1, -0.2));
            let ddf = max_difference(&plain.df, &fbar.df);
            let scale = plain.stress.iter().map(|s| s.amax()).fold(0.0, f64::max);
            let dstress = max_difference(&plain.stress, &fbar.stress) / scale;
            let dvolume = plain
                .volume
                .iter()
                .zip(&fbar.volume)
                .map(|(x, y)| ((x - y) / x).abs())
                .fold(0.0, f64::max);
            println!("{shape}: |ΔF̄ − ΔF| = {ddf:.1e}, |σ̄ − σ|/|σ| = {dstress:.1e}, |V̄ − V|/V = {dvolume:.1e}");
            assert!(ddf < 1e-14 && dstress < 1e-12 && dvolume < 1e-14, "{shape}");
        }
    }

    /// Under a non-homogeneous deformation every particle of a cell takes the
    /// cell's volume-weighted mean dilatation (det ΔF̄_p = ΔJ̄_c), the deviatoric
    /// part of ΔF_p is kept (ΔF̄_p ∝ ΔF_p), and the result is bit-identical for 1
    /// and 2 threads.
    #[test]
    fn each_cell_takes_its_mean_dilatation_on_any_number_of_threads() {
        let u = |x: &Vector<2>| {
            Vector::<2>::new(
                0.02 * (1.3 * x[1]).sin() + 0.01 * x[0] * x[0],
                -0.03 * x[0] * x[1],
            )
        };
        for shape in crate::scene::ShapeFunction::iter().map(|s| s.name()) {
            let (plain, fbar) = trials(shape, u);
            let state = fbar.fbar.as_ref().unwrap();
            let cells = &state.cells;
            let mut worst_j: f64 = 0.0;
            let mut worst_shape: f64 = 0.0;
            let mut spread: f64 = 0.0;
            for c in 0..cells.len() {
                let members = cells.members(c);
                let (mut v, mut vj) = (0.0, 0.0);
                for &q in members {
                    let q = q as usize;
                    v += fbar.volume[q] / fbar.df[q].determinant();
                    vj += fbar.volume[q] / fbar.df[q].determinant() * plain.df[q].determinant();
                }
                for &q in members {
                    let q = q as usize;
                    worst_j = worst_j.max((fbar.df[q].determinant() - vj / v).abs());
                    let beta = fbar.df[q][(0, 0)] / plain.df[q][(0, 0)];
                    let mut expected = plain.df[q] * beta;
                    expected[(2, 2)] = 1.0;
                    worst_shape = worst_shape.max((fbar.df[q] - expected).amax());
                    spread = spread.max((plain.df[q].determinant() - vj / v).abs());
                }
            }
            println!(
                "{shape}: {} cells; |det ΔF̄ − ΔJ̄| = {worst_j:.1e} (spread of det ΔF in the cells {spread:.1e}), \
                 |ΔF̄ − βΔF| = {worst_shape:.1e}",
                cells.len()
            );
            assert!(spread > 1e-4, "{shape}: the field varies within the cells");
            assert!(worst_j < 1e-14 && worst_shape < 1e-14, "{shape}");
            let on = |threads| crate::parallel::on_threads(threads, || trials(shape, u).1);
            let (one, two) = (on(1), on(2));
            assert!(one.df.len() > 1024, "enough particles to run in parallel");
            assert_eq!(
                one.df, two.df,
                "{shape}: ΔF̄ differs between 1 and 2 threads"
            );
            assert_eq!(one.stress, two.stress);
        }
    }
}
