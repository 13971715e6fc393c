//! Peridynamic bodies (PMB and beam bonds) in explicit runs (issue 51;
//! `physics::peridynamics`): the elastic bar wave speed against c0 = √(E/ρ),
//! the shipped notched plate cracking from its notch, and the scene keys'
//! errors. The exact unit checks (Σ F = 0, rigid motions, a single bond
//! breaking, cut-bond energy against G0, interior energy against the
//! classical one, the beam bond's constants and Poisson ratio, the non-local
//! F) are next to the code (`material::bond`, `physics::peridynamics`).

use crate::common::{assert_within, rejected_at, run_problem, run_text, Table};
use mpm::scene::Scene;

/// A free–free plane-stress bar L × W, Δx = 0.5 mm, m = 3, in its first
/// axial mode v = v0 cos(πx/L): the kinetic energy vanishes first at a quarter
/// period, T/4 = L/(2c), c the bar's wave speed.
fn bar(length: f64, width: f64) -> String {
    let cells = (length / 1e-3).round() as usize + 4;
    let rows = (width / 1e-3).round() as usize + 4;
    format!(
        r#"
dimension = 2
[grid]
min = [-0.002, -0.002]
max = [{gx}, {gy}]
cells = [{cells}, {rows}]
shape_function = "linear"
[[material]]
name = "al"
model = "linear_elastic"
density = 2700.0
youngs_modulus = 70e9
poisson_ratio = 0.333333
[[body]]
kind = "peridynamic"
plane = "stress"
material = "al"
shape = "rectangle"
min = [0.0, 0.0]
max = [{length}, {width}]
particles_per_cell = 2
velocity_expr = ["0.1*cos(pi*x/{length})", "0"]
[solver]
kind = "explicit"
end_time = {end}
[output]
frames = 0
history_interval = 0.0
"#,
        gx = length + 0.002,
        gy = width + 0.002,
        end = 0.7 * length / (70e9f64 / 2700.0).sqrt(),
    )
}

/// The first minimum of the kinetic energy: the time of the row before the
/// first rise, refined by a parabola through it and its neighbours.
fn first_minimum(t: &[f64], k: &[f64]) -> f64 {
    let i = (1..k.len() - 1)
        .find(|&i| k[i] <= k[i - 1] && k[i] < k[i + 1])
        .expect("the kinetic energy has a minimum");
    let (a, b, c) = (k[i - 1], k[i], k[i + 1]);
    let h = t[i] - t[i - 1];
    t[i] + 0.5 * h * (a - c) / (a - 2.0 * b + c)
}

#[test]
fn the_bar_wave_speed_is_the_elastic_one_to_the_surface_error() {
    let c0 = (70e9f64 / 2700.0).sqrt();
    let (length, width) = (0.1, 0.01);
    let (summary, dir) = run_text(&bar(length, width), &[]);
    summary.expect("the bar runs");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let quarter = first_minimum(h.col("t"), h.col("kinetic"));
    let c = length / (2.0 * quarter);
    // Bond-based, m = 3, no surface or partial-volume correction: the lattice
    // interior is stiffer than E (+6.5 % in energy, `pmb` unit test), the bonds
    // missing within δ of the faces softer; measured +0.93 % (0.1 m × 10 mm,
    // Δx = 0.5 mm, 157 steps).
    assert_within("bar wave speed c/c0 − 1", c / c0 - 1.0, 0.03);
    // The mode is elastic: it lost no bond.
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    assert!(p.col("damage").iter().all(|&d| d == 0.0));
}

/// The beam bond (`bond_model = "beam"`) in the same bar, at ν = 0 and
/// ν = 0.2: a thin bar's wave speed is √(E/ρ) whatever ν, so the tangential
/// micromodulus the lower ν adds must leave it there (to the surface error).
#[test]
fn the_beam_bond_bar_wave_speed_is_the_elastic_one_at_any_poisson_ratio() {
    let c0 = (70e9f64 / 2700.0).sqrt();
    let (length, width) = (0.1, 0.01);
    for nu in ["0.0", "0.2"] {
        let scene = bar(length, width)
            .replace("poisson_ratio = 0.333333", &format!("poisson_ratio = {nu}"))
            .replace(
                "plane = \"stress\"",
                "plane = \"stress\"\nbond_model = \"beam\"",
            );
        let (summary, dir) = run_text(&scene, &[]);
        summary.expect("the bar runs");
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let c = length / (2.0 * first_minimum(h.col("t"), h.col("kinetic")));
        assert_within(&format!("beam ν = {nu}: c/c0 − 1"), c / c0 - 1.0, 0.03);
    }
}

/// The overrides that make the shipped plate a correspondence body (plane
/// strain, its glass's own linear elastic update, the default zero-energy
/// control).
const CORRESPONDENCE_PLATE: [&str; 2] = [
    "body.0.bond_model=\"correspondence\"",
    "body.0.plane=\"strain\"",
];

