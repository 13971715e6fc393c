//! What the implicit contact carries out of a converged step: into the next
//! step (tangential forces, contact points, the meetings' gaps), into a
//! checkpoint, and into contact.csv (the pair totals, until they are taken).
//!
//! Checkpoint layout (`SolverState`, format version 2): `contact_tangential`
//! holds the tangential force of every particle against the rigid bodies (D
//! values each, none without friction), then [`CarriedMeeting::VALUES`] values
//! per meeting of two deformable bodies; `contact_points` holds 2 + D values
//! per particle with a carried contact point (particle, rigid body, point).

use crate::dim::Vector;
use crate::physics::contact::totals::PairTotal;

/// What a meeting of two deformable fields carries to the next step, kept
/// under its grid node and fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarriedMeeting<const D: usize> {
    /// (grid node, r, s).
    pub key: [u32; 3],
    /// Tangential force at the step's end.
    pub tangential: Vector<D>,
    /// Gap at the step's end, D − δ·n.
    pub gap: f64,
    /// Each side's reference particle (`bodies::assign_history`).
    pub reference: [u32; 2],
}

impl<const D: usize> CarriedMeeting<D> {
    /// Values per meeting in a checkpoint: its grid node, fields r and s,
    /// tangential force (D), gap and reference particles (2).
    pub const VALUES: usize = 6 + D;

    /// Its checkpoint values, appended to `out`.
    pub fn write(&self, out: &mut Vec<f64>) {
        out.extend(self.key.iter().map(|&k| k as f64));
        out.extend(self.tangential.iter().copied());
        out.push(self.gap);
        out.extend(self.reference.iter().map(|&q| q as f64));
    }

    /// The meetings of checkpoint values `c`, or None unless they are a whole
    /// number of meetings.
    pub fn read_all(c: &[f64]) -> Option<Vec<Self>> {
        (c.len() % Self::VALUES == 0).then(|| {
            (c.chunks_exact(Self::VALUES))
                .map(|c| CarriedMeeting {
                    key: [c[0] as u32, c[1] as u32, c[2] as u32],
                    tangential: Vector::<D>::from_column_slice(&c[3..3 + D]),
                    gap: c[3 + D],
                    reference: [c[4 + D] as u32, c[5 + D] as u32],
                })
                .collect()
        })
    }
}

/// A particle's contact point carried to the next step: the rigid body it
/// faces and the point (None: it has none).
pub type CarriedPoint<const D: usize> = Option<(usize, Vector<D>)>;

/// The checkpoint values of carried contact points: 2 + D per particle that
/// has one (particle, rigid body, point).
pub fn write_points<const D: usize>(carried: &[CarriedPoint<D>]) -> Vec<f64> {
    (carried.iter().enumerate())
        .filter_map(|(q, c)| c.map(|(k, c)| (q, k, c)))
        .flat_map(|(q, k, c)| {
            let point: [f64; D] = c.into();
            [q as f64, k as f64].into_iter().chain(point)
        })
        .collect()
}

/// The carried contact points of `n` particles from checkpoint values
/// (`write_points`), against `bodies` rigid bodies. An entry that names no
/// particle or rigid body, or whose point is not finite, is left out: that
/// particle's point is set on its domain, as for a particle that comes near a
/// body.
pub fn read_points<const D: usize>(
    values: &[f64],
    n: usize,
    bodies: usize,
) -> Vec<CarriedPoint<D>> {
    let mut carried = vec![None; n];
    let index =
        |v: f64, len: usize| (v >= 0.0 && v.fract() == 0.0 && v < len as f64).then_some(v as usize);
    for c in values.chunks_exact(2 + D) {
        let point = Vector::<D>::from_column_slice(&c[2..]);
        if let (Some(q), Some(k), true) = (
            index(c[0], n),
            index(c[1], bodies),
            point.iter().all(|x| x.is_finite()),
        ) {
            carried[q] = Some((k, point));
        }
    }
    carried
}

/// Hand the totals `own` (one per pair of fields) over to contact.csv's
/// `into`: added to it (an empty `into` takes a copy), then `own`'s impulse
/// and dissipation reset (the nodes in contact stay those of the last step).
/// The two kinds of contact total disjoint pairs, so the sum of theirs is each
/// pair's own.
pub fn hand_over<const D: usize>(own: &mut [PairTotal<D>], into: &mut Vec<PairTotal<D>>) {
    if into.is_empty() {
        into.extend_from_slice(own);
    } else {
        for (a, b) in into.iter_mut().zip(own.iter()) {
            a.impulse += b.impulse;
            a.dissipation += b.dissipation;
            a.nodes += b.nodes;
        }
    }
    for t in own {
        t.impulse = Vector::<D>::zeros();
        t.dissipation = 0.0;
    }
}
