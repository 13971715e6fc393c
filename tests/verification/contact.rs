//! Contact between bodies in the explicit solver (`[[contact]]`,
//! `mpm::solver::explicit::contact`).
//!
//! - A block sliding on an elastic base tilted by rotating gravity,
//!   g = 9.81 (sin θ, −cos θ), θ = 45° (`problems/contact_incline.toml`): the
//!   centre of mass moves x(t) = ½ g t² (sin θ − μ cos θ) when tan θ > μ, not at
//!   all when tan θ ≤ μ. MPM-Geomechanics' terrain contact, on the same test at
//!   θ = 45°, is 0.009 %, 0.11 % and 0.68 % off at μ = 0, 0.3, 0.5; the issue asks
//!   1 % at the end time.
//! - Two elastic disks colliding off-centre with friction
//!   (`problems/contact_disks.toml`): they bounce off and separate, where one
//!   shared velocity field keeps them together; momentum is conserved to
//!   round-off; kinetic + strain energy + the energy friction dissipated stays
//!   within the explicit method's own energy error of the initial energy.

use crate::common::{
    assert_within, newton_order, problem, read_output, run_cli, run_problem, run_text,
    shape_functions, step_residuals, Table,
};
use mpm::run::summary::Status;
use mpm::scene::ShapeFunction;
use strum::IntoEnumIterator;

const G: f64 = 9.81;

/// (time, centre-of-mass displacement of the block along the incline, output)
/// of `problems/contact_incline.toml`.
fn slide(theta_deg: f64, mu: f64, extra: &[&str]) -> (f64, f64, tempfile::TempDir) {
    let text = std::fs::read_to_string(problem("contact_incline.toml")).unwrap();
    slide_on(&text, theta_deg, mu, extra)
}

/// [`slide`] for the incline scene `text` (e.g. with a rigid base).
fn slide_on(text: &str, theta_deg: f64, mu: f64, extra: &[&str]) -> (f64, f64, tempfile::TempDir) {
    let th = theta_deg.to_radians();
    let gravity = format!("gravity=[{},{}]", G * th.sin(), -G * th.cos());
    let mu = format!("contact.0.friction_coefficient={mu}");
    let mut overrides = vec![gravity.as_str(), mu.as_str(), "output.frames=0"];
    overrides.extend(extra);
    let (result, dir) = run_text(text, &overrides);
    assert_eq!(result.unwrap().status, Status::Completed);
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, x) = (h.col("t"), h.col("body1_x"));
    (*t.last().unwrap(), x.last().unwrap() - x[0], dir)
}

/// The text of `problems/NAME` with `from`, which it must hold, replaced by `to`.
fn problem_with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(problem(name)).unwrap();
    assert!(text.contains(from), "{name} holds no {from:?}");
    text.replace(from, to)
}

/// The rigid block's acceleration down the slope, g (sin θ − μ cos θ), or 0 where
/// it sticks.
fn acceleration(theta_deg: f64, mu: f64) -> f64 {
    let th = theta_deg.to_radians();
    G * (th.sin() - mu * th.cos()).max(0.0)
}

fn closed_form(theta_deg: f64, mu: f64, t: f64) -> f64 {
    0.5 * acceleration(theta_deg, mu) * t * t
}

#[test]
fn block_slides_on_an_elastic_incline_as_the_closed_form() {
    // Measured: +0.038 %, +0.128 %, +0.644 % (cpGIMP, 20 cells over the block);
    // the issue's 1 % at μ = 0.5, where it is tighter than twice that.
    for (mu, tolerance) in [(0.0, 1e-3), (0.3, 3e-3), (0.5, 1e-2)] {
        let (t, x, _) = slide(45.0, mu, &[]);
        let exact = closed_form(45.0, mu, t);
        println!("mu {mu}: x = {x:.5} m, closed form {exact:.5} m");
        assert_within(&format!("mu {mu}: error"), x / exact - 1.0, tolerance);
    }
}

#[test]
fn contact_force_carries_the_block() {
    // Sliding at μ = 0.3: the block presses on the base with its weight's normal
    // part m g cos θ and drags it with μ times that. contact.csv holds the mean
    // force on the base (the pair's first body) between rows; averaged over the
    // slide after the first 0.1 s (the weight comes on suddenly and rings), from
    // the row of 0.1 s on (rows every 0.01 s, each within half a step of its
    // time). The mean moves by 1 % when the start moves by 0.01 s (the ringing).
    let (_, _, dir) = slide(45.0, 0.3, &[]);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fx, fy) = (c.col("t"), c.col("fx"), c.col("fy"));
    let (mut ix, mut iy, mut span) = (0.0, 0.0, 0.0);
    for k in 1..t.len() {
        if t[k - 1] >= 0.1 - 0.005 {
            let dt = t[k] - t[k - 1];
            ix += fx[k] * dt;
            iy += fy[k] * dt;
            span += dt;
        }
    }
    let (fx, fy) = (ix / span, iy / span);
    let weight = 1000.0 * 1.0 * 0.5 * G * 45f64.to_radians().cos();
    println!(
        "mean force on the base: ({fx:.1}, {fy:.1}) N/m; m g cos θ = {weight:.1}, μ m g cos θ = {:.1}",
        0.3 * weight
    );
    // Measured +0.08 % and +0.08 % (−0.14 % and −0.13 % from a row at 0.101 s
    // when the rows drifted late, issue 56).
    assert_within("normal force / (m g cos θ) − 1", -fy / weight - 1.0, 4e-3);
    assert_within(
        "friction force / (μ m g cos θ) − 1",
        fx / (0.3 * weight) - 1.0,
        4e-3,
    );
}

/// Explicit contact forces per particle (particles_final.csv's `contact_f*`):
/// the momentum exchanged at each node in the last step, shared by its
/// field's particles by their mass, over Δt. With a history row at every
/// step, contact.csv's last row is the last step's force on the base (the
/// pair's first body): the base's particles sum to it, the block's to its
/// opposite, to round-off (measured ≤ 4.6e-16), and only the
/// particles along the interface carry any (86 of the base's 1400).
#[test]
fn explicit_contact_forces_per_particle_sum_to_the_pair_force() {
    let (result, dir) = run_problem(
        "contact_incline.toml",
        &["output.history_interval=0", "output.frames=0"],
    );
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let last = c.col("t").len() - 1;
    let pair = [c.col("fx")[last], c.col("fy")[last]];
    let scale = pair[0].hypot(pair[1]);
    assert!(scale > 0.0, "the block presses on the base");
    let body = p.col("body");
    for (b, sign, what) in [(0.0, 1.0, "base"), (1.0, -1.0, "block")] {
        for (d, column) in ["contact_fx", "contact_fy"].into_iter().enumerate() {
            let sum: f64 = (p.col(column).iter().zip(body))
                .filter(|(_, &k)| k == b)
                .map(|(f, _)| f)
                .sum();
            assert_within(
                &format!("{what}: sum of {column} / pair force - sign, relative"),
                (sum - sign * pair[d]) / scale,
                1e-12,
            );
        }
    }
    let (fx, fy) = (p.col("contact_fx"), p.col("contact_fy"));
    let touching = (0..fx.len())
        .filter(|&q| fx[q] != 0.0 || fy[q] != 0.0)
        .count();
    assert!(
        touching > 0 && touching < fx.len() / 4,
        "{touching} particles carry a force"
    );
}

#[test]
fn block_sticks_when_tan_theta_is_below_mu() {
    // tan 45° = 1 < μ = 1.2. The weight comes on suddenly and the base pressure
    // rings between 0 and twice the weight, so at its low instants the block
    // creeps (78 mm undamped); a little local damping (10 %) lets the load come on
    // gently, as in tests/verification/friction.rs. The damped frictionless run
    // slides ~0.8 m.
    // Closer to the limit, μ = 1.05 = 1.05 tan θ with the same damping and
    // gravity raised over 0.3 s holds too: measured 1.2 mm in 1 s (4.4 mm in
    // 0.5 s with gravity at once).
    let (_, x, _) = slide(45.0, 1.2, &["solver.damping=0.1"]);
    let (_, free, _) = slide(45.0, 0.0, &["solver.damping=0.1"]);
    let near = [
        "solver.damping=0.1",
        "solver.gravity_ramp_time=0.3",
        "solver.end_time=1.0",
    ];
    let (_, close, _) = slide(45.0, 1.05, &near);
    println!("stick: x = {x:.2e} m, at mu 1.05 {close:.2e} m; frictionless damped: {free:.3} m");
    assert!(free > 0.7, "frictionless damped run moved only {free}");
    assert!(x.abs() < 5e-3, "block crept {x} m with tan θ < μ");
    assert!(
        close.abs() < 3e-3,
        "block crept {close} m at μ = 1.05 tan θ"
    );
}

/// `problems/contact_incline.toml` with the base a rigid body at rest.
fn rigid_incline() -> String {
    let text = std::fs::read_to_string(problem("contact_incline.toml")).unwrap();
    let rigid = text
        .replace(
            "[[body]]\nname = \"base\"\nmaterial = \"elastic\"",
            "[[material]]\nname = \"rigid\"\nmodel = \"rigid\"\ndensity = 1000.0\n\n\
             [[body]]\nname = \"base\"\nmaterial = \"rigid\"",
        )
        .replace("[[boundary]]\nface = \"ymin\"\ncondition = \"fixed\"\n", "");
    assert!(rigid.contains("model = \"rigid\"") && !rigid.contains("[[boundary]]"));
    rigid
}

#[test]
#[ignore = "slow tier, 21 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn block_sticks_undamped_under_gradual_gravity_on_a_30_degree_slope() {
    // θ = 30°, μ = 0.7 = 1.21 tan θ, gravity raised over 0.3 s, no damping, 1 s.
    // Measured: 0.38 mm on the elastic base, 0.15 mm on a rigid one;
    // frictionless 1.79 m. What it does not cover
    // (docs/contact.md, "Sticking needs damping"): gravity applied at once (the
    // block slides 94 mm and 0.41 m) and slopes from 40° on with FLIP (at 45°:
    // 0.27 m here, 0.59 m on a rough grid face, even with the ramp; PIC, or a
    // block whose weight acts within the middle third, holds: the tests below).
    let gradual = ["solver.gravity_ramp_time=0.3", "solver.end_time=1.0"];
    let elastic = std::fs::read_to_string(problem("contact_incline.toml")).unwrap();
    let moved = |text: &str, mu: f64| slide_on(text, 30.0, mu, &gradual).1;
    let (on_elastic, on_rigid) = (moved(&elastic, 0.7), moved(&rigid_incline(), 0.7));
    let free = moved(&elastic, 0.0);
    println!(
        "θ = 30°, μ = 0.7, undamped: {on_elastic:.2e} m on the elastic base, \
         {on_rigid:.2e} m on the rigid one; frictionless {free:.3} m"
    );
    assert!(free > 1.0, "frictionless run moved only {free}");
    assert!(
        on_elastic.abs() < 1e-3 && on_rigid.abs() < 1e-3,
        "{on_elastic}, {on_rigid}"
    );
}

/// The block's displacement at t ≥ `ramp` when gravity rises linearly from zero
/// over `ramp` (`solver.gravity_ramp_time`): the acceleration a = g (sin θ − μ cos θ)
/// grows as a t / T, so x = a (t²/2 − T t/2 + T²/6).
fn closed_form_ramped(theta_deg: f64, mu: f64, t: f64, ramp: f64) -> f64 {
    assert!(t >= ramp);
    acceleration(theta_deg, mu) * (t * t / 2.0 - ramp * t / 2.0 + ramp * ramp / 6.0)
}

#[test]
#[ignore = "slow tier, 23 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn block_slides_and_sticks_near_the_limit_with_pic_and_gravity_raised() {
    // 45°, PIC, gravity raised over 0.3 s, undamped, 1 s. Near tan θ = 1 FLIP's
    // and APIC's particle velocities lift the block off the base (10–30 mm) and
    // its friction falls short; PIC keeps it down (docs/contact.md, "Sliding near
    // the sticking limit"). Measured: μ = 0.7: −0.0 % (FLIP +1.3 %, APIC −0.8 %);
    // μ = 0.8: +0.7 % (FLIP +24.2 %, APIC +0.3 %); μ = 1.2 sticks: 1.2 mm
    // (FLIP 0.27 m, APIC 0.16 m).
    let pic = [
        "solver.flip=0.0",
        "solver.gravity_ramp_time=0.3",
        "solver.end_time=1.0",
    ];
    // Measured −0.017 % and +0.69 % (the issue's 1 % at μ = 0.8).
    for (mu, tolerance) in [(0.7, 5e-4), (0.8, 1e-2)] {
        let (t, x, _) = slide(45.0, mu, &pic);
        let exact = closed_form_ramped(45.0, mu, t, 0.3);
        println!("PIC, mu {mu}: x = {x:.5} m, closed form {exact:.5} m");
        assert_within(&format!("PIC, mu {mu}: error"), x / exact - 1.0, tolerance);
    }
    let (_, stuck, _) = slide(45.0, 1.2, &pic);
    println!("PIC, mu 1.2: x = {stuck:.2e} m");
    assert!(stuck.abs() < 3e-3, "block crept {stuck} m with tan θ < μ");
}

