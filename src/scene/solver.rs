//! The `[solver]` table (and each `[[stage]]`): the solver kind and its settings,
//! their defaults, and where each optional key applies (`SCOPES`), which the
//! validation checks with one loop: a key given where it does not apply is an
//! error "does not apply to …".

use serde::{Deserialize, Serialize};
use strum::{EnumIter, IntoStaticStr};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum SolverKind {
    Explicit,
    Implicit,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Scheme {
    Usf,
    Usl,
    Musl,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Integrator {
    /// Newmark with Newton-Raphson (thesis 2-33…2-38).
    Newmark,
    /// No inertia: gravity and loads scaled by the load factor t / end_time.
    QuasiStatic,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum MassMatrix {
    Lumped,
    Consistent,
}

/// How the implicit solver solves each Newton correction (thesis 2-38).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum LinearSolver {
    /// Assembled consistent tangent, sparse Cholesky / LU (needs an analytic tangent).
    Direct,
    /// Matrix-free restarted GMRES with finite-difference products (2-39).
    Gmres,
    /// Matrix-free conjugate gradients (symmetric positive definite tangents).
    Cg,
}

/// The fill-reducing ordering of the sparse direct solver's Cholesky
/// factorizations (the direct linear solver and the `lagged_direct`
/// preconditioner; LU orders its columns by COLAMD).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum DirectOrdering {
    /// METIS in 3D, AMD in 2D (docs/performance.md).
    Auto,
    /// Approximate minimum degree on the node graph.
    Amd,
    /// METIS nested dissection on the node graph.
    Metis,
}

/// How the explicit step moves values between particles and nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Transfer {
    /// Particle-side scatter on a box of nodes (`solver::explicit::node_box`) where the
    /// scene allows it, else `Gather`.
    Auto,
    /// Node-side gathers through the node map (`physics::transfer`): every
    /// scene, and the reference the scatter is checked against.
    Gather,
}

/// How the explicit step gives the particles their velocity back from the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum VelocityTransfer {
    /// The PIC/FLIP blend of `flip` (2-27).
    Flip,
    /// Affine particle-in-cell (Jiang et al. 2015, 2017; `solver::explicit::apic`): the
    /// particle carries an affine velocity field, transferred without loss of
    /// linear or angular momentum and without FLIP's noise.
    Apic,
}

/// Preconditioner of the Krylov solvers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum PreconditionerKind {
    None,
    /// Inverse of the tangent's diagonal, built particle by particle.
    Jacobi,
    /// Inverse of each node's D×D diagonal block, built particle by particle.
    BlockJacobi,
    /// The assembled tangent of an earlier iteration, factorized once and reused.
    LaggedDirect,
    /// Geometric multigrid on the background grid over the assembled tangent,
    /// which is then also the Krylov operator (`solver::linear::multigrid`).
    Multigrid,
    /// The same multigrid built from the assembled tangent of an earlier
    /// iteration and kept (as `LaggedDirect` keeps its factorization); the Krylov
    /// operator stays the matrix-free difference product.
    LaggedMultigrid,
}

