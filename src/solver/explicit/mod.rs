//! Explicit MPM: central difference in time (thesis 2-29, 2-30) with the USF, USL
//! and MUSL orderings of the stress update (§2.2.1), a PIC/FLIP blend or APIC,
//! and local damping for dynamic relaxation.
//!
//! The step is written once (`step`) over two transfer back-ends: the node map
//! (`gather`), which serves every feature, and the box scatter (`scatter`,
//! on `node_box`), which serves the features that need no node map. Which one a
//! step takes follows from what its features declare (`features`). The rules
//! at a node and at a particle are the back-ends' common ones (`grid_update`,
//! `motion`); the features have their own modules (`apic`, `bulk_viscosity`,
//! `contact`, `mirror`).

pub(crate) mod apic;
pub(crate) mod bulk_viscosity;
pub(crate) mod contact;
pub mod features;
pub(crate) mod gather;
pub(crate) mod grid_update;
pub(crate) mod mirror;
pub(crate) mod motion;
pub mod node_box;
pub(crate) mod p2g;
pub(crate) mod scatter;
pub(crate) mod step;

use crate::model::loads::LoadTime;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::contact::totals::PairTotal;
use crate::physics::shape::ShapeFunction;
use crate::scene::{Scheme, SolverConfig, Transfer};
use crate::solver::divergence::Divergence;
use crate::solver::explicit::bulk_viscosity::BulkViscosity;
use crate::solver::explicit::features::needs_node_map;
use crate::solver::explicit::gather::NodeMapStep;
use crate::solver::explicit::scatter::ScatterStep;
use crate::solver::explicit::step::{advance, Step};
use crate::solver::report::{SolverReport, TransferPath};
use crate::solver::stepper::Stepper;
use rayon::prelude::*;

pub struct Explicit<const D: usize> {
    pub shape: ShapeFunction,
    pub scheme: Scheme,
    pub cfl: f64,
    pub fixed_dt: Option<f64>,
    pub flip: f64,
    /// APIC (`solver::explicit::apic`) instead of the PIC/FLIP blend (`flip` is then 0).
    pub apic: bool,
    pub damping: f64,
    /// Gravity rises linearly from zero over `gravity_ramp_time` on the run's
    /// clock, as a load's `ramp_time` (0: in full from the start), unless the
    /// scene gives a `gravity_history` (`Model::gravity_factor`).
    pub gravity_ramp: LoadTime,
    /// F-bar against volumetric locking (`crate::physics::kinematics::fbar`).
    pub fbar: bool,
    /// Artificial bulk viscosity (`crate::solver::explicit::bulk_viscosity`), if asked for.
    pub viscosity: Option<BulkViscosity>,
    /// `solver.transfer`: `Auto` takes the box scatter where the features allow.
    pub transfer: Transfer,
    /// The node map's state (`solver::explicit::gather`).
    node_map: NodeMapStep<D>,
    /// The box scatter's buffers (`solver::explicit::scatter`), while it runs.
    scatter: Option<ScatterStep<D>>,
}

impl<const D: usize> Explicit<D> {
    pub fn new(shape: ShapeFunction, s: &SolverConfig) -> Self {
        Explicit {
            shape,
            scheme: s.scheme(),
            cfl: s.cfl(),
            fixed_dt: s.dt,
            flip: if s.apic() { 0.0 } else { s.flip() },
            apic: s.apic(),
            damping: s.damping(),
            gravity_ramp: LoadTime::Ramp(s.gravity_ramp_time()),
            fbar: s.fbar(),
            viscosity: s
                .bulk_viscosity()
                .map(|(quadratic, linear)| BulkViscosity { quadratic, linear }),
            transfer: s.transfer(),
            node_map: NodeMapStep::default(),
            scatter: None,
        }
    }

    /// What the step from t to t + dt reads besides the model.
    fn settings(&self, m: &Model<D>, t: f64, dt: f64, step: usize) -> Step<D> {
        Step {
            shape: self.shape,
            scheme: self.scheme,
            flip: self.flip,
            apic: self.apic,
            damping: self.damping,
            fbar: self.fbar,
            viscosity: self.viscosity,
            gravity: m.gravity * m.gravity_factor(t, &self.gravity_ramp),
            scales: m.load_scales(t),
            tiny: Step::tiny_mass(m),
            t,
            dt,
            step,
        }
    }

    /// Critical time step min_p h / (c_p + |v_p|) (2-45).
    pub fn critical_dt(m: &Model<D>) -> f64 {
        Self::critical_dt_with(m, None)
    }

    /// The critical step, and with bulk viscosity also its stable step
    /// h/(C_L c + √(C_L² c² + c²)) at every particle, in one pass. Removed
    /// particles (eroded, or outside the grid) do not count, unless all are.
    fn critical_dt_with(m: &Model<D>, viscosity: Option<&BulkViscosity>) -> f64 {
        let removes = m.removes_particles();
        let active = Self::critical_dt_over(m, viscosity, &|q| !(removes && m.removed(q)));
        match active.is_finite() {
            true => active,
            false => Self::critical_dt_over(m, viscosity, &|_| true),
        }
    }

