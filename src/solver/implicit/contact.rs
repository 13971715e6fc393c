//! Penalty contact in the implicit solver (quasi-static and Newmark): with
//! rigid bodies, and between deformable bodies.
//!
//! A rigid body with a prescribed motion is not part of the grid problem: its
//! particles touch no node (their stencils are emptied) and move at their
//! velocity when a step is committed. Its `[[body]]` geometry, carried by that
//! motion to the end of the step, is the master surface of a penalty contact
//! (`solver::implicit::rigid_penalty`) with every deformable particle of a body declared
//! in contact with it: a particle at x_p(u) = x_p + Σ_I S_Ip u_I inside the body
//! feels f_p, which enters the residual like an external force and the tangent
//! through its derivative:
//!
//!   r_I −= S_Ip f_p,   K_IJ −= S_Ip S_Jp ∂f_p/∂x_p.
//!
//! With linear hats or a particle-domain basis (uGIMP, cpGIMP, CPDI,
//! cpbspline2) the point that touches is the particle's contact point instead
//! (`contact_points`):
//! the point c of its domain that faces the nearest body when it first comes
//! within two cells of it, moved by the point basis N_I of the family,
//! x_c(u) = c + Σ_I N_I(c) u_I, in contact when inside the body; S_Ip above
//! becomes N_I(c). The next step starts from where the converged step left it
//! (it moves with the grid, as the body's surface does), while the particle
//! faces the same body. The load then enters at the body's surface, not half a
//! particle inside it.
//!
//! The penalty of particle p is ε_n = ε_t = α M_p A_p / h (α the contact's
//! `penalty_factor`, M_p its material's P-wave modulus, A_p = V⁰_p^{(D−1)/D} its
//! face, h the smallest cell size): a particle pressed by a traction t sinks
//! g ≈ t h / (α M) into the body, which the run reports (summary.json's
//! `contact_penetration`, the deepest of the converged steps).
//! The tangential force at the step start of each particle in contact is kept
//! for the next step (stick carries over steps).
//!
//! **Two deformable bodies** are kept apart on the grid: every grid node that
//! both touch is split into one node per body (`physics::contact::field_split`), so each
//! body has its own displacement there and neither drags the other along. At
//! such a node I the two fields r < s meet with the common normal n (from r to
//! s) and the distance D between their surfaces at the step start (both from the
//! step-start particles, `Meeting`). The step's displacements move the two
//! surfaces by δ relative to each other and close the gap to D − δ·n, so r is
//!
//!   g = δ·n − D
//!
//! deep in s, and a penalty with the same law as above (`penalty_force` with the
//! outward normal −n, fixed within the step, and the relative motion δ) pushes r
//! back and s forward. δ = Σ_a c_a u_a over the nodes of the two surfaces
//! (`surface_points`: the meeting's two nodes, c = ±1, with a point basis; each
//! field's nodes at its surface point, c = ±S_a, with a particle-domain basis),
//! and with ∂f = ∂f/∂δ
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

use super::assembly::{Components, Dofs, Pattern, Storage, Tangent};
use super::ties::NodeFields;
use crate::dim::Mat3;
use crate::dim::Tensor;
use crate::dim::Vector;
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::contact::field_split::{pair_position, FieldSplit, Meeting};
use crate::physics::contact::totals::{pair_totals, PairTotal};
use crate::physics::rigid::newton_euler::to3;
use crate::physics::rigid::surface::{
    on_grid_boundary, rigid_surfaces, Inside, Placement, Surface,
};
use crate::physics::shape::{
    contiguous_half_length, deformation_for, evaluate, ShapeFunction, Stencils,
};
use crate::physics::transfer::{interpolate, stencils, NodeMap};
use crate::scene::contact::ContactPlan;
use crate::solver::implicit::rigid_penalty::{penalty_force, ParticleContact, Penalty};
use rayon::prelude::*;

/// A particle in contact at the last evaluation of the residual.
#[derive(Clone, Copy, Debug)]
pub struct Touch<const D: usize> {
    pub particle: usize,
    /// Index of the rigid body in `PenaltyContact::surfaces`.
    pub surface: usize,
    pub contact: ParticleContact<D>,
    /// Whether it touches at its contact point (`PenaltyContact::contact_points`:
    /// its force and motion go with the point's weights) or at its centre.
    pub at_point: bool,
    /// What round-off in the particle's position leaves in its force:
    /// ε_n × 2.2e-16 × (|x|∞ + |surface point|∞).
    pub round_off: f64,
}

