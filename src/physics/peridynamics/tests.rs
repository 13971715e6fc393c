//! Unit checks of the bond forces (issue 51): Σ F = 0, rigid motions, a bond
//! breaking, the crack energy, the interior energy and a plate in tension.

use super::*;
use crate::dim::Tensor;
use crate::material::bond::correspondence::{Correspondence, Influence, ZERO_ENERGY_CONTROL};
use crate::material::bond::{beam::Beam, pmb::Pmb, BondLaw, Space};
use crate::material::linear_elastic::LinearElastic;
use crate::model::peridynamics::state::StressState;
use crate::model::peridynamics::PdBody;

const E: f64 = 70e9;
/// The step handed to the bond forces (the correspondence law's stress update).
const DT: f64 = 1e-8;

/// A lattice of n^D points of spacing dx, each moved by `perturb` × dx
/// times a deterministic pseudo-random number in [−1, 1).
fn lattice<const D: usize>(n: usize, dx: f64, perturb: f64) -> Vec<Vector<D>> {
    let mut seed = 12345u64;
    let mut rand = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n.pow(D as u32))
        .map(|q| {
            Vector::<D>::from_fn(|d, _| {
                ((q / n.pow(d as u32)) % n) as f64 * dx + perturb * dx * rand()
            })
        })
        .collect()
}

fn body<const D: usize>(x: &[Vector<D>], dx: f64, space: Space) -> PdBody<D> {
    let v = vec![dx.powi(D as i32); x.len()];
    PdBody::new(
        0,
        (0..x.len()).collect(),
        x,
        v,
        BondLaw::Pmb(Pmb::new(space, E, 3.0 * dx)),
    )
}

/// A body of law `law` on points x of volumes v; a correspondence body gets a
/// linear elastic material of E and ν = 1/4 (ρ = 1) at rest.
fn pd_body<const D: usize>(x: &[Vector<D>], v: Vec<f64>, law: BondLaw) -> PdBody<D> {
    let b = PdBody::new(0, (0..x.len()).collect(), x, v, law);
    match law {
        BondLaw::Correspondence(_) => {
            let elastic = LinearElastic::new(1.0, E, 0.25);
            b.with_stress(StressState::at_rest(Box::new(elastic), x.len()))
        }
        _ => b,
    }
}

/// The correspondence law of E, ν = 1/4, horizon 3 mm and zero-energy control `g`.
fn correspondence(space: Space, g: f64) -> BondLaw {
    let m = E * 0.75 / (1.25 * 0.5);
    BondLaw::Correspondence(Correspondence::new(space, m, 3.0 * 1e-3, g))
}

/// The same with seed 004's Gaussian influence function.
fn gaussian(space: Space, g: f64) -> BondLaw {
    match correspondence(space, g) {
        BondLaw::Correspondence(c) => {
            BondLaw::Correspondence(c.with_influence(Influence::Gaussian))
        }
        _ => unreachable!(),
    }
}

fn pmb_of<const D: usize>(b: &PdBody<D>) -> Pmb {
    match b.law {
        BondLaw::Pmb(p) => p,
        _ => unreachable!("a PMB body"),
    }
}

fn max_norm<const D: usize>(f: &[Vector<D>]) -> f64 {
    f.iter().map(|v| v.norm()).fold(0.0, f64::max)
}

/// Σ F = 0 to round-off for bond law `law` (horizon 3Δx, Δx = 1 mm) on a
/// perturbed lattice.
fn sum_of_forces_vanishes<const D: usize>(law: BondLaw) {
    let dx = 1e-3;
    let x = lattice::<D>(if D == 2 { 20 } else { 8 }, dx, 0.2);
    let v = vec![dx.powi(D as i32); x.len()];
    let mut b = pd_body(&x, v, law);
    // A deformed state: each point moved by up to 1 % of dx at random.
    let n = if D == 2 { 20 } else { 8 };
    let jitter = lattice::<D>(n, dx, 0.01);
    let y: Vec<Vector<D>> = (x.iter().zip(&jitter))
        .map(|(p, l)| p + (l - lattice_point::<D>(l, dx)))
        .collect();
    let f = bond_forces(&mut b, &y, DT);
    let total: Vector<D> = f.iter().sum();
    let scale: f64 = f.iter().map(|v| v.norm()).sum();
    println!("{law:?}: |Σ F| = {:.3e}, Σ |F| = {scale:.3e}", total.norm());
    assert!(scale > 0.0);
    assert!(total.norm() <= 1e-13 * scale, "{} vs {scale}", total.norm());
}

