//! Penalty contact between two deformable bodies on their split nodes.
//!
//! The two bodies are kept apart on the grid: every grid node that both touch
//! is split into one node per body (`super::super::super::grid`,
//! `physics::contact::field_split`), so each body has its own displacement
//! there and neither drags the other along. At such a node I the two fields
//! r < s meet with the common normal n (from r to s) and the distance D
//! between their surfaces at the step start (both from the step-start
//! particles, `Meeting`). The step's displacements move the two surfaces by δ
//! relative to each other and close the gap to D − δ·n, so r is
//!
//!   g = δ·n − D
//!
//! deep in s, and a penalty with the law of the rigid bodies'
//! (`super::penalty::penalty_force` with the outward normal −n, fixed within
//! the step, and the relative motion δ) pushes r back and s forward.
//! δ = Σ_a c_a u_a over the nodes of the two surfaces (`surface_points`: the
//! meeting's two nodes, c = ±1, with a point basis; each field's nodes at its
//! surface point, c = ±S_a, with a particle-domain basis), and with
//! ∂f = ∂f/∂δ
//!
//!   r_a −= c_a f,   K_ab −= c_a c_b ∂f.
//!
//! Its normal penalty is ε_n = α M A_I / h, with A_I the meeting's nodal area and
//! M the stiffer P-wave modulus of the particles at the two nodes; its tangential
//! penalty is a tenth of that (`TANGENTIAL_PENALTY`). The tangential
//! force of a meeting is kept for the next step under its grid node and
//! fields. Unlike the explicit contact this one does not use the gap factor λ:
//! the penalty acts from D = 0 on (a node where the bodies touch at the step
//! start carries stiffness but no force).

use super::penalty::{penalty_force, ParticleContact, Penalty};
use super::state::{hand_over, CarriedMeeting};
use crate::dim::{Mat3, Tensor, Vector};
use crate::model::grid::Grid;
use crate::physics::contact::field_split::Meeting;
use crate::physics::contact::totals::{pair_totals, PairTotal};
use crate::physics::rigid::surface::Inside;
use crate::physics::shape::{evaluate, ShapeFunction};
use crate::scene::contact::ContactPlan;
use crate::solver::implicit::assembly::stiffness::ParticleTangents;
use crate::solver::implicit::assembly::{Components, Coupling, Tangent};
use crate::solver::implicit::terms::{
    Couplings, Restore, StepStart, StepTerm, StepView, TermReport,
};
use crate::solver::implicit::ties::NodeFields;
use crate::solver::stepper::SolverState;

/// The smallest nodal area of a meeting, as a fraction of a cell face h^{D−1}.
const MIN_AREA: f64 = 0.05;

/// How far, as a fraction of the smallest cell size, the outermost particle of
/// a side at a meeting must lie beyond or short of its reference particle along
/// the normal before the carried gap follows it (`assign_history`).
/// A sliding disk of radius R changes the gap at a node by about h²/(8R) as it
/// passes (0.0125 h at R = 10 h); the strain between neighbouring particles of a
/// flat face moves them by much less.
const OUTERMOST_SWITCH: f64 = 1e-3;

/// ε_t / ε_n at a meeting of two deformable fields. With ε_t = ε_n a meeting
/// sticks only while its tangential slip in the step stays below μ g, g the
/// normal penetration (about 1e-6 of a cell): where the bodies hardly move
/// against each other (a block's Poisson spreading against its slide, from
/// rest) the friction force flips between ±μ ε_n g from one Newton iterate to
/// the next, and the step stalls. A tenth widens that band tenfold. Measured
/// on `problems/contact_incline_implicit.toml` (Newton iterations of the whole
/// run, with `newton`'s line search as it is now): 1,507 → 857
/// (μ = 0.3) and 1,126 → 661 (μ = 0.5), cut-backs 36 → 8 and 18 → 0; 0.3 did
/// as well, 0.5 and 0.8 less (1,028, 1,478 at μ = 0.3), 0.03 and 0.01 less
/// again (891, 955).
const TANGENTIAL_PENALTY: f64 = 0.1;