/// How far a contact point carried from the last step may stray from the
/// point of the particle's domain that faces the body, as a fraction of its
/// largest half-length, before it is set back there. Carried, the point rides
/// on the soil's surface and its gap stays continuous from step to step; set
/// anew from x_p − s every step the point left the footing of
/// `problems/contact_footing_implicit.toml` where the soil flows (F of a
/// plastic particle does not move its domain's edge with the grid: gaps of up
/// to 1.4e-4 m grew under the footing's edge), and the points under the
/// footing chattered in and out of contact (1,662 Newton rows, 66 cut-backs,
/// against 576 and 2 carried). Carried, they strayed at most 0.14 of a
/// half-length in that run.
const CARRIED_POINT_STRAY: f64 = 0.5;

/// The smallest nodal area of a meeting, as a fraction of a cell face h^{D−1}.
const MIN_AREA: f64 = 0.05;

/// How far, as a fraction of the smallest cell size, the outermost particle of
/// a side at a meeting must lie beyond or short of its reference particle along
/// the normal before the carried gap follows it (`Fields::assign_history`).
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

/// Two deformable fields in contact at a split node at the last evaluation of
/// the residual.
#[derive(Clone, Copy, Debug)]
pub struct NodeTouch<const D: usize> {
    /// Index of the meeting in `Fields::joints`.
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
    /// Gap at the last residual, D − δ·n.
    gap_end: f64,
    /// Each side's reference particle (`Fields::assign_history`): the
    /// meeting's outermost particles when it began, or where they moved on.
    reference: [u32; 2],
}

/// What a meeting carries to the next step: (grid node, r, s), tangential
/// force, gap at the step's end, reference particles.
type Carried<const D: usize> = ([u32; 3], Vector<D>, f64, [u32; 2]);

/// The contact between deformable bodies on the split grid.
#[derive(Clone, Debug)]
struct Fields<const D: usize> {
    split: FieldSplit,
    /// The field of every active node of this step.
    nodes: Option<NodeFields>,
    /// The meetings of this step.
    joints: Vec<Joint<D>>,
    /// What each meeting carried out of the last step, by (grid node, r, s):
    /// its tangential force, its gap at the step's end and its reference
    /// particles (`Joint::reference`).
    history: Vec<Carried<D>>,
    /// Meetings in contact at the last residual.
    touches: Vec<NodeTouch<D>>,
}

impl<const D: usize> Fields<D> {
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
            if let Ok(i) = history.binary_search_by_key(&j.key, |k| k.0) {
                let (_, f_t0, gap_end, reference) = history[i];
                j.f_t0 = f_t0;
                j.meeting.gap = gap_end;
                j.reference = j.meeting.outermost;
                // Each side's outward normal: n for r, −n for s.
                let outward = [j.meeting.normal, -j.meeting.normal];
                for side in 0..2 {
                    // How far the outermost particle lies beyond the reference.
                    let (now, then) = (j.meeting.outermost[side], reference[side]);
                    let (Some(a), Some(b)) = (x.get(now as usize), x.get(then as usize)) else {
                        continue;
                    };
                    let beyond = (a - b).dot(&outward[side]);
                    match beyond.abs() > OUTERMOST_SWITCH * h {
                        true => j.meeting.gap -= beyond,
                        false => j.reference[side] = then,
                    }
                }
            }
        }
    }

    /// The meetings in contact at the displacement increments u: the penalty
    /// of field r against s (module docs).
    fn evaluate(&mut self, u: &[Vector<D>]) {
        self.touches.clear();
        for (k, j) in self.joints.iter_mut().enumerate() {
            let mt = &j.meeting;
            let relative =
                (j.points.iter()).fold(Vector::<D>::zeros(), |acc, &(a, c)| acc + u[a] * c);
            let depth = relative.dot(&mt.normal) - mt.gap;
            j.gap_end = -depth;
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
            self.touches.push(NodeTouch {
                meeting: k,
                contact: penalty_force(&law, &inside, &relative, &j.f_t0),
            });
        }
    }
}

/// The implicit solver's penalty contact.
#[derive(Clone, Debug)]
pub struct PenaltyContact<const D: usize> {
    plan: ContactPlan,
    /// Field of each particle.
    field: Vec<u32>,
    /// The rigid bodies some deformable body is in contact with.
    surfaces: Vec<Surface>,
    /// Whether each field is deformable and in contact with a rigid body.
    slave: Vec<bool>,
    /// Tangential force of each particle at the step start (empty when every
    /// contact is frictionless).
    tangential: Vec<Vector<D>>,
    /// The rigid bodies' placements at the end of the step and their motion
    /// over it.
    end: Vec<Placement>,
    motion: Vec<Vector<D>>,
    /// Contacts at the last residual, in particle order.
    pub touches: Vec<Touch<D>>,
    /// Per stencil entry (stride of the step's stencils) of each particle: the
    /// weight with which its contact point moves and takes its force
    /// (`contact_points`); empty when the particles' own weights serve.
    point_weights: Vec<f64>,
    /// Each particle's contact point at the step start and the rigid body it
    /// faces, where it has one.
    contact_point: Vec<Option<(usize, Vector<D>)>>,
    /// How far each contact point has moved at the last residual, Σ N_I(c) u_I.
    point_motion: Vec<Option<Vector<D>>>,
    /// Where the last converged step left them: the next step's contact points.
    carried: Vec<Option<(usize, Vector<D>)>>,
    totals: Vec<PairTotal<D>>,
    /// The deepest penalty depth of a converged step so far.
    pub deepest: f64,
    /// Contact between deformable bodies (None without such a pair).
    fields: Option<Fields<D>>,
}