/// The lattice point nearest l.
fn lattice_point<const D: usize>(l: &Vector<D>, dx: f64) -> Vector<D> {
    l.map(|c| (c / dx).round() * dx)
}

#[test]
fn the_bond_forces_sum_to_zero_on_a_perturbed_lattice() {
    let pmb = |space| BondLaw::Pmb(Pmb::new(space, E, 3.0 * 1e-3));
    sum_of_forces_vanishes::<2>(pmb(Space::PlaneStress));
    sum_of_forces_vanishes::<3>(pmb(Space::ThreeD));
}

/// A rotation by `angle`: in-plane (2D), about the axis (1, 2, 3) (3D).
fn rotation<const D: usize>(angle: f64) -> Tensor<D> {
    let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(1.0, 2.0, 3.0));
    let r3 = match D {
        2 => *nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), angle).matrix(),
        _ => *nalgebra::Rotation3::from_axis_angle(&axis, angle).matrix(),
    };
    crate::dim::restrict::<D>(&r3)
}

/// Bond law `law` (on a perturbed lattice, Δx = 1 mm) under a rigid
/// translation and a 30° rotation: no force, against the force of a 1e-3
/// stretch. Returns the body, the rotated positions and that force scale.
fn rigid_motion_gives_no_force<const D: usize>(law: BondLaw) -> (PdBody<D>, Vec<Vector<D>>, f64) {
    let dx = 1e-3;
    let x = lattice::<D>(if D == 2 { 15 } else { 7 }, dx, 0.2);
    let v = vec![dx.powi(D as i32); x.len()];
    // A fresh body for each motion: a correspondence body's stress follows
    // its history.
    let fresh = || pd_body(&x, v.clone(), law);
    let stretched: Vec<Vector<D>> = x.iter().map(|p| p * 1.001).collect();
    let scale = max_norm(&bond_forces(&mut fresh(), &stretched, DT));
    let shift = Vector::<D>::from_element(0.37);
    let r = rotation::<D>(30f64.to_radians());
    let moved: Vec<Vector<D>> = x.iter().map(|p| r * p + shift).collect();
    let translated: Vec<Vector<D>> = x.iter().map(|p| p + shift).collect();
    let ft = max_norm(&bond_forces(&mut fresh(), &translated, DT));
    let mut b = fresh();
    let fr = max_norm(&bond_forces(&mut b, &moved, DT));
    println!("{law:?}: max |F| translated {ft:.2e}, rotated 30° {fr:.2e}, at s = 1e-3 {scale:.2e}");
    assert!(ft <= 1e-9 * scale && fr <= 1e-9 * scale);
    (b, moved, scale)
}

#[test]
fn a_rigid_translation_and_a_30_degree_rotation_give_no_force() {
    let pmb = |space| BondLaw::Pmb(Pmb::new(space, E, 3.0 * 1e-3));
    rigid_motion_gives_no_force::<2>(pmb(Space::PlaneStress));
    rigid_motion_gives_no_force::<3>(pmb(Space::ThreeD));
}