/// Two deformable fields in contact at a split node at the iterate.
#[derive(Clone, Copy, Debug)]
pub struct NodeTouch<const D: usize> {
    /// Index of the meeting in `BodyContact::joints`.
    pub meeting: usize,
    /// The force on field r (s gets the opposite) and its derivative by u_r.
    pub contact: ParticleContact<D>,
}

/// A meeting of two deformable fields and what its penalty needs.
#[derive(Clone, Debug)]
struct Joint<const D: usize> {
    meeting: Meeting<D>,
    /// ε = α M A / h.
    penalty: f64,
    /// (grid node, r, s): what its history is kept under.
    key: [u32; 3],
    /// Tangential force at the step start.
    f_t0: Vector<D>,
    /// The nodes whose displacements make the relative displacement δ of the
    /// two surfaces, with signed weights (`surface_points`).
    points: Vec<(usize, f64)>,
    /// Each side's reference particle (`assign_history`): the meeting's
    /// outermost particles when it began, or where they moved on.
    reference: [u32; 2],
}

/// The meetings at one displacement increment u.
#[derive(Clone, Debug, Default)]
struct Meetings<const D: usize> {
    /// Those in contact.
    touches: Vec<NodeTouch<D>>,
    /// Every meeting's gap, D − δ·n.
    gap: Vec<f64>,
}

/// The contact between the deformable bodies on the split grid.
#[derive(Clone, Debug)]
pub struct BodyContact<const D: usize> {
    plan: ContactPlan,
    /// The meetings of this step.
    joints: Vec<Joint<D>>,
    /// What each meeting carried out of the last step, by (grid node, r, s),
    /// ascending.
    history: Vec<CarriedMeeting<D>>,
    /// The meetings at the iterate.
    at: Meetings<D>,
    totals: Vec<PairTotal<D>>,
    /// The deepest penalty depth of a converged step so far.
    deepest: f64,
}

impl<const D: usize> BodyContact<D> {
    /// The contact between the deformable bodies under `plan`, or None
    /// without a pair of them in contact.
    pub fn new(plan: &ContactPlan) -> Option<Self> {
        let deformable = |i: usize| !plan.rigid[i];
        let deformable_pair = (0..plan.fields).any(|i| {
            (i + 1..plan.fields)
                .any(|j| deformable(i) && deformable(j) && plan.law(i as u32, j as u32).is_some())
        });
        deformable_pair.then(|| BodyContact {
            plan: plan.clone(),
            joints: Vec::new(),
            history: Vec::new(),
            at: Meetings::default(),
            totals: pair_totals(plan),
            deepest: 0.0,
        })
    }

    /// The meetings of this step at the split nodes of `step`'s grid (from
    /// the step-start particles), but those at tied (weakly supported) nodes:
    /// a tied node's displacement is extrapolated from its masters, and a
    /// penalty on it would act on them through the extrapolation's lever
    /// (coefficients 2 and −1).
    fn find_meetings(&mut self, step: &StepView<'_, D>, shape: ShapeFunction) {
        let (m, st, map) = (step.m, step.stencils, step.map);
        let (Some(split), Some(nodes)) = (step.grid.split(), step.grid.node_fields()) else {
            unreachable!("contact between deformable bodies on a grid without a split")
        };
        let h = m.grid.h_min();
        let mut meetings = split.meetings(&self.plan, m, st, map, true);
        // Where both fields' volume gradients are small the node is inside both
        // stencils but at neither surface: its normal would be round-off and
        // its gap along it meaningless (two bodies' particles side by side
        // across the node), so it is no meeting.
        let face = h.powi(D as i32 - 1);
        meetings.retain(|mt| mt.area >= MIN_AREA * face);
        let (p, owner) = (&m.particles, st.owner());
        // ε = α M A / h, M the stiffer material at the two nodes.
        let modulus = |a: usize| {
            (map.node_entries(a).iter())
                .map(|&e| m.materials[p.material[owner.of(e)] as usize].p_wave_modulus())
                .fold(0.0, f64::max)
        };
        self.joints = (meetings.into_iter())
            .map(|mut mt| {
                // A gap of round-off (faces that coincide at the step start) is none.
                if mt.gap.abs() <= 1e-9 * h {
                    mt.gap = 0.0;
                }
                let [r, s] = mt.fields;
                Joint {
                    penalty: mt.law.penalty_factor * modulus(mt.r).max(modulus(mt.s)) * mt.area / h,
                    key: [map.grid_node(mt.r) as u32, r as u32, s as u32],
                    f_t0: Vector::<D>::zeros(),
                    points: surface_points(&mt, shape, &m.grid, nodes),
                    reference: mt.outermost,
                    meeting: mt,
                }
            })
            .collect();
        self.assign_history(&p.x, h);
        let tied = |a: usize| step.dofs.ties.get(a).is_some_and(Option::is_some);
        self.joints
            .retain(|j| !tied(j.meeting.r) && !tied(j.meeting.s));
    }