impl<const D: usize> PenaltyContact<D> {
    /// The contact of model m with rigid bodies, or None without any.
    pub fn new(m: &Model<D>) -> Option<Self> {
        let plan = m.contact.clone()?;
        let p = &m.particles;
        let field: Vec<u32> = (p.body.iter())
            .map(|&b| plan.field_of_body[b as usize])
            .collect();
        let paired = |k: usize| (0..plan.fields).any(|j| plan.law(k as u32, j as u32).is_some());
        let surfaces = rigid_surfaces(&plan, m, &field, &paired);
        let deformable = |i: usize| !plan.rigid[i];
        let deformable_pair = (0..plan.fields).any(|i| {
            (i + 1..plan.fields)
                .any(|j| deformable(i) && deformable(j) && plan.law(i as u32, j as u32).is_some())
        });
        if surfaces.is_empty() && !deformable_pair {
            return None;
        }
        let touches_some =
            |f: usize| (surfaces.iter()).any(|s| plan.law(f as u32, s.field).is_some());
        let slave: Vec<bool> = (0..plan.fields)
            .map(|f| !plan.rigid[f] && touches_some(f))
            .collect();
        let friction = (plan.laws.iter()).any(|l| l.is_some_and(|l| l.friction > 0.0));
        let tangential = match friction && !surfaces.is_empty() {
            true => vec![Vector::<D>::zeros(); p.len()],
            false => Vec::new(),
        };
        let fields = deformable_pair.then(|| Fields {
            split: FieldSplit::new(field.clone()),
            nodes: None,
            joints: Vec::new(),
            history: Vec::new(),
            touches: Vec::new(),
        });
        let totals = pair_totals(&plan);
        Some(PenaltyContact {
            plan,
            field,
            surfaces,
            slave,
            tangential,
            end: Vec::new(),
            motion: Vec::new(),
            touches: Vec::new(),
            point_weights: Vec::new(),
            contact_point: Vec::new(),
            point_motion: Vec::new(),
            carried: Vec::new(),
            totals,
            deepest: 0.0,
            fields,
        })
    }

