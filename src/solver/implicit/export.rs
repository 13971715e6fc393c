//! The linear systems K δu = −r of Newton iterations (2-38) as Matrix Market
//! files, for users who benchmark their own linear solvers on the code's
//! tangents (`[output] linear_systems`). Per system, in `linear_systems/`:
//! `stepSSSSSS_cutC_iterII.mtx` (the tangent over the free unknowns: its lower
//! triangle, `symmetric`, when K is symmetric, else `general`) and
//! `…_rhs.mtx` (−r); per step and cut-back attempt, `stepSSSSSS_cutC_unknowns.csv`:
//! each unknown's grid node, component and node coordinates (for near-null
//! spaces such as the rigid-body modes of smoothed-aggregation multigrid). The
//! components are those of the step's unknowns (`Dofs::per_node`): 0..D the
//! displacements, then any scalar fields.

use super::assembly::Tangent;
use super::failure::Failure;
use super::step::StepSystem;
use crate::model::Model;
use crate::output::csv_file::{CsvWriter, Field};
use crate::output::matrix_market::{write_sparse, write_vector};
use crate::scene::LinearSystems;
use std::path::PathBuf;

/// Where the systems go and which iterations write one.
#[derive(Clone, Debug)]
pub struct Export {
    pub dir: PathBuf,
    pub which: LinearSystems,
}

/// The Newton iteration a system belongs to (`step` counted from 1, as in
/// newton.csv).
#[derive(Clone, Copy, Debug)]
pub struct Iterate {
    pub step: usize,
    pub cutback: usize,
    pub iteration: usize,
}

impl Export {
    /// Whether iteration `iteration` (0-based) of a step writes its system.
    pub fn wants(&self, iteration: usize) -> bool {
        match self.which {
            LinearSystems::None => false,
            LinearSystems::First => iteration == 0,
            LinearSystems::All => true,
        }
    }

    /// Writes K and the right-hand side of `at`, and at its first iteration the
    /// unknowns' table.
    pub fn write<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &StepSystem<D>,
        k: &Tangent,
        rhs: &[f64],
        at: Iterate,
    ) -> Result<(), Failure> {
        let attempt = format!("step{:06}_cut{}", at.step, at.cutback);
        let stem = format!("{attempt}_iter{:02}", at.iteration);
        let failed = |e: std::io::Error| Failure {
            particle: None,
            message: format!(
                "cannot write the linear system {stem} to {}: {e}",
                self.dir.display()
            ),
        };
        write_sparse(
            &self.dir.join(format!("{stem}.mtx")),
            k.matrix(),
            k.symmetric(),
        )
        .map_err(failed)?;
        write_vector(&self.dir.join(format!("{stem}_rhs.mtx")), rhs).map_err(failed)?;
        if at.iteration == 0 {
            self.write_unknowns(m, sys, &format!("{attempt}_unknowns.csv"))
                .map_err(failed)?;
        }
        Ok(())
    }

    /// unknown, node (global grid id), component (`Dofs`: the displacements
    /// first), x, y(, z) of every unknown.
    fn write_unknowns<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &StepSystem<D>,
        name: &str,
    ) -> std::io::Result<()> {
        let axes = ["x", "y", "z"];
        let mut header = vec!["unknown", "node", "component"];
        header.extend(&axes[..D]);
        let mut csv = CsvWriter::create(&self.dir.join(name), &header)?;
        let mut rows: Vec<(usize, u32, usize)> = Vec::with_capacity(sys.dofs.free);
        for a in 0..sys.map.len() {
            let node = sys.map.grid_node(a) as u32;
            for c in 0..sys.dofs.per_node() {
                if let Some(i) = sys.dofs.of(a, c) {
                    rows.push((i, node, c));
                }
            }
        }
        rows.sort_unstable();
        for (i, node, d) in rows {
            let x = m.grid.node_position(m.grid.node_ijk(node as usize));
            let mut fields: Vec<Field> = vec![i.into(), node.into(), d.into()];
            fields.extend(x.iter().map(|&c| Field::from(c)));
            csv.row(fields)?;
        }
        csv.flush()
    }
}