#[test]
fn block_sticks_undamped_on_45_degrees_when_its_weight_acts_within_the_middle_third() {
    // The 1 m × 0.5 m block sticking on 45° takes a friction force m g sin θ at its
    // base, H/2 below its centre; the base's reaction then acts e = (H/2) tan θ =
    // 0.25 m ahead of the centre, beyond the middle third (L/6 = 0.167 m), so the
    // rear of the base unloads and the undamped block rocks and creeps (0.27 m
    // in 1 s with FLIP). Half as tall (e = 0.125 m) it sticks: measured 0.25 mm.
    let gradual = [
        "solver.gravity_ramp_time=0.3",
        "solver.end_time=1.0",
        "body.1.max=[1.0,0.5]",
    ];
    let (_, stuck, _) = slide(45.0, 1.2, &gradual);
    let (t, x, _) = slide(45.0, 0.5, &gradual);
    let exact = closed_form_ramped(45.0, 0.5, t, 0.3);
    println!(
        "H = 0.25 m, FLIP, undamped: mu 1.2 moved {stuck:.2e} m; mu 0.5 slid {x:.4} m \
         (closed form {exact:.4} m)"
    );
    assert!((x / exact - 1.0).abs() < 0.01, "mu 0.5: {x}, exact {exact}");
    assert!(stuck.abs() < 1e-3, "block crept {stuck} m with tan θ < μ");
}

/// Particles of the final state: (body, x, y, vx, vy, mass).
fn final_particles(dir: &tempfile::TempDir) -> Vec<(usize, f64, f64, f64, f64, f64)> {
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (b, x, y) = (p.col("body"), p.col("x"), p.col("y"));
    let (vx, vy, m) = (p.col("vx"), p.col("vy"), p.col("mass"));
    (0..b.len())
        .map(|i| (b[i] as usize, x[i], y[i], vx[i], vy[i], m[i]))
        .collect()
}

/// The smallest distance between particles of body 0 and body 1.
fn closest_approach(p: &[(usize, f64, f64, f64, f64, f64)]) -> f64 {
    let mut d = f64::INFINITY;
    for a in p.iter().filter(|a| a.0 == 0) {
        for b in p.iter().filter(|b| b.0 == 1) {
            d = d.min((a.1 - b.1).hypot(a.2 - b.2));
        }
    }
    d
}

/// The disks scene without its `[[contact]]` table.
fn disks_without_contact() -> String {
    let text = std::fs::read_to_string(problem("contact_disks.toml")).unwrap();
    text.replace("[[contact]]\nfriction_coefficient = 0.3\n", "")
}

#[test]
fn disks_bounce_off_and_separate_with_momentum_conserved() {
    disks_bounce_off(&[]);
    // APIC (`solver::explicit::apic`): the same with the affine transfers.
    disks_bounce_off(&["solver.velocity_transfer=\"apic\""]);
}

fn disks_bounce_off(overrides: &[&str]) {
    let sets = [&["output.frames=0"], overrides].concat();
    let (result, dir) = run_problem("contact_disks.toml", &sets);
    result.unwrap();
    let p = final_particles(&dir);
    let gap = closest_approach(&p);
    // Momentum: zero at the start (equal disks, opposite velocities).
    let (px, py) = p
        .iter()
        .fold((0.0, 0.0), |(x, y), q| (x + q.5 * q.3, y + q.5 * q.4));
    let scale: f64 = p.iter().map(|q| q.5 * 0.2).sum();
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let vx0 = *h.col("body0_vx").last().unwrap();
    println!(
        "contact {overrides:?}: closest particles {gap:.4} m apart at the end, left disk vx {vx0:.4}, \
         momentum ({:.1e}, {:.1e}) of m v0",
        px / scale,
        py / scale
    );
    assert!(gap > 0.1, "the disks did not separate: {gap}");
    assert!(vx0 < -0.05, "the left disk did not rebound: vx = {vx0}");
    assert!((px / scale).abs() < 1e-12 && (py / scale).abs() < 1e-12);
}

/// The spin ω = L/I of body 0 about its centre of mass at the end.
fn spin(p: &[(usize, f64, f64, f64, f64, f64)]) -> f64 {
    spin_of(p, 0)
}

/// The spin of body `body`: its angular momentum about its centre of mass over
/// its moment of inertia there.
fn spin_of(p: &[(usize, f64, f64, f64, f64, f64)], body: usize) -> f64 {
    let q: Vec<_> = p.iter().filter(|q| q.0 == body).collect();
    let m: f64 = q.iter().map(|q| q.5).sum();
    let xc = q.iter().map(|q| q.5 * q.1).sum::<f64>() / m;
    let yc = q.iter().map(|q| q.5 * q.2).sum::<f64>() / m;
    let l: f64 = q
        .iter()
        .map(|q| q.5 * ((q.1 - xc) * q.4 - (q.2 - yc) * q.3))
        .sum();
    let i: f64 = q
        .iter()
        .map(|q| q.5 * ((q.1 - xc).powi(2) + (q.2 - yc).powi(2)))
        .sum();
    l / i
}

#[test]
fn frictionless_disks_do_not_spin_where_one_field_carries_them_along() {
    // A frictionless contact pushes along the normal only, through the disks'
    // centres: it leaves them without spin. One shared velocity field (no
    // contact) grips them tangentially like a rough contact. Measured ω: 0.015
    // rad/s frictionless, 0.53 with μ = 0.3, 0.44 with one field.
    let (result, dir) = run_problem(
        "contact_disks.toml",
        &["contact.0.friction_coefficient=0", "output.frames=0"],
    );
    result.unwrap();
    let smooth = spin(&final_particles(&dir));
    let (result, dir) = run_text(&disks_without_contact(), &["output.frames=0"]);
    result.unwrap();
    let carried = spin(&final_particles(&dir));
    println!(
        "spin of the left disk: frictionless contact {smooth:.4} rad/s, one field {carried:.4}"
    );
    assert!(
        carried.abs() > 0.3,
        "one field should spin the disks: {carried}"
    );
    assert!(
        smooth.abs() < 0.1 * carried.abs(),
        "frictionless contact spun the disk: {smooth}"
    );
}

#[test]
fn disks_do_not_interpenetrate() {
    // At the deepest compression (t = 0.65 s) the particles of the two disks keep
    // at least half a particle spacing (0.0125 m) apart.
    let (result, dir) = run_problem(
        "contact_disks.toml",
        &["solver.end_time=0.65", "output.frames=0"],
    );
    result.unwrap();
    let d = closest_approach(&final_particles(&dir));
    println!("closest particles of the two disks at t = 0.65 s: {d:.4} m");
    assert!(d > 0.5 * 0.0125, "particles of the disks came within {d} m");
}

#[test]
fn disks_account_for_their_energy() {
    // Kinetic + strain + frictional dissipation against the initial kinetic energy,
    // at every history row. The explicit method's own energy error on this scene
    // is +3.1 % without friction (μ = 0: nothing dissipated); with μ = 0.3 friction
    // dissipates 0.14 J of 5.0 J and the balance stays within 2 %.
    let (result, dir) = run_problem("contact_disks.toml", &["output.frames=0"]);
    result.unwrap();
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, k, s) = (h.col("t"), h.col("kinetic"), h.col("strain"));
    let (tc, dissipated) = (c.col("t"), c.col("dissipation"));
    let e0 = k[0] + s[0];
    let mut worst: f64 = 0.0;
    for i in 0..t.len() {
        let d = (0..tc.len())
            .find(|&j| tc[j] == t[i])
            .map_or(0.0, |j| dissipated[j]);
        worst = worst.max(((k[i] + s[i] + d) / e0 - 1.0).abs());
    }
    let total = *dissipated.last().unwrap();
    println!("friction dissipated {total:.4} J of {e0:.4} J; worst balance {worst:.3e}");
    assert!(
        total > 0.01 * e0,
        "friction should dissipate something: {total}"
    );
    assert!(worst < 0.03, "energy balance off by {worst}");
}

#[test]
fn bodies_that_never_touch_run_bit_for_bit_as_without_contact() {
    // The disks moving apart: no node is ever shared, so nothing is split.
    let apart = [
        "body.0.velocity=[-0.2,0.0]",
        "body.1.velocity=[0.2,0.0]",
        "solver.end_time=0.5",
        "output.frames=0",
    ];
    let (with, dir_with) = run_problem("contact_disks.toml", &apart);
    with.unwrap();
    // Contact runs on the node map; without contact the scene would take the
    // scatter path (`solver.transfer`), equal only to round-off.
    let gather = [&apart[..], &["solver.transfer=\"gather\""]].concat();
    let (without, dir_without) = run_text(&disks_without_contact(), &gather);
    without.unwrap();
    assert!(
        read_output(&dir_with, "history.csv") == read_output(&dir_without, "history.csv"),
        "history.csv differs"
    );
    // particles_final.csv: the same columns to the bit, and the contact run's
    // per-particle contact forces (its extra columns) zero.
    let table =
        |dir: &tempfile::TempDir| Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (a, b) = (table(&dir_with), table(&dir_without));
    for name in &a.header {
        match name.starts_with("contact_f") {
            true => assert!(a.col(name).iter().all(|&f| f == 0.0), "{name} is not zero"),
            false => assert!(
                (a.col(name).iter().zip(b.col(name))).all(|(x, y)| x.to_bits() == y.to_bits()),
                "particles_final.csv: {name} differs"
            ),
        }
    }
    assert_eq!(a.header.len(), b.header.len() + 2, "{:?}", a.header);
}

#[test]
fn contact_does_not_depend_on_the_number_of_threads() {
    let set = ["solver.end_time=1.0", "output.frames=0"];
    let one = run_cli("contact_disks.toml", 1, &set);
    let two = run_cli("contact_disks.toml", 2, &set);
    for f in ["particles_final.csv", "contact.csv", "history.csv"] {
        assert!(read_output(&one, f) == read_output(&two, f), "{f} differs");
    }
}

/// The cylinder of `problems/contact_cylinder.toml` as first built: a
/// grid-aligned lattice (a stepped bottom), contact within half a cell
/// (λ = 0.5), gravity applied at once.
const LATTICE_CYLINDER: [&str; 3] = [
    "body.1.fill=\"lattice\"",
    "contact.0.gap_factor=0.5",
    "solver.gravity_ramp_time=0",
];

/// Centre-of-mass displacement of the lattice cylinder (`LATTICE_CYLINDER`)
/// at 0.5 s, and the rigid cylinder's closed form.
fn roll(mu: f64, extra: &[&str]) -> (f64, f64) {
    let mu_set = format!("contact.0.friction_coefficient={mu}");
    let mut overrides = vec![mu_set.as_str(), "output.frames=0"];
    overrides.extend(LATTICE_CYLINDER);
    overrides.extend(extra);
    let (result, dir) = run_problem("contact_cylinder.toml", &overrides);
    assert_eq!(result.unwrap().status, Status::Completed);
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, x) = (h.col("t"), h.col("body1_x"));
    let t = *t.last().unwrap();
    let th = 45f64.to_radians();
    // Slip when tan θ > 3μ: a = g (sin θ − μ cos θ); else rolling: a = ⅔ g sin θ.
    let a = if th.tan() > 3.0 * mu {
        G * (th.sin() - mu * th.cos())
    } else {
        2.0 / 3.0 * G * th.sin()
    };
    (x.last().unwrap() - x[0], 0.5 * a * t * t)
}

#[test]
fn slipping_cylinder_follows_the_closed_form() {
    // Measured: −0.052 % (μ = 0), +0.084 % (μ = 0.1).
    for (mu, tolerance) in [(0.0, 1.5e-3), (0.1, 2e-3)] {
        let (x, exact) = roll(mu, &[]);
        println!("cylinder, mu {mu}: x = {x:.4} m, closed form {exact:.4} m");
        assert_within(
            &format!("cylinder, mu {mu}: error"),
            x / exact - 1.0,
            tolerance,
        );
    }
}