/// The `[solver]` table (or a `[[stage]]`). The accessors give the documented
/// defaults; `SCOPES` says where each optional key applies.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverConfig {
    /// Stage name (for `[[stage]]` tables; optional).
    pub name: Option<String>,
    /// From this stage on, c, tan φ and tan ψ of the frictional materials are the
    /// scene's values divided by this factor (default: the previous stage's, 1 at
    /// the start). docs/strength_reduction.md.
    pub strength_reduction_factor: Option<f64>,
    pub kind: SolverKind,
    /// Duration of the run or stage (implicit quasi-static: the pseudo-time over
    /// which the loads rise to full value).
    pub end_time: f64,
    /// Explicit: fixed step instead of the CFL rule. Implicit: the step (required
    /// for Newmark; quasi-static may give `load_steps` instead).
    pub dt: Option<f64>,
    // Explicit keys.
    pub scheme: Option<Scheme>,
    pub cfl: Option<f64>,
    pub flip: Option<f64>,
    /// Explicit particle velocity update (default `flip`).
    pub velocity_transfer: Option<VelocityTransfer>,
    pub damping: Option<f64>,
    /// Artificial bulk viscosity C_Q and C_L (`solver::explicit::bulk_viscosity`; off
    /// unless one is given, the other then takes its standard value).
    pub bulk_viscosity_quadratic: Option<f64>,
    pub bulk_viscosity_linear: Option<f64>,
    /// Explicit transfers (default `auto`).
    pub transfer: Option<Transfer>,
    // Implicit keys.
    pub integrator: Option<Integrator>,
    pub beta: Option<f64>,
    pub gamma: Option<f64>,
    pub mass: Option<MassMatrix>,
    pub load_steps: Option<usize>,
    pub residual_tolerance: Option<f64>,
    pub displacement_tolerance: Option<f64>,
    pub max_iterations: Option<usize>,
    /// Newton gives an attempt up once its residual has risen in this many
    /// consecutive iterations (`max_rising_iterations()`).
    pub max_rising_iterations: Option<usize>,
    /// Newton gives an attempt up once its residual has fallen by less than
    /// 10 % over this many iterations (`stall_iterations()`).
    pub stall_iterations: Option<usize>,
    pub line_search: Option<bool>,
    pub max_cutbacks: Option<usize>,
    pub min_node_support: Option<f64>,
    // Linear solver of the Newton corrections (implicit).
    pub linear_solver: Option<LinearSolver>,
    pub preconditioner: Option<PreconditionerKind>,
    pub krylov_tolerance: Option<f64>,
    pub krylov_restart: Option<usize>,
    pub krylov_max_iterations: Option<usize>,
    pub direct_ordering: Option<DirectOrdering>,
    /// The multigrid preconditioner coarsens until a level has at most this many
    /// unknowns.
    pub multigrid_coarse_unknowns: Option<usize>,
    /// Quasi-static: ramp gravity from zero over the stage (default true); false
    /// applies it in full from the first step (after a geostatic initialisation).
    pub gravity_ramp: Option<bool>,
    /// Explicit: raise gravity linearly from zero over this time on the run's
    /// clock (default: in full from the start).
    pub gravity_ramp_time: Option<f64>,
    /// F-bar against volumetric locking (explicit and implicit; default false).
    pub fbar: Option<bool>,
    // Staged construction (`[[stage]]` only; `scene::staging`, `model::staging`).
    /// Bodies, by name, whose particles leave the model at the stage's start.
    pub deactivate: Option<Vec<String>>,
    /// Regions whose continuum particles leave the model at the stage's start.
    pub excavate: Option<Vec<super::region::RegionConfig>>,
    /// Bodies, by name (`active = false`), that enter the model at the stage's
    /// start, unstressed.
    pub activate: Option<Vec<String>>,
    /// Displacements measured from the stage's start (default false).
    pub reset_displacement: Option<bool>,
}

impl SolverKind {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

impl Scheme {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

impl Integrator {
    pub fn name(&self) -> &'static str {
        self.into()
    }

    /// How messages name it.
    fn described(&self) -> &'static str {
        match self {
            Integrator::Newmark => "the Newmark integrator",
            Integrator::QuasiStatic => "the quasi-static integrator",
        }
    }
}

impl MassMatrix {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

impl LinearSolver {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

impl PreconditionerKind {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

impl DirectOrdering {
    pub fn name(&self) -> &'static str {
        self.into()
    }

