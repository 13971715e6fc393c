//! The grid of several velocity fields: every field (`scene::contact`: bodies
//! without a contact between them form one) gets a node of its own at each grid
//! node that particles of two or more fields touch, and each pair of fields
//! that meets there gets a common normal, a nodal area and the gap between
//! their surfaces (a [`Meeting`]). The explicit contact (`solver::explicit::contact`)
//! corrects the fields' velocities at the meetings; the implicit one
//! (`solver::implicit::terms::contact::bodies`) puts a penalty between their displacements.
//!
//! **Split nodes.** A shared grid node is split: each field gets a node with an
//! id past the grid's node count (`NodeMap::split`), and the stencil entries of
//! its particles there are renumbered to it. Every transfer then works per field
//! without change, and a node that one field touches stays as it is. A scene
//! whose fields never share a node splits nothing.
//!
//! **A meeting** of fields r < s at grid node I:
//! - normal: one n from r to s (review 002 eq. 37), from the "volume gradients"
//!   g = Σ_p V_p ∇S_Ip of the fields (≈ ∮ S_I n dA over a field's boundary, so g
//!   points out of its field): by default the unit g of the field with the
//!   larger |g|, ĝ_r or −ĝ_s (Nairn's maximum volume gradient); or the average
//!   (ĝ_r − ĝ_s)/|ĝ_r − ĝ_s| (MPM3D);
//! - gap: D = D_r + D_s (42), with D_r = −max_p((x_p − x_I)·n + l_p) over r's
//!   particles at I and D_s the same along −n (001 eq. 5); l_p is the extent of
//!   the particle's domain along the normal, Σ_d l⁰_d |n·F e_d|. Between two
//!   deformable fields the max runs over the particles whose domain spans the
//!   line through x_I along n (lateral offset within the domain's extent that
//!   way), not over the whole stencil: the gap at the node, not the smallest gap
//!   within 1–2 cells of it (docs/contact.md, "Why the spin lagged");
//! - area: the mean of |g_r| and |g_s| (the nodal share of the interface).

use crate::dim::Vector;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::rigid::surface::on_grid_boundary;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::scene::contact::{ContactLaw, ContactPlan};
use crate::scene::ContactNormal;
use rayon::prelude::*;
use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;

/// Two fields meeting at a node in this step.
#[derive(Clone, Copy, Debug)]
pub struct Meeting<const D: usize> {
    /// Active indices of the two split nodes (field r < field s).
    pub r: usize,
    pub s: usize,
    /// Index of the field pair in `Contact::totals`.
    pub pair: usize,
    /// The fields r < s.
    pub fields: [usize; 2],
    /// The grid node's position.
    pub position: Vector<D>,
    /// Common normal, from r to s.
    pub normal: Vector<D>,
    /// Whether r and s are rigid bodies.
    pub rigid: [bool; 2],
    /// Nodal contact area (length per unit thickness in 2D).
    pub area: f64,
    /// Distance between the fields' surfaces along the normal, D = D_r + D_s
    /// (negative where they overlap).
    pub gap: f64,
    /// How far each field's surface lies beyond the node along its outward
    /// normal (n for r, −n for s): r's surface is at x_I + reach[0] n, s's at
    /// x_I − reach[1] n.
    pub reach: [f64; 2],
    /// The particles of r and s whose centres lie farthest along n and −n
    /// among those that give the gap (`u32::MAX` where none does): the implicit
    /// contact follows them from step to step (`solver::implicit::terms::contact::bodies`).
    pub outermost: [u32; 2],
    /// The gap criterion D ≤ λ h holds.
    pub close: bool,
    pub law: ContactLaw,
}

/// The position of the pair of fields i < j among `fields` fields in
/// [`pair_totals`]: the pairs (0, 1), (0, 2), …, (1, 2), … in order.
pub fn pair_position(fields: usize, i: usize, j: usize) -> usize {
    debug_assert!(i < j && j < fields);
    i * fields - i * (i + 1) / 2 + (j - i - 1)
}

/// The split of shared grid nodes into one node per field.
#[derive(Debug, Default)]
pub struct FieldSplit {
    /// Field of each particle.
    field: Vec<u32>,
    /// Grid node and field of each split node of this step, ascending.
    split: Vec<(u32, u32)>,
    /// Scratch of `split_shared_nodes`, one entry per grid node: the fields that
    /// touch it (bit f for field f) and, at a shared node, its first split id.
    fields_at: Vec<AtomicU64>,
    offset: Vec<u32>,
}

