//! The keys of a peridynamic body (`kind = "peridynamic"`,
//! `physics::peridynamics`): its horizon, fracture, plane, zero-energy and
//! influence keys, its material (E and the PMB Poisson ratio for the
//! bond-based laws; a continuum model without erosion or pore water for the
//! correspondence law), the scene around it (continuum bodies met through
//! the nodal contact, rigid bodies by the rigid projection alone, on explicit
//! stages only: implicit PD is a later slice of issue 51), and none of these
//! keys on other bodies.

use super::check::{ensure, forbidden, Check};
use crate::material::bond::Space;
use crate::scene::{BodyKindName, BondModel, SceneConfig, SolverKind};

/// The keys only a peridynamic body takes, refused on body i of another kind.
pub fn not_peridynamic(i: usize, s: &SceneConfig) -> Check {
    let (b, key) = (&s.bodies[i], |k: &str| format!("body.{i}.{k}"));
    let what = "a body that is not kind = \"peridynamic\"";
    forbidden(&b.horizon, key("horizon"), what)?;
    forbidden(&b.horizon_factor, key("horizon_factor"), what)?;
    forbidden(&b.bond_model, key("bond_model"), what)?;
    forbidden(&b.fracture_energy, key("fracture_energy"), what)?;
    forbidden(&b.critical_stretch, key("critical_stretch"), what)?;
    forbidden(&b.zero_energy_control, key("zero_energy_control"), what)?;
    forbidden(&b.influence, key("influence"), what)?;
    forbidden(&b.short_range_force, key("short_range_force"), what)?;
    forbidden(&b.plane, key("plane"), what)
}

/// Peridynamic body i.
pub fn body(i: usize, s: &SceneConfig) -> Check {
    let (b, key) = (&s.bodies[i], |k: &str| format!("body.{i}.{k}"));
    forbidden(&b.motion, key("motion"), "a peridynamic body")?;
    let positive = |v: Option<f64>, k: &str| match v {
        Some(v) => ensure(
            v > 0.0 && v.is_finite(),
            key(k),
            format!("must be a positive number; got {v}"),
        ),
        None => Ok(()),
    };
    positive(b.horizon, "horizon")?;
    positive(b.horizon_factor, "horizon_factor")?;
    positive(b.fracture_energy, "fracture_energy")?;
    positive(b.critical_stretch, "critical_stretch")?;
    if let Some(f) = b.short_range_force {
        ensure(
            f >= 0.0 && f.is_finite(),
            key("short_range_force"),
            format!("must be a finite number ≥ 0 (0: no repulsion); got {f}"),
        )?;
    }
    let correspondence = b.bond_model == Some(BondModel::Correspondence);
    if let Some(g) = b.zero_energy_control {
        ensure(
            correspondence,
            key("zero_energy_control"),
            "is the zero-energy control of bond_model = \"correspondence\"; the bond-based \
             models have no zero-energy modes",
        )?;
        ensure(
            g >= 0.0 && g.is_finite(),
            key("zero_energy_control"),
            format!("must be a finite number ≥ 0; got {g}"),
        )?;
    }
    ensure(
        correspondence || b.influence.is_none(),
        key("influence"),
        "is the influence function of bond_model = \"correspondence\"; the bond-based \
         micromoduli are those of a constant one",
    )?;
    ensure(
        !(correspondence && b.plane == Some(crate::scene::Plane::Stress)),
        key("plane"),
        "bond_model = \"correspondence\" takes its stress from the materials' update, \
         which is 3D or plane strain: give plane = \"strain\"",
    )?;
    ensure(
        b.horizon.is_none() || b.horizon_factor.is_none(),
        key("horizon_factor"),
        "give `horizon` or `horizon_factor`, not both",
    )?;
    ensure(
        b.fracture_energy.is_none() || b.critical_stretch.is_none(),
        key("critical_stretch"),
        "give `fracture_energy` or `critical_stretch`, not both",
    )?;
    ensure(
        !s.dimension.is_axisymmetric(),
        "dimension",
        "a peridynamic body is 2D (plane strain or stress) or 3D, not axisymmetric",
    )?;
    if s.dimension.spatial() == 3 {
        forbidden(&b.plane, key("plane"), "a 3D body")?;
    }
    ensure(
        s.horizon(i) >= s.particle_spacing(i),
        key(if b.horizon.is_some() {
            "horizon"
        } else {
            "horizon_factor"
        }),
        format!(
            "the horizon {:e} is below the particle spacing {:e}: no bonds",
            s.horizon(i),
            s.particle_spacing(i)
        ),
    )?;
    material(i, s)?;
    scene(i, s)
}