    /// What `auto` means in D dimensions: METIS in 3D, where it stores about a
    /// quarter less than minimum degree and factors faster; AMD in 2D, where the
    /// fill is the same and AMD is 10× faster to compute (docs/performance.md).
    pub fn resolved(self, dimension: usize) -> DirectOrdering {
        match (self, dimension) {
            (DirectOrdering::Auto, 3) => DirectOrdering::Metis,
            (DirectOrdering::Auto, _) => DirectOrdering::Amd,
            (chosen, _) => chosen,
        }
    }
}

/// Where an optional key of the solver table applies: to these solver kinds
/// and, for the implicit solver, to these integrators and linear solvers (empty:
/// all of them).
#[derive(Clone, Copy, Debug)]
pub struct Scope {
    pub key: &'static str,
    /// Whether the table gives the key.
    pub given: fn(&SolverConfig) -> bool,
    pub kinds: &'static [SolverKind],
    pub integrators: &'static [Integrator],
    pub linear_solvers: &'static [LinearSolver],
    /// Added to the error where an integrator or a linear solver rules the key out.
    pub note: &'static str,
}

impl Scope {
    const fn new(
        key: &'static str,
        given: fn(&SolverConfig) -> bool,
        kinds: &'static [SolverKind],
        integrators: &'static [Integrator],
        linear_solvers: &'static [LinearSolver],
        note: &'static str,
    ) -> Scope {
        Scope {
            key,
            given,
            kinds,
            integrators,
            linear_solvers,
            note,
        }
    }
}

const EXPLICIT: &[SolverKind] = &[SolverKind::Explicit];
const IMPLICIT: &[SolverKind] = &[SolverKind::Implicit];
// Explicit solvers report the Newmark default of `integrator`.
const EXPLICIT_OR_IMPLICIT: &[SolverKind] = &[SolverKind::Explicit, SolverKind::Implicit];
const NEWMARK: &[Integrator] = &[Integrator::Newmark];
const QUASI_STATIC: &[Integrator] = &[Integrator::QuasiStatic];
const KRYLOV: &[LinearSolver] = &[LinearSolver::Gmres, LinearSolver::Cg];
const GMRES: &[LinearSolver] = &[LinearSolver::Gmres];
// Notes added to "does not apply to …".
const SET_KRYLOV: &str = " (set \"gmres\" or \"cg\")";
const RESTART_LENGTH: &str = " (it is the GMRES restart length)";
const FULL_GRAVITY: &str = " (gravity is always in full)";
const GIVE_DT: &str = " (give dt)";
const RAMP_WITH_LOAD: &str = " (gravity ramps with the load factor: gravity_ramp)";

/// The `Scope` of the optional key `key`, a field of `SolverConfig` named as in
/// the table.
macro_rules! scope {
    ($key:ident, $($where:expr),*) => {
        Scope::new(stringify!($key), |s| s.$key.is_some(), $($where),*)
    };
}

/// The optional keys that apply to some solvers only (every other key applies to
/// all): key, whether it is given, solver kinds, integrators, linear solvers
/// (`&[]`: all), note.
pub const SCOPES: &[Scope] = &[
    scope!(scheme, EXPLICIT, &[], &[], ""),
    scope!(cfl, EXPLICIT, &[], &[], ""),
    scope!(flip, EXPLICIT, &[], &[], ""),
    scope!(velocity_transfer, EXPLICIT, &[], &[], ""),
    scope!(damping, EXPLICIT, &[], &[], ""),
    scope!(
        gravity_ramp_time,
        EXPLICIT_OR_IMPLICIT,
        NEWMARK,
        &[],
        RAMP_WITH_LOAD
    ),
    scope!(bulk_viscosity_quadratic, EXPLICIT, &[], &[], ""),
    scope!(bulk_viscosity_linear, EXPLICIT, &[], &[], ""),
    scope!(transfer, EXPLICIT, &[], &[], ""),
    scope!(integrator, IMPLICIT, &[], &[], ""),
    scope!(beta, IMPLICIT, NEWMARK, &[], ""),
    scope!(gamma, IMPLICIT, NEWMARK, &[], ""),
    scope!(mass, IMPLICIT, NEWMARK, &[], ""),
    scope!(gravity_ramp, IMPLICIT, QUASI_STATIC, &[], FULL_GRAVITY),
    scope!(load_steps, IMPLICIT, QUASI_STATIC, &[], GIVE_DT),
    scope!(residual_tolerance, IMPLICIT, &[], &[], ""),
    scope!(displacement_tolerance, IMPLICIT, &[], &[], ""),
    scope!(max_iterations, IMPLICIT, &[], &[], ""),
    scope!(max_rising_iterations, IMPLICIT, &[], &[], ""),
    scope!(stall_iterations, IMPLICIT, &[], &[], ""),
    scope!(line_search, IMPLICIT, &[], &[], ""),
    scope!(max_cutbacks, IMPLICIT, &[], &[], ""),
    scope!(min_node_support, IMPLICIT, &[], &[], ""),
    scope!(linear_solver, IMPLICIT, &[], &[], ""),
    scope!(preconditioner, IMPLICIT, &[], KRYLOV, SET_KRYLOV),
    scope!(krylov_tolerance, IMPLICIT, &[], KRYLOV, SET_KRYLOV),
    scope!(krylov_restart, IMPLICIT, &[], GMRES, RESTART_LENGTH),
    scope!(krylov_max_iterations, IMPLICIT, &[], KRYLOV, SET_KRYLOV),
    scope!(direct_ordering, IMPLICIT, &[], &[], ""),
    scope!(multigrid_coarse_unknowns, IMPLICIT, &[], KRYLOV, SET_KRYLOV),
];

impl SolverConfig {
    pub fn scheme(&self) -> Scheme {
        self.scheme.unwrap_or(Scheme::Musl)
    }
    /// Fraction of the CFL limit (2-45); default 0.5.
    pub fn cfl(&self) -> f64 {
        self.cfl.unwrap_or(0.5)
    }
    /// FLIP fraction: 1 = FLIP (default), 0 = PIC.
    pub fn flip(&self) -> f64 {
        self.flip.unwrap_or(1.0)
    }
    /// The artificial bulk viscosity, if either coefficient is given (standard
    /// values C_Q = 1.5, C_L = 0.06 for the other).
    pub fn bulk_viscosity(&self) -> Option<(f64, f64)> {
        (self.bulk_viscosity_quadratic.is_some() || self.bulk_viscosity_linear.is_some()).then(
            || {
                (
                    self.bulk_viscosity_quadratic.unwrap_or(1.5),
                    self.bulk_viscosity_linear.unwrap_or(0.06),
                )
            },
        )
    }
    /// Local damping α (default 0).
    pub fn damping(&self) -> f64 {
        self.damping.unwrap_or(0.0)
    }
    /// The explicit gravity ramp's duration (0: gravity in full from the start).
    pub fn gravity_ramp_time(&self) -> f64 {
        self.gravity_ramp_time.unwrap_or(0.0)
    }
    pub fn integrator(&self) -> Integrator {
        self.integrator.unwrap_or(Integrator::Newmark)
    }
    /// Newmark β (default 1/4, trapezoidal).
    pub fn beta(&self) -> f64 {
        self.beta.unwrap_or(0.25)
    }
    /// Newmark γ (default 1/2).
    pub fn gamma(&self) -> f64 {
        self.gamma.unwrap_or(0.5)
    }
    pub fn mass(&self) -> MassMatrix {
        self.mass.unwrap_or(MassMatrix::Lumped)
    }
    /// Implicit step: `dt`, or end_time / load_steps.
    pub fn implicit_dt(&self) -> f64 {
        self.dt
            .unwrap_or_else(|| self.end_time / self.load_steps.unwrap_or(1) as f64)
    }
    /// Newton converges when ‖R‖ ≤ this × the reference force (default 1e-9).
    pub fn residual_tolerance(&self) -> f64 {
        self.residual_tolerance.unwrap_or(1e-9)
    }
    /// … and ‖δu‖ ≤ this × ‖u‖ (default 1e-9).
    pub fn displacement_tolerance(&self) -> f64 {
        self.displacement_tolerance.unwrap_or(1e-9)
    }
    /// Newton iteration cap per attempt (default 25).
    pub fn max_iterations(&self) -> usize {
        self.max_iterations.unwrap_or(25)
    }
    /// Newton fails an attempt (the step is cut back, or the run stops) once
    /// ‖r‖ has risen in this many consecutive iterations, a divergence check
    /// as in Abaqus's (default: none, only the iteration cap; a
    /// strength-reduction trial takes 2, `analyses::strength_reduction`).
    pub fn max_rising_iterations(&self) -> Option<usize> {
        self.max_rising_iterations
    }
    /// Newton fails an attempt once ‖r‖ has fallen by less than 10 % over
    /// this many iterations (`newton::STALL_REDUCTION`): it creeps instead of
    /// converging (default: none; a strength-reduction trial takes 10).
    pub fn stall_iterations(&self) -> Option<usize> {
        self.stall_iterations
    }
    /// Backtracking line search on the residual norm (default off).
    pub fn line_search(&self) -> bool {
        self.line_search.unwrap_or(false)
    }
    /// Times a failing step may be halved before the run stops (default 5).
    pub fn max_cutbacks(&self) -> usize {
        self.max_cutbacks.unwrap_or(5)
    }