#[test]
fn a_single_bond_breaks_past_s0_and_never_heals() {
    let dx = 1e-3;
    let x = vec![Vector::<2>::zeros(), Vector::<2>::new(dx, 0.0)];
    let s0 = 1e-3;
    let pmb = Pmb::new(Space::PlaneStress, E, 1.5 * dx).with_critical_stretch(s0);
    let mut b = PdBody::new(0, vec![0, 1], &x, vec![dx * dx; 2], BondLaw::Pmb(pmb));
    assert_eq!(b.bonds.len(), 1);
    let at = |s: f64| vec![x[0], Vector::<2>::new(dx * (1.0 + s), 0.0)];
    let f = bond_forces(&mut b, &at(0.999 * s0), DT);
    let expected = pmb.micromodulus * 0.999 * s0 * dx.powi(4);
    assert!((f[0][0] - expected).abs() <= 1e-9 * expected && f[1][0] == -f[0][0]);
    assert!(b.bonds.intact[0]);
    bond_forces(&mut b, &at(1.001 * s0), DT);
    assert!(!b.bonds.intact[0]);
    assert_eq!(b.damage(), vec![1.0, 1.0]);
    for s in [0.5 * s0, 0.0, -0.01] {
        let f = bond_forces(&mut b, &at(s), DT);
        assert!(!b.bonds.intact[0] && f[0] == Vector::<2>::zeros() && f[1] == Vector::<2>::zeros());
    }
}

/// The energy of the bonds cut by a straight crack (the line x = x_c
/// between two lattice columns), per unit crack length, against G0: the
/// lattice's quadrature of the G0 integral (no partial volumes, m = 3).
#[test]
fn the_bonds_cut_by_a_straight_crack_hold_g0_per_unit_area() {
    let (dx, g0) = (1e-3, 100.0);
    let n = 30;
    let x = lattice::<2>(n, dx, 0.0);
    let space = Space::PlaneStress;
    let b = body(&x, dx, space);
    let p = pmb_of(&b).with_fracture_energy(space, g0);
    let xc = 14.5 * dx;
    let (y0, y1) = (10.0 * dx, 20.0 * dx);
    let energy: f64 = (0..b.bonds.len())
        .filter(|&k| {
            let [i, j] = b.bonds.ends(k).map(|e| x[e]);
            let mid = 0.5 * (i[1] + j[1]);
            (i[0] - xc) * (j[0] - xc) < 0.0 && mid >= y0 && mid < y1
        })
        .map(|k| p.bond_energy(p.critical_stretch, b.bonds.length[k]) * dx.powi(4))
        .sum();
    let ratio = energy / (y1 - y0) / g0;
    println!("cut-bond energy / (G0 × length) = {ratio:.4}");
    assert!((ratio - 1.0).abs() < 0.06, "{ratio}");
}

/// The strain energy density of an interior particle under a homogeneous
/// uniaxial-stress strain (ε, −νε) against ½Eε² (plane stress), and under
/// an isotropic strain against 9Kε²/2 (3D): the lattice calibration error
/// of m = 3 without partial volumes.
#[test]
fn interior_strain_energy_matches_the_classical_one_to_the_lattice_error() {
    let (dx, eps) = (1e-3, 1e-4);
    let x = lattice::<2>(13, dx, 0.0);
    let b = body(&x, dx, Space::PlaneStress);
    let y: Vec<Vector<2>> = x
        .iter()
        .map(|p| Vector::<2>::new(p[0] * (1.0 + eps), p[1] * (1.0 - eps / 3.0)))
        .collect();
    let w = interior_energy(&b, &y, 6 * 13 + 6, dx * dx);
    let ratio_2d = w / (0.5 * E * eps * eps);
    let x3 = lattice::<3>(9, dx, 0.0);
    let b3 = body(&x3, dx, Space::ThreeD);
    let y3: Vec<Vector<3>> = x3.iter().map(|p| p * (1.0 + eps)).collect();
    let w3 = interior_energy(&b3, &y3, 4 * 81 + 4 * 9 + 4, dx.powi(3));
    let ratio_3d = w3 / (4.5 * (2.0 * E / 3.0) * eps * eps);
    println!("interior W_PD / W: plane stress {ratio_2d:.4}, 3D {ratio_3d:.4}");
    assert!((ratio_2d - 1.0).abs() < 0.15 && (ratio_3d - 1.0).abs() < 0.15);
}