#[test]
#[ignore = "slow tier, 41 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn rolling_cylinder_converges_at_first_order() {
    // Rolling (μ = 0.5 > tan θ / 3): the particle lattice gives the disk a flat,
    // stepped bottom that resists rolling, an error of first order in h (the same
    // on a rough rigid face). Measured: −17.2 % at h = R/10, −6.9 % at R/20.
    let (coarse, exact) = roll(0.5, &[]);
    let (fine, _) = roll(0.5, &["grid.cells=[120,56]"]);
    let (e1, e2) = ((coarse / exact - 1.0).abs(), (fine / exact - 1.0).abs());
    let rate = (e1 / e2).log2();
    println!("rolling cylinder: error {e1:.3} (h = R/10), {e2:.3} (R/20), rate {rate:.2}");
    assert!(e2 < 0.12 && rate > 0.8, "errors {e1}, {e2}");
    // A polar fill (rings about the centre: a smooth outer surface) takes a third
    // of the coarse error away: measured −11.7 % at R/10 (−13.3 % before the gap
    // was taken at the node). What
    // is left is the contact's: nodes that enter the contact ahead of the
    // rolling point lose their approach velocity, a loss per unit rolled length
    // of order h.
    let (polar, _) = roll(0.5, &["body.1.fill=\"polar\""]);
    let e3 = (polar / exact - 1.0).abs();
    println!("rolling cylinder, polar fill: error {e3:.3} (h = R/10)");
    assert!(e3 < e1, "polar fill: {e3} against {e1}");
    assert_within("rolling cylinder, polar fill: error at R/10", e3, 0.24);
}

/// The cylinder of `problems/contact_cylinder.toml` as shipped (filled in rings,
/// contact declared only where the surfaces touch, λ = 0.02) on `cells`, gravity
/// raised linearly over `ramp` seconds (0: at once): the errors of its centre's
/// displacement and of its spin at 0.5 s against the rigid cylinder's closed
/// form. With a ramp over T the motion is that of a sudden load at T/2 plus a
/// small offset: x = a ((t − T/2)²/2 + T²/24), ω = −2μ g cos θ (t − T/2)/R in
/// slip and −a (t − T/2)/R rolling.
fn roll_at_touch(mu: f64, cells: &str, ramp: f64) -> (f64, f64) {
    let set = [
        format!("contact.0.friction_coefficient={mu}"),
        format!("grid.cells={cells}"),
        format!("solver.gravity_ramp_time={ramp}"),
    ];
    let (result, dir) = run_problem(
        "contact_cylinder.toml",
        &[&set[0], &set[1], &set[2], "output.frames=0"],
    );
    assert_eq!(result.unwrap().status, Status::Completed);
    cylinder_errors(&dir, mu, ramp)
}

/// The errors of the centre's displacement and of the spin of
/// `contact_cylinder.toml`'s disk (body 1, R = 0.5 m, 45°) in the run written to
/// `dir`, against the rigid cylinder's closed form with gravity raised over
/// `ramp` (`roll_at_touch`): slipping where tan θ > 3μ, else rolling.
fn cylinder_errors(dir: &tempfile::TempDir, mu: f64, ramp: f64) -> (f64, f64) {
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, x) = (h.col("t"), h.col("body1_x"));
    let te = *t.last().unwrap() - 0.5 * ramp;
    let th = 45f64.to_radians();
    let (a, omega) = if th.tan() > 3.0 * mu {
        (
            G * (th.sin() - mu * th.cos()),
            -2.0 * mu * G * th.cos() * te / 0.5,
        )
    } else {
        let a = 2.0 / 3.0 * G * th.sin();
        (a, -a * te / 0.5)
    };
    let moved = x.last().unwrap() - x[0];
    let exact = a * (0.5 * te * te + ramp * ramp / 24.0);
    let spin = spin_of(&final_particles(dir), 1);
    (moved / exact - 1.0, spin / omega - 1.0)
}

#[test]
fn rolling_cylinder_filled_in_rings_with_contact_at_touch_is_within_3_percent() {
    // The rolling loss of `rolling_cylinder_converges_at_first_order` has three
    // causes: the lattice's stepped bottom, nodes declared in contact ahead of
    // the rolling point (λ = 0.5: within half a cell), and a gap taken as the
    // smallest in a node's support, so that the nodes just ahead of the rolling
    // point lost their approach (the rotation) at every step: a counter-torque
    // (docs/contact.md). A polar fill, λ = 0.02 and the gap at the node remove
    // them. Measured, centre (spin): rolling +0.54 % (−5.4 %) at R/10, +0.91 %
    // (−5.4 %) at R/20; slipping at μ = 0.1 −0.56 % (−1.2 %) at R/10, −1.05 %
    // (−0.58 %) at R/20. (With the smallest gap in the support the spin was
    // −5.2 %, −7.1 %, −28 % and −4.8 %.) Rolling, the disk still slips at 0.5 s
    // (v + ωR = 0.13 and 0.16 m/s): the spin misses the issue's 3 % there;
    // gravity raised over 0.1 s removes that (the next test, which also runs
    // R/20; this one keeps R/10 for time).
    for (mu, cells, spin_bound) in [(0.5, "[60,28]", 0.07), (0.1, "[60,28]", 0.03)] {
        let (x, spin) = roll_at_touch(mu, cells, 0.0);
        println!("cylinder in rings, λ = 0.02, μ = {mu}, {cells}: centre {x:+.4}, spin {spin:+.4}");
        assert!(x.abs() < 0.03, "μ = {mu}, {cells}: centre {x}");
        assert!(spin.abs() < spin_bound, "μ = {mu}, {cells}: spin {spin}");
    }
}

#[test]
#[ignore = "slow tier, 37 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn rolling_cylinder_under_ramped_gravity_rolls_within_3_percent() {
    // Gravity applied at once makes the disk bounce on the base for the whole
    // run (the normal force swings between 0 and twice the weight) and slip
    // while it is light. Raised over 0.1 s (about one period of that bounce) it
    // rolls: v + ωR = 0.012 m/s at R/10 against 0.13 without the ramp. Measured,
    // centre (spin): rolling −0.91 % (−2.2 %) at R/10, −0.99 % (−2.0 %) at R/20
    // (not run here, for time); slipping −1.1 % (−2.15 %) at R/20 (at R/10
    // +0.01 % but the spin −3.75 %, so slipping is checked at R/20).
    for (mu, cells) in [(0.5, "[60,28]"), (0.1, "[120,56]")] {
        let (x, spin) = roll_at_touch(mu, cells, 0.1);
        println!("cylinder in rings, gravity over 0.1 s, μ = {mu}, {cells}: centre {x:+.4}, spin {spin:+.4}");
        assert!(
            x.abs() < 0.03 && spin.abs() < 0.03,
            "μ = {mu}, {cells}: centre {x}, spin {spin}"
        );
    }
}

#[test]
fn a_polar_fill_has_the_disk_s_area_and_centre() {
    // Rings of equal width about the centre, equal areas within a ring: the
    // areas sum to πR² and the centroid is the centre, to round-off.
    let text = std::fs::read_to_string(problem("contact_cylinder.toml")).unwrap();
    assert!(text.contains("fill = \"polar\""));
    let scene = mpm::scene::Scene::parse("c.toml", &text, &[]).unwrap();
    let m = mpm::model::Model::<2>::build(&scene).unwrap();
    let p = &m.particles;
    let disk: Vec<usize> = (0..p.len()).filter(|&q| p.body[q] == 1).collect();
    let area: f64 = disk.iter().map(|&q| p.volume[q]).sum();
    let exact = std::f64::consts::PI * 0.25;
    assert!((area / exact - 1.0).abs() < 1e-12, "area {area} vs {exact}");
    let (cx, cy) = disk.iter().fold((0.0, 0.0), |(x, y), &q| {
        (x + p.volume[q] * p.x[q][0], y + p.volume[q] * p.x[q][1])
    });
    assert!((cx / area).abs() < 1e-12 && (cy / area - 0.75).abs() < 1e-12);
    // Every particle is inside the disk, the outer ring half a ring width in.
    let outer = disk
        .iter()
        .map(|&q| (p.x[q] - nalgebra::Vector2::new(0.0, 0.75)).norm());
    assert!((outer.fold(0.0, f64::max) - 0.4875).abs() < 1e-12);
}

#[test]
fn a_polar_fill_of_a_cylinder_is_the_disk_s_fill_in_layers() {
    // papers/contact/seed_cylinder_3d.toml: R = 3.2 m, 4 m long, spacing 0.2 m:
    // 20 layers of 0.2 m, each the rings of the 2D disk of the same radius and
    // spacing; the volumes sum to πR²H and the centroid is on the axis at
    // mid-length, to round-off.
    let read = |name: &str| {
        let path = format!("{}/papers/contact/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap();
        mpm::scene::Scene::parse(&path, &text, &[]).unwrap()
    };
    let m = mpm::model::Model::<3>::build(&read("seed_cylinder_3d.toml")).unwrap();
    let p = &m.particles;
    let cyl: Vec<usize> = (0..p.len()).filter(|&q| p.body[q] == 1).collect();
    let volume: f64 = cyl.iter().map(|&q| p.volume[q]).sum();
    let exact = std::f64::consts::PI * 3.2 * 3.2 * 4.0;
    assert!(
        (volume / exact - 1.0).abs() < 1e-12,
        "volume {volume} vs {exact}"
    );
    let centroid = cyl
        .iter()
        .fold(nalgebra::Vector3::zeros(), |c, &q| c + p.volume[q] * p.x[q])
        / volume;
    let err = (centroid - nalgebra::Vector3::new(4.0, 5.2, 2.0)).norm();
    assert!(err < 1e-12, "centroid {centroid:?}");
    let disk = mpm::model::Model::<2>::build(&read("seed_cylinder.toml")).unwrap();
    let in_disk = (0..disk.particles.len())
        .filter(|&q| disk.particles.body[q] == 1)
        .count();
    assert_eq!(cyl.len(), 20 * in_disk);
    // Every domain is 0.2 m long along the axis, and inside the cylinder.
    for &q in &cyl {
        let r = (p.x[q].xy() - nalgebra::Vector2::new(4.0, 5.2)).norm();
        assert!(
            (p.half_length0[q].z - 0.1).abs() < 1e-12
                && r < 3.2
                && p.x[q].z > 0.0
                && p.x[q].z < 4.0
        );
    }
}

#[test]
fn rigid_plate_compresses_a_block_to_the_hencky_stress() {
    // problems/contact_plate.toml without its local damping: a rigid plate pushed
    // at 0.1 m/s 0.25 m into a 1 m block (Hencky, ν = 0, lateral rollers), so that
    // σ_yy(t) = E ln λ / λ with λ = 1 − 0.1 t, −383.6 kPa at the end. Measured:
    // volume mean of σ_yy −0.67 % off at the end; the plate's force in contact.csv
    // within 3.6 % of σ_yy(t) × 1 m at every row after 0.5 s; the plate's work equal
    // to the block's kinetic + strain energy to 1.6e-4; the plate on its path to
    // round-off; the block's top layer's domains 0.19 h into the plate (0.32 h
    // before the rigid projection kept the particle centres out).
    let (result, dir) = run_problem(
        "contact_plate.toml",
        &["output.frames=0", "solver.damping=0"],
    );
    assert_eq!(result.unwrap().status, Status::Completed);
    let hencky = hencky_plate_stress;
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, y, y0) = (p.col("body"), p.col("y"), p.col("Y0"));
    let (syy, volume) = (p.col("syy"), p.col("volume"));
    let (mut moment, mut v, mut plate_moved, mut block_top) = (0.0, 0.0, 0.0f64, f64::MIN);
    for i in 0..body.len() {
        if body[i] == 0.0 {
            moment += syy[i] * volume[i];
            v += volume[i];
            block_top = block_top.max(y[i]);
        } else {
            plate_moved = plate_moved.max((y[i] - y0[i] + 0.25).abs());
        }
    }
    let (mean, exact) = (moment / v, hencky(2.5));
    // The plate's force on the block, row by row, and its work.
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fy) = (c.col("t"), c.col("fy"));
    let (mut work, mut worst) = (0.0, 0.0f64);
    for k in 0..t.len() {
        work += fy[k] * -0.1 * (t[k] - if k == 0 { 0.0 } else { t[k - 1] });
        if t[k] >= 0.5 {
            worst = worst.max((fy[k] / hencky(t[k]) - 1.0).abs());
        }
    }
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let energy = h.col("kinetic").last().unwrap() + h.col("strain").last().unwrap();
    let penetration = block_top + 0.0125 * 0.75 - 0.75;
    println!(
        "mean syy {mean:.1} Pa, Hencky {exact:.1} Pa ({:.2e}); force within {worst:.3} of sigma(t) A; \
         plate work {work:.1} J against kinetic + strain {energy:.1} J; plate off its path by \
         {plate_moved:.1e} m; penetration {:.2} h",
        mean / exact - 1.0,
        penetration / 0.05
    );
    assert!(
        (mean / exact - 1.0).abs() < 0.015,
        "mean syy {mean}, exact {exact}"
    );
    assert!(worst < 0.05, "the plate's force is {worst} off sigma A");
    // Measured 1.6e-4.
    assert_within(
        "plate work / (kinetic + strain) − 1",
        work / energy - 1.0,
        5e-4,
    );
    assert!(
        plate_moved < 1e-12,
        "the rigid plate left its path by {plate_moved}"
    );
    // The particle centres stay out of the plate (the rigid projection), so the
    // top layer's domains overlap it by at most their half-width, 0.0125 m.
    assert!(
        penetration <= 0.0125 * (1.0 + 1e-9),
        "the block entered the plate by {penetration} m"
    );
}