    /// Each meeting's tangential force and gap at the step start: those its
    /// grid node and fields carried out of the last step; a new meeting starts
    /// with no tangential force and the gap between the particles' surfaces.
    /// (The particles' surfaces would not do for a meeting that goes on: a
    /// compressed particle's extent shrinks with F, so the gap they show opens
    /// by the compression of the two half-domains at every step, and the
    /// penalty, closing it, strains the cells at the interface.)
    ///
    /// The carried gap is pinned to the grid node, and a body that slides past
    /// the node brings other particles to it: on a curved surface the gap
    /// there changes although neither surface moved along n (ahead of a
    /// sliding disk's lowest point it closes, behind it opens). So each side
    /// keeps a reference particle, the outermost at the node when the meeting
    /// began; where the outermost particle now lies farther along n than the
    /// reference by more than `OUTERMOST_SWITCH` h, or nearer by as much, the
    /// gap changes by that difference of their centres (both at their
    /// step-start positions x) and the outermost becomes the reference. On a
    /// flat face neighbouring particles differ by the strain between them
    /// only, the reference stays and so does the carried gap.
    fn assign_history(&mut self, x: &[Vector<D>], h: f64) {
        let history = &self.history;
        for j in &mut self.joints {
            j.f_t0 = Vector::<D>::zeros();
            if let Ok(i) = history.binary_search_by_key(&j.key, |k| k.key) {
                let carried = &history[i];
                j.f_t0 = carried.tangential;
                j.meeting.gap = carried.gap;
                j.reference = j.meeting.outermost;
                // Each side's outward normal: n for r, −n for s.
                let outward = [j.meeting.normal, -j.meeting.normal];
                for (side, outward) in outward.iter().enumerate() {
                    // How far the outermost particle lies beyond the reference.
                    let (now, then) = (j.meeting.outermost[side], carried.reference[side]);
                    let (Some(a), Some(b)) = (x.get(now as usize), x.get(then as usize)) else {
                        continue;
                    };
                    let beyond = (a - b).dot(outward);
                    match beyond.abs() > OUTERMOST_SWITCH * h {
                        true => j.meeting.gap -= beyond,
                        false => j.reference[side] = then,
                    }
                }
            }
        }
    }

