//! The `[[contact]]` tables resolved into what the solver needs: which bodies
//! share a velocity field ("glued": no contact declared between them) and the
//! contact law between every two fields.
//!
//! Bodies without a contact between them move as one field, as in a scene without
//! contact. Fields are the groups of bodies connected by undeclared pairs, so a
//! declared pair must not end up in one group, and every declared pair between two
//! groups must carry the same law.

use super::config::{BodyKindName, ContactConfig, ContactNormal, SceneConfig};
use crate::material::parameters::KeyError;
use crate::material::rigid::Motion;

/// Velocity fields a scene may have (the split of shared nodes keeps the fields at
/// a node as the bits of a u64).
pub const MAX_FIELDS: u32 = 64;

/// The law of one contact: Coulomb friction with adhesion, and the gap factor λ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    pub friction: f64,
    /// Shear strength per unit area of the interface.
    pub adhesion: f64,
    /// Contact needs the gap D ≤ λ h.
    pub gap_factor: f64,
    pub normal: ContactNormal,
    /// Deformable particles that enter a rigid body are put back on its surface.
    pub rigid_projection: bool,
    /// α of the implicit solver's penalty against rigid bodies.
    pub penalty_factor: f64,
}

impl ContactLaw {
    fn of(c: &ContactConfig) -> Self {
        ContactLaw {
            friction: c.friction_coefficient,
            adhesion: c.adhesion,
            gap_factor: c.gap_factor,
            normal: c.normal,
            rigid_projection: c.rigid_projection,
            penalty_factor: c.penalty_factor,
        }
    }
}

/// The scene's contact set-up: the field of each body and the law between fields.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPlan {
    /// Field of each body (by body index); fields are numbered in order of their
    /// first body.
    pub field_of_body: Vec<u32>,
    /// Law between fields i and j at `laws[i * fields + j]` (symmetric); `None` on
    /// the diagonal.
    pub laws: Vec<Option<ContactLaw>>,
    pub fields: usize,
    /// Whether each field is a rigid body (`SceneConfig::body_kind`, the kind
    /// `model::body::BodyKind` is built from; a rigid body has a field of its
    /// own).
    pub rigid: Vec<bool>,
    /// Whether each field is a free rigid body (`SceneConfig::rigid_motion`).
    pub free: Vec<bool>,
    /// Whether each field holds peridynamic bodies: their particles are
    /// advanced by their bonds, not by the grid. They meet rigid bodies by the
    /// rigid projection alone and continuum bodies by the nodal contact
    /// (`solver::explicit::contact`).
    pub bonded: Vec<bool>,
}

impl ContactPlan {
    /// The law between fields i and j (None for i = j).
    pub fn law(&self, i: u32, j: u32) -> Option<ContactLaw> {
        self.laws[i as usize * self.fields + j as usize]
    }

    /// Do fields i and j meet at the nodes? Not a rigid field and a
    /// peridynamic one (the rigid projection alone keeps them apart), nor two
    /// peridynamic ones (their short-range repulsion does).
    pub fn meet_at_nodes(&self, i: usize, j: usize) -> bool {
        match (self.bonded[i], self.bonded[j]) {
            (false, false) => true,
            (true, false) => !self.rigid[j],
            (false, true) => !self.rigid[i],
            (true, true) => false,
        }
    }

    /// Does peridynamic field k meet a continuum field at the nodes? Then its
    /// bond forces go to its nodes, and the nodal contact's exchange to its
    /// particles.
    pub fn bonded_meets_continuum(&self, k: usize) -> bool {
        self.bonded[k]
            && (0..self.fields).any(|j| {
                j != k && self.law(k as u32, j as u32).is_some() && self.meet_at_nodes(k, j)
            })
    }
}

/// The body index named `name`, or an error at `path`.
fn body_index(s: &SceneConfig, name: &str, path: &str) -> Result<usize, KeyError> {
    let named: Vec<usize> = (0..s.bodies.len())
        .filter(|&b| s.bodies[b].name.as_deref() == Some(name))
        .collect();
    match named[..] {
        [b] => Ok(b),
        [] => Err((path.into(), format!("no body is named `{name}`"))),
        _ => Err((
            path.into(),
            format!(
                "{} bodies are named `{name}`: give the bodies in contact distinct names",
                named.len()
            ),
        )),
    }
}

/// The declared pairs of table i, (body, body) with the smaller index first.
pub(crate) fn table_pairs(s: &SceneConfig, i: usize) -> Result<Vec<(usize, usize)>, KeyError> {
    let n = s.bodies.len();
    let Some(names) = &s.contacts[i].bodies else {
        return Ok((0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .collect());
    };
    let path = format!("contact.{i}.bodies");
    if names.len() != 2 {
        return Err((path, format!("names two bodies, has {}", names.len())));
    }
    let a = body_index(s, &names[0], &format!("{path}.0"))?;
    let b = body_index(s, &names[1], &format!("{path}.1"))?;
    if a == b {
        return Err((path, format!("pairs body `{}` with itself", names[0])));
    }
    Ok(vec![(a.min(b), a.max(b))])
}

/// Check the law's numbers of table i.
fn check_law(c: &ContactConfig, i: usize) -> Result<(), KeyError> {
    let key = |k: &str| format!("contact.{i}.{k}");
    for (k, v) in [
        ("friction_coefficient", c.friction_coefficient),
        ("adhesion", c.adhesion),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            return Err((key(k), "must be a finite number ≥ 0".into()));
        }
    }
    for (k, v) in [
        ("gap_factor", c.gap_factor),
        ("penalty_factor", c.penalty_factor),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return Err((key(k), "must be a finite number > 0".into()));
        }
    }
    Ok(())
}

