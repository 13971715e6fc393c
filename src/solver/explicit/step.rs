//! The explicit step, written once: central differences in time (thesis 2-29,
//! 2-30) with the USF, USL or MUSL ordering of the stress update (§2.2.1), over a
//! transfer back-end that moves the values between particles and nodes.
//!
//! A back-end (`Backend`) does the passes; the rules they apply at a node or a
//! particle are shared: the grid update (`solver::explicit::grid_update`), the
//! particles' motion and the work of the loads (`solver::explicit::motion`),
//! the applied forces (`Step::applied`). Two back-ends exist:
//! - the node map (`solver::explicit::gather`): stored stencils and node-side
//!   gathers through `physics::transfer::NodeMap`, which every feature can use;
//! - the box scatter (`solver::explicit::scatter`): particle-side scatters on a
//!   box of nodes (`solver::explicit::node_box`), without a node map or stored
//!   stencils, fusing the passes where the scheme allows.
//!
//! Which one a step takes follows from what its features declare
//! (`solver::explicit::features`).

use crate::dim::Vector;
use crate::model::load_factor;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::ShapeFunction;
use crate::physics::transfer::applied_to;
use crate::scene::Scheme;
use crate::solver::divergence::Divergence;
use crate::solver::explicit::bulk_viscosity::BulkViscosity;
use crate::solver::explicit::grid_update::TINY_MASS_FRACTION;
use rayon::prelude::*;

/// What one explicit step reads besides the model: the solver's settings, the
/// loads at the step's start, and the step's time.
#[derive(Clone, Debug)]
pub struct Step<const D: usize> {
    pub shape: ShapeFunction,
    pub scheme: Scheme,
    /// The FLIP fraction of the PIC/FLIP blend (0 with APIC).
    pub flip: f64,
    /// APIC (`solver::explicit::apic`) instead of the PIC/FLIP blend.
    pub apic: bool,
    /// Local damping α (`grid_update::local_damping`).
    pub damping: f64,
    /// F-bar against volumetric locking (`physics::kinematics::fbar`).
    pub fbar: bool,
    /// Artificial bulk viscosity (`solver::explicit::bulk_viscosity`), if asked for.
    pub viscosity: Option<BulkViscosity>,
    /// Gravity at this step (ramped, `Explicit::gravity_ramp`).
    pub gravity: Vector<D>,
    /// The load factor of each load time history at t (`Model::load_scales`).
    pub scales: Vec<f64>,
    /// Nodes not heavier than this get no acceleration (`TINY_MASS_FRACTION`
    /// of the lightest particle).
    pub tiny: f64,
    pub t: f64,
    pub dt: f64,
    /// The run's step number (a divergence reports step + 1).
    pub step: usize,
}

impl<const D: usize> Step<D> {
    /// The lightest-node threshold of model m (`TINY_MASS_FRACTION`).
    pub fn tiny_mass(m: &Model<D>) -> f64 {
        let lightest = m
            .particles
            .mass
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min);
        TINY_MASS_FRACTION * lightest
    }

    /// The force applied to particle q: m_q g + s_q f_q (2-52), from the
    /// particles' masses and loads and the load histories `ramp_of`.
    #[inline(always)]
    pub fn applied(
        &self,
        ramp_of: &[u32],
        mass: &[f64],
        load: &[Vector<D>],
        q: usize,
    ) -> Vector<D> {
        applied_to(&self.gravity, mass[q], load, q, || {
            load_factor(ramp_of, q, &self.scales)
        })
    }

    /// Does the step have forces that read the step-start nodal velocity (bulk
    /// viscosity, absorbing faces)?
    pub fn reads_start_velocity(&self, m: &Model<D>) -> bool {
        self.viscosity.is_some() || !m.absorbing.faces.is_empty()
    }
}

/// Per particle: is it removed from the transfers this step (eroded, or
/// outside the grid: `Model::removed`, at the step start)? Empty when the
/// scene removes none. A removed particle touches no node, and keeps its
/// position and velocity; no load does work on it.
pub fn removed_particles<const D: usize>(m: &Model<D>) -> Vec<bool> {
    match m.removes_particles() {
        true => (0..m.particles.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| m.removed(q))
            .collect(),
        false => Vec::new(),
    }
}

/// What a P2G pass gathers at the nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum P2g {
    /// Mass (2-24) and momentum (2-25; APIC: with its affine part).
    Motion,
    /// The nodal force f_ext − f_int (2-51, 2-52) from the particles' stress.
    Force,
    /// Both in one pass.
    MotionAndForce,
}

/// Whether the grid update finds the step-start velocity formed
/// (`Backend::start_velocity`) or forms it itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    Formed,
    Form,
}