    /// The peridynamic bodies' stable step (`Peridynamics::stable_dt`);
    /// infinite without one.
    fn peridynamic_dt(m: &Model<D>) -> f64 {
        m.peridynamics
            .as_ref()
            .map_or(f64::INFINITY, |pd| pd.stable_dt)
    }

    /// The stable step of coupled pore flow (`Drainage::stable_dt`); infinite
    /// without it.
    fn pore_flow_dt(m: &Model<D>) -> f64 {
        (m.drainage.as_ref()).map_or(f64::INFINITY, |d| d.stable_dt(&m.grid))
    }

    fn critical_dt_over(
        m: &Model<D>,
        viscosity: Option<&BulkViscosity>,
        counts: &(dyn Fn(usize) -> bool + Sync),
    ) -> f64 {
        let p = &m.particles;
        let h = m.grid.h_min();
        (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&q| counts(q))
            .map(|q| {
                let c = m.materials[p.material[q] as usize]
                    .wave_speed(p.f.get(q).determinant(), p.history.get(q));
                let dt = h / (c + p.v[q].norm());
                viscosity.map_or(dt, |v| dt.min(v.stable_dt(c, h, 0.0)))
            })
            .reduce(|| f64::INFINITY, f64::min)
    }
}

impl<const D: usize> Stepper<D> for Explicit<D> {
    /// The step to take now: the fixed one, or cfl × the critical one (with bulk
    /// viscosity, also within its stable step at every particle, its rate from
    /// the particle's F rate being unknown here: ε̇_v = 0, the linear term only).
    /// With peridynamic bodies, also within their stable step (Silling–Askari
    /// with its safety factor, `material::bond::SAFETY`). With coupled pore
    /// water, also within the flow's stable step h²/(2 D c_f), a bound with a
    /// margin of its own (`Drainage::stable_dt`), so cfl does not scale it.
    fn dt(&self, m: &Model<D>) -> f64 {
        self.fixed_dt.unwrap_or_else(|| {
            let grid = self.cfl * Self::critical_dt_with(m, self.viscosity.as_ref());
            grid.min(Self::pore_flow_dt(m)).min(Self::peridynamic_dt(m))
        })
    }

    /// Advance the model from t to t + dt. Returns the work done by gravity and
    /// applied loads over the step.
    fn step(&mut self, m: &mut Model<D>, t: f64, dt: f64, step: usize) -> Result<f64, Divergence> {
        let s = self.settings(m, t, dt, step);
        // The box scatter where the scene leaves the choice to the solver and
        // no feature of the step needs the node map (`solver::explicit::features`).
        match self.transfer == Transfer::Auto && !needs_node_map(&s, m) {
            true => {
                let scatter = self.scatter.get_or_insert_with(ScatterStep::default);
                advance(scatter, m, &s)
            }
            false => {
                self.scatter = None;
                advance(&mut self.node_map, m, &s)
            }
        }
    }

    /// A fixed Δt above the critical step min h/(c + |v|) (with bulk viscosity,
    /// its stable step) of the stage's starting state.
    fn step_warning(&self, m: &Model<D>) -> Option<String> {
        let dt = self.fixed_dt?;
        let bonds = Self::peridynamic_dt(m);
        if dt > bonds {
            return Some(format!(
                "the fixed time step dt = {dt:e} is {:.3} × the stable step {bonds:.6e} of the \
                 peridynamic bodies (Silling–Askari, with safety factor {}): explicit \
                 integration of their bonds is unstable above it",
                dt / bonds,
                crate::material::bond::SAFETY
            ));
        }
        let flow = Self::pore_flow_dt(m);
        if dt > flow {
            return Some(format!(
                "the fixed time step dt = {dt:e} is {:.3} × the stable step {flow:.6e} of the \
                 coupled pore flow (h²/(2 D c_f), c_f = K_f k/γ_w): its explicit update is \
                 unstable above it",
                dt / flow
            ));
        }
        let critical = Self::critical_dt_with(m, self.viscosity.as_ref());
        (dt > critical).then(|| {
            format!(
                "the fixed time step dt = {dt:e} is {:.3} × the critical step {critical:.6e} \
                 (min over particles of h_min/(c + |v|) at the stage's start): explicit \
                 integration is unstable above it",
                dt / critical
            )
        })
    }

    fn active_nodes(&self) -> usize {
        match &self.scatter {
            Some(s) => s.active,
            None => self.node_map.map.len(),
        }
    }

    fn report(&self) -> SolverReport {
        let transfer = match self.scatter {
            Some(_) => TransferPath::Scatter,
            None => TransferPath::Gather,
        };
        SolverReport::explicit(self.scheme, transfer)
    }

    fn take_contact(&mut self) -> Vec<PairTotal<D>> {
        self.node_map.take_contact()
    }

    fn contact_forces(&self, m: &Model<D>) -> Option<Vec<crate::dim::Vector<D>>> {
        self.node_map.contact_forces(m)
    }
}