#[test]
fn the_notched_plate_cracks_from_its_notch() {
    notched_plate_cracks_from_its_notch(&[]);
}

/// The same plate as a correspondence body: the crack through the ligament,
/// and no damage at its free ends (where a weaker zero-energy control lets
/// the non-affine oscillations break bonds: material::bond::correspondence).
#[test]
fn the_correspondence_notched_plate_cracks_from_its_notch_only() {
    notched_plate_cracks_from_its_notch(&CORRESPONDENCE_PLATE);
}

fn notched_plate_cracks_from_its_notch(sets: &[&str]) {
    let (summary, dir) = run_problem("peridynamic_plate.toml", sets);
    let summary = summary.expect("the plate runs");
    println!("steps {}", summary.steps);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (x, y, d) = (p.col("X0"), p.col("Y0"), p.col("damage"));
    let max = d.iter().cloned().fold(0.0, f64::max);
    // The crack: every row of particles below the notch tip (y < 15 mm) has a
    // particle with φ > 1/2 within 3 mm of the middle (a particle a crack
    // passes by loses about half its bonds); far from the middle (|x − 20 mm|
    // > 12 mm) none has (measured there: φ ≤ 0.29, edge particles' bonds).
    let rows = 30;
    let row = |q: usize| (y[q] / 5e-4) as usize;
    let cracked = (0..rows)
        .filter(|&r| (0..d.len()).any(|q| row(q) == r && (x[q] - 0.02).abs() < 0.003 && d[q] > 0.5))
        .count();
    let far = (0..d.len())
        .filter(|&q| (x[q] - 0.02).abs() > 0.012)
        .map(|q| d[q])
        .fold(0.0, f64::max);
    println!("max damage {max:.3}; rows cracked below the notch {cracked} of {rows}; max φ far from it {far:.3}");
    assert!(cracked == rows && far < 0.5);
}