impl Clone for FieldSplit {
    /// The fields and this step's split; the scratch starts afresh.
    fn clone(&self) -> Self {
        FieldSplit {
            field: self.field.clone(),
            split: self.split.clone(),
            ..Default::default()
        }
    }
}

impl FieldSplit {
    /// The split for particles of the given fields.
    pub fn new(field: Vec<u32>) -> Self {
        FieldSplit {
            field,
            ..Default::default()
        }
    }

    /// Field of particle q.
    pub fn field(&self, q: usize) -> u32 {
        self.field[q]
    }

    /// Split the shared nodes of the stencils `st` (their entries renumbered)
    /// and build the node map over the grid's and the split nodes.
    pub fn split<const D: usize>(
        &mut self,
        st: &mut Stencils<D>,
        map: &mut NodeMap,
        n_grid: usize,
    ) {
        map.split = self.split_shared_nodes(st, n_grid);
        map.build(st, n_grid + map.split.len());
    }

    /// Give every field its own node at each grid node that several fields touch:
    /// renumber those stencil entries to split ids (n_grid + k) and return the grid
    /// node of each split id. A bit mask of the fields at each grid node finds the
    /// shared nodes; the split ids follow grid node and field order, so they are
    /// the same for any order of the particles and any number of threads.
    fn split_shared_nodes<const D: usize>(
        &mut self,
        st: &mut Stencils<D>,
        n_grid: usize,
    ) -> Vec<u32> {
        if self.fields_at.len() != n_grid {
            self.fields_at = (0..n_grid).map(|_| AtomicU64::new(0)).collect();
            self.offset = vec![0; n_grid];
        }
        let (mask, field) = (&self.fields_at, &self.field);
        let n_particles = st.count.len();
        (0..n_particles)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|p| {
                let bit = 1u64 << field[p];
                for e in st.range(p) {
                    let m = &mask[st.node[e] as usize];
                    if m.load(Relaxed) & bit == 0 {
                        m.fetch_or(bit, Relaxed);
                    }
                }
            });
        let several = |m: u64| m & m.wrapping_sub(1) != 0;
        let shared: Vec<u32> = (0..n_grid as u32)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&g| several(mask[g as usize].load(Relaxed)))
            .collect();
        self.split.clear();
        for &g in &shared {
            self.offset[g as usize] = self.split.len() as u32;
            let mut m = mask[g as usize].load(Relaxed);
            while m != 0 {
                self.split.push((g, m.trailing_zeros()));
                m &= m - 1;
            }
        }
        let (stride, count, offset) = (st.stride, &st.count, &self.offset);
        st.node
            .par_chunks_mut(stride)
            .zip(count.par_iter())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(p, (nodes, &n))| {
                let below = (1u64 << field[p]) - 1;
                for g in &mut nodes[..n as usize] {
                    let m = mask[*g as usize].load(Relaxed);
                    if several(m) {
                        let k = offset[*g as usize] + (m & below).count_ones();
                        *g = (n_grid as u32) + k;
                    }
                }
            });
        // Clear the masks for the next step.
        mask.par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|m| m.store(0, Relaxed));
        self.split.iter().map(|&(g, _)| g).collect()
    }

    /// The meetings of this step: at every split grid node, each pair of fields
    /// with its normal, area and gap criterion, from the step-start particles.
    /// With `in_plane_at_faces`, a node on a face of the grid takes the fields'
    /// volume gradients within that face only: the bodies are cut there (a
    /// symmetry or roller plane), and the gradient's component across the face
    /// is the cut's, not the interface's (it tilts the normal of two stacked
    /// blocks to 45° at the grid's side faces).
    pub fn meetings<const D: usize>(
        &self,
        plan: &ContactPlan,
        m: &Model<D>,
        st: &Stencils<D>,
        map: &NodeMap,
        in_plane_at_faces: bool,
    ) -> Vec<Meeting<D>> {
        let on_boundary = on_grid_boundary(&m.grid);
        let mut meetings = Vec::new();
        let first_split = map.len() - self.split.len();
        let p = &m.particles;
        let owner = st.owner();
        // Volume gradient of each split node, Σ_p V_p ∇S_Ip. In axisymmetric mode
        // the r–z area A_p = V_p/r_p weighs it: Σ_p r_p A_p ∇S_Ip would be the
        // gradient of r × the body's indicator, tilted towards the axis by about
        // h/r at a flat face.
        let axisymmetric = m.axisymmetric;
        let weight = |q: usize| match axisymmetric {
            true => p.volume[q] / p.x[q][0],
            false => p.volume[q],
        };
        let gradient: Vec<Vector<D>> = (first_split..map.len())
            .into_par_iter()
            .map(|a| {
                map.node_entries(a)
                    .iter()
                    .fold(Vector::<D>::zeros(), |acc, &e| {
                        acc + st.grad(e as usize) * weight(owner.of(e))
                    })
            })
            .collect();
        // Farthest extent of a field's particles along a direction n, from node
        // a: over all its particles, or (`local`) over those whose domain spans
        // the node's line along n, so that D is the gap at the node and not the
        // smallest gap in its support (a rolling body's surface just ahead of
        // the contact point is not in contact). With it, the particle whose
        // centre lies farthest along n.
        let extent = |a: usize, x_node: &Vector<D>, n: &Vector<D>, local: bool| -> (f64, u32) {
            // A particle's reach along a unit direction u: Σ_d l_d |u · F e_d|.
            let reach = |q: usize, u: &Vector<D>| -> f64 {
                let f = &p.f.get(q);
                (0..D)
                    .map(|d| {
                        let column = Vector::<D>::from_fn(|i, _| f[(i, d)]);
                        p.half_length0[q][d] * u.dot(&column).abs()
                    })
                    .sum()
            };
            let (mut farthest, mut outermost) = (f64::NEG_INFINITY, (f64::NEG_INFINITY, u32::MAX));
            for &e in map.node_entries(a) {
                let q = owner.of(e);
                let r = p.x[q] - x_node;
                let lateral = r - n * r.dot(n);
                let off = lateral.norm();
                if local && off > 0.0 && off > reach(q, &(lateral / off)) * (1.0 + 1e-9) {
                    continue;
                }
                let along = r.dot(n);
                farthest = farthest.max(along + reach(q, n));
                if along > outermost.0 {
                    outermost = (along, q as u32);
                }
            }
            (farthest, outermost.1)
        };
        let unit = |v: Vector<D>| {
            let n = v.norm();
            if n > 0.0 {
                v / n
            } else {
                v
            }
        };
        let h = m.grid.h_min();
        let f = plan.fields;
        let mut k = 0;
        while k < self.split.len() {
            let g = self.split[k].0;
            let end = k + self.split[k..].iter().take_while(|s| s.0 == g).count();
            let x_node = m.grid.node_position(m.grid.node_ijk(g as usize));
            for i in k..end {
                for j in i + 1..end {
                    let (fr, fs) = (self.split[i].1 as usize, self.split[j].1 as usize);
                    let law = plan.law(fr as u32, fs as u32).expect("fields in contact");
                    let in_plane = |g: Vector<D>| {
                        Vector::<D>::from_fn(|d, _| match on_boundary(d, x_node[d]) {
                            true => 0.0,
                            false => g[d],
                        })
                    };
                    let (gr, gs) = match in_plane_at_faces {
                        true => (in_plane(gradient[i]), in_plane(gradient[j])),
                        false => (gradient[i], gradient[j]),
                    };
                    let normal = match law.normal {
                        ContactNormal::MaxGradient if gr.norm() >= gs.norm() => unit(gr),
                        ContactNormal::MaxGradient => -unit(gs),
                        ContactNormal::Average => unit(unit(gr) - unit(gs)),
                    };
                    if normal == Vector::<D>::zeros() {
                        continue;
                    }
                    let (r, s) = (first_split + i, first_split + j);
                    // Against a rigid body the support-wide extent: with the
                    // local one the rigid plate's energy balance, the free
                    // striker's deceleration and the momentum of the rigid-disk
                    // impact left their tolerances (tests/verification/contact.rs).
                    let local = !(plan.rigid[fr] || plan.rigid[fs]);
                    let (reach_r, outer_r) = extent(r, &x_node, &normal, local);
                    let (reach_s, outer_s) = extent(s, &x_node, &-normal, local);
                    let reach = [reach_r, reach_s];
                    let gap = -reach[0] - reach[1];
                    // The contact area (adhesion), per radian in axisymmetric mode.
                    let ring = if axisymmetric { x_node[0] } else { 1.0 };
                    meetings.push(Meeting {
                        r,
                        s,
                        pair: pair_position(f, fr, fs),
                        fields: [fr, fs],
                        position: x_node,
                        normal,
                        rigid: [plan.rigid[fr], plan.rigid[fs]],
                        area: 0.5 * (gr.norm() + gs.norm()) * ring,
                        gap,
                        reach,
                        outermost: [outer_r, outer_s],
                        close: gap <= law.gap_factor * h,
                        law,
                    });
                }
            }
            k = end;
        }
        meetings
    }
}