/// W_i = ½ Σ_j (c s² |ξ|/2) V_j.
fn interior_energy<const D: usize>(b: &PdBody<D>, y: &[Vector<D>], i: usize, v: f64) -> f64 {
    0.5 * b.bonds.gather_scalar(i, |k, _| {
        pmb_of(b).bond_energy(b.bonds.stretch(k, y), b.bonds.length[k]) * v
    })
}

/// A plate nx × ny (spacing dx) of body law `law` in homogeneous uniaxial
/// tension σ: equal and opposite forces σW on its end columns, the static
/// state found by dynamic relaxation (viscous damping, a fictitious ρ = 1). The
/// strains between the columns at L/4 and 3L/4 (εxx, averaged over the width)
/// and between the rows at W/4 and 3W/4 (εyy, averaged over the columns
/// between L/4 and 3L/4), and the residual reached.
fn plate_in_tension(
    law: BondLaw,
    nx: usize,
    ny: usize,
    dx: f64,
    e: f64,
    sigma: f64,
) -> (f64, f64, f64) {
    let x: Vec<Vector<2>> = (0..nx * ny)
        .map(|q| Vector::<2>::new((q % nx) as f64 * dx, (q / nx) as f64 * dx))
        .collect();
    let v0 = dx * dx;
    let mut b = pd_body(&x, vec![v0; x.len()], law);
    let per = sigma * (ny as f64 * dx) / ny as f64;
    let load = |q: usize| match q % nx {
        0 => Vector::<2>::new(-per, 0.0),
        c if c == nx - 1 => Vector::<2>::new(per, 0.0),
        _ => Vector::zeros(),
    };
    let mass = vec![v0; x.len()];
    let dt = b.stable_dt(&mass);
    let omega = std::f64::consts::PI / (nx as f64 * dx) * e.sqrt();
    let damping = 2.0 * omega * dt;
    let (mut y, mut v) = (x.clone(), vec![Vector::<2>::zeros(); x.len()]);
    let mut residual = f64::INFINITY;
    for _ in 0..100_000 {
        let f = bond_forces(&mut b, &y, DT);
        residual = 0.0;
        for q in 0..y.len() {
            let total = f[q] + load(q);
            residual = f64::max(residual, total.norm() / per);
            v[q] = v[q] * (1.0 - damping) + total * (dt / mass[q]);
            y[q] += v[q] * dt;
        }
        if residual < 1e-6 {
            break;
        }
    }
    let u = |q: usize, d: usize| y[q][d] - x[q][d];
    let (c1, c2, r1, r2) = (nx / 4, 3 * nx / 4, ny / 4, 3 * ny / 4);
    let column = |c: usize| (0..ny).map(|r| u(r * nx + c, 0)).sum::<f64>() / ny as f64;
    let row = |r: usize| (c1..=c2).map(|c| u(r * nx + c, 1)).sum::<f64>() / (c2 - c1 + 1) as f64;
    let exx = (column(c2) - column(c1)) / ((c2 - c1) as f64 * dx);
    let eyy = (row(r2) - row(r1)) / ((r2 - r1) as f64 * dx);
    (exx, eyy, residual)
}

/// Homogeneous uniaxial tension of a PMB plane-stress plate 40Δx × 20Δx
/// (m = 3, no surface or partial-volume correction): εxx against σ/E.
#[test]
fn a_plane_stress_plate_in_tension_stretches_by_sigma_over_e_to_the_surface_error() {
    let (dx, e, sigma) = (1e-3, 70e9, 7e6);
    let pmb = Pmb::new(Space::PlaneStress, e, 3.0 * dx);
    let (strain, _, residual) = plate_in_tension(BondLaw::Pmb(pmb), 40, 20, dx, e, sigma);
    let error = strain / (sigma / e) - 1.0;
    println!("residual {residual:.1e}; strain/(σ/E) − 1 = {error:+.4}");
    assert!(residual < 1e-6, "not converged: {residual:e}");
    assert!(error.abs() < 0.08, "{error}");
}