const BODY: &str = r#"
dimension = 2
[grid]
min = [0.0, 0.0]
max = [1.0, 1.0]
cells = [10, 10]
[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 1.0
poisson_ratio = 0.25
[[body]]
kind = "peridynamic"
material = "m"
shape = "rectangle"
min = [0.2, 0.2]
max = [0.8, 0.8]
"#;

fn with(extra_body: &str, rest: &str) -> String {
    format!("{BODY}{extra_body}\n[solver]\nkind = \"explicit\"\nend_time = 1.0\n{rest}")
}

#[test]
fn the_scene_keys_of_a_peridynamic_body_are_checked_by_key() {
    // Runs as given (plane strain, ν = 1/4, m = 3).
    Scene::parse("scene.toml", &with("", ""), &[]).expect("valid");
    rejected_at(
        &with("plane = \"stress\"", ""),
        "material.0.poisson_ratio",
        &["1/3", "0.333333", "plane stress"],
    );
    // The beam bond takes ν in (−1, 1/4] in plane strain, (−1, 1/3] in plane stress.
    let beam = |nu: &str, extra: &str| {
        with(&format!("bond_model = \"beam\"\n{extra}"), "")
            .replace("poisson_ratio = 0.25", &format!("poisson_ratio = {nu}"))
    };
    Scene::parse("scene.toml", &beam("-0.5", ""), &[]).expect("beam, ν = −0.5");
    Scene::parse("scene.toml", &beam("0.3", "plane = \"stress\""), &[]).expect("beam, ν = 0.3");
    rejected_at(
        &beam("0.3", ""),
        "material.0.poisson_ratio",
        &["(−1, 1/4]", "plane strain", "0.3"],
    );
    rejected_at(
        &beam("0.4", "plane = \"stress\""),
        "material.0.poisson_ratio",
        &["(−1, 1/3]"],
    );
    rejected_at(
        &with("", "").replace("poisson_ratio = 0.25", "poisson_ratio = 0.3"),
        "material.0.poisson_ratio",
        &["bond_model = \"beam\""],
    );
    rejected_at(&with("horizon = -1.0", ""), "body.0.horizon", &["positive"]);
    rejected_at(
        &with("horizon = 0.1\nhorizon_factor = 3.0", ""),
        "body.0.horizon_factor",
        &["not both"],
    );
    rejected_at(
        &with("horizon = 0.01", ""),
        "body.0.horizon",
        &["below the particle spacing"],
    );
    rejected_at(
        &with("fracture_energy = 1.0\ncritical_stretch = 0.01", ""),
        "body.0.critical_stretch",
        &["not both"],
    );
    rejected_at(
        &with("motion = \"free\"", ""),
        "body.0.motion",
        &["peridynamic"],
    );
    Scene::parse("scene.toml", &with("short_range_force = 0.0", ""), &[]).expect("no repulsion");
    rejected_at(
        &with("short_range_force = -15.0", ""),
        "body.0.short_range_force",
        &["≥ 0"],
    );
    let implicit = with("", "").replace("kind = \"explicit\"", "kind = \"implicit\"");
    rejected_at(&implicit, "solver.kind", &["explicit stages only"]);
    // Its keys on a continuum body.
    let continuum = with("", "").replace("kind = \"peridynamic\"", "kind = \"continuum\"");
    rejected_at(
        &continuum.replace(
            "shape = \"rectangle\"",
            "shape = \"rectangle\"\nhorizon = 0.3",
        ),
        "body.0.horizon",
        &["not kind = \"peridynamic\""],
    );
    // Beside an MPM body: in velocity fields of their own, by a contact table.
    let two = format!(
        "{}\n[[material]]\nname = \"n\"\nmodel = \"linear_elastic\"\ndensity = 1.0\nyoungs_modulus = 1.0\npoisson_ratio = 0.3\n[[body]]\nmaterial = \"n\"\nshape = \"rectangle\"\nmin = [0.0, 0.0]\nmax = [0.1, 0.1]\n",
        with("", "")
    );
    rejected_at(
        &two,
        "contact",
        &["declare a [[contact]]", "continuum body 1"],
    );
    let friction = format!("{two}\n[[contact]]\nfriction_coefficient = 0.3\n");
    Scene::parse("scene.toml", &friction, &[]).expect("a peridynamic and a continuum body");
    // Two peridynamic bodies meet by their repulsion, not a contact table.
    let pair = bars_meeting(1.0, 1e-6);
    Scene::parse("scene.toml", &pair, &[]).expect("two peridynamic bodies");
    rejected_at(
        &format!("{pair}\n[[contact]]\nfriction_coefficient = 0.0\n"),
        "contact.0.bodies",
        &["short-range repulsion", "short_range_force"],
    );
    rejected_at(
        &continuum.replace(
            "shape = \"rectangle\"",
            "shape = \"rectangle\"\nshort_range_force = 1.0",
        ),
        "body.0.short_range_force",
        &["not kind = \"peridynamic\""],
    );
}

/// The bar of [`bar`] at rest, struck at x = 0 by a rigid piston: a body of
/// `motion` (prescribed or free), given `velocity`, its face on the bar's first
/// particle centres; the two meet by the rigid projection alone.
fn struck_bar(length: f64, width: f64, motion: &str, velocity: f64, end: f64) -> String {
    let piston = format!(
        r#"
[[material]]
name = "piston"
model = "rigid"
density = 7800.0
[[body]]
name = "piston"
kind = "rigid"
motion = "{motion}"
material = "piston"
shape = "rectangle"
min = [-0.00175, -0.0005]
max = [0.00025, {top}]
velocity = [{velocity}, 0.0]
[[contact]]
friction_coefficient = 0.0
"#,
        top = width + 0.0005,
    );
    bar(length, width)
        .replace(
            "velocity_expr = [\"0.1*cos(pi*x/0.1)\", \"0\"]",
            "name = \"bar\"",
        )
        .replace("[solver]", &format!("{piston}[solver]"))
        .replace(
            &format!("end_time = {}", 0.7 * length / (70e9f64 / 2700.0).sqrt()),
            &format!("end_time = {end}"),
        )
}

/// A rigid piston at a prescribed V into the plane-stress PMB bar drives the
/// compression wave of the 1D impact: the bar pushes back with ρ c0 V W while
/// the wave runs (before it returns from the free end at 2L/c0), the particles
/// behind the front move at V and those ahead of it are at rest (seed 003's
/// push-out of particles from a rigid body, eqs. 28–29).
#[test]
fn a_rigid_piston_drives_the_one_dimensional_impact_wave_into_a_peridynamic_bar() {
    let (rho, c0, v) = (2700.0, (70e9f64 / 2700.0).sqrt(), 1.0);
    let (length, width) = (0.1, 0.01);
    let end = 0.6 * length / c0;
    let scene = struck_bar(length, width, "prescribed", v, end);
    let (summary, dir) = run_text(&scene, &[]);
    summary.expect("the struck bar runs");
    let c = Table::read(&dir.path().join("contact.csv")).unwrap();
    let (t, fx) = (c.col("t"), c.col("fx"));
    let window: Vec<f64> = (0..t.len())
        .filter(|&k| t[k] > 0.15 * length / c0)
        .map(|k| fx[k])
        .collect();
    let mean = window.iter().sum::<f64>() / window.len() as f64;
    let impedance = rho * c0 * v * width;
    println!(
        "rows {}, mean force {mean:.6e}, ρ c0 V W {impedance:.6e}",
        window.len()
    );
    // Measured +1.7 % (the bar's wave speed is +0.9 % of c0, above).
    assert_within(
        "bar's push-back / (ρ c0 V W) − 1",
        mean / impedance - 1.0,
        0.05,
    );
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (x, vx, body) = (p.col("X0"), p.col("vx"), p.col("body"));
    let front = c0 * end;
    let mean_v = |lo: f64, hi: f64| {
        let v: Vec<f64> = (0..x.len())
            .filter(|&q| body[q] == 0.0 && x[q] > lo && x[q] < hi)
            .map(|q| vx[q])
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let behind = mean_v(0.2 * front, 0.7 * front);
    let ahead = mean_v(1.15 * front, 2.0 * length);
    println!("behind the front {behind:.4} m/s, ahead {ahead:.2e} m/s");
    // Measured −2.3 % (the lattice's dispersion rings behind the front) and
    // 1.7e-4 (its precursor).
    assert_within("velocity behind the front / V − 1", behind / v - 1.0, 0.05);
    assert_within("velocity ahead of the front / V", ahead / v, 5e-4);
}

/// A free rigid piston striking the bar: the rigid projection gives the piston
/// what it takes from the bar, so the momentum of all particles is the
/// piston's initial one to round-off (measured 2e-14); the light piston
/// (2 mm of steel against 0.1 m of aluminium) bounces back.
#[test]
fn a_free_rigid_piston_and_a_peridynamic_bar_conserve_momentum() {
    let (length, width, v) = (0.1, 0.01, 1.0);
    let end = 0.6 * length / (70e9f64 / 2700.0).sqrt();
    let scene = struck_bar(length, width, "free", v, end);
    let (summary, dir) = run_text(&scene, &[]);
    summary.expect("the struck bar runs");
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (mass, vx, vy, body) = (p.col("mass"), p.col("vx"), p.col("vy"), p.col("body"));
    let piston: f64 = (0..mass.len())
        .filter(|&q| body[q] == 1.0)
        .map(|q| mass[q])
        .sum();
    let momentum = |d: &[f64]| (0..mass.len()).map(|q| mass[q] * d[q]).sum::<f64>();
    let (px, py) = (momentum(vx), momentum(vy));
    let bar: f64 = (0..mass.len())
        .filter(|&q| body[q] == 0.0)
        .map(|q| mass[q] * vx[q])
        .sum();
    println!(
        "Σ m vx {px:.15e} against {:.15e}; the bar's {bar:.6e}",
        piston * v
    );
    assert!(bar > 0.05 * piston * v, "the bar took momentum: {bar:e}");
    assert_within("Σ m vx / (M V) − 1", px / (piston * v) - 1.0, 1e-12);
    assert_within("Σ m vy / (M V)", py / (piston * v), 1e-12);
}

#[test]
fn the_contact_of_a_peridynamic_body_is_checked_by_key() {
    let (length, width) = (0.1, 0.01);
    let scene = struck_bar(length, width, "prescribed", 1.0, 1e-6);
    Scene::parse("scene.toml", &scene, &[]).expect("valid");
    let friction = scene.replace("friction_coefficient = 0.0", "friction_coefficient = 0.3");
    rejected_at(
        &friction,
        "contact.0.friction_coefficient",
        &["frictionless"],
    );
    let adhesion = scene.replace(
        "friction_coefficient = 0.0",
        "friction_coefficient = 0.0\nadhesion = 1.0",
    );
    rejected_at(&adhesion, "contact.0.adhesion", &["no adhesion"]);
    let projection = scene.replace(
        "friction_coefficient = 0.0",
        "friction_coefficient = 0.0\nrigid_projection = false",
    );
    rejected_at(
        &projection,
        "contact.0.rigid_projection",
        &["rigid projection"],
    );
}

/// A line x = a + b y through the points (x on y: the cracks are steep), as
/// the angle to the x axis (the notches), in degrees.
fn steep_line_angle(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxy, syy) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx) * (p.1 - my), b + (p.1 - my).powi(2))
    });
    (1.0f64).atan2((sxy / syy).abs()).to_degrees()
}