    /// Whether this stage changes the model at its start (staged
    /// construction: `scene::staging`, `model::staging`).
    pub fn changes_model(&self) -> bool {
        self.activate.as_ref().is_some_and(|v| !v.is_empty())
            || self.deactivate.as_ref().is_some_and(|v| !v.is_empty())
            || self.excavate.as_ref().is_some_and(|v| !v.is_empty())
            || self.reset_displacement == Some(true)
    }

    /// Quasi-static gravity ramps from zero over the stage (default true).
    /// A stage that changes the model (`changes_model`) finds the ground under
    /// gravity already: there gravity is in full by default.
    pub fn gravity_ramp(&self) -> bool {
        self.gravity_ramp.unwrap_or(!self.changes_model())
    }
    /// Nodes whose particle support Σ_p V_p S_Ip is below this fraction of a cell
    /// volume are tied to two neighbours by linear extrapolation (default 1e-2;
    /// 0 turns it off). See `solver::implicit::ties`.
    pub fn min_node_support(&self) -> f64 {
        self.min_node_support.unwrap_or(1e-2)
    }
    pub fn velocity_transfer(&self) -> VelocityTransfer {
        self.velocity_transfer.unwrap_or(VelocityTransfer::Flip)
    }

    /// An explicit stage with APIC: its particles keep affine moments.
    pub fn apic(&self) -> bool {
        self.kind == SolverKind::Explicit && self.velocity_transfer() == VelocityTransfer::Apic
    }