/// Its material: a table of its own; with E > 0 and the PMB ν of its space
/// (bond-based), or any continuum model (correspondence).
fn material(i: usize, s: &SceneConfig) -> Check {
    let b = &s.bodies[i];
    let k = (s.materials.iter())
        .position(|m| m.name == b.material)
        .unwrap();
    let m = &s.materials[k];
    if b.bond_model == Some(BondModel::Correspondence) {
        let built = m.build(k).ok();
        let modulus = built.as_ref().map(|m| m.p_wave_modulus());
        ensure(
            modulus.is_some_and(|p| p > 0.0 && p.is_finite()),
            format!("material.{k}.model"),
            format!(
                "the correspondence body {i} takes its stress from its material `{}`: give \
                 it a continuum model with a positive stiffness, not model = \"{}\"",
                m.name, m.model
            ),
        )?;
        // What the grid's points do with a material and bonds do not.
        let built = built.expect("built above");
        ensure(
            !built.erodes(),
            format!("material.{k}"),
            format!(
                "the correspondence body {i}'s particles are not eroded (its bonds break \
                 instead): give material `{}` no erosion key",
                m.name
            ),
        )?;
        ensure(
            built.pore_fluid().is_none(),
            format!("material.{k}.drainage"),
            format!(
                "the correspondence body {i} carries no pore water: give material `{}` no \
                 drainage",
                m.name
            ),
        )?;
        ensure(
            b.shape != crate::scene::BodyShape::Particles,
            format!("body.{i}.shape"),
            "a correspondence body starts unstressed, and a particle file's stress columns \
             would be lost: fill its shape instead",
        )?;
        return own_table(i, s);
    }
    let e = s.youngs_modulus(i);
    ensure(
        e.is_some_and(|e| e > 0.0 && e.is_finite()),
        format!("material.{k}.youngs_modulus"),
        format!(
            "peridynamic body {i} takes E from its material `{}`: give it a positive \
             youngs_modulus (model = \"linear_elastic\", say)",
            m.name
        ),
    )?;
    poisson_ratio(i, k, s)?;
    own_table(i, s)
}

/// Body i's material table is no other kind of body's (peridynamic bodies
/// may share one: each builds its bond law, and a correspondence body its
/// own material, from the table).
fn own_table(i: usize, s: &SceneConfig) -> Check {
    let b = &s.bodies[i];
    let shared = (0..s.bodies.len()).find(|&j| {
        j != i && s.bodies[j].material == b.material && s.body_kind(j) != BodyKindName::Peridynamic
    });
    match shared {
        Some(j) => Err((
            format!("body.{i}.material"),
            format!(
                "material `{}` is also the material of body {j}, which is not \
                 peridynamic: a peridynamic body's particles carry no stress of their \
                 material, so give it a [[material]] table of its own",
                b.material
            ),
        )),
        None => Ok(()),
    }
}