/// The shipped Kalthoff–Winkler plate (`problems/kalthoff_winkler.toml`, Δx =
/// 1 mm; papers/kalthoff_winkler): from each notch tip a crack runs outwards
/// at 63°–72° to the notch (experiment ≈ 70°, seed 003 68.3°), the two
/// mirror images of each other, and its tip, sampled every 10 μs, stays below
/// the Rayleigh speed c_R ≈ 0.93 c_s (ν = 1/3: c_s = 2.98 km/s).
#[test]
fn the_kalthoff_winkler_plate_cracks_from_its_notches_at_about_70_degrees() {
    let (summary, dir) = run_problem("kalthoff_winkler.toml", &[]);
    summary.expect("the plate runs");
    let threshold = 0.35;
    let tips = [(0.05, 0.12575, 1.0), (0.05, 0.07425, -1.0)];
    // The damaged particles beyond notch k (y beyond its tip by 3 Δx).
    let crack = |t: &Table, k: usize| -> Vec<(f64, f64)> {
        let (x, y, d, body) = (t.col("X0"), t.col("Y0"), t.col("damage"), t.col("body"));
        let (xt, yt, side) = tips[k];
        (0..x.len())
            .filter(|&q| body[q] == 0.0 && d[q] > threshold)
            .filter(|&q| side * (y[q] - yt) > 3e-3 && x[q] > xt - 1e-3)
            .map(|q| (x[q], y[q]))
            .collect()
    };
    let last = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let angles: Vec<f64> = (0..2).map(|k| steep_line_angle(&crack(&last, k))).collect();
    println!("crack angles {angles:?}");
    // Measured 67.63° both (Δx = 2 mm: 67.07°, 0.5 mm: 67.54°).
    for a in &angles {
        assert!(
            (63.0..=72.0).contains(a),
            "crack angle {a:.2}° outside 63°–72°"
        );
    }
    assert!(
        (angles[0] - angles[1]).abs() < 1.0,
        "the cracks are mirror images: {angles:?}"
    );
    let times = Table::read(&dir.path().join("particle_times.csv")).unwrap();
    let reach = |file: &str| {
        let t = Table::read(&dir.path().join(file)).unwrap();
        let (xt, yt, _) = tips[0];
        (crack(&t, 0).iter())
            .map(|p| ((p.0 - xt).powi(2) + (p.1 - yt).powi(2)).sqrt())
            .fold(0.0, f64::max)
    };
    let t = times.col("t");
    let lengths: Vec<f64> = times.text["file"].iter().map(|f| reach(f)).collect();
    let speed = (1..t.len())
        .map(|k| (lengths[k] - lengths[k - 1]) / (t[k] - t[k - 1]))
        .fold(0.0, f64::max);
    let c_rayleigh = 0.93 * (190e9 / (2.0 * (1.0 + 1.0 / 3.0)) / 8000.0f64).sqrt();
    println!("crack lengths {lengths:?}; fastest tip {speed:.0} m/s, c_R {c_rayleigh:.0} m/s");
    // Measured 1,725 m/s (0.62 c_R); the crack reaches 79 mm.
    assert!(
        speed > 0.2 * c_rayleigh && speed < c_rayleigh,
        "tip speed {speed:.0} m/s"
    );
    assert!(
        lengths.last().unwrap() > &0.06,
        "the crack runs through the plate"
    );
}