    /// The step's stencils and node map: the rigid bodies' particles left out
    /// and, with contact between deformable bodies, their shared nodes split
    /// and the meetings there found (from the step-start particles).
    pub fn stencils(
        &mut self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &mut Stencils<D>,
        map: &mut NodeMap,
    ) {
        stencils(m, shape, st);
        self.leave_out_rigid(st);
        let n_grid = m.grid.node_count();
        let Some(fields) = self.fields.as_mut() else {
            map.build(st, n_grid);
            return;
        };
        fields.split.split(st, map, n_grid);
        let h = m.grid.h_min();
        let mut meetings = fields.split.meetings(&self.plan, m, st, map, true);
        // Where both fields' volume gradients are small the node is inside both
        // stencils but at neither surface: its normal would be round-off and
        // its gap along it meaningless (two bodies' particles side by side
        // across the node), so it is no meeting.
        let face = h.powi(D as i32 - 1);
        meetings.retain(|mt| mt.area >= MIN_AREA * face);
        let (p, owner) = (&m.particles, st.owner());
        let of = (0..map.len())
            .map(|a| fields.split.field(owner.of(map.node_entries(a)[0])))
            .collect();
        let nodes = NodeFields::new(map, of);
        // ε = α M A / h, M the stiffer material at the two nodes.
        let modulus = |a: usize| {
            (map.node_entries(a).iter())
                .map(|&e| m.materials[p.material[owner.of(e)] as usize].p_wave_modulus())
                .fold(0.0, f64::max)
        };
        fields.joints = (meetings.into_iter())
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
                    points: surface_points(&mt, shape, &m.grid, &nodes),
                    gap_end: mt.gap,
                    reference: mt.outermost,
                    meeting: mt,
                }
            })
            .collect();
        fields.nodes = Some(nodes);
        fields.assign_history(&p.x, h);
        fields.touches.clear();
    }

    /// Drop the meetings at tied (weakly supported) nodes: a tied node's
    /// displacement is extrapolated from its masters, and a penalty on it would
    /// act on them through the extrapolation's lever (coefficients 2 and −1).
    pub fn drop_tied_meetings(&mut self, dofs: &Dofs) {
        let Some(f) = self.fields.as_mut() else {
            return;
        };
        let tied = |a: usize| dofs.ties.get(a).is_some_and(Option::is_some);
        f.joints
            .retain(|j| !tied(j.meeting.r) && !tied(j.meeting.s));
    }

    /// The field of every active node of this step, with contact between
    /// deformable bodies (for the ties of weakly supported nodes, which must
    /// not cross bodies).
    pub fn node_fields(&self) -> Option<&NodeFields> {
        self.fields.as_ref()?.nodes.as_ref()
    }

    /// Pairs of active nodes that the contact couples beyond the stencils (the
    /// two nodes of each meeting), for the tangent's pattern.
    pub fn coupled_nodes(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for j in self.fields.iter().flat_map(|f| &f.joints) {
            for &(a, _) in &j.points {
                for &(b, _) in j.points.iter().filter(|&&(b, _)| a < b) {
                    pairs.push((a as u32, b as u32));
                }
            }
        }
        pairs
    }

    /// Whether particle q belongs to a rigid body (it stays off the grid).
    pub fn is_rigid(&self, q: usize) -> bool {
        self.plan.rigid[self.field[q] as usize]
    }

    /// Empty the stencils of the rigid bodies' particles.
    pub fn leave_out_rigid(&self, st: &mut Stencils<D>) {
        for q in (0..self.field.len()).filter(|&q| self.is_rigid(q)) {
            st.count[q] = 0;
        }
    }

    /// The rigid bodies' motion over the step t → t + dt (their particles'
    /// velocity) and their placements at its end.
    pub fn start_step(
        &mut self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &Stencils<D>,
        map: &NodeMap,
        dt: f64,
    ) {
        let p = &m.particles;
        self.motion = (self.surfaces.iter())
            .map(|s| p.v[s.particle()] * dt)
            .collect();
        self.end = (self.surfaces.iter().zip(&self.motion))
            .map(|(s, u)| s.placement(p).shifted(&to3(u)))
            .collect();
        self.touches.clear();
        (self.point_weights, self.contact_point) = self.contact_points(m, shape, st, map);
    }

    /// Each particle's contact point at the step start and the weight of each
    /// of its stencil entries there: c = x_p − s, s the point of its domain
    /// (`domain_support`) that faces the nearest rigid surface (outward normal
    /// n, at the end of the step), with the point basis of the family (linear
    /// hats for linear, uGIMP, cpGIMP and CPDI, quadratic B-splines for cpbspline2)
    /// over the particle's own nodes, renormalised. A point that faced the same
    /// body in the last step goes on from where that step's motion took it
    /// (`carried`), unless it strayed from x_p − s by more than
    /// `CARRIED_POINT_STRAY` of the particle's half-length. None (and the
    /// particle keeps its own weights) where no rigid body is within two cells or the
    /// basis is a B-spline: such a particle is a point with its reach. Linear
    /// hats take the point of their reference domain, as uGIMP does: the
    /// explicit contact supports a body's nodes, and where the implicit
    /// penalty acted at the centres a block handed from an implicit stage to
    /// an explicit one on a rigid base rang (kinetic energy 1.6e-2 of the
    /// strain energy; at the contact points 7.6e-10).
    fn contact_points(
        &self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &Stencils<D>,
        map: &NodeMap,
    ) -> (Vec<f64>, Vec<Option<(usize, Vector<D>)>>) {
        let point = match shape {
            ShapeFunction::Linear
            | ShapeFunction::Ugimp
            | ShapeFunction::Cpgimp
            | ShapeFunction::Cpdi => ShapeFunction::Linear,
            ShapeFunction::Cpbspline2 => ShapeFunction::Bspline2,
            _ => return (Vec::new(), Vec::new()),
        };
        if self.surfaces.is_empty() {
            return (Vec::new(), Vec::new());
        }
        let p = &m.particles;
        let on_boundary = on_grid_boundary(&m.grid);
        let h = m.grid.h_min();
        let stride = st.stride;
        let mut out = vec![0.0; p.len() * stride];
        let mut points = vec![None; p.len()];
        out.par_chunks_mut(stride)
            .zip(points.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(q, (w, point_of))| {
                // A particle without a contact point keeps its own weights
                // (`Touch::at_point` false): its row here is not read.
                if !self.slave[self.field[q] as usize] || st.count[q] == 0 {
                    return;
                }
                let ell = &p.half_length0[q];
                let near = ell.add_scalar(2.0 * h);
                // The nearest of the bodies it is in contact with.
                let found = (self.surfaces.iter().enumerate())
                    .filter_map(|(k, s)| {
                        self.plan.law(self.field[q], s.field)?;
                        Some((k, s.reached(&self.end[k], &p.x[q], &near, &on_boundary)?))
                    })
                    .max_by(|a, b| a.1.depth.total_cmp(&b.1.depth));
                let Some((body, inside)) = found else {
                    return;
                };
                let f = deformation_for(shape, || p.f.get(q));
                let offset = domain_support(shape, &m.grid, ell, &f, &inside.normal);
                let on_domain = p.x[q] - offset;
                let c = match self.carried.get(q).copied().flatten() {
                    Some((k, c))
                        if k == body
                            && (c - on_domain).norm() <= CARRIED_POINT_STRAY * ell.max() =>
                    {
                        c
                    }
                    _ => on_domain,
                };
                let c = c.sup(&m.grid.min).inf(&m.grid.max);
                let one = Vector::<D>::zeros();
                let (mut node, mut nw, mut grad) =
                    ([0u32; 64], [0.0; 64], [Vector::<D>::zeros(); 64]);
                let count = evaluate(
                    point,
                    &m.grid,
                    &c,
                    &one,
                    &Mat3::identity(),
                    &mut node,
                    &mut nw,
                    &mut grad,
                );
                let mut total = 0.0;
                for (k, e) in st.range(q).enumerate() {
                    let g = map.grid_node(map.local_of(st, e)) as u32;
                    w[k] = (0..count).find(|&i| node[i] == g).map_or(0.0, |i| nw[i]);
                    total += w[k];
                }
                if total < 0.5 {
                    return;
                }
                w.iter_mut().for_each(|x| *x /= total);
                *point_of = Some((body, c));
            });
        (out, points)
    }

    /// The weight of stencil entry e of a particle in contact (`at_point`:
    /// at its contact point, else at its centre).
    fn contact_weight(&self, at_point: bool, st: &Stencils<D>, e: usize) -> f64 {
        match at_point {
            true => self.point_weights[e],
            false => st.weight(e),
        }
    }

    /// The contacts at the nodal displacement increments u (`touches`).
    pub fn evaluate(&mut self, m: &Model<D>, st: &Stencils<D>, map: &NodeMap, u: &[Vector<D>]) {
        let p = &m.particles;
        let on_boundary = on_grid_boundary(&m.grid);
        let h = m.grid.h_min();
        self.point_motion = (self.contact_point.par_iter().enumerate())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(q, point)| {
                point.map(|_| {
                    st.range(q).fold(Vector::<D>::zeros(), |acc, e| {
                        acc + u[map.local_of(st, e)] * self.point_weights[e]
                    })
                })
            })
            .collect();
        let this = &*self;
        let touches = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&q| this.slave[this.field[q] as usize] && st.count[q] > 0)
            .filter_map(|q| {
                let f = this.field[q];
                let point = this.contact_point.get(q).copied().flatten();
                let touch = |k: usize, at_point: bool| {
                    let s = &this.surfaces[k];
                    let law = this.plan.law(f, s.field)?;
                    // At its contact point (a point: a reach of 1e-9 of the
                    // particle's), or at its centre with the particle's reach.
                    let point_reach = p.half_length0[q] * 1e-9;
                    let (x, dx, ell) = match (at_point, point) {
                        (true, Some((_, c))) => {
                            let dx = this.point_motion[q].expect("a contact point moves");
                            (c + dx, dx, &point_reach)
                        }
                        _ => {
                            let dx = interpolate(map, st, q, u);
                            (p.x[q] + dx, dx, &p.half_length0[q])
                        }
                    };
                    let inside = s.reached(&this.end[k], &x, ell, &on_boundary)?;
                    // ε = α M A / h.
                    let modulus = m.materials[p.material[q] as usize].p_wave_modulus();
                    let face = p.volume0[q].powf((D as f64 - 1.0) / D as f64);
                    let epsilon = law.penalty_factor * modulus * face / h;
                    let penalty = Penalty {
                        normal: epsilon,
                        tangential: epsilon,
                        friction: law.friction,
                    };
                    let f_t0 = this
                        .tangential
                        .get(q)
                        .copied()
                        .unwrap_or(Vector::<D>::zeros());
                    let relative = dx - this.motion[k];
                    let magnitude = x.amax() + inside.point.amax();
                    Some(Touch {
                        particle: q,
                        surface: k,
                        contact: penalty_force(&penalty, &inside, &relative, &f_t0),
                        at_point,
                        round_off: epsilon * f64::EPSILON * magnitude,
                    })
                };
                // The body its contact point faces at that point; the others
                // (a corner of two bodies) at its centre.
                let faced = point.map(|(k, _)| k);
                faced.and_then(|k| touch(k, true)).or_else(|| {
                    (0..this.surfaces.len())
                        .filter(|&k| Some(k) != faced)
                        .find_map(|k| touch(k, false))
                })
            })
            .collect();
        self.touches = touches;
        if let Some(fields) = self.fields.as_mut() {
            fields.evaluate(u);
        }
    }

    /// r_I −= S_Ip f_p over the particles in contact; r_a −= c_a f over the
    /// nodes of the meetings in contact.
    pub fn add_residual(&self, map: &NodeMap, st: &Stencils<D>, r: &mut [Vector<D>]) {
        for t in &self.touches {
            for e in st.range(t.particle) {
                r[map.local_of(st, e)] -= t.contact.force * self.contact_weight(t.at_point, st, e);
            }
        }
        for (f, t) in self.node_touches() {
            for &(a, c) in &f.joints[t.meeting].points {
                r[a] -= t.contact.force * c;
            }
        }
    }

    /// The meetings in contact at the last residual, with their fields.
    fn node_touches(&self) -> impl Iterator<Item = (&Fields<D>, &NodeTouch<D>)> {
        (self.fields.iter()).flat_map(|f| f.touches.iter().map(move |t| (f, t)))
    }

    /// The residual's round-off floor from the contacts with rigid bodies at
    /// the last residual: √Σ (ε_n ε_mach |x|)² over the particles in contact.
    /// A particle's depth is a difference of positions (r − d, d from x and the
    /// surface point), so it carries round-off ε_mach |x| whatever u is, and
    /// its force ε_n times that: with ε_n = α M A / h this can exceed the
    /// residual tolerance (a block of E = 10 MPa resting on a rigid base with
    /// h = 0.05 m: 1–2.4e-9 of its weight against an estimate of 1.9e-9).
    pub fn residual_floor(&self) -> f64 {
        (self.touches.iter())
            .map(|t| t.round_off * t.round_off)
            .sum::<f64>()
            .sqrt()
    }

    /// Whether every contact's derivative is symmetric (plane faces, no slip).
    pub fn symmetric(&self) -> bool {
        let symmetric = |c: &ParticleContact<D>| {
            let d = &c.derivative;
            (d - d.transpose()).amax() <= 1e-10 * d.amax()
        };
        self.touches.iter().all(|t| symmetric(&t.contact))
            && self.node_touches().all(|(_, t)| symmetric(&t.contact))
    }

    /// K_IJ −= S_Ip S_Jp ∂f_p/∂x_p over the particles in contact; K_ab −= c_a
    /// c_b ∂f over the nodes of the meetings in contact.
    pub fn add_tangent(
        &self,
        k: &mut Tangent,
        pattern: &Pattern,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
    ) {
        for (f, t) in self.node_touches() {
            let d = &t.contact.derivative;
            let points = &f.joints[t.meeting].points;
            for &(a, ca) in points {
                for &(b, cb) in points {
                    add_node_block(k, dofs, a, b, &(d * (-ca * cb)));
                }
            }
        }
        if self.touches.is_empty() {
            return;
        }
        let (col_ptr, storage) = (k.col_ptr, k.storage);
        let touches = &self.touches;
        pattern.add_stencil_terms(
            &mut k.values,
            col_ptr,
            storage,
            map,
            st,
            dofs,
            Components::All,
            |q, e2, needed, block| {
                let Ok(i) = touches.binary_search_by_key(&q, |t| t.particle) else {
                    return false;
                };
                let (d, at_point) = (&touches[i].contact.derivative, touches[i].at_point);
                let w2 = self.contact_weight(at_point, st, e2);
                for (local, e1) in st.range(q).enumerate() {
                    if !needed[local] {
                        continue;
                    }
                    let w = -self.contact_weight(at_point, st, e1) * w2;
                    for a in 0..D {
                        for b in 0..D {
                            block[local * D * D + a * D + b] = w * d[(a, b)];
                        }
                    }
                }
                true
            },
        );
    }

    /// The converged step: the tangential forces and the contact points
    /// carried to the next step, the contact forces into the pair totals
    /// (force × dt), and the rigid bodies' particles moved by their motion.
    pub fn commit(&mut self, p: &mut Particles<D>, dt: f64) {
        self.carried = (self.contact_point.iter().zip(&self.point_motion))
            .map(|(c, dx)| Some((c.as_ref()?.0, c.as_ref()?.1 + (*dx)?)))
            .collect();
        self.deepest = self.deepest.max(self.max_penetration());
        if !self.tangential.is_empty() {
            self.tangential
                .iter_mut()
                .for_each(|f| *f = Vector::<D>::zeros());
            for t in &self.touches {
                self.tangential[t.particle] = t.contact.tangential;
            }
        }
        for total in &mut self.totals {
            total.nodes = 0;
        }
        for t in &self.touches {
            let (r, s) = (self.field[t.particle], self.surfaces[t.surface].field);
            let (lo, hi) = (r.min(s) as usize, r.max(s) as usize);
            let i = pair_position(self.plan.fields, lo, hi);
            let sign = if r < s { 1.0 } else { -1.0 };
            let total = &mut self.totals[i];
            total.impulse += t.contact.force * (sign * dt);
            total.nodes += 1;
            total.dissipation += t.contact.dissipation;
        }
        if let Some(f) = self.fields.as_mut() {
            let mut tangential = vec![Vector::<D>::zeros(); f.joints.len()];
            for t in &f.touches {
                tangential[t.meeting] = t.contact.tangential;
            }
            f.history = (f.joints.iter().zip(tangential))
                .map(|(j, f_t)| (j.key, f_t, j.gap_end, j.reference))
                .collect();
            f.history.sort_by_key(|h| h.0);
            for t in &f.touches {
                let total = &mut self.totals[f.joints[t.meeting].meeting.pair];
                total.impulse += t.contact.force * dt;
                total.nodes += 1;
                total.dissipation += t.contact.dissipation;
            }
        }
        for q in 0..p.len() {
            if self.is_rigid(q) {
                p.x[q] += p.v[q] * dt;
            }
        }
    }

    /// Values per meeting in `tangential_state`: its grid node, fields r and
    /// s, tangential force (D), gap and reference particles (2).
    const MEETING_VALUES: usize = 6 + D;

    /// The tangential forces carried to the next step, D values per particle
    /// (empty without friction), for a checkpoint.
    /// Then, with contact between deformable bodies, `MEETING_VALUES` per
    /// meeting.
    pub fn tangential_state(&self) -> Vec<f64> {
        let particles = self.tangential.iter().flat_map(|f| f.iter().copied());
        let meetings = (self.fields.iter()).flat_map(|f| {
            (f.history.iter()).flat_map(|(key, v, gap, reference)| {
                let key = key.iter().map(|&k| k as f64);
                let reference = reference.iter().map(|&q| q as f64);
                key.chain(v.iter().copied()).chain([*gap]).chain(reference)
            })
        });
        particles.chain(meetings).collect()
    }

    /// Continue with the tangential forces of a checkpoint (`tangential_state`;
    /// nothing happens with an empty one), the particles at x, h the smallest
    /// cell size.
    pub fn restore_tangential(&mut self, state: &[f64], x: &[Vector<D>], h: f64) {
        let n = self.tangential.len() * D;
        if state.is_empty() || state.len() < n || (state.len() - n) % Self::MEETING_VALUES != 0 {
            return;
        }
        self.tangential = (state[..n].chunks_exact(D))
            .map(Vector::<D>::from_column_slice)
            .collect();
        if let Some(f) = self.fields.as_mut() {
            f.history = (state[n..].chunks_exact(Self::MEETING_VALUES))
                .map(|c| {
                    let key = [c[0] as u32, c[1] as u32, c[2] as u32];
                    let reference = [c[4 + D] as u32, c[5 + D] as u32];
                    (
                        key,
                        Vector::<D>::from_column_slice(&c[3..3 + D]),
                        c[3 + D],
                        reference,
                    )
                })
                .collect();
            f.assign_history(x, h);
        }
    }

    /// The contact points carried to the next step, for a checkpoint: 2 + D
    /// values per particle that has one (particle, rigid body, point).
    pub fn carried_points(&self) -> Vec<f64> {
        (self.carried.iter().enumerate())
            .filter_map(|(q, c)| c.map(|(k, c)| (q, k, c)))
            .flat_map(|(q, k, c)| {
                let point: [f64; D] = c.into();
                [q as f64, k as f64].into_iter().chain(point)
            })
            .collect()
    }

    /// Continue with the contact points of a checkpoint (`carried_points`) for
    /// the n particles. An entry that names no particle or rigid body, or whose
    /// point is not finite, is left out: that particle's point is set on its
    /// domain, as for a particle that comes near a body.
    pub fn restore_carried_points(&mut self, state: &[f64], n: usize) {
        self.carried = vec![None; n];
        let index = |v: f64, len: usize| {
            (v >= 0.0 && v.fract() == 0.0 && v < len as f64).then_some(v as usize)
        };
        for c in state.chunks_exact(2 + D) {
            let point = Vector::<D>::from_column_slice(&c[2..]);
            if let (Some(q), Some(k), true) = (
                index(c[0], n),
                index(c[1], self.surfaces.len()),
                point.iter().all(|x| x.is_finite()),
            ) {
                self.carried[q] = Some((k, point));
            }
        }
    }

    /// Contacts sticking and slipping at the last residual (particles against
    /// rigid bodies and meetings of deformable bodies).
    pub fn stick_and_slip(&self) -> (usize, usize) {
        let slips = (self.touches.iter().map(|t| t.contact.slips))
            .chain(self.node_touches().map(|(_, t)| t.contact.slips));
        slips.fold((0, 0), |(k, s), slip| match slip {
            true => (k, s + 1),
            false => (k + 1, s),
        })
    }

    /// The contact force on each of `n` particles at the last residual (zero
    /// for particles out of contact and for the rigid bodies' own).
    pub fn particle_forces(&self, n: usize) -> Vec<Vector<D>> {
        let mut f = vec![Vector::<D>::zeros(); n];
        for t in &self.touches {
            f[t.particle] += t.contact.force;
        }
        f
    }

    /// The deepest penetration at the last residual.
    pub fn max_penetration(&self) -> f64 {
        let particles = self.touches.iter().map(|t| t.contact.depth);
        let nodes = self.node_touches().map(|(_, t)| t.contact.depth);
        particles.chain(nodes).fold(0.0, f64::max)
    }

    /// The totals since the last call, reset.
    pub fn take_totals(&mut self) -> Vec<PairTotal<D>> {
        let out = self.totals.clone();
        for t in &mut self.totals {
            t.impulse = Vector::<D>::zeros();
            t.dissipation = 0.0;
        }
        out
    }
}