/// An elastic block (0.5 m, 500 kg/m) thrown at 2 m/s against a rigid plate at rest.
const THROWN_BLOCK: &str = r#"dimension = 2
[grid]
min = [-0.5, -0.5]
max = [1.5, 1.0]
cells = [40, 30]
shape_function = "cpgimp"
[[material]]
name = "soil"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.0
[[material]]
name = "steel"
model = "rigid"
density = 1000.0
[[body]]
name = "block"
material = "soil"
shape = "rectangle"
min = [0.0, 0.0]
max = [1.0, 0.5]
velocity = [0.0, 2.0]
[[body]]
name = "plate"
material = "steel"
shape = "rectangle"
min = [-0.5, 0.6]
max = [1.5, 0.7]
[[contact]]
[solver]
kind = "explicit"
end_time = 0.2
cfl = 0.5
[output]
frames = 0
history_interval = 0.0
"#;

#[test]
fn contact_csv_holds_the_momentum_the_contact_passed() {
    // The recorded impulse (Σ f Δt over contact.csv's rows) against the block's
    // momentum change (history.csv), with FLIP and with PIC. Measured: equal to
    // 3e-15 relative.
    for flip in ["1.0", "0.0"] {
        let (result, dir) = run_text(THROWN_BLOCK, &[&format!("solver.flip={flip}")]);
        result.unwrap();
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let c = Table::read(&dir.path().join("contact.csv")).unwrap();
        let vy = h.col("body0_vy");
        let change = 500.0 * (vy.last().unwrap() - vy[0]);
        let (t, fy) = (c.col("t"), c.col("fy"));
        let impulse: f64 = (0..t.len())
            .map(|k| fy[k] * (t[k] - if k == 0 { 0.0 } else { t[k - 1] }))
            .sum();
        println!("flip {flip}: momentum change {change:.6} N s, recorded impulse {impulse:.6} N s");
        assert!(change < -1500.0, "the block did not bounce: {change}");
        assert!(
            (impulse / change - 1.0).abs() < 1e-12,
            "{impulse} against {change}"
        );
    }
}

#[test]
fn adhesion_holds_the_block_in_shear() {
    // Frictionless with adhesion c on the 1 m long interface: the block slides with
    // a = g sin θ − c L / m (m = 500 kg/m) while c L < m g sin θ = 3468 N/m, and
    // sticks above. Measured: +4.2 % at c = 2 kPa; 1.2 mm at c = 5 kPa.
    let (t, x, _) = slide(45.0, 0.0, &["contact.0.adhesion=2000"]);
    let a = G * 45f64.to_radians().sin() - 2000.0 / 500.0;
    let exact = 0.5 * a * t * t;
    let (_, stuck, _) = slide(45.0, 0.0, &["contact.0.adhesion=5000"]);
    println!("adhesion 2 kPa: x = {x:.4} m, closed form {exact:.4} m; 5 kPa: {stuck:.2e} m");
    assert_within("adhesion 2 kPa: error", x / exact - 1.0, 0.1);
    assert!(stuck.abs() < 5e-3, "the adhesive block slid {stuck} m");
}

/// The incline in 3D: a 1 × 0.5 × 0.5 m block on an elastic base, rollers on the
/// z faces, 10 cells along the block.
const INCLINE_3D: &str = r#"dimension = 3
gravity = [6.936717523440031, -6.936717523440031, 0.0]

[grid]
min = [-0.5, 0.0, 0.0]
max = [3.0, 1.0, 0.5]
cells = [35, 10, 5]
shape_function = "cpgimp"

[[material]]
name = "elastic"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3

[[body]]
name = "base"
material = "elastic"
shape = "box"
min = [-0.5, 0.0, 0.0]
max = [3.0, 0.3, 0.5]
particles_per_cell = 2

[[body]]
name = "block"
material = "elastic"
shape = "box"
min = [0.0, 0.3, 0.0]
max = [1.0, 0.8, 0.5]
particles_per_cell = 2

[[contact]]
bodies = ["block", "base"]
friction_coefficient = 0.3

[[boundary]]
face = "ymin"
condition = "fixed"

[[boundary]]
face = "zmin"
condition = "roller"

[[boundary]]
face = "zmax"
condition = "roller"

[solver]
kind = "explicit"
end_time = 0.5
cfl = 0.5

[output]
frames = 0
history_interval = 0.01
"#;

#[test]
#[ignore = "slow tier, 30 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn block_slides_on_an_elastic_incline_in_3d() {
    // The same closed form as in 2D. Measured: +0.082 % (μ = 0), −0.107 % (μ = 0.3).
    for (mu, tolerance) in [(0.0, 2e-3), (0.3, 3e-3)] {
        let (result, dir) = run_text(
            INCLINE_3D,
            &[&format!("contact.0.friction_coefficient={mu}")],
        );
        assert_eq!(result.unwrap().status, Status::Completed);
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let (t, x) = (h.col("t"), h.col("body1_x"));
        let (t, x) = (*t.last().unwrap(), x.last().unwrap() - x[0]);
        let exact = closed_form(45.0, mu, t);
        println!("3D, mu {mu}: x = {x:.5} m, closed form {exact:.5} m");
        assert_within(&format!("3D, mu {mu}: error"), x / exact - 1.0, tolerance);
    }
}

#[test]
fn rigid_plate_compresses_a_cylinder_in_axisymmetric_mode() {
    // problems/contact_plate.toml as a solid of revolution (the xmin roller is
    // then the axis): a rigid plate compresses a cylinder 25 % in uniaxial strain,
    // σ_zz = E ln λ / λ. The contact normals come from the r–z areas V_p/r_p; with
    // the per-radian volumes themselves they lean towards the axis by about h/r
    // and the mean stress was 4.8 % low (σ_rr up to 0.66 MPa). Measured now:
    // −0.67 %, as in plane strain (−0.66 % with this damping).
    let (result, dir) = run_problem(
        "contact_plate.toml",
        &["dimension=\"axisymmetric\"", "output.frames=0"],
    );
    assert_eq!(result.unwrap().status, Status::Completed);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, syy, sxx, volume) = (p.col("body"), p.col("syy"), p.col("sxx"), p.col("volume"));
    let block: Vec<usize> = (0..body.len()).filter(|&i| body[i] == 0.0).collect();
    let v: f64 = block.iter().map(|&i| volume[i]).sum();
    let mean = block.iter().map(|&i| syy[i] * volume[i]).sum::<f64>() / v;
    let exact = 1.0e6 * 0.75f64.ln() / 0.75;
    let radial = block.iter().map(|&i| sxx[i] * volume[i]).sum::<f64>() / v;
    println!(
        "axisymmetric plate: mean σ_zz {mean:.4e} vs {exact:.4e} ({:+.4}), mean σ_rr {radial:.3e}",
        mean / exact - 1.0
    );
    assert!(
        (mean / exact - 1.0).abs() < 0.01,
        "mean σ_zz {mean} vs {exact}"
    );
    // Measured 2.5e-4 of σ_zz.
    assert_within("mean σ_rr / |σ_zz|", radial / exact.abs(), 7.5e-4);
}

#[test]
fn free_rigid_striker_decelerates_as_the_closed_form_and_conserves_momentum() {
    // A rigid mass M on a free elastic bar of mass m = M (problems/rigid_striker.toml):
    // V = V0 exp(−Z t/M) while they touch (Z/M = 100/s), separation at 2L/c = 0.02 s
    // with V0 exp(−2) left. Measured: within 1.4 % up to 0.019 s, 0.1431 at the
    // end (+5.8 %: the grid smears the tension front that separates them).
    let (result, dir) = run_problem("rigid_striker.toml", &[]);
    result.expect("the striker runs");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, striker, bar) = (h.col("t"), h.col("body0_vx"), h.col("body1_vx"));
    for i in 0..t.len() {
        if t[i] <= 0.019 {
            let exact = (-100.0 * t[i]).exp();
            assert!(
                (striker[i] / exact - 1.0).abs() < 0.02,
                "t = {}: {} vs {exact}",
                t[i],
                striker[i]
            );
        }
        // Equal masses: V_striker + V_bar = V0, up to the nodes of tiny mass.
        assert!(
            (striker[i] + bar[i] - 1.0).abs() < 1e-9,
            "momentum at t = {}",
            t[i]
        );
    }
    let last = *striker.last().unwrap();
    assert!((last / (-2f64).exp() - 1.0).abs() < 0.08, "final {last}");
    // Separated: the striker's velocity no longer changes.
    assert_eq!(striker[t.len() - 5], last);
}

#[test]
fn free_rigid_body_falls_under_gravity() {
    // Gravity on, the striker moved away from the bar: free fall, v = −g t exactly
    // (the sum of the steps), y within g Δt t/2 of y0 − g t²/2 (symplectic Euler).
    let (result, dir) = run_problem(
        "rigid_striker.toml",
        &[
            "gravity=[0.0, -9.81]",
            "body.0.velocity=[0.0, 0.0]",
            "body.0.min=[0.0, 0.0]",
            "body.0.max=[0.1, 0.1]",
            "grid.min=[0.0, -0.2]",
            "grid.cells=[140, 30]",
            "solver.end_time=0.1",
        ],
    );
    result.expect("the fall runs");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, y, vx, vy) = (
        h.col("t"),
        h.col("body0_y"),
        h.col("body0_vx"),
        h.col("body0_vy"),
    );
    for i in 0..t.len() {
        assert!(vx[i].abs() < 1e-12, "t = {}: vx = {}", t[i], vx[i]);
        assert!(
            (vy[i] + G * t[i]).abs() <= 1e-12 * G * t[i].max(1.0),
            "t = {}: {}",
            t[i],
            vy[i]
        );
        let exact = 0.05 - 0.5 * G * t[i] * t[i];
        assert!(
            (y[i] - exact).abs() <= 0.5 * G * 1e-3 * t[i] + 1e-12,
            "t = {}: {} vs {exact}",
            t[i],
            y[i]
        );
    }
}

#[test]
fn free_rigid_body_spins_as_a_rigid_body() {
    // The striker given a spin ω = 2 rad/s about its centre (0.15, 0.05) besides
    // its 1 m/s, away from the bar (it touches nothing): after 0.1 s it has turned
    // by ω t = 0.2 rad about its centre, which moved 0.1 m, and every particle
    // keeps v = V + ω × r; ω and the shape stay exact to round-off.
    let (result, dir) = run_problem(
        "rigid_striker.toml",
        &[
            "body.0.min=[0.3, 0.6]",
            "body.0.max=[0.4, 0.7]",
            "body.1.max=[1.2, 0.4]",
            "grid.max=[1.4, 1.0]",
            "grid.cells=[140, 100]",
            "body.0.velocity_expr=[\"-2*(y-0.65)\", \"2*(x-0.35)\"]",
            "solver.end_time=0.1",
        ],
    );
    result.expect("the spin runs");
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, x0, y0, x, y) = (
        p.col("body"),
        p.col("X0"),
        p.col("Y0"),
        p.col("x"),
        p.col("y"),
    );
    let (vx, vy) = (p.col("vx"), p.col("vy"));
    let (c, s) = (0.2f64.cos(), 0.2f64.sin());
    for q in (0..body.len()).filter(|&q| body[q] == 0.0) {
        let (rx, ry) = (x0[q] - 0.35, y0[q] - 0.65);
        let (ex, ey) = (0.45 + c * rx - s * ry, 0.65 + s * rx + c * ry);
        assert!(
            (x[q] - ex).abs() < 1e-12 && (y[q] - ey).abs() < 1e-12,
            "particle {q}"
        );
        let (ux, uy) = (1.0 - 2.0 * (y[q] - 0.65), 2.0 * (x[q] - 0.45));
        assert!(
            (vx[q] - ux).abs() < 1e-12 && (vy[q] - uy).abs() < 1e-12,
            "particle {q}"
        );
    }
}