/// A correspondence bar (plane strain, ν = 1/4) in its first axial mode: a
/// thin plane-strain bar's speed is √(E/((1 − ν²)ρ)).
#[test]
fn the_correspondence_bar_wave_speed_is_the_plane_strain_bar_speed() {
    let (length, width, nu) = (0.1, 0.01, 0.25);
    let c0 = (70e9 / ((1.0f64 - nu * nu) * 2700.0)).sqrt();
    let scene = bar(length, width)
        .replace("poisson_ratio = 0.333333", "poisson_ratio = 0.25")
        .replace("plane = \"stress\"", "bond_model = \"correspondence\"");
    // Measured −0.63 % (constant) and −0.57 % (seed 004's Gaussian influence);
    // no surface correction is needed: F is exact at the faces.
    for influence in ["constant", "gaussian"] {
        let set = format!("body.0.influence=\"{influence}\"");
        let (summary, dir) = run_text(&scene, &[set.as_str()]);
        summary.expect("the bar runs");
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let c = length / (2.0 * first_minimum(h.col("t"), h.col("kinetic")));
        assert_within(
            &format!("correspondence bar, {influence}: c/c0 − 1"),
            c / c0 - 1.0,
            0.03,
        );
    }
}

/// The same bar's stresses in particles_final.csv (the body's own state, not
/// the zero-stress material its particles carry on the grid): at a quarter
/// period, u = (v0/ω) cos(πx/L) sin(ωt) gives at mid-length
/// ε = −v0/c and σxx = −ρ c v0 (c = √(E/((1 − ν²)ρ)), σyy ≈ 0 in a thin bar).
#[test]
fn the_correspondence_bar_writes_its_own_stresses() {
    let (length, width, nu, rho, v0) = (0.1, 0.01, 0.25, 2700.0, 0.1);
    let c = (70e9 / ((1.0f64 - nu * nu) * rho)).sqrt();
    let scene = bar(length, width)
        .replace("poisson_ratio = 0.333333", "poisson_ratio = 0.25")
        .replace("plane = \"stress\"", "bond_model = \"correspondence\"");
    let end = format!("solver.end_time={}", length / (2.0 * c));
    let (summary, dir) = run_text(&scene, &[end.as_str()]);
    summary.expect("the bar runs");
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let mid: Vec<usize> = (0..p.len())
        .filter(|&q| (p.col("X0")[q] - 0.5 * length).abs() < 1e-3)
        .collect();
    let mean = |col: &str| mid.iter().map(|&q| p.col(col)[q]).sum::<f64>() / mid.len() as f64;
    let expected = -rho * c * v0;
    // Measured −0.87 % and syy/sxx −2.4 % (2026-12-04); the zero-stress grid
    // material would give −100 %.
    assert_within(
        "mid-length sxx / (−ρ c v0) − 1",
        mean("sxx") / expected - 1.0,
        0.03,
    );
    assert_within("mid-length syy / sxx", mean("syy") / expected, 0.03);
}