/// K_ab += block over the unknowns of active nodes a and b (a tied node's
/// terms going to its masters; the lower triangle only with `Lower`).
fn add_node_block<const D: usize>(
    k: &mut Tangent,
    dofs: &Dofs,
    a: usize,
    b: usize,
    block: &Tensor<D>,
) {
    for i in 0..D {
        let rows = dofs.terms(a, i);
        for j in 0..D {
            for &(r, cr) in rows.as_slice() {
                for &(c, cc) in dofs.terms(b, j).as_slice() {
                    if k.storage == Storage::Full || r >= c {
                        let s = k.slot(r, c).expect("contact entry in the pattern");
                        k.values[s] += block[(i, j)] * cr * cc;
                    }
                }
            }
        }
    }
}

/// The point of a particle's domain that faces a surface of outward normal n,
/// relative to the particle: the support point of its reach ellipse as the
/// family shapes the domain. Linear and uGIMP: the reference half-lengths L,
/// L² n / |L n|;
/// cpGIMP and cpbspline2: the same with the contiguous half-lengths (L stretched
/// by F_dd, axis-aligned, `contiguous_half_length`); CPDI: the ellipse carried by
/// F, F L² Fᵀ n / |L Fᵀ n|.
fn domain_support<const D: usize>(
    shape: ShapeFunction,
    grid: &Grid<D>,
    half_length0: &Vector<D>,
    f: &Mat3,
    n: &Vector<D>,
) -> Vector<D> {
    let support = |l: &Vector<D>, n: &Vector<D>| {
        let l2n = l.component_mul(l).component_mul(n);
        l2n / l2n.dot(n).sqrt()
    };
    match shape {
        ShapeFunction::Cpgimp | ShapeFunction::Cpbspline2 => {
            support(&contiguous_half_length(grid, half_length0, f), n)
        }
        ShapeFunction::Cpdi => {
            let f = crate::dim::restrict::<D>(f);
            let ftn = f.transpose() * n;
            let l2ftn = half_length0.component_mul(half_length0).component_mul(&ftn);
            f * l2ftn / half_length0.component_mul(&ftn).norm()
        }
        _ => support(half_length0, n),
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// The contact point faces the surface on the domain as each family shapes
    /// it: CPDI's ellipse turns with F, cpGIMP's box stretches along the axes.
    #[test]
    fn a_domain_s_support_point_follows_its_family() {
        let grid = Grid::<2>::new(Vector2::zeros(), Vector2::new(4.0, 4.0), [4, 4], 1);
        let up = Vector2::new(0.0, 1.0);
        // Turned by 90°: the long half-axis 0.2 now points along y.
        let turn = Mat3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let ell = Vector2::new(0.2, 0.1);
        let cpdi = domain_support(ShapeFunction::Cpdi, &grid, &ell, &turn, &up);
        assert!((cpdi - Vector2::new(0.0, 0.2)).norm() < 1e-15, "{cpdi}");
        // Squashed to half along y (and stretched along x).
        let squash = Mat3::new(1.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0);
        let round = Vector2::new(0.1, 0.1);
        let cp = domain_support(ShapeFunction::Cpgimp, &grid, &round, &squash, &up);
        assert!((cp - Vector2::new(0.0, 0.05)).norm() < 1e-15, "{cp}");
        // uGIMP's domain does not deform; a tilted normal meets the ellipse
        // where its outward normal is n.
        let n = Vector2::new(0.6, 0.8);
        let u = domain_support(ShapeFunction::Ugimp, &grid, &ell, &squash, &n);
        let on_ellipse = (u[0] / ell[0]).powi(2) + (u[1] / ell[1]).powi(2);
        let normal = Vector2::new(u[0] / ell[0].powi(2), u[1] / ell[1].powi(2)).normalize();
        assert!((on_ellipse - 1.0).abs() < 1e-14 && (normal - n).norm() < 1e-14);
    }
}