#[test]
#[ignore = "slow tier, 43 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn rigid_cylinder_rolls_and_slips_as_the_closed_form_up_to_its_stepped_bottom() {
    // The lattice cylinder (LATTICE_CYLINDER) made a free rigid body (it now
    // turns: Newton–Euler, physics::rigid::newton_euler). Slipping: measured
    // −1.34 % at μ = 0, −0.19 % at μ = 0.1; rolling lags like the elastic disk,
    // from the same stepped lattice bottom, at first order: −25.0 %, −11.7 %.
    let text = problem_with(
        "contact_cylinder.toml",
        "[[body]]\nname = \"cylinder\"\nmaterial = \"elastic\"",
        "[[material]]\nname = \"rigid\"\nmodel = \"rigid\"\nmotion = \"free\"\ndensity = 1000.0\n\n[[body]]\nname = \"cylinder\"\nmaterial = \"rigid\"",
    );
    let th = 45f64.to_radians();
    let run = |mu: f64, cells: &str| {
        let mu = format!("contact.0.friction_coefficient={mu}");
        let cells = format!("grid.cells={cells}");
        let mut overrides = vec![mu.as_str(), "output.frames=0", cells.as_str()];
        overrides.extend(LATTICE_CYLINDER);
        let (result, dir) = run_text(&text, &overrides);
        result.expect("the cylinder runs");
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let (t, x) = (h.col("t"), h.col("body1_x"));
        (x.last().unwrap() - x[0], *t.last().unwrap())
    };
    for (mu, tolerance) in [(0.0, 3e-2), (0.1, 5e-3)] {
        let (x, t) = run(mu, "[60, 28]");
        let exact = 0.5 * G * (th.sin() - mu * th.cos()) * t * t;
        println!("rigid cylinder, mu {mu}: x = {x:.4} m, closed form {exact:.4} m");
        assert_within(
            &format!("rigid cylinder, mu {mu}: error"),
            x / exact - 1.0,
            tolerance,
        );
    }
    let (coarse, t) = run(0.5, "[60, 28]");
    let (fine, _) = run(0.5, "[120, 56]");
    let exact = 0.5 * 2.0 / 3.0 * G * th.sin() * t * t;
    let (e1, e2) = ((coarse / exact - 1.0).abs(), (fine / exact - 1.0).abs());
    println!("rigid rolling cylinder: error {e1:.3} (h = R/10), {e2:.3} (R/20)");
    assert_within("rigid rolling cylinder: error at R/20", e2, 0.25);
    assert!((e1 / e2).log2() > 0.8, "errors {e1}, {e2}");
}

/// problems/rigid_disk_impact.toml with or without the rigid projection.
fn rigid_disk_into_soft_disk(projection: bool) -> Vec<(usize, f64, f64, f64, f64, f64)> {
    let set = format!("contact.0.rigid_projection={projection}");
    let (result, dir) = run_problem("rigid_disk_impact.toml", &[&set]);
    result.expect("the impact runs");
    final_particles(&dir)
}

#[test]
fn rigid_bodies_keep_deformable_particles_out_and_conserve_momentum() {
    // problems/rigid_disk_impact.toml: a free rigid disk (R = 0.2) at 5 m/s into a
    // soft elastic disk, four times its wave speed, h = R/8: node-based contact alone lets 12 particle centres
    // into the rigid disk by up to 0.16 h at t = 0.1; with the projection onto
    // its surface none is inside. Linear momentum is conserved to round-off
    // either way (the body takes the opposite of what it gives the particles).
    let radius = 0.2;
    for projection in [true, false] {
        let p = rigid_disk_into_soft_disk(projection);
        let rigid: Vec<_> = p.iter().filter(|a| a.0 == 0).collect();
        let mass: f64 = rigid.iter().map(|a| a.5).sum();
        let cx = rigid.iter().map(|a| a.5 * a.1).sum::<f64>() / mass;
        let cy = rigid.iter().map(|a| a.5 * a.2).sum::<f64>() / mass;
        let inside = (p.iter().filter(|a| a.0 == 1))
            .filter(|a| (a.1 - cx).hypot(a.2 - cy) < radius * (1.0 - 1e-12))
            .count();
        let soft: f64 = p.iter().filter(|a| a.0 == 1).map(|a| a.5).sum();
        let (px, py) = p
            .iter()
            .fold((0.0, 0.0), |(x, y), a| (x + a.5 * a.3, y + a.5 * a.4));
        let p0 = 5.0 * mass - 0.2 * soft;
        assert!(
            (px / p0 - 1.0).abs() < 1e-9,
            "{projection}: p_x {px} vs {p0}"
        );
        assert!(py.abs() < 1e-9 * p0, "{projection}: p_y {py}");
        match projection {
            true => assert_eq!(inside, 0, "particles inside the rigid disk"),
            false => assert!(
                inside > 0,
                "node contact alone keeps all out: the test is moot"
            ),
        }
    }
}

#[test]
fn a_rigid_body_impact_does_not_depend_on_the_number_of_threads() {
    let one = run_cli("rigid_disk_impact.toml", 1, &[] as &[&str]);
    let two = run_cli("rigid_disk_impact.toml", 2, &[] as &[&str]);
    for file in ["particles_final.csv", "history.csv", "contact.csv"] {
        assert!(
            read_output(&one, file) == read_output(&two, file),
            "{file} differs between 1 and 2 threads"
        );
    }
}

/// The Cauchy stress E ln λ / λ of the Hencky block (E = 1 MPa, ν = 0) that
/// the rigid plate has compressed to λ = 1 − 0.1 t at time t.
fn hencky_plate_stress(t: f64) -> f64 {
    let lambda = 1.0 - 0.1 * t;
    1.0e6 * lambda.ln() / lambda
}

/// The plate's force (contact.csv) row by row against σ_yy(t) × 1 m of the
/// Hencky block compressed at 0.1 m/s: the largest relative difference, and the
/// one of the last row.
fn plate_force_error(dir: &tempfile::TempDir) -> (f64, f64) {
    let hencky = hencky_plate_stress;
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fy) = (c.col("t"), c.col("fy"));
    let errors: Vec<f64> = (0..t.len())
        .map(|k| (fy[k] / hencky(t[k]) - 1.0).abs())
        .collect();
    (
        errors.iter().fold(0.0, |a, &b| a.max(b)),
        *errors.last().unwrap(),
    )
}

#[test]
fn implicit_rigid_plate_compresses_a_block_to_the_hencky_stress() {
    // problems/contact_plate_implicit.toml: the plate of
    // `rigid_plate_compresses_a_block_to_the_hencky_stress` as a quasi-static
    // implicit run with penalty contact (25 load steps to λ = 0.75). Measured: the
    // plate's force within 0.11 % of σ_yy(t) × 1 m at every step and at the end;
    // the volume mean of σ_yy −0.11 %; every step in at most 3 Newton
    // iterations, converging quadratically (order 1.93); the deepest penalty
    // penetration 1.92e-4 m, the estimate σ h / (α M). (With the contact at the
    // particles' centres, half a particle below the surface, and the
    // undeformed half-width as their reach, before the contact points: 2.2 %,
    // 1.3 % at the end, −0.50 %, 5 iterations.)
    let (result, dir) = run_problem("contact_plate_implicit.toml", &["output.frames=0"]);
    let summary = result.unwrap();
    assert_eq!(summary.status, Status::Completed);
    let (worst, last) = plate_force_error(&dir);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, syy, volume) = (p.col("body"), p.col("syy"), p.col("volume"));
    let (mut moment, mut v) = (0.0, 0.0);
    for i in (0..body.len()).filter(|&i| body[i] == 0.0) {
        moment += syy[i] * volume[i];
        v += volume[i];
    }
    let mean = moment / v / (1.0e6 * 0.75f64.ln() / 0.75) - 1.0;
    let penetration = summary.solver.contact_penetration.unwrap();
    let newton = Table::read(&dir.path().join("newton.csv")).unwrap();
    let most = (1..=25)
        .map(|s| step_residuals(&newton, s as f64).len() - 1)
        .max()
        .unwrap();
    let (order, _) = newton_order(&step_residuals(&newton, 20.0));
    println!(
        "force within {worst:.4} of σ(t) A ({last:.4} at the end); mean σ_yy {mean:+.4}; \
         penetration {penetration:.2e} m; at most {most} Newton iterations a step, order {order:.2}"
    );
    assert!(worst < 0.005 && last < 0.005, "force {worst}, {last}");
    assert!(mean.abs() < 0.005, "mean σ_yy off by {mean}");
    // σ h / (α M) = 3.9e5 × 0.05 / (100 × 1e6) = 1.9e-4 m at the end.
    assert!(
        penetration > 1.7e-4 && penetration < 2.2e-4,
        "penetration {penetration}"
    );
    assert!(most <= 4 && order > 1.8, "{most} iterations, order {order}");
}

#[test]
fn implicit_contact_takes_the_same_path_through_krylov_and_any_thread_count() {
    // The plate through GMRES on finite-difference products (lagged direct
    // preconditioner, whose tangent holds the contact terms) reaches the direct
    // solver's forces to the Newton tolerance; 1 and 2 threads write the same
    // bytes. A tight Krylov tolerance: with the default Eisenstat–Walker forcing
    // (η = 0.5 first) and the previous step's factorization as preconditioner,
    // the inexact corrections of step 2 took Newton through 5 cut-backs to
    // another equilibrium, 13 % lower (docs/contact.md); with no preconditioner,
    // block Jacobi or multigrid the default forcing reached the direct forces.
    let set = [
        "output.frames=0",
        "solver.end_time=1.0",
        "solver.load_steps=10",
    ];
    let direct = run_cli("contact_plate_implicit.toml", 2, &set);
    let one = run_cli("contact_plate_implicit.toml", 1, &set);
    for f in ["particles_final.csv", "contact.csv"] {
        assert!(
            read_output(&one, f) == read_output(&direct, f),
            "{f} differs"
        );
    }
    let mut krylov_set = set.to_vec();
    krylov_set.extend([
        "solver.linear_solver=gmres",
        "solver.preconditioner=lagged_direct",
        "solver.krylov_tolerance=1e-10",
    ]);
    let krylov = run_cli("contact_plate_implicit.toml", 2, &krylov_set);
    let force = |d: &tempfile::TempDir| {
        let t = Table::read(&d.path().join("contact.csv")).unwrap();
        t.col("fy").to_vec()
    };
    let (a, b) = (force(&direct), force(&krylov));
    let worst = (a.iter().zip(&b)).fold(0.0f64, |w, (x, y)| w.max((x / y - 1.0).abs()));
    println!("GMRES against direct: forces within {worst:.2e}");
    // Measured 2.5e-11 (GMRES to 1e-10).
    assert!(a.len() >= 10, "{} rows", a.len());
    assert_within("GMRES against direct: forces", worst, 1e-10);
}

/// q/c_u of `problems/contact_footing_implicit.toml` (contact force over B/2 =
/// 1 m, c_u = 10 kPa) at the end, its relative error against Prandtl's 2 + π,
/// and the relative change over the last fifth of the run (the plateau), and
/// the rows of newton.csv (Newton iterations, cut-back attempts included).
fn implicit_footing(cells: &str) -> (f64, f64, f64, usize) {
    implicit_footing_with(&[cells])
}

/// [`implicit_footing`] with any overrides.
fn implicit_footing_with(overrides: &[&str]) -> (f64, f64, f64, usize) {
    let (result, dir) = run_problem("contact_footing_implicit.toml", overrides);
    assert_eq!(result.unwrap().status, Status::Completed);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let q: Vec<f64> = c.col("fy").iter().map(|f| -f / 1.0e4).collect();
    let (last, earlier) = (q[q.len() - 1], q[q.len() * 4 / 5]);
    let prandtl = 2.0 + std::f64::consts::PI;
    let rows = Table::read(&dir.path().join("newton.csv"))
        .unwrap()
        .col("step")
        .len();
    (last, last / prandtl - 1.0, last / earlier - 1.0, rows)
}