#[test]
fn the_keys_of_a_correspondence_body_are_checked_by_key() {
    let corr = |extra: &str| with(&format!("bond_model = \"correspondence\"\n{extra}"), "");
    Scene::parse("scene.toml", &corr(""), &[]).expect("valid");
    // Any ν: the material's own update.
    Scene::parse(
        "scene.toml",
        &corr("").replace("poisson_ratio = 0.25", "poisson_ratio = 0.4"),
        &[],
    )
    .expect("ν = 0.4");
    rejected_at(
        &corr("plane = \"stress\""),
        "body.0.plane",
        &["plane strain"],
    );
    rejected_at(
        &corr("zero_energy_control = -1.0"),
        "body.0.zero_energy_control",
        &["≥ 0"],
    );
    rejected_at(
        &with("zero_energy_control = 1.0", ""),
        "body.0.zero_energy_control",
        &["correspondence"],
    );
    Scene::parse("scene.toml", &corr("influence = \"gaussian\""), &[]).expect("Gaussian");
    rejected_at(
        &with("influence = \"gaussian\"", ""),
        "body.0.influence",
        &["correspondence"],
    );
    let bad = corr("influence = \"cubic\"");
    assert!(
        Scene::parse("scene.toml", &bad, &[]).is_err(),
        "an unknown influence is refused"
    );
}

/// Two equal plane-stress PMB bars, L = 50 mm × 10 mm, laid face to face,
/// the first striking at V (bodies 0 and 1 of a plain scene: no contact
/// table, the default short-range repulsion).
fn bars_meeting(v: f64, end: f64) -> String {
    let (length, width) = (0.05, 0.01);
    let one = bar(length, width);
    let body = |name: &str, from: f64, velocity: f64| {
        format!(
            r#"
[[body]]
name = "{name}"
kind = "peridynamic"
plane = "stress"
material = "al"
shape = "rectangle"
min = [{from}, 0.0]
max = [{to}, {width}]
particles_per_cell = 2
velocity = [{velocity}, 0.0]
"#,
            to = from + length
        )
    };
    let start = one.find("[[body]]").unwrap();
    let solver = one.find("[solver]").unwrap();
    let head = one[..start]
        .replace(
            &format!("max = [{}, {}]", length + 0.002, width + 0.002),
            &format!("max = [{}, {}]", 2.0 * length + 0.002, width + 0.002),
        )
        .replace(
            &format!("cells = [{}, ", (length / 1e-3).round() as usize + 4),
            &format!("cells = [{}, ", (2.0 * length / 1e-3).round() as usize + 4),
        );
    let tail = one[solver..].replace(
        &format!("end_time = {}", 0.7 * length / (70e9f64 / 2700.0).sqrt()),
        &format!("end_time = {end}"),
    );
    format!(
        "{head}{}{}{tail}",
        body("striker", 0.0, v),
        body("target", length, 0.0)
    )
}

/// Of the target (body 1) of a 1D impact at V with contact time `contact`,
/// from history.csv in `dir`: the time it passes V/2 (interpolated between
/// rows) and its acceleration over the middle half of the contact (a
/// least-squares slope).
fn target_history(dir: &std::path::Path, v: f64, contact: f64) -> (f64, f64) {
    let h = Table::read(&dir.join("history.csv")).unwrap();
    let (t, target) = (h.col("t"), h.col("body1_vx"));
    let k = (1..t.len())
        .find(|&k| target[k] >= 0.5 * v)
        .expect("the target moves");
    let half =
        t[k - 1] + (t[k] - t[k - 1]) * (0.5 * v - target[k - 1]) / (target[k] - target[k - 1]);
    let window: Vec<usize> = (0..t.len())
        .filter(|&k| t[k] > 0.25 * contact && t[k] < 0.75 * contact)
        .collect();
    let n = window.len() as f64;
    let mt = window.iter().map(|&k| t[k]).sum::<f64>() / n;
    let mv = window.iter().map(|&k| target[k]).sum::<f64>() / n;
    let slope = window
        .iter()
        .map(|&k| (t[k] - mt) * (target[k] - mv))
        .sum::<f64>()
        / window.iter().map(|&k| (t[k] - mt).powi(2)).sum::<f64>();
    (half, slope)
}

/// After a 1D impact, from particles_final.csv in `dir`: the momenta of the
/// striker (body 0) and the target (body 1) over the striker's mass, the
/// striker's front and the target's back.
fn after_impact(dir: &std::path::Path) -> (f64, f64, f64, f64) {
    let p = Table::read(&dir.join("particles_final.csv")).unwrap();
    let (x, vx, mass, body) = (p.col("x"), p.col("vx"), p.col("mass"), p.col("body"));
    let of = |b: f64| (0..x.len()).filter(move |&q| body[q] == b);
    let momentum = |b: f64| of(b).map(|q| mass[q] * vx[q]).sum::<f64>();
    let total: f64 = of(0.0).map(|q| mass[q]).sum();
    let front = of(0.0).map(|q| x[q]).fold(f64::NEG_INFINITY, f64::max);
    let back = of(1.0).map(|q| x[q]).fold(f64::INFINITY, f64::min);
    (momentum(0.0) / total, momentum(1.0) / total, front, back)
}