/// The beam bond's Poisson ratio, measured in the plate's homogeneous
/// tension as −εyy/εxx (plane stress) or −εyy/εxx = ν/(1 − ν) (plane strain),
/// against the one asked for, and εxx against σ/E (plane stress) or
/// σ(1 − ν²)/E (plane strain), m = 3 without surface correction.
#[test]
fn the_beam_bond_gives_the_poisson_ratio_asked_for() {
    let (dx, e, sigma) = (1e-3, 70e9, 7e6);
    let cases = [
        (Space::PlaneStress, -0.2),
        (Space::PlaneStress, 0.0),
        (Space::PlaneStress, 0.2),
        (Space::PlaneStress, 1.0 / 3.0),
        (Space::PlaneStrain, 0.0),
        (Space::PlaneStrain, 0.25),
    ];
    for (space, nu) in cases {
        let beam = Beam::new(space, e, nu, 3.0 * dx);
        let (exx, eyy, residual) = plate_in_tension(BondLaw::Beam(beam), 40, 24, dx, e, sigma);
        let (measured, axial) = match space {
            Space::PlaneStress => (-eyy / exx, exx / (sigma / e)),
            _ => {
                let r = -eyy / exx; // ν/(1 − ν)
                (r / (1.0 + r), exx / (sigma * (1.0 - nu * nu) / e))
            }
        };
        println!(
            "{space:?} ν = {nu:+.3}: measured ν {measured:+.4} (Δ {:+.4}), εxx/(σ/E′) − 1 = {:+.4}, residual {residual:.1e}",
            measured - nu,
            axial - 1.0
        );
        assert!(residual < 1e-6, "not converged: {residual:e}");
        assert!(
            (measured - nu).abs() < 0.03,
            "{space:?} ν = {nu}: measured {measured}"
        );
        assert!((axial - 1.0).abs() < 0.08, "{space:?} ν = {nu}: {axial}");
    }
}

/// The beam bond under a rigid translation and a 30° rotation: no force with
/// the rotation taken out (its ends' polar rotations), and a force of the
/// order of a 1e-3 stretch's without it (R = I), so the test can fail.
fn beam_rigid_motion<const D: usize>(space: Space) {
    let beam = Beam::new(space, E, 0.0, 3.0 * 1e-3);
    let (b, moved, scale) = rigid_motion_gives_no_force::<D>(BondLaw::Beam(beam));
    let (x, v, i) = (&b.reference, &b.volume, Tensor::<D>::identity());
    let uncorrected: Vec<Vector<D>> = (0..x.len())
        .map(|p| {
            b.bonds.gather(p, |_, j| {
                beam.pair_force(&moved[p], &moved[j], &(x[j] - x[p]), &i, &i) * (v[p] * v[j])
            })
        })
        .collect();
    let fu = max_norm(&uncorrected);
    println!("beam {space:?}: rotated without the correction {fu:.2e}, at s = 1e-3 {scale:.2e}");
    assert!(
        fu > 10.0 * scale,
        "the uncorrected measure resists the rotation only {fu:e}"
    );
}

#[test]
fn the_beam_bond_resists_no_rigid_rotation_once_the_rotation_is_taken_out() {
    beam_rigid_motion::<2>(Space::PlaneStress);
    beam_rigid_motion::<3>(Space::ThreeD);
}

#[test]
fn the_beam_bond_forces_sum_to_zero_on_a_perturbed_lattice() {
    let beam = |space| BondLaw::Beam(Beam::new(space, E, 0.1, 3.0 * 1e-3));
    sum_of_forces_vanishes::<2>(beam(Space::PlaneStress));
    sum_of_forces_vanishes::<3>(beam(Space::ThreeD));
}