#[test]
#[ignore = "slow tier, 34 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn implicit_contact_footing_converges_to_prandtl_at_first_order() {
    // A rigid smooth footing pushed into weightless Tresca soil through implicit
    // penalty contact (F-bar, cpGIMP). Measured: q/c_u = 5.544 (+7.8 %) at
    // h = 0.25 m and 5.364 (+4.3 %) at h = 0.125 m, error ratio 1.81 (first
    // order); 5.270 (+2.5 %) at h = 0.0625 m (the ignored test below). With the
    // contact at the particles' centres (before the contact points): +13.9,
    // +7.3, +3.8 %; the explicit contact footing: +17, +12, +8.4 %.
    let (q1, e1, p1, n1) = implicit_footing("grid.cells=[20,14]");
    let (q2, e2, p2, n2) = implicit_footing("grid.cells=[40,28]");
    println!(
        "q/c_u {q1:.4} ({:+.2} %), {q2:.4} ({:+.2} %); error ratio {:.2}; plateau changes \
         {p1:.1e}, {p2:.1e}; Newton rows {n1}, {n2}",
        100.0 * e1,
        100.0 * e2,
        e1 / e2
    );
    assert!(e1 > 0.0 && e2 > 0.0, "{e1} {e2}: from above");
    assert_within("q/c_u error at h = 0.25 m", e1, 0.16);
    assert_within("q/c_u error at h = 0.125 m", e2, 0.09);
    assert!(e1 / e2 > 1.6, "first order: ratio {}", e1 / e2);
    assert!(p1.abs() < 5e-3 && p2.abs() < 5e-3, "plateau {p1} {p2}");
    // Newton's cost: 442 and 576 rows with the contact points carried from step
    // to step; 750 and 1,662 (66 cut-backs at h = 0.125 m) when they were set
    // anew on the particles' domains every step and drifted off the footing
    // where the soil flows (docs/contact.md, "Contact points").
    assert!(n1 < 550 && n2 < 750, "Newton rows {n1} {n2}");
    // Rough (μ = 10: the soil sticks under the footing): Newton converges through
    // the stick–slip changes at the footing's edge; 5.625 (+9.4 %) at h = 0.25 m
    // (before the contact points 5.921, +15.2 %).
    let (q, e, p, n) =
        implicit_footing_with(&["grid.cells=[20,14]", "contact.0.friction_coefficient=10"]);
    println!(
        "rough: q/c_u {q:.4} ({:+.2} %), plateau change {p:.1e}, Newton rows {n}",
        100.0 * e
    );
    assert!(e > e1 && p.abs() < 5e-3, "rough {e}, plateau {p}");
    assert_within("rough: q/c_u error at h = 0.25 m", e, 0.19);
}

#[test]
#[ignore = "about 6 minutes: the h = B/32 footings, smooth and rough"]
fn implicit_contact_footing_is_within_5_percent_of_prandtl_at_h_b_over_32() {
    // Measured: smooth 5.270 (+2.5 %), rough (μ = 10) 5.284 (+2.8 %) (before
    // the contact points: +3.8 %, +4.3 %); 384 s for both.
    for mu in ["0", "10"] {
        let friction = format!("contact.0.friction_coefficient={mu}");
        let (q, e, p, n) = implicit_footing_with(&["grid.cells=[80,56]", &friction]);
        println!(
            "μ = {mu}: q/c_u {q:.4} ({:+.2} %), plateau change {p:.1e}, Newton rows {n}",
            100.0 * e
        );
        assert!(e.abs() < 0.05, "μ = {mu}: {e}");
    }
}

/// An elastic block (1 m × 0.5 m, 1000 kg/m³) resting on a rigid base under
/// gravity, lateral rollers, frictional contact its only vertical support.
const RESTING_BLOCK: &str = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, -0.2]
max = [1.0, 1.0]
cells = [10, 12]
shape_function = "cpgimp"
[[material]]
name = "soil"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
[[material]]
name = "steel"
model = "rigid"
density = 1000.0
[[body]]
name = "block"
material = "soil"
shape = "rectangle"
min = [0.0, 0.0]
max = [1.0, 0.5]
[[body]]
name = "base"
material = "steel"
shape = "rectangle"
min = [0.0, -0.1]
max = [1.0, 0.0]
[[contact]]
friction_coefficient = 0.5
[[boundary]]
face = "xmin"
condition = "roller"
[[boundary]]
face = "xmax"
condition = "roller"
[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 5
[output]
frames = 0
history_interval = 0.0
"#;

#[test]
fn implicit_contact_carries_a_block_resting_on_a_rigid_base() {
    // Gravity ramped in 5 quasi-static steps onto a block whose only vertical
    // support is the contact: the contact force equals the weight applied so far
    // (λ × 5000 N/m) at every step. The bottom layer starts exactly touching the
    // base (depth 0), so the contact's stiffness, not its force, holds the block
    // at the first iteration.
    let (result, dir) = run_text(RESTING_BLOCK, &[]);
    assert_eq!(result.unwrap().status, Status::Completed);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fx, fy) = (c.col("t"), c.col("fx"), c.col("fy"));
    let worst = (0..t.len()).fold(0.0f64, |w, k| {
        w.max((fy[k] / (5000.0 * t[k]) - 1.0).abs())
            .max(fx[k].abs() / 5000.0)
    });
    println!(
        "{} rows: contact force within {worst:.1e} of the weight applied",
        t.len()
    );
    assert!(t.len() == 5 && worst < 1e-8, "{worst}");
}

/// A block (1 m × 0.5 m, Hencky, E = 10 MPa) laid on a base (3.5 m × 0.25 m)
/// at y = 0.25 m with μ = 0.5 and nothing else to hold it: gravity brought on
/// in 10 quasi-static implicit load steps, then 0.5 s of explicit dynamics
/// (MUSL). `BASE` is the base's material: "elastic" or "steel" (rigid).
const STAGED_BLOCK: &str = r#"dimension = 2
gravity = [0.0, -9.81]
[grid]
min = [-0.5, 0.0]
max = [3.0, 1.0]
cells = [70, 20]
shape_function = "cpgimp"
[[material]]
name = "elastic"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
[[material]]
name = "steel"
model = "rigid"
density = 1000.0
[[body]]
name = "base"
material = "BASE"
shape = "rectangle"
min = [-0.5, 0.0]
max = [3.0, 0.25]
[[body]]
name = "block"
material = "elastic"
shape = "rectangle"
min = [0.0, 0.25]
max = [1.0, 0.75]
[[contact]]
bodies = ["block", "base"]
friction_coefficient = 0.5
[[boundary]]
face = "ymin"
condition = "fixed"
[[stage]]
name = "gravity"
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 10
[[stage]]
name = "dynamics"
kind = "explicit"
scheme = "musl"
end_time = 0.5
[output]
frames = 0
history_interval = 0.01
"#;

/// The staged block on `base`: the Newton rows of the implicit stage, the
/// largest error of the contact force against the weight applied in it, the
/// largest kinetic energy of the explicit stage over the strain energy at the
/// hand-over, and the block's volume mean of σ_yy at the end against ρ g H / 2.
fn staged_block(base: &str, shape: &str) -> (usize, f64, f64, f64) {
    let scene = STAGED_BLOCK
        .replace("BASE", base)
        .replace("\"cpgimp\"", &format!("\"{shape}\""));
    let (result, dir) = run_text(&scene, &[]);
    assert_eq!(result.unwrap().status, Status::Completed);
    let newton = Table::read(&dir.path().join("newton.csv")).unwrap();
    let weight = 1000.0 * 9.81 * 0.5;
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fy) = (c.col("t"), c.col("fy"));
    let force = (0..t.len())
        .filter(|&k| t[k] <= 1.0 + 1e-9 && ((t[k] * 10.0).round() - t[k] * 10.0).abs() < 1e-9)
        .map(|k| (fy[k].abs() / (weight * t[k]) - 1.0).abs())
        .fold(0.0, f64::max);
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, kinetic, strain) = (h.col("t"), h.col("kinetic"), h.col("strain"));
    let handed = (0..t.len()).find(|&k| (t[k] - 1.0).abs() < 1e-9).unwrap();
    let ke = (handed..t.len()).map(|k| kinetic[k]).fold(0.0, f64::max) / strain[handed];
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, syy, v) = (p.col("body"), p.col("syy"), p.col("volume"));
    let block: Vec<usize> = (0..body.len()).filter(|&q| body[q] == 1.0).collect();
    let volume: f64 = block.iter().map(|&q| v[q]).sum();
    let mean = block.iter().map(|&q| syy[q] * v[q]).sum::<f64>() / volume;
    let stress = mean / (-1000.0 * 9.81 * 0.25) - 1.0;
    let implicit_rows = newton.col("step").len();
    (implicit_rows, force, ke, stress)
}

#[test]
fn staged_block_is_loaded_implicitly_and_handed_to_an_explicit_stage() {
    // Contact across stages (issue 14, item 5). On a rigid base the block laid
    // at y = 0.25 used to find no contact at all (its bottom particles reached
    // 0.0125 while lying 0.012500000000000011 above the base), and the first
    // tangent was singular; with that fixed, Newton's residual stalled at
    // 1–2.4e-9 of the weight, above the tolerance, from the penalty's
    // round-off (ε_n × 2.2e-16 × |x|), until the round-off floor counted as
    // converged. Measured: 4 Newton rows a step (iterations 0–3, the last the
    // converged check), the contact force the weight applied to 9.6e-11
    // (rigid) and 2.7e-14 (elastic base); over the explicit stage the largest
    // kinetic energy 2.5e-5 of the strain energy at the hand-over on the rigid
    // base (mean σ_yy −1.2e-4 off ρ g H / 2 at the end) and 2.2e-4 on the
    // elastic one (−1.4e-4). On the rigid base the implicit penalty acts at
    // the bottom particles' contact points, on the base's surface, where the
    // explicit contact supports the block's nodes; when it acted at their
    // centres (before the contact points) the kinetic energy reached 1.6 % of
    // the strain energy and σ_yy swung about +0.9 %.
    //
    // Linear hats (the point basis the explicit contact takes) act at their
    // contact points too: KE/SE 7.6e-10 and 1.3e-9, σ_yy −1.1e-4 and −5.8e-4
    // (rigid, elastic base); at the particle centres the rigid base's KE/SE
    // was 1.6e-2 and σ_yy +5.9e-3.
    //
    // Every family the explicit contact takes (measured, rigid and elastic
    // base): uGIMP KE/SE 2.1e-5 and 3.8e-3, CPDI 3.9e-6 and 8.6e-3 (the
    // elastic base rings more with them than with cpGIMP: a finding, not yet
    // explained), σ_yy within 2.0e-4. The contact force is the weight to the
    // Newton tolerance's floor (1e-9 of the weight; measured 1.1e-10 at most).
    let splines = "the explicit stage's contact refuses B-splines (supports of 3–4 cells)";
    let families = shape_functions(&[
        (ShapeFunction::Bspline2, splines),
        (ShapeFunction::Bspline3, splines),
        (ShapeFunction::Cpbspline2, splines),
    ]);
    for family in families {
        let shape = family.name();
        // KE/SE: 2–3 times the larger of the two bases' measured values.
        let quiet = match family {
            ShapeFunction::Linear => 4e-9,
            ShapeFunction::Ugimp => 1e-2,
            ShapeFunction::Cpgimp => 6e-4,
            ShapeFunction::Cpdi => 2e-2,
            _ => unreachable!("left out above"),
        };
        for (base, name) in [("steel", "rigid"), ("elastic", "elastic")] {
            let (rows, force, ke, stress) = staged_block(base, shape);
            println!(
                "{shape}, {name} base: {rows} Newton rows, contact force {force:.1e} off, \
                 KE/SE {ke:.2e}, σ_yy {stress:+.2e}"
            );
            assert!(rows <= 40, "{shape}, {name} base: {rows} Newton rows");
            assert_within(&format!("{shape}, {name} base: contact force"), force, 1e-9);
            assert_within(&format!("{shape}, {name} base: KE/SE"), ke, quiet);
            assert_within(&format!("{shape}, {name} base: σ_yy"), stress, 1e-3);
        }
    }
}

/// Least-squares (intercept, slope) of y = a + s x.
fn fit_line(pts: &[(f64, f64)]) -> (f64, f64) {
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    (my - sxy / sxx * mx, sxy / sxx)
}