/// The 1D impact of two equal bars, PD against PD through the short-range
/// repulsion (`material::bond::short_range`): while they touch, the target's
/// velocity rises at the rate the interface stress ρ c0 V/2 gives it
/// (c0 V/(2L)), through V/2 at L/c0, and contact ends at 2L/c0 with the
/// velocities exchanged; the bars never pass into each other and momentum is
/// kept to round-off. Without the repulsion (`short_range_force = 0`) the
/// target takes nothing.
#[test]
fn two_peridynamic_bars_meet_as_the_one_dimensional_impact() {
    let (c0, v, length) = ((70e9f64 / 2700.0).sqrt(), 1.0, 0.05);
    let contact = 2.0 * length / c0;
    let scene = bars_meeting(v, 1.5 * contact);
    let (summary, dir) = run_text(&scene, &[]);
    summary.expect("the bars run");
    let (half, slope) = target_history(dir.path(), v, contact);
    let (striker, hit, front, back) = after_impact(dir.path());
    println!(
        "V/2 at {half:.4e} s (L/c0 {:.4e}); slope {slope:.4e} (c0 V/2L {:.4e}); \
         after: striker {striker:.4} m/s, target {hit:.4} m/s; gap {:.3} mm",
        length / c0,
        c0 * v / (2.0 * length),
        (back - front) * 1e3
    );
    assert_within("time of V/2 / (L/c0) − 1", half / (length / c0) - 1.0, 0.03);
    assert_within(
        "target acceleration / (c0 V/2L) − 1",
        slope / (c0 * v / (2.0 * length)) - 1.0,
        0.05,
    );
    assert_within("striker's velocity after / V", striker / v, 0.03);
    assert_within("target's velocity after / V − 1", hit / v - 1.0, 0.03);
    assert_within("momentum / (M V) − 1", (striker + hit) / v - 1.0, 1e-12);
    assert!(front < back, "the bars overlap: {front} ≥ {back}");
    // The control.
    let (summary, dir) = run_text(&scene, &["body.0.short_range_force=0"]);
    summary.expect("the bars run");
    // The target's momentum over the striker's mass (`after_impact`).
    let (_, hit, _, _) = after_impact(dir.path());
    assert!(
        hit.abs() < 1e-9 * v,
        "without repulsion the target took {hit:e} of the striker's M V"
    );
}

/// A bar of `bond_model` (and `plane`, material `pd`) striking an equal MPM
/// bar (material `mpm`, Young's modulus `e_mpm` and ν `nu`, so that its bar
/// wave speed in plane strain is c0 = √(E/ρ) of the striker) at V = 1 m/s,
/// the two meeting through the nodal contact.
fn striking_a_continuum_bar(bond_model: &str, plane: &str, nu: f64, e_mpm: f64) -> String {
    let (length, c0) = (0.05, (70e9f64 / 2700.0).sqrt());
    format!(
        r#"
dimension = 2
[grid]
min = [-0.002, -0.002]
max = [0.102, 0.012]
cells = [104, 14]
shape_function = "linear"
[[material]]
name = "pd"
model = "linear_elastic"
density = 2700.0
youngs_modulus = 70e9
poisson_ratio = {nu}
[[material]]
name = "mpm"
model = "linear_elastic"
density = 2700.0
youngs_modulus = {e_mpm}
poisson_ratio = {nu}
[[body]]
name = "striker"
kind = "peridynamic"
bond_model = "{bond_model}"
plane = "{plane}"
material = "pd"
shape = "rectangle"
min = [0.0, 0.0]
max = [{length}, 0.01]
particles_per_cell = 2
velocity = [1.0, 0.0]
[[body]]
name = "target"
material = "mpm"
shape = "rectangle"
min = [{length}, 0.0]
max = [{twice}, 0.01]
particles_per_cell = 2
[[contact]]
bodies = ["striker", "target"]
[solver]
kind = "explicit"
end_time = {end}
[output]
frames = 0
history_interval = 0.0
"#,
        twice = 2.0 * length,
        end = 3.0 * length / c0,
    )
}