    /// The meetings at the displacement increments u: the penalty of field r
    /// against s (module docs).
    fn meetings_at(&self, u: &[Vector<D>]) -> Meetings<D> {
        let mut at = Meetings {
            touches: Vec::new(),
            gap: Vec::with_capacity(self.joints.len()),
        };
        for (k, j) in self.joints.iter().enumerate() {
            let mt = &j.meeting;
            let relative =
                (j.points.iter()).fold(Vector::<D>::zeros(), |acc, &(a, c)| acc + u[a] * c);
            let depth = relative.dot(&mt.normal) - mt.gap;
            at.gap.push(-depth);
            if depth < 0.0 {
                continue;
            }
            let inside = Inside {
                point: mt.position,
                normal: -mt.normal,
                normal_derivative: Tensor::<D>::zeros(),
                depth,
                depth_gradient: mt.normal,
            };
            let law = Penalty {
                normal: j.penalty,
                tangential: j.penalty * TANGENTIAL_PENALTY,
                friction: mt.law.friction,
            };
            at.touches.push(NodeTouch {
                meeting: k,
                contact: penalty_force(&law, &inside, &relative, &j.f_t0),
            });
        }
        at
    }

    /// r_a −= c_a f over the nodes of the meetings in contact.
    fn add_forces(&self, at: &Meetings<D>, r: &mut [Vector<D>]) {
        for t in &at.touches {
            for &(a, c) in &self.joints[t.meeting].points {
                r[a] -= t.contact.force * c;
            }
        }
    }
}

impl<const D: usize> StepTerm<D> for BodyContact<D> {
    fn name(&self) -> &'static str {
        "contact between deformable bodies"
    }

    fn cloned(&self) -> Box<dyn StepTerm<D>> {
        Box::new(self.clone())
    }

    fn begin_step(&mut self, step: &StepView<'_, D>, start: &StepStart<'_, D>) {
        self.find_meetings(step, start.shape);
        self.at = Meetings::default();
    }

    /// The nodes of each meeting's two surfaces, pair by pair.
    fn couplings(&self) -> Couplings<'_, D> {
        let mut pairs = Vec::new();
        for j in &self.joints {
            for &(a, _) in &j.points {
                for &(b, _) in j.points.iter().filter(|&&(b, _)| a < b) {
                    pairs.push((a as u32, b as u32));
                }
            }
        }
        Couplings {
            node_pairs: pairs,
            neighbours: None,
        }
    }

    fn evaluate(&mut self, _step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        self.at = self.meetings_at(u);
        self.add_forces(&self.at, r);
    }

    fn probe(&self, _step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        self.add_forces(&self.meetings_at(u), r);
    }

    /// K_ab −= c_a c_b ∂f over the nodes of the meetings in contact.
    fn add_tangent(&self, step: &StepView<'_, D>, _a: &ParticleTangents<D>, k: &mut Tangent) {
        let displacements = Coupling::<D, D>::displacements(Components::All);
        for t in &self.at.touches {
            let d = &t.contact.derivative;
            let points = &self.joints[t.meeting].points;
            for &(a, ca) in points {
                for &(b, cb) in points {
                    let block = d * (-ca * cb);
                    k.add_node_block(step.dofs, (a, b), displacements, |i, j| block[(i, j)]);
                }
            }
        }
    }

    /// Symmetric while every meeting's derivative is (no slip).
    fn symmetric(&self) -> bool {
        (self.at.touches.iter()).all(|t| t.contact.is_symmetric())
    }

    /// Each meeting's tangential force, gap and reference particles carried
    /// to the next step, the contact forces into the pair totals (force × dt).
    fn commit(&mut self, step: &StepView<'_, D>, _u: &[Vector<D>]) {
        debug_assert_eq!(self.at.gap.len(), self.joints.len(), "evaluated");
        let mut tangential = vec![Vector::<D>::zeros(); self.joints.len()];
        for t in &self.at.touches {
            tangential[t.meeting] = t.contact.tangential;
        }
        self.history = (self.joints.iter().zip(tangential).zip(&self.at.gap))
            .map(|((j, f_t), &gap)| CarriedMeeting {
                key: j.key,
                tangential: f_t,
                gap,
                reference: j.reference,
            })
            .collect();
        self.history.sort_by_key(|h| h.key);
        let deepest = (self.at.touches.iter()).map(|t| t.contact.depth);
        self.deepest = self.deepest.max(deepest.fold(0.0, f64::max));
        for total in &mut self.totals {
            total.nodes = 0;
        }
        for t in &self.at.touches {
            let total = &mut self.totals[self.joints[t.meeting].meeting.pair];
            total.impulse += t.contact.force * step.dt;
            total.nodes += 1;
            total.dissipation += t.contact.dissipation;
        }
    }

    /// `CarriedMeeting::VALUES` per meeting, after the rigid bodies' part.
    fn save(&self, state: &mut SolverState) {
        for h in &self.history {
            h.write(&mut state.contact_tangential);
        }
    }

    /// The meetings a checkpoint carried (the next step assigns them).
    fn restore(&mut self, from: &mut Restore<'_>) {
        if let Some(history) = CarriedMeeting::read_all(from.rest_tangential()) {
            self.history = history;
        }
    }

    fn report(&self, report: &mut TermReport) {
        report.penetration(self.deepest);
        report.contacts(self.at.touches.iter().map(|t| t.contact.slips));
    }

    fn take_pair_totals(&mut self, totals: &mut Vec<PairTotal<D>>) {
        hand_over(&mut self.totals, totals);
    }

    /// Its forces act at the split nodes, not on particles: none, but a run
    /// with contact has the `contact_f*` columns.
    fn add_particle_forces(&self, _forces: &mut [Vector<D>]) -> bool {
        true
    }
}