/// The correspondence laws the exact checks run over, (2D, 3D): constant
/// influence with G = 0.1, Gaussian with G = 1.
fn correspondence_laws() -> [(BondLaw, BondLaw); 2] {
    [
        (
            correspondence(Space::PlaneStrain, 0.1),
            correspondence(Space::ThreeD, 0.1),
        ),
        (
            gaussian(Space::PlaneStrain, 1.0),
            gaussian(Space::ThreeD, 1.0),
        ),
    ]
}

#[test]
fn the_correspondence_forces_sum_to_zero_on_a_perturbed_lattice() {
    for (two, three) in correspondence_laws() {
        sum_of_forces_vanishes::<2>(two);
        sum_of_forces_vanishes::<3>(three);
    }
}

/// The stress of a rigid rotation is none (the linear elastic update is
/// objective), and the zero-energy control sees no non-affine motion.
#[test]
fn a_correspondence_body_resists_no_rigid_motion() {
    for (two, three) in correspondence_laws() {
        rigid_motion_gives_no_force::<2>(two);
        rigid_motion_gives_no_force::<3>(three);
    }
}

/// Homogeneous uniaxial tension of a plane-strain correspondence plate 40Δx ×
/// 20Δx (m = 3, linear elastic E, ν = 1/4): εxx against σ(1 − ν²)/E and the
/// Poisson ratio −εyy/εxx = ν/(1 − ν); F is exact for affine maps at every
/// particle, surface included, so no surface correction is needed.
#[test]
fn a_correspondence_plate_in_tension_stretches_as_the_continuum() {
    let (dx, sigma, nu) = (1e-3, 7e6, 0.25);
    let laws = [
        correspondence(Space::PlaneStrain, ZERO_ENERGY_CONTROL),
        gaussian(Space::PlaneStrain, ZERO_ENERGY_CONTROL),
    ];
    for law in laws {
        let (exx, eyy, residual) = plate_in_tension(law, 40, 20, dx, E, sigma);
        let axial = exx / (sigma * (1.0 - nu * nu) / E) - 1.0;
        let poisson = -eyy / exx / (nu / (1.0 - nu)) - 1.0;
        println!("{law:?}: residual {residual:.1e}; εxx/(σ(1 − ν²)/E) − 1 = {axial:+.5}, ν' error {poisson:+.5}");
        assert!(residual < 1e-6, "not converged: {residual:e}");
        assert!(axial.abs() < 0.02, "{axial}");
        assert!(poisson.abs() < 0.02, "{poisson}");
    }
}

/// The checkerboard u_j = ±a e_x on a lattice has no affine part in any
/// interior family (the neighbours at ±ξ move alike), so F = I and the stress
/// forces vanish two horizons from the edges: a zero-energy mode. The control resists it: with G = 0.1 every
/// interior particle is pulled back (f·u < 0) with a force of the order of
/// G × the PMB force of a stretch a/Δx; with G = 0 the force is round-off.
#[test]
fn the_zero_energy_control_resists_the_checkerboard_mode() {
    let (n, dx, a) = (21, 1e-3, 1e-6);
    let x = lattice::<2>(n, dx, 0.0);
    let sign = |q: usize| if (q % n + q / n) % 2 == 0 { 1.0 } else { -1.0 };
    let y: Vec<Vector<2>> = (0..x.len())
        .map(|q| x[q] + Vector::<2>::new(a * sign(q), 0.0))
        .collect();
    // Two horizons from the edges: the families of i and of its neighbours are whole.
    let interior = |q: usize| (6..n - 6).contains(&(q % n)) && (6..n - 6).contains(&(q / n));
    let v = vec![dx * dx; x.len()];
    let pmb = pmb_of(&pd_body(
        &x,
        v.clone(),
        BondLaw::Pmb(Pmb::new(Space::PlaneStrain, E, 3.0 * dx)),
    ));
    let scale = pmb.micromodulus * (a / dx) * dx.powi(4) * 28.0;
    for g in [0.0, 0.1] {
        let f = bond_forces(
            &mut pd_body(&x, v.clone(), correspondence(Space::PlaneStrain, g)),
            &y,
            DT,
        );
        let (mut worst, mut weakest) = (f64::NEG_INFINITY, f64::INFINITY);
        for q in (0..x.len()).filter(|&q| interior(q)) {
            let along = f[q].x * sign(q);
            worst = worst.max(along);
            weakest = weakest.min(-along);
            if g == 0.0 {
                assert!(
                    f[q].norm() < 1e-9 * scale,
                    "G = 0: |f| {:e} against {scale:e}",
                    f[q].norm()
                );
            }
        }
        println!("G = {g}: largest f·u/|u| {worst:.3e}, weakest pull-back {weakest:.3e}, scale {scale:.3e}");
        if g > 0.0 {
            assert!(
                worst < 0.0,
                "an interior particle is not pulled back: {worst:e}"
            );
            // Measured 0.32 G × scale.
            assert!(
                weakest > 0.1 * g * scale,
                "pull-back {weakest:e} against {scale:e}"
            );
        }
    }
}