/// Resolve the `[[contact]]` tables (None when there are none), with the first
/// problem named by its key.
pub fn plan(s: &SceneConfig) -> Result<Option<ContactPlan>, KeyError> {
    let rigid = |b: usize| s.body_kind(b) == BodyKindName::Rigid;
    let free = |b: usize| rigid(b) && s.rigid_motion(b) == Motion::Free;
    let bonded = |b: usize| s.body_kind(b) == BodyKindName::Peridynamic;
    if s.contacts.is_empty() {
        return match (0..s.bodies.len()).find(|&b| rigid(b)) {
            Some(b) => Err((
                s.body_kind_key(b),
                "a rigid body meets other bodies only through contact: add a [[contact]] \
                 between it and every body it may touch"
                    .into(),
            )),
            None => Ok(None),
        };
    }
    let n = s.bodies.len();
    if n < 2 {
        return Err((
            "contact".into(),
            "contact needs at least two [[body]] tables".into(),
        ));
    }
    // Declared law per body pair, and which table declared it.
    let mut declared: Vec<Option<(ContactLaw, usize)>> = vec![None; n * n];
    for (i, c) in s.contacts.iter().enumerate() {
        check_law(c, i)?;
        for (a, b) in table_pairs(s, i)? {
            if let Some((_, j)) = declared[a * n + b] {
                return Err((
                    format!("contact.{i}"),
                    format!(
                        "declares the contact of bodies {a} and {b} again (also in contact.{j})"
                    ),
                ));
            }
            declared[a * n + b] = Some((ContactLaw::of(c), i));
        }
    }
    // Fields: bodies connected by undeclared pairs (union–find, smallest root).
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], a: usize) -> usize {
        let mut r = a;
        while root[r] != r {
            r = root[r];
        }
        root[a] = r;
        r
    }
    for a in 0..n {
        for b in a + 1..n {
            if declared[a * n + b].is_none() {
                let (ra, rb) = (find(&mut root, a), find(&mut root, b));
                root[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let mut field_of_body = vec![u32::MAX; n];
    let mut fields = 0;
    for b in 0..n {
        let r = find(&mut root, b);
        if field_of_body[r] == u32::MAX {
            field_of_body[r] = fields;
            fields += 1;
        }
        field_of_body[b] = field_of_body[r];
    }
    if fields > MAX_FIELDS {
        return Err((
            "contact".into(),
            format!(
                "the contacts make {fields} velocity fields; at most {MAX_FIELDS} are supported \
                 (bodies without a contact between them share a field)"
            ),
        ));
    }
    for b in (0..n).filter(|&b| rigid(b)) {
        if let Some(other) = (0..n).find(|&o| o != b && field_of_body[o] == field_of_body[b]) {
            return Err((
                s.body_kind_key(b),
                format!(
                    "rigid body {b} would share a velocity field with body {other} (no \
                     [[contact]] between them): a rigid body needs a contact with every \
                     other body"
                ),
            ));
        }
    }
    let mut laws: Vec<Option<(ContactLaw, usize)>> = vec![None; fields as usize * fields as usize];
    let f = fields as usize;
    for a in 0..n {
        for b in a + 1..n {
            let Some((law, i)) = declared[a * n + b] else {
                continue;
            };
            let (fa, fb) = (field_of_body[a] as usize, field_of_body[b] as usize);
            if fa == fb {
                return Err((
                    format!("contact.{i}"),
                    format!(
                        "bodies {a} and {b} are declared in contact, but other bodies without a \
                         contact between them glue them into one velocity field: declare the \
                         contact of every pair that touches"
                    ),
                ));
            }
            match laws[fa * f + fb] {
                Some((other, j)) if other != law => {
                    return Err((
                        format!("contact.{i}"),
                        format!(
                            "bodies {a} and {b} lie in velocity fields whose contact contact.{j} \
                             already sets with another law (bodies without a contact between \
                             them share a field): give these contacts the same law"
                        ),
                    ))
                }
                _ => {
                    laws[fa * f + fb] = Some((law, i));
                    laws[fb * f + fa] = Some((law, i));
                }
            }
        }
    }
    let field_of = |is: &dyn Fn(usize) -> bool| -> Vec<bool> {
        (0..f)
            .map(|k| (0..n).any(|b| field_of_body[b] as usize == k && is(b)))
            .collect()
    };
    let (rigid, free, bonded) = (field_of(&rigid), field_of(&free), field_of(&bonded));
    Ok(Some(ContactPlan {
        field_of_body,
        laws: laws.into_iter().map(|l| l.map(|(law, _)| law)).collect(),
        fields: f,
        rigid,
        free,
        bonded,
    }))
}