#[test]
fn implicit_contact_reproduces_hertz_line_contact() {
    // problems/contact_hertz.toml (papers/contact_hertz): a rigid cylinder
    // R = 0.5 m pressed 0.01 m into an elastic block (E = 1 MPa, ν = 0.3), h =
    // 0.02 m. Hertz for the measured force P: b = √(4PR/(πE*)) = 0.0607 m (6.1
    // cells across 2b), p0 = 2P/(πb). Below the contact's centre σ_z(z) =
    // −p0/√(1 + z²/b²): fitting 1/σ² = 1/p0² + z²/(p0² b²) to the axis column
    // between one cell and 1.6 b deep gives b +1.5 %, p0 −1.2 % (the issue asks
    // 10 % from 5 cells across 2b; h = 0.04 m, 3.1 cells: +19 %, −13 %; h =
    // 0.01 m: +0.5 %, −0.3 %). The top layer's σ_yy peaks at p0 −0.3 % (printed,
    // not asserted). Before the contact points (the load at the top particles'
    // centres): b −7.6 %, p0 +7.5 %, and a top-layer peak of 28–54 % of p0.
    let (result, dir) = run_problem("contact_hertz.toml", &[]);
    assert_eq!(result.unwrap().status, Status::Completed);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let force = -*c.col("fy").last().unwrap();
    let (r, e_star) = (0.5, 1.0e6 / (1.0 - 0.09));
    let b = (4.0 * force * r / (std::f64::consts::PI * e_star)).sqrt();
    let p0 = 2.0 * force / (std::f64::consts::PI * b);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, x0, y0, x, syy) = (
        p.col("body"),
        p.col("X0"),
        p.col("Y0"),
        p.col("x"),
        p.col("syy"),
    );
    let block: Vec<usize> = (0..body.len()).filter(|&i| body[i] == 0.0).collect();
    let axis: Vec<(f64, f64)> = (block.iter())
        .filter(|&&i| (x0[i] - 0.005).abs() < 1e-9)
        .map(|&i| (0.5 - y0[i], -syy[i]))
        .filter(|&(z, _)| (0.02..=1.6 * b).contains(&z))
        .map(|(z, s)| (z * z, 1.0 / (s * s)))
        .collect();
    let (a, s) = fit_line(&axis);
    let (p0_axis, b_axis) = (1.0 / a.sqrt(), (a / s).sqrt());
    let top = block.iter().fold(f64::MIN, |t, &i| t.max(y0[i]));
    let layer: Vec<(f64, f64)> = (block.iter())
        .filter(|&&i| y0[i] == top)
        .map(|&i| (x[i], -syy[i]))
        .collect();
    let peak = layer.iter().fold(0.0f64, |m, p| m.max(p.1));
    let shape: Vec<(f64, f64)> = (layer.iter())
        .filter(|p| p.1 > 0.25 * peak)
        .map(|p| (p.0 * p.0, p.1 * p.1))
        .collect();
    let (a, s) = fit_line(&shape);
    let b_layer = (-a / s).sqrt();
    let rel = |m: f64, e: f64| m / e - 1.0;
    println!(
        "P = {force:.1} N/m; Hertz b = {b:.5} m, p0 = {p0:.1} Pa; axis fit b {:+.4}, p0 {:+.4} \
         ({} points); top layer b {:+.4}, peak {:+.4}",
        rel(b_axis, b),
        rel(p0_axis, p0),
        axis.len(),
        rel(b_layer, b),
        rel(peak, p0)
    );
    assert!(2.0 * b / 0.02 >= 5.0, "2b/h = {}", 2.0 * b / 0.02);
    assert!(rel(b_axis, b).abs() < 0.03 && rel(p0_axis, p0).abs() < 0.03);
}

/// problems/contact_plate_implicit.toml as a cube (h = 0.2 m across, 0.1 m
/// along the plate's motion), rollers on the four sides.
const PLATE_3D: &str = r#"dimension = 3

[grid]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.5]
cells = [5, 5, 15]
shape_function = "cpgimp"

[[material]]
name = "soil"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e6
poisson_ratio = 0.0

[[material]]
name = "steel"
model = "rigid"
density = 1000.0

[[body]]
name = "block"
material = "soil"
shape = "box"
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]

[[body]]
name = "plate"
material = "steel"
shape = "box"
min = [0.0, 0.0, 1.0]
max = [1.0, 1.0, 1.1]
velocity = [0.0, 0.0, -0.1]

[[contact]]
friction_coefficient = 0.0

[[boundary]]
face = "zmin"
condition = "fixed"

[[boundary]]
face = "xmin"
condition = "roller"

[[boundary]]
face = "xmax"
condition = "roller"

[[boundary]]
face = "ymin"
condition = "roller"

[[boundary]]
face = "ymax"
condition = "roller"

[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 2.5
load_steps = 25

[output]
frames = 0
"#;

#[test]
fn implicit_rigid_plate_compresses_a_hencky_cube_in_3d() {
    // The cube compressed 25 % by a rigid plate through implicit penalty contact
    // (issue 14: the Cauchy σ within 1 % with the penetration stated). Measured:
    // the volume mean of σ_zz −0.36 % of E ln λ/λ; the plate's force within
    // 0.36 % of σ(t) A along the way; penetration 6.1e-4 m. (With the contact at
    // the top layer's centres, before the contact points: +0.25 % and 4.4 %, an
    // O(h) offset with h = 0.1 m along z.)
    let (result, dir) = run_text(PLATE_3D, &[]);
    let summary = result.unwrap();
    assert_eq!(summary.status, Status::Completed);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, szz, volume) = (p.col("body"), p.col("szz"), p.col("volume"));
    let (mut moment, mut v) = (0.0, 0.0);
    for i in (0..body.len()).filter(|&i| body[i] == 0.0) {
        moment += szz[i] * volume[i];
        v += volume[i];
    }
    let hencky = hencky_plate_stress;
    let mean = moment / v / hencky(2.5) - 1.0;
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fz) = (c.col("t"), c.col("fz"));
    let worst = (0..t.len()).fold(0.0f64, |w, k| w.max((fz[k] / hencky(t[k]) - 1.0).abs()));
    let penetration = summary.solver.contact_penetration.unwrap();
    println!("mean σ_zz {mean:+.4}; force within {worst:.4}; penetration {penetration:.2e} m");
    assert!(mean.abs() < 0.01, "mean σ_zz off by {mean}");
    assert!(worst < 0.01, "force {worst}");
    assert!(
        penetration > 0.0 && penetration < 1e-3,
        "penetration {penetration}"
    );
}

/// Friction's dissipation in implicit contact (`problems/contact_shear_implicit.toml`):
/// a rigid plate pressed into a block and dragged across it, slipping from the
/// first step. The work of the plate on the block (the contact force of
/// contact.csv times the plate's velocity, trapezoidal over the rows) is the
/// block's strain energy plus the dissipation, to the energy stored in the
/// penalty springs: measured W = 587.1 J, strain 331.7 J, dissipation 254.9 J,
/// W − (strain + dissipation) = 0.48 J (8.1e-4 of W; 7.7e-4 with 80 load
/// steps; the dissipation per step is trapezoidal in the force).
/// With the end-of-step force it was first order (2.1e-2 … 2.0e-3), and
/// without dissipation the balance is off by 44 %.
#[test]
fn implicit_friction_dissipation_closes_the_energy_balance() {
    for steps in [20, 80] {
        let steps_key = format!("solver.load_steps={steps}");
        let (result, dir) = run_problem("contact_shear_implicit.toml", &[steps_key.as_str()]);
        result.unwrap();
        let c = Table::read(&dir.path().join("contact.csv")).unwrap();
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let (t, fx, fy, dissipation) = (c.col("t"), c.col("fx"), c.col("fy"), c.col("dissipation"));
        let v = [0.1, -0.02];
        let (mut work, mut previous, mut t0) = (0.0, [0.0, 0.0], 0.0);
        for k in 0..t.len() {
            let f = [fx[k], fy[k]];
            work += 0.5 * ((previous[0] + f[0]) * v[0] + (previous[1] + f[1]) * v[1]) * (t[k] - t0);
            (previous, t0) = (f, t[k]);
        }
        let strain = *h.col("strain").last().unwrap();
        let dissipated = *dissipation.last().unwrap();
        let balance = (work - strain - dissipated) / work;
        let slipping = (fx.last().unwrap() / fy.last().unwrap()).abs();
        println!(
            "{steps} steps: plate work {work:.3} J, strain {strain:.3} J, dissipation \
             {dissipated:.3} J, balance {balance:+.2e}, |f_t/f_n| {slipping:.4}"
        );
        assert!(
            (slipping - 0.3).abs() < 1e-6,
            "the plate slips: |f_t/f_n| = {slipping}"
        );
        assert!(
            dissipated > 0.3 * work,
            "friction dissipates: {dissipated} of {work}"
        );
        assert!(
            balance > 0.0 && balance < 2e-3,
            "energy balance {balance:+.2e}"
        );
        assert!(
            dissipation.windows(2).all(|d| d[1] >= d[0]),
            "dissipation never decreases"
        );
        // Each particle's contact force (particles_final.csv) sums to the pair's.
        let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
        let (cx, cy, body) = (p.col("contact_fx"), p.col("contact_fy"), p.col("body"));
        let (sx, sy): (f64, f64) = (cx.iter().sum(), cy.iter().sum());
        let touching = cy.iter().filter(|f| **f != 0.0).count();
        let on_plate = (0..body.len())
            .filter(|&i| body[i] == 1.0 && cy[i] != 0.0)
            .count();
        println!("   particle forces sum to ({sx:.3}, {sy:.3}) N over {touching} particles");
        assert!(
            (sx / fx.last().unwrap() - 1.0).abs() < 1e-9,
            "Σ contact_fx {sx}"
        );
        assert!(
            (sy / fy.last().unwrap() - 1.0).abs() < 1e-9,
            "Σ contact_fy {sy}"
        );
        assert!(
            touching > 0 && on_plate == 0,
            "{touching} particles, {on_plate} on the plate"
        );
    }
}

/// The block's slide along the incline at the end time of
/// `problems/contact_incline_implicit.toml` (two deformable bodies, Newmark)
/// with friction μ, and the end time.
fn implicit_slide(mu: f64, extra: &[&str]) -> (f64, f64, tempfile::TempDir) {
    let mu = format!("contact.0.friction_coefficient={mu}");
    let mut overrides = vec![mu.as_str(), "output.frames=0"];
    overrides.extend(extra);
    let (result, dir) = run_problem("contact_incline_implicit.toml", &overrides);
    assert_eq!(result.unwrap().status, Status::Completed);
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, x) = (h.col("t"), h.col("body1_x"));
    (*t.last().unwrap(), x.last().unwrap() - x[0], dir)
}

#[test]
fn implicit_block_slides_on_a_deformable_incline_as_the_closed_form() {
    // Gravity raised linearly over T = 0.04 s (about one period of the block's
    // bounce on the base) and the rigid block's law for it, x = A (T²/6 +
    // T (t − T)/2 + (t − T)²/2), A = g (sin θ − μ cos θ). Measured: −0.032 %,
    // −0.044 %, +0.238 % at t = 0.5 s (Newmark, Δt = 5 ms, cpGIMP, 20 cells
    // over the block), 699, 660 and 767 rows of newton.csv. With gravity in
    // full from the first step the elastic block bounces: the normal force
    // swings between 0 and 2.6 times the weight's normal part (a suddenly
    // applied load, dynamic factor 2) and friction follows it (μ N to 1e-3),
    // so where the undamped ringing stands at t = 0.5 s sets the slide:
    // −0.05 %, −0.13 %, +1.12 % against ½ g t² (sin θ − μ cos θ)
    // (729, 822, 708 rows). One shared velocity field would carry the block
    // with the base: it would not move.
    let ramp = 0.04;
    let ramp_key = format!("solver.gravity_ramp_time={ramp}");
    for (mu, rows, tolerance) in [(0.0, 750, 1e-3), (0.3, 800, 1.2e-3), (0.5, 1100, 6e-3)] {
        let (t, x, dir) = implicit_slide(mu, &[&ramp_key]);
        let a = closed_form(45.0, mu, 1.0) * 2.0;
        let exact = a * (ramp * ramp / 6.0 + ramp * (t - ramp) / 2.0 + (t - ramp).powi(2) / 2.0);
        let newton = Table::read(&dir.path().join("newton.csv")).unwrap();
        let iterations = newton.col("iteration").len();
        println!(
            "mu {mu}: x = {x:.5} m, closed form {exact:.5} m, {iterations} rows of newton.csv"
        );
        assert_within(&format!("mu {mu}: error"), x / exact - 1.0, tolerance);
        assert!(iterations < rows, "mu {mu}: {iterations} Newton rows");
    }
}