/// Any material of `material/` on correspondence particles, through the
/// update MPM particles take: under an affine map beyond yield (Johnson–Cook
/// copper, plane strain), every particle of a perturbed lattice, surface
/// included, has the stress and history of the single-point update under
/// the same F, and it has yielded.
#[test]
fn correspondence_particles_take_the_stress_update_of_their_material() {
    use crate::dim::{embed_deformation, Mat3};
    use crate::material::Increment;
    let text = "youngs_modulus = 117.0e9\npoisson_ratio = 0.35\nyield_stress = 157.0e6\n\
                hardening_modulus = 425.0e6\nhardening_exponent = 1.0";
    let values: toml::Table = toml::from_str(text).unwrap();
    let copper =
        crate::material::registry::build("material.0", "johnson_cook", 8930.0, &values).unwrap();
    let dx = 1e-3;
    let x = lattice::<2>(12, dx, 0.2);
    let m = copper.p_wave_modulus();
    let law = BondLaw::Correspondence(Correspondence::new(Space::PlaneStrain, m, 3.0 * dx, 0.1));
    let b = PdBody::new(0, (0..x.len()).collect(), &x, vec![dx * dx; x.len()], law);
    let mut b = b.with_stress(StressState::at_rest(copper.clone(), x.len()));
    let f = Tensor::<2>::new(1.02, 0.01, 0.0, 0.99);
    let y: Vec<Vector<2>> = x.iter().map(|p| f * p).collect();
    bond_forces(&mut b, &y, DT);
    let nh = copper.n_history();
    let mut h = vec![0.0; nh];
    copper.initial_history(&Mat3::zeros(), &mut h);
    let h0 = h.clone();
    let inc = Increment::new(
        Mat3::identity(),
        embed_deformation(&f),
        DT,
        Mat3::zeros(),
        &h0,
    );
    let single = copper.update(&inc, &mut h);
    let s = b.stress.as_ref().unwrap();
    let worst = (0..x.len())
        .map(|i| (s.stress[i] - single).norm() / single.norm())
        .fold(0.0, f64::max);
    let eps_p = copper.equivalent_plastic_strain(&h).unwrap_or(0.0);
    println!("σ against the single point: worst relative {worst:.2e}; ε_p {eps_p:.4}");
    assert!(eps_p > 0.005, "the map is beyond yield: ε_p = {eps_p}");
    assert!(worst < 1e-10, "{worst:e}");
    let history_worst = (0..x.len())
        .flat_map(|i| (0..nh).map(move |k| (i, k)))
        .map(|(i, k)| (s.history[i * nh + k] - h[k]).abs() / h[k].abs().max(1e-3))
        .fold(0.0, f64::max);
    println!("history {h:?}: worst relative {history_worst:.2e}");
    assert!(history_worst < 1e-10, "{history_worst:e}");
}