/// What follows G2P in the same step, which a back-end may do in the same pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Then {
    /// USL: the stress update from the updated nodal velocity.
    Stress,
    /// MUSL: the particles' updated momentum mapped back to the nodes.
    Remap,
    /// USF: nothing (its stress was updated before the grid update).
    Nothing,
}

/// The nodal velocity a separate stress update reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Velocity {
    /// USF: the step-start velocity with the conditions.
    Start,
    /// MUSL: the velocity of the remapped momentum with the conditions.
    Remapped,
}

/// A transfer back-end: the passes of the explicit step over particles and nodes.
pub trait Backend<const D: usize> {
    /// Where the particles are on the grid this step (their stencils and the
    /// nodes they touch), and what the features set up from the step-start
    /// state (APIC's first affine moments, contact's velocity fields, F-bar's
    /// cells).
    fn locate(&mut self, m: &mut Model<D>, s: &Step<D>);

    /// P2G: what `what` names, from the particles' state now.
    fn p2g(&mut self, m: &Model<D>, s: &Step<D>, what: P2g);

    /// The step-start nodal velocity v = p/m (2-25) with the conditions: the
    /// prescribed components, friction faces, and what the back-end's features
    /// add (the mirror at faces, contact between bodies).
    fn start_velocity(&mut self, m: &Model<D>, s: &Step<D>);

    /// Add the forces that read the step-start velocity to the nodal force:
    /// bulk viscosity, absorbing faces (after `start_velocity`).
    fn start_forces(&mut self, m: &Model<D>, s: &Step<D>);

    /// The grid update (2-23, 2-29, `grid_update`): the acceleration with local
    /// damping and the updated velocity, with the conditions.
    fn grid_update(&mut self, m: &Model<D>, s: &Step<D>, start: Start);

    /// G2P: the particles' velocity from the updated nodes (PIC/FLIP 2-27, or
    /// APIC), their positions (2-26), the bodies that are no continuum taking
    /// their own motion, and `then`. Returns the work of the loads over the step.
    fn g2p(&mut self, m: &mut Model<D>, s: &Step<D>, then: Then) -> Result<f64, Divergence>;

    /// MUSL: the nodal velocity of the remapped momentum, with the conditions.
    fn remapped_velocity(&mut self, m: &Model<D>, s: &Step<D>);

    /// The stress update ΔF = I + Δt L, L = Σ v_I ⊗ ∇S_I (2-31, 2-32), from the
    /// nodal velocity `from`.
    fn update_stress(
        &mut self,
        m: &mut Model<D>,
        s: &Step<D>,
        from: Velocity,
    ) -> Result<(), Divergence>;

    /// Stop on a state the run cannot go on from (`divergence::check_state`),
    /// unless the last pass checked it.
    fn check(&self, m: &Model<D>, s: &Step<D>) -> Result<(), Divergence>;
}

/// Advance the model from t to t + Δt on back-end `b`; returns the work of the
/// gravity and the applied loads over the step.
pub fn advance<const D: usize, B: Backend<D>>(
    b: &mut B,
    m: &mut Model<D>,
    s: &Step<D>,
) -> Result<f64, Divergence> {
    b.locate(m, s);
    let work = match s.scheme {
        Scheme::Usl => {
            grid_update_after_p2g(b, m, s);
            b.g2p(m, s, Then::Stress)?
        }
        Scheme::Musl => {
            grid_update_after_p2g(b, m, s);
            let work = b.g2p(m, s, Then::Remap)?;
            b.remapped_velocity(m, s);
            b.update_stress(m, s, Velocity::Remapped)?;
            work
        }
        Scheme::Usf => {
            b.p2g(m, s, P2g::Motion);
            b.start_velocity(m, s);
            b.update_stress(m, s, Velocity::Start)?;
            b.p2g(m, s, P2g::Force);
            if s.reads_start_velocity(m) {
                b.start_forces(m, s);
            }
            b.grid_update(m, s, Start::Formed);
            b.g2p(m, s, Then::Nothing)?
        }
    };
    b.check(m, s)?;
    Ok(work)
}

/// USL and MUSL: P2G of mass, momentum and force from the step-start state,
/// the forces that read the step-start velocity, and the grid update.
fn grid_update_after_p2g<const D: usize, B: Backend<D>>(b: &mut B, m: &Model<D>, s: &Step<D>) {
    b.p2g(m, s, P2g::MotionAndForce);
    match s.reads_start_velocity(m) {
        true => {
            b.start_velocity(m, s);
            b.start_forces(m, s);
            b.grid_update(m, s, Start::Formed);
        }
        false => b.grid_update(m, s, Start::Form),
    }
}