/// The 1D impact of equal bars, a peridynamic striker on a continuum (MPM)
/// target, through the grid's nodal contact
/// (`solver::explicit::contact`, with the exchange reaching the
/// peridynamic particles through the consistent mass, `Contact::bonded_kicks`):
/// the target passes V/2 at L/c0 with the acceleration c0 V/(2L) of the
/// interface stress ρ c0 V/2, the velocities are exchanged at 2L/c0, momentum
/// is kept to round-off and the bars do not pass into each other. The
/// correspondence striker (plane strain, ν = 0) and a PMB one (plane stress,
/// ν = 1/3, against an MPM bar of E (1 − ν²)) both. With the lumped (FLIP)
/// share of the exchange instead, the interface kept approaching at 7 % of V
/// and the acceleration was low by 7.6 % (correspondence).
#[test]
fn a_peridynamic_bar_meets_a_continuum_bar_through_the_grid() {
    let (c0, v, length) = ((70e9f64 / 2700.0).sqrt(), 1.0, 0.05);
    let contact = 2.0 * length / c0;
    let cases = [
        ("correspondence", "strain", 0.0, 70e9, 0.01, 0.02),
        (
            "pmb",
            "stress",
            0.333333,
            70e9 * (1.0 - 0.333333f64.powi(2)),
            0.02,
            0.04,
        ),
    ];
    for (model, plane, nu, e, tol_time, tol_after) in cases {
        let (summary, dir) = run_text(&striking_a_continuum_bar(model, plane, nu, e), &[]);
        summary.expect("the bars run");
        let (half, slope) = target_history(dir.path(), v, contact);
        let (striker, hit, front, back) = after_impact(dir.path());
        println!(
            "{model}: V/2 at {:+.4} of L/c0; acceleration {:+.4} of c0 V/2L; after: striker \
             {striker:.4} m/s, target {hit:.4} m/s; gap {:.3} mm",
            half / (length / c0) - 1.0,
            slope / (c0 * v / (2.0 * length)) - 1.0,
            (back - front) * 1e3
        );
        assert_within(
            "time of V/2 / (L/c0) − 1",
            half / (length / c0) - 1.0,
            tol_time,
        );
        assert_within(
            "target acceleration / (c0 V/2L) − 1",
            slope / (c0 * v / (2.0 * length)) - 1.0,
            2.0 * tol_time,
        );
        assert_within("striker's velocity after / V", striker / v, tol_after);
        assert_within("target's velocity after / V − 1", hit / v - 1.0, tol_after);
        assert_within("momentum / (M V) − 1", (striker + hit) / v - 1.0, 1e-12);
        assert!(front < back, "the bars overlap: {front} ≥ {back}");
    }
    // Stopped in contact: the particles' contact forces sum to the pair's.
    let scene = striking_a_continuum_bar("correspondence", "strain", 0.0, 70e9);
    let (summary, dir) = run_text(&scene, &[&format!("solver.end_time={}", length / c0)]);
    summary.expect("the bars run");
    let pair = Table::read(&dir.path().join("contact.csv")).unwrap();
    let fx = *pair.col("fx").last().unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (force, body) = (p.col("contact_fx"), p.col("body"));
    let on = |b: f64| {
        (0..force.len())
            .filter(|&q| body[q] == b)
            .map(|q| force[q])
            .sum::<f64>()
    };
    println!(
        "contact.csv fx {fx:.6e}; on the striker {:.6e}, the target {:.6e}",
        on(0.0),
        on(1.0)
    );
    assert!(
        fx.abs() > 0.5 * 2700.0 * c0 * 0.5 * v * 0.01,
        "in contact: {fx}"
    );
    assert_within("striker's Σ f / pair's − 1", on(0.0) / fx - 1.0, 1e-9);
    assert_within("target's Σ f / pair's + 1", on(1.0) / fx + 1.0, 1e-9);
}

/// history.csv's `strain` counts the bonds' energy
/// (`physics::peridynamics::energy`): a bar swinging in its first axial mode
/// keeps K + W to its initial kinetic energy while K falls to nearly nothing
/// at a quarter period and comes back, for each bond model (PMB in plane
/// stress, the beam law at ν = 0.2, correspondence at ν = 1/4 in plane strain).
#[test]
fn a_swinging_bar_keeps_its_energy_with_the_bonds_counted() {
    let (length, width) = (0.1, 0.01);
    let plain = bar(length, width);
    let beam = plain
        .replace("poisson_ratio = 0.333333", "poisson_ratio = 0.2")
        .replace(
            "plane = \"stress\"",
            "plane = \"stress\"\nbond_model = \"beam\"",
        );
    let correspondence = plain
        .replace("poisson_ratio = 0.333333", "poisson_ratio = 0.25")
        .replace("plane = \"stress\"", "bond_model = \"correspondence\"");
    for (name, scene) in [
        ("pmb", plain.clone()),
        ("beam", beam),
        ("correspondence", correspondence),
    ] {
        let (summary, dir) = run_text(&scene, &[]);
        summary.expect("the bar runs");
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let (k, w) = (h.col("kinetic"), h.col("strain"));
        let e0 = k[0] + w[0];
        let drift = (0..k.len())
            .map(|i| (k[i] + w[i] - e0).abs() / e0)
            .fold(0.0, f64::max);
        let stored = w.iter().copied().fold(0.0, f64::max) / e0;
        println!("{name}: max |K + W − E0|/E0 {drift:.2e}, max W/E0 {stored:.4}");
        assert_within(&format!("{name}: max |K + W − E0|/E0"), drift, 0.01);
        assert_within(&format!("{name}: max W/E0 − 1"), stored - 1.0, 0.03);
    }
}