/// The nodes and signed weights that make a meeting's relative displacement
/// u_r(c_r) − u_s(c_s).
///
/// With a particle-domain basis (uGIMP, cpGIMP, CPDI, cpbspline2) each field's
/// surface point (`Meeting::reach`) with the point basis of the family (linear
/// hats, quadratic B-splines), over that field's nodes there, renormalised
/// where the field lacks a node of the basis (the two nodes of the meeting
/// alone if a field holds less than half of it): a body that has settled s
/// below the node row reaches the next row with its domains, and a force at
/// the node would leave s/h of the load there uncarried (1.7 % in the cells
/// beside the interface of two stacked blocks; 0.18 % with the surface points).
///
/// With a point basis (linear, quadratic B-splines) the two nodes of the
/// meeting: a particle transfers to the nodes of its own cell, the bodies
/// exchange their load at the nodes both reach, and a surface point would put
/// s/h of the force on the next row down (1.6 % against 4.5e-5 at the node).
fn surface_points<const D: usize>(
    mt: &Meeting<D>,
    shape: ShapeFunction,
    grid: &Grid<D>,
    nodes: &NodeFields,
) -> Vec<(usize, f64)> {
    let point = match shape {
        ShapeFunction::Linear | ShapeFunction::Bspline2 | ShapeFunction::Bspline3 => {
            return vec![(mt.r, 1.0), (mt.s, -1.0)];
        }
        ShapeFunction::Cpbspline2 => ShapeFunction::Bspline2,
        ShapeFunction::Ugimp | ShapeFunction::Cpgimp | ShapeFunction::Cpdi => ShapeFunction::Linear,
    };
    let one = Vector::<D>::zeros();
    let mut out = Vec::new();
    for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
        let x = mt.position + mt.normal * (sign * mt.reach[side]);
        let x = x.sup(&grid.min).inf(&grid.max);
        let (mut node, mut w, mut grad) = ([0u32; 64], [0.0; 64], [Vector::<D>::zeros(); 64]);
        let n = evaluate(
            point,
            grid,
            &x,
            &one,
            &Mat3::identity(),
            &mut node,
            &mut w,
            &mut grad,
        );
        let field = mt.fields[side] as u32;
        let held: Vec<(usize, f64)> = (0..n)
            .filter(|&k| w[k] != 0.0)
            .filter_map(|k| Some((nodes.active(node[k] as usize, field)?, w[k])))
            .collect();
        let total: f64 = held.iter().map(|h| h.1).sum();
        let own = [mt.r, mt.s][side];
        match total >= 0.5 {
            true => out.extend(held.iter().map(|&(a, w)| (a, sign * w / total))),
            false => out.push((own, sign)),
        }
    }
    out
}