    pub fn transfer(&self) -> Transfer {
        self.transfer.unwrap_or(Transfer::Auto)
    }

    /// F-bar: per background cell, the particles' volume change is the cell
    /// average (default false). See `fbar`.
    pub fn fbar(&self) -> bool {
        self.fbar.unwrap_or(false)
    }
    /// Linear solver of the Newton corrections (default direct).
    pub fn linear_solver(&self) -> LinearSolver {
        self.linear_solver.unwrap_or(LinearSolver::Direct)
    }
    /// Krylov preconditioner (default block_jacobi).
    pub fn preconditioner(&self) -> PreconditionerKind {
        self.preconditioner
            .unwrap_or(PreconditionerKind::BlockJacobi)
    }
    /// GMRES restart length (default 30).
    pub fn krylov_restart(&self) -> usize {
        self.krylov_restart.unwrap_or(30)
    }
    /// The direct solver's fill-reducing ordering (default auto).
    pub fn direct_ordering(&self) -> DirectOrdering {
        self.direct_ordering.unwrap_or(DirectOrdering::Auto)
    }
    /// Krylov iterations allowed per Newton correction (default 1000).
    pub fn krylov_max_iterations(&self) -> usize {
        self.krylov_max_iterations.unwrap_or(1000)
    }
    /// Largest coarsest level of the multigrid preconditioner (default 3000
    /// unknowns).
    pub fn multigrid_coarse_unknowns(&self) -> usize {
        self.multigrid_coarse_unknowns.unwrap_or(3000)
    }

    /// An optional key given where it does not apply (`SCOPES`), with what it
    /// does not apply to: "the explicit solver", "the Newmark integrator (give
    /// dt)", "linear_solver = \"direct\" (set \"gmres\" or \"cg\")". The solver
    /// kind rules keys out first, then the integrator, then the linear solver;
    /// within each, the first key in `SCOPES` is named.
    pub fn key_out_of_scope(&self) -> Option<(&'static str, String)> {
        let (integrator, linear_solver) = (self.integrator(), self.linear_solver());
        let ruled_out = |s: &Scope| {
            if !s.kinds.contains(&self.kind) {
                Some((0, format!("the {} solver", self.kind.name())))
            } else if !s.integrators.is_empty() && !s.integrators.contains(&integrator) {
                Some((1, format!("{}{}", integrator.described(), s.note)))
            } else if !s.linear_solvers.is_empty() && !s.linear_solvers.contains(&linear_solver) {
                let name = linear_solver.name();
                Some((2, format!("linear_solver = \"{name}\"{}", s.note)))
            } else {
                None
            }
        };
        (SCOPES.iter())
            .filter(|s| (s.given)(self))
            .filter_map(|s| ruled_out(s).map(|(by, outside)| (by, s.key, outside)))
            .min_by_key(|&(by, _, _)| by)
            .map(|(_, key, outside)| (key, outside))
    }
}
