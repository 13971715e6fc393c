//! Where the pore water of coupled materials (`drainage = "coupled"`,
//! `material::undrained`) may leave the body: the drained faces of the grid,
//! and the largest diffusivity that bounds the explicit step. None in a scene
//! without a coupled material, which then computes no flow
//! (`physics::pore_flow` does the flow; docs/pore_water.md).

use crate::material::Material;
use crate::model::conditions::FaceCondition;
use crate::model::grid::Grid;

/// The flow's conditions and its stable-step data.
#[derive(Clone, Debug)]
pub struct Drainage<const D: usize> {
    /// Faces (`[[boundary]] condition = "drained"`, optionally within a
    /// region) whose nodes hold the excess pore pressure at its value (0
    /// unless `pore_pressure` is given); every other boundary of the saturated
    /// particles is impermeable (no flux).
    pub drained: Vec<(FaceCondition<D>, f64)>,
    /// max over the coupled materials of c_f = K_f k/γ_w, the diffusivity of
    /// the excess pore pressure at a fixed skeleton (m²/s).
    pub diffusivity: f64,
}

impl<const D: usize> Drainage<D> {
    /// The drainage of `materials` with the drained faces `drained`; None when
    /// no material lets its water flow.
    pub fn new(
        materials: &[Box<dyn Material>],
        drained: Vec<(FaceCondition<D>, f64)>,
    ) -> Option<Self> {
        let diffusivity = (materials.iter())
            .filter_map(|m| m.pore_fluid())
            .map(|f| f.bulk_modulus * f.mobility)
            .fold(0.0, f64::max);
        (diffusivity > 0.0).then_some(Drainage {
            drained,
            diffusivity,
        })
    }

    /// The pressure grid node `ijk` holds, if it is drained (on a node of two
    /// drained faces, the first listed).
    pub fn drains(&self, grid: &Grid<D>, ijk: [usize; D]) -> Option<f64> {
        (self.drained.iter())
            .find(|(f, _)| f.acts_on(grid, ijk))
            .map(|&(_, p)| p)
    }

    /// The explicit flow's stable step h²/(2 D c_f) (forward Euler of the
    /// lumped diffusion: the largest eigenvalue of the grid Laplacian over the
    /// lumped storage is at most 4 D c_f/h², h the smallest cell size). The
    /// particles' pressure reaches the gradient through its projection, which
    /// smooths the highest modes: the Terzaghi column (one cell wide, linear
    /// shapes, 2 × 2 particles per cell) runs at 5 × this step and diverges at
    /// 6 × (tests/verification/consolidation.rs), so the bound is used as it
    /// is, without the CFL factor.
    pub fn stable_dt(&self, grid: &Grid<D>) -> f64 {
        let h = grid.h_min();
        h * h / (2.0 * D as f64 * self.diffusivity)
    }
}