/// Its material's ν: PMB's one ν of its space, or, beam, in (−1, PMB's].
fn poisson_ratio(i: usize, k: usize, s: &SceneConfig) -> Check {
    let space = s.peridynamic_space(i);
    let nu = s.poisson_ratio(i);
    let want = space.poisson_ratio();
    let (name, fraction) = match space {
        Space::ThreeD => ("3D", "1/4"),
        Space::PlaneStrain => ("plane strain", "1/4"),
        Space::PlaneStress => ("plane stress", "1/3"),
    };
    let got = nu.map_or("none".to_string(), |nu| nu.to_string());
    let key = format!("material.{k}.poisson_ratio");
    match s.bodies[i].bond_model.unwrap_or_default() {
        BondModel::Pmb => ensure(
            nu.is_some_and(|nu| (nu - want).abs() <= 1e-4),
            key,
            format!(
                "the bond-based (PMB) peridynamic body {i} has ν = {fraction} in {name} \
                 (one micromodulus fixes it); got {got}: set poisson_ratio = {want:.6}, \
                 bond_model = \"beam\" for another ν, or, in 2D, the other `plane`"
            ),
        ),
        BondModel::Correspondence => Ok(()),
        BondModel::Beam => ensure(
            nu.is_some_and(|nu| nu > -1.0 && nu <= want + 1e-4),
            key,
            format!(
                "the beam-based peridynamic body {i} takes ν in (−1, {fraction}] in {name} \
                 (its tangential micromodulus would be negative above); got {got}"
            ),
        ),
    }
}

/// The scene around it: continuum bodies met through the nodal contact, in
/// velocity fields of their own (a `[[contact]]` with each); rigid bodies met
/// by the rigid projection alone; explicit stages only.
fn scene(i: usize, s: &SceneConfig) -> Check {
    let continuum: Vec<usize> = (0..s.bodies.len())
        .filter(|&j| s.body_kind(j) == BodyKindName::Continuum)
        .collect();
    if !continuum.is_empty() {
        let plan = crate::scene::contact::plan(s)?;
        for j in continuum {
            let apart = (plan.as_ref()).is_some_and(|p| p.field_of_body[i] != p.field_of_body[j]);
            ensure(
                apart,
                "contact",
                format!(
                    "peridynamic body {i} and continuum body {j} meet through the grid's \
                     contact only: declare a [[contact]] between them (bodies without one \
                     share a velocity field, and a peridynamic body's particles do not move \
                     with the grid)"
                ),
            )?;
        }
    }
    for k in 0..s.contacts.len() {
        rigid_projection(k, s)?;
    }
    let implicit = match &s.solver {
        Some(st) => (st.kind == SolverKind::Implicit).then(|| "solver.kind".to_string()),
        None => (s
            .stages
            .iter()
            .position(|st| st.kind == SolverKind::Implicit))
        .map(|k| format!("stage.{k}.kind")),
    };
    match implicit {
        Some(key) => Err((
            key,
            format!(
                "body {i} is peridynamic, which runs on explicit stages only: implicit \
                 peridynamics is a later slice (issue 51)"
            ),
        )),
        None => Ok(()),
    }
}

/// Contact table k in a scene with peridynamic bodies: between a peridynamic
/// body and a rigid one, by the rigid projection alone (frictionless, no
/// adhesion: `solver::explicit::contact`); with a continuum body, any nodal
/// law; never between two peridynamic bodies.
fn rigid_projection(k: usize, s: &SceneConfig) -> Check {
    let c = &s.contacts[k];
    let key = |name: &str| format!("contact.{k}.{name}");
    for (a, b) in crate::scene::contact::table_pairs(s, k)? {
        let kinds = [s.body_kind(a), s.body_kind(b)];
        if !kinds.contains(&BodyKindName::Peridynamic) || kinds.contains(&BodyKindName::Continuum) {
            continue;
        }
        ensure(
            kinds.contains(&BodyKindName::Rigid),
            key("bodies"),
            format!(
                "bodies {a} and {b} are both peridynamic: they meet through their \
                 short-range repulsion (body.N.short_range_force), without a contact table"
            ),
        )?;
        let what = format!("the contact of bodies {a} and {b}");
        ensure(
            c.rigid_projection,
            key("rigid_projection"),
            format!(
                "{what} is the rigid projection (a peridynamic body takes part in no \
                 nodal contact): leave rigid_projection = true"
            ),
        )?;
        ensure(
            c.friction_coefficient == 0.0,
            key("friction_coefficient"),
            format!("{what} is the rigid projection, which is frictionless: give 0"),
        )?;
        ensure(
            c.adhesion == 0.0,
            key("adhesion"),
            format!("{what} is the rigid projection, which has no adhesion: give 0"),
        )?;
    }
    Ok(())
}