#[test]
fn near_the_sticking_limit_both_solvers_slide_the_ringing_block_past_the_rigid_law() {
    // μ = 0.8 tan θ, gravity in full at once, undamped: the elastic block rings
    // on the base and both solvers, with their different contact laws (explicit:
    // velocity corrections at shared nodes; implicit: a penalty between split
    // nodes), slide it farther than the rigid block's law, by about as much.
    // Measured at 0.5 s: implicit +14.43 % (Δt = 5 ms), explicit PIC +11.66 %,
    // FLIP +16.29 % (APIC +13.51 %). So the excess of the explicit runs near
    // the limit (docs/contact.md, "Sliding near the sticking limit") belongs to
    // the undamped elastic block on this grid, not to the explicit contact law.
    let mu = 0.8;
    let (t, implicit, _) = implicit_slide(mu, &[]);
    let rigid = closed_form(45.0, mu, t);
    let e_implicit = implicit / rigid - 1.0;
    for flip in ["solver.flip=0.0", "solver.flip=1.0"] {
        let (t_explicit, explicit, _) = slide(45.0, mu, &[flip]);
        assert!((t_explicit - t).abs() < 1e-9, "end times {t_explicit}, {t}");
        let e_explicit = explicit / rigid - 1.0;
        println!(
            "μ = {mu}, gravity at once, {flip}: explicit {e_explicit:+.4}, implicit \
             {e_implicit:+.4} against the rigid block"
        );
        assert!(
            (0.10..0.20).contains(&e_implicit) && (0.10..0.20).contains(&e_explicit),
            "{flip}: explicit {e_explicit:+.4}, implicit {e_implicit:+.4}"
        );
        assert!(
            (e_explicit - e_implicit).abs() < 0.05,
            "{flip}: explicit {e_explicit:+.4}, implicit {e_implicit:+.4}"
        );
    }
}

#[test]
fn implicit_cylinder_slips_down_a_deformable_incline_with_the_rigid_cylinder_s_spin() {
    // problems/contact_cylinder.toml solved implicitly (Newmark, Δt = 2.5 ms),
    // slipping at μ = 0.1, against the rigid cylinder's closed form for gravity
    // raised over T: x = a ((t − T/2)²/2 + T²/24), ω = −2μ g cos θ (t − T/2)/R.
    // The gap a meeting carries from step to step was pinned to its grid node:
    // as the disk slid past, the gap ahead of its lowest point stayed open and
    // the one behind stayed shut, so the normal force acted behind the centre
    // and spun the disk (frictionless −0.676 rad/s at 0.5 s, at μ = 0.1 +33 %).
    // With the gap following the outermost particles at the node
    // (solver::implicit::terms::contact::bodies, `assign_history`), measured: centre
    // −0.47 %, spin −1.1 % (frictionless +0.082 rad/s; rolling at μ = 0.5 centre
    // −0.41 %, spin −2.2 %).
    let text = problem_with(
        "contact_cylinder.toml",
        "kind = \"explicit\"\nend_time = 0.5\ncfl = 0.5",
        "kind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 0.5\ndt = 0.0025\nline_search = true",
    );
    let mu = 0.1;
    let (result, dir) = run_text(
        &text,
        &["contact.0.friction_coefficient=0.1", "output.frames=0"],
    );
    assert_eq!(result.unwrap().status, Status::Completed);
    // The scene raises gravity over 0.1 s.
    let (centre, spin) = cylinder_errors(&dir, mu, 0.1);
    println!("implicit cylinder, μ = {mu}: centre {centre:+.4}, spin {spin:+.4}");
    assert!(
        centre.abs() < 0.01 && spin.abs() < 0.03,
        "centre {centre}, spin {spin}"
    );
}

/// A block resting on another, rollers on the sides, quasi-static gravity: in
/// uniaxial strain a frictionless or rough interface changes nothing, so the
/// stresses equal those of the glued pair (one body).
const STACKED: &str = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [1.0, 2.5]
cells = [10, 25]
shape_function = "cpgimp"
[[material]]
name = "soil"
model = "hencky"
density = 2000.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
[[body]]
name = "base"
material = "soil"
shape = "rectangle"
min = [0.0, 0.0]
max = [1.0, 1.0]
[[body]]
name = "top"
material = "soil"
shape = "rectangle"
min = [0.0, 1.0]
max = [1.0, 2.0]
[[contact]]
bodies = ["base", "top"]
friction_coefficient = 0.3
[[boundary]]
face = "ymin"
condition = "fixed"
[[boundary]]
face = "xmin"
condition = "roller"
[[boundary]]
face = "xmax"
condition = "roller"
[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 4
[output]
frames = 0
"#;

#[test]
fn implicit_contact_carries_a_deformable_block_resting_on_another_as_if_glued() {
    // Measured (4 load steps): the contact force is the top block's weight,
    // 20 kN/m, to 3e-14 at every step; the penetration 1.5e-6 m = σ h / (α M).
    // σ_yy against the glued pair, relative to the exact ρ g (2 − y): linear
    // 4.5e-5 and quadratic B-splines 5.6e-5 (force at the meeting's nodes);
    // uGIMP 1.5e-3, cpGIMP 1.8e-3 and CPDI 1.3e-3 (force at the surfaces'
    // points: at the nodes it was 1.7 %, docs/contact.md); quadratic B-splines
    // averaged over the domains 7.7e-3, with a penetration of 1.9e-6 m against
    // 1.5e-6 m for the others (a finding, not yet explained).
    for family in ShapeFunction::iter() {
        let tolerance = match family {
            ShapeFunction::Linear | ShapeFunction::Bspline2 => 1e-4,
            ShapeFunction::Ugimp | ShapeFunction::Cpgimp | ShapeFunction::Cpdi => 3e-3,
            ShapeFunction::Cpbspline2 => 2e-2,
            // Left out: the scene check refuses implicit contact between bodies
            // with cubic B-splines ("two blocks resting on each other came out
            // wrong beside the interface").
            ShapeFunction::Bspline3 => continue,
        };
        let shape = family.name();
        let shape_set = format!("grid.shape_function={shape}");
        let glued_text = STACKED.replace(
            "[[contact]]\nbodies = [\"base\", \"top\"]\nfriction_coefficient = 0.3\n",
            "",
        );
        let (glued, gdir) = run_text(&glued_text, &[shape_set.as_str()]);
        assert_eq!(glued.unwrap().status, Status::Completed);
        let syy = |dir: &tempfile::TempDir| {
            let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
            (t.col("Y0").to_vec(), t.col("syy").to_vec())
        };
        let (y0, reference) = syy(&gdir);
        for mu in ["0.0", "0.3"] {
            let set = format!("contact.0.friction_coefficient={mu}");
            let (summary, dir) = run_text(STACKED, &[set.as_str(), shape_set.as_str()]);
            let summary = summary.unwrap();
            assert_eq!(summary.status, Status::Completed);
            let c = Table::read(&dir.path().join("contact.csv")).unwrap();
            let (t, fx, fy) = (c.col("t"), c.col("fx"), c.col("fy"));
            let weight = 2000.0 * 1.0 * 10.0;
            let force = (0..t.len()).fold(0.0f64, |w, k| {
                let off = (fy[k] / (-weight * t[k]) - 1.0).abs();
                w.max(off).max((fx[k] / weight).abs())
            });
            let (_, s) = syy(&dir);
            let stress = (0..s.len()).fold(0.0f64, |w, q| {
                w.max((s[q] - reference[q]).abs() / (2000.0 * 10.0 * (2.0 - y0[q])))
            });
            let depth = summary.solver.contact_penetration.unwrap_or(0.0);
            println!(
                "{shape} mu {mu}: contact force within {force:.1e} of the weight, σ_yy within \
                 {stress:.1e} of the glued pair, penetration {depth:.2e} m"
            );
            assert!(
                t.len() == 4 && force < 1e-9,
                "{} rows, force off by {force}",
                t.len()
            );
            assert_within(
                &format!("{shape} mu {mu}: σ_yy off the glued pair"),
                stress,
                tolerance,
            );
            assert!(depth > 0.0 && depth < 1e-5, "penetration {depth}");
        }
    }
}

#[test]
fn implicit_block_sticks_on_a_deformable_incline_and_the_contact_carries_its_weight() {
    // tan 45° = 1 < μ = 1.2, gravity ramped quasi-statically over 10 load steps:
    // the block stays (its shift, 0.75 mm, is the elastic shear of the two
    // bodies), 4 Newton iterations a step, and the contact force on the base is
    // the block's weight, ρ V g (sin θ, −cos θ) = (3468.4, −3468.4) N/m, at
    // every step. With μ = 0.9 < tan θ there is no equilibrium: the step fails.
    let quasi_static = [
        "solver.integrator=quasi_static",
        "solver.end_time=1.0",
        "solver.dt=0.1",
    ];
    let (_, x, dir) = implicit_slide(1.2, &quasi_static);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fx, fy) = (c.col("t"), c.col("fx"), c.col("fy"));
    let weight = 1000.0 * 0.5 * G * 45f64.to_radians().sin();
    let worst = (0..t.len()).fold(0.0f64, |w, k| {
        let load = weight * t[k];
        w.max((fx[k] / load - 1.0).abs())
            .max((-fy[k] / load - 1.0).abs())
    });
    println!("stuck: x = {x:.2e} m; contact force within {worst:.2e} of the weight");
    assert!(t.len() == 10 && worst < 1e-8, "{} rows, {worst}", t.len());
    assert!(x.abs() < 2e-3, "the block moved {x} m with tan θ < μ");
    let mut slides = quasi_static.to_vec();
    slides.extend(["contact.0.friction_coefficient=0.9", "output.frames=0"]);
    let (result, _) = run_problem("contact_incline_implicit.toml", &slides);
    assert!(
        result.is_err(),
        "a quasi-static block with tan θ > μ found equilibrium"
    );
}

#[test]
fn implicit_contact_of_deformable_bodies_does_not_depend_on_the_number_of_threads() {
    let set = ["output.frames=0", "solver.end_time=0.05"];
    let one = run_cli("contact_incline_implicit.toml", 1, &set);
    let two = run_cli("contact_incline_implicit.toml", 2, &set);
    for f in ["particles_final.csv", "contact.csv", "newton.csv"] {
        let strip = |bytes: Vec<u8>| -> String {
            // newton.csv's wall-clock column differs between any two runs.
            String::from_utf8(bytes)
                .unwrap()
                .lines()
                .map(|l| {
                    l.split(',')
                        .enumerate()
                        .filter(|(i, _)| *i != 7)
                        .map(|(_, v)| v)
                        .collect::<Vec<_>>()
                        .join(",")
                })
                .collect::<Vec<_>>()
                .join("\n")
        };
        assert!(
            strip(read_output(&one, f)) == strip(read_output(&two, f)),
            "{f} differs"
        );
    }
}

#[test]
fn implicit_contact_of_deformable_and_rigid_bodies_together_balances() {
    // The stacked blocks with a rigid plate pressed onto the top one (1 cm/s):
    // both kinds of implicit contact in one system. At every step the base
    // carries the top block's weight plus the plate's force (measured 1.9e-10
    // of the force at most), in 4 Newton iterations a step.
    let plate = "[[material]]\nname = \"steel\"\nmodel = \"rigid\"\ndensity = 1000.0\n\
                 [[body]]\nname = \"plate\"\nmaterial = \"steel\"\nshape = \"rectangle\"\n\
                 min = [0.0, 2.0]\nmax = [1.0, 2.1]\nvelocity = [0.0, -0.01]\n\
                 [[contact]]\nfriction_coefficient = 0.3\n";
    let text = STACKED.replace(
        "[[contact]]\nbodies = [\"base\", \"top\"]\nfriction_coefficient = 0.3\n",
        plate,
    );
    let (summary, dir) = run_text(&text, &[]);
    let summary = summary.unwrap();
    assert_eq!(summary.status, Status::Completed);
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, first, second, fy) = (c.col("t"), c.col("first"), c.col("second"), c.col("fy"));
    let weight = 2000.0 * 1.0 * 10.0;
    let mut pressed = 0;
    for k in (0..t.len()).filter(|&k| first[k] == 0.0 && second[k] == 1.0) {
        // The plate's row (bodies 1 and 2) at the same time.
        let j = (0..t.len())
            .find(|&j| t[j] == t[k] && first[j] == 1.0 && second[j] == 2.0)
            .unwrap();
        let expected = -weight * t[k] + fy[j];
        let off = (fy[k] / expected - 1.0).abs();
        println!(
            "t = {}: base–top {:.1} N/m, top–plate {:.1} N/m, balance {off:.1e}",
            t[k], fy[k], fy[j]
        );
        // Measured 1.9e-10 at most.
        assert_within(&format!("t = {}: balance", t[k]), off, 5e-10);
        pressed += (fy[j] < -1.0) as usize;
    }
    assert!(pressed >= 2, "the plate pressed in {pressed} steps");
    let newton = summary.solver.newton_iterations.unwrap_or(usize::MAX);
    assert!(newton <= 4 * 4, "{newton} Newton iterations in 4 steps");
}
