//! Staged construction (issue 55, item 2; `model::staging`, docs/staging.md):
//! an opening excavated in an elastic medium under an isotropic stress against
//! Kirsch's closed form; an excavation in one stage against the same in two;
//! a fill placed in layers against the elastic closed form of a layer on a
//! rigid base and against the same fill placed at once.

use crate::common::{assert_within, run_problem, run_text, Table};
use std::path::Path;

const P0: f64 = 1.0e3;
const G: f64 = 1.0e8 / (2.0 * 1.25);

fn particles(dir: &Path) -> Table {
    Table::read(&dir.join("particles_final.csv")).unwrap()
}

/// Per particle: its radius r (reference position at the excavation's
/// start), radial displacement since then and hoop stress σ_θθ.
fn polar(p: &Table) -> Vec<(f64, f64, f64)> {
    let (x0, y0, x, y) = (p.col("X0"), p.col("Y0"), p.col("x"), p.col("y"));
    let (sxx, syy, sxy) = (p.col("sxx"), p.col("syy"), p.col("sxy"));
    (0..x0.len())
        .map(|q| {
            let r = x0[q].hypot(y0[q]);
            let (c, s) = (x0[q] / r, y0[q] / r);
            let u_r = (x[q] - x0[q]) * c + (y[q] - y0[q]) * s;
            let hoop = s * s * sxx[q] + c * c * syy[q] - 2.0 * c * s * sxy[q];
            (r, u_r, hoop)
        })
        .collect()
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (n, sum) = v.fold((0, 0.0), |(n, s), x| (n + 1, s + x));
    sum / n as f64
}

/// Kirsch (K0 = 1, plane strain, tension positive): u_r = −p0 a²/(2 G r),
/// σ_θθ = −p0 (1 + a²/r²). The shipped scene: a = 1 m, a quarter of a 16 m
/// square, a/Δx = 8. Over the particles of the first cell layer off the wall
/// (a ≤ r < a + Δx), each against the closed form at its own radius: the wall
/// moves 2.0 % more than Kirsch's (about 0.6 % of it the finite square's, a
/// hollow cylinder of that size), and σ_θθ is 1.4 % under it; the issue asks
/// for 3 %. The in-situ stage leaves the uniform stress −p0 (checked in the
/// far field). The opening takes out the particles of r < a, and the run
/// reports fewer particles.
#[test]
fn an_opening_excavated_under_isotropic_stress_follows_kirsch() {
    let (result, dir) = run_problem("tunnel_excavation.toml", &["output.frames=0"]);
    let s = result.unwrap();
    let p = particles(dir.path());
    let rows = polar(&p);
    let built = 128 * 128 * 4;
    let inside = (built - s.particles) as f64 * (16.0 / 256.0_f64).powi(2);
    // The particles taken out fill the quarter disk of r < a (π/4 = 0.785).
    assert_within(
        "area excavated / (pi a^2 / 4) - 1",
        inside / std::f64::consts::FRAC_PI_4 - 1.0,
        0.03,
    );
    assert!(
        rows.iter().all(|r| r.0 >= 1.0),
        "no particle left inside r < a"
    );
    let wall: Vec<&(f64, f64, f64)> = rows.iter().filter(|r| r.0 < 1.125).collect();
    let u = mean(wall.iter().map(|&&(r, u, _)| u / (-P0 / (2.0 * G * r))));
    let hoop = mean(
        wall.iter()
            .map(|&&(r, _, h)| h / (-P0 * (1.0 + 1.0 / (r * r)))),
    );
    // Measured +2.0e-2 and -1.4e-2; the bound is 3 %.
    assert_within("wall displacement / Kirsch's - 1", u - 1.0, 0.03);
    assert_within("hoop stress at the wall / Kirsch's - 1", hoop - 1.0, 0.03);
    // Kirsch's σ_rr + σ_θθ = −2 p0 at every r (the a²/r² terms cancel).
    let (x0, y0) = (p.col("X0"), p.col("Y0"));
    let far: Vec<usize> = (0..x0.len())
        .filter(|&q| (8.0..12.0).contains(&x0[q].hypot(y0[q])))
        .collect();
    let trace = mean(far.iter().map(|&q| p.col("sxx")[q] + p.col("syy")[q]));
    // Measured 4e-3 (the tractions act half a particle spacing inside the faces).
    assert_within(
        "far-field (sxx + syy) / (-2 p0) - 1",
        trace / (-2.0 * P0) - 1.0,
        1e-2,
    );
}

/// An elastic medium: the opening dug in one stage, or its inner half first
/// and the rest in a second stage, ends in the same state (to the geometric
/// nonlinearity of strains of 1e-5 and Newton's tolerance): displacements
/// since the first excavation and stresses. The coarse grid of the scene
/// (a/Δx = 4, 10 m square) suffices.
#[test]
fn an_excavation_in_one_stage_equals_the_same_in_two() {
    let text = std::fs::read_to_string(crate::common::problem("tunnel_excavation.toml")).unwrap();
    let coarse = [&crate::common::TUNNEL_COARSE[..], &["output.frames=0"]].concat();
    let once = run_text(&text, &coarse);
    let half = "excavate = [{ shape = \"disk\", centre = [0.0, 0.0], radius = 0.5 }]";
    let whole = "excavate = [{ shape = \"disk\", centre = [0.0, 0.0], radius = 1.0 }]";
    let second = format!(
        "\n[[stage]]\nname = \"rest\"\n{whole}\nkind = \"implicit\"\n\
         integrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1\n"
    );
    let staged = text
        .replace(whole, half)
        .replace("\n[output]", &format!("{second}\n[output]"));
    let twice = run_text(&staged, &coarse);
    let (a, b) = (once.0.unwrap(), twice.0.unwrap());
    assert_eq!(a.particles, b.particles, "the same particles are taken out");
    assert_eq!(b.stages.len(), 3);
    let (pa, pb) = (particles(once.1.path()), particles(twice.1.path()));
    let u_wall = P0 / (2.0 * G);
    let mut du: f64 = 0.0;
    let mut ds: f64 = 0.0;
    for q in 0..a.particles {
        for c in ["x", "y"] {
            du = du.max((pa.col(c)[q] - pb.col(c)[q]).abs() / u_wall);
        }
        for c in ["sxx", "syy", "sxy"] {
            ds = ds.max((pa.col(c)[q] - pb.col(c)[q]).abs() / P0);
        }
    }
    // The displacements are measured from the first excavation's start in both
    // (reset_displacement); the reference positions X0 then agree too.
    // Measured 4.8e-6 and 1.5e-5 (strains of 1e-5: the updated geometry's part).
    assert_within("one stage vs two: displacement / (p0 a / 2G)", du, 2e-5);
    assert_within("one stage vs two: stress / p0", ds, 5e-5);
}

/// Three layers of 10 m placed one per stage, each entering unstressed: the
/// vertical stress is −ρ g (H − Y) and the first layer settles as if the fill
/// had been placed at once, u(Y) = −ρ g (H Y − Y²/2)/M. Linear shape
/// functions give a stress constant per cell, off the closed form at the
/// particles by at most ρ g Δy/4 (0.83 % of ρ g H at Δy = 1 m); the settlement
/// of the first layer's top row is 0.04 % under the closed form, and the fill
/// placed at once gives the first layer's displacements to 3e-5 of it.
#[test]
fn a_fill_placed_in_layers_settles_as_the_closed_form() {
    let (staged, dir) = run_problem("fill_layers.toml", &[]);
    let staged = staged.unwrap();
    assert_eq!(staged.stages.len(), 3);
    assert_eq!(staged.particles, 120);
    let p = particles(dir.path());
    let (y0, y, syy) = (p.col("Y0"), p.col("y"), p.col("syy"));
    let (weight, height, m) = (2.0e4, 30.0, 1.0e9 * 0.7 / (1.3 * 0.4));
    let stress = (0..y0.len())
        .map(|q| (syy[q] + weight * (height - y0[q])).abs() / (weight * height))
        .fold(0.0, f64::max);
    // Measured 8.6e-3 against the bound 1/4 of a cell's weight, 8.3e-3 and
    // the Newton tolerance.
    assert_within("max |syy - closed form| / (rho g H)", stress, 1.0e-2);
    let top_of_first = |q: &usize| (y0[*q] - 9.75).abs() < 1e-9;
    let rows: Vec<usize> = (0..y0.len()).filter(top_of_first).collect();
    let u = mean(rows.iter().map(|&q| y[q] - y0[q]));
    let closed = -weight * (height * 9.75 - 9.75 * 9.75 / 2.0) / m;
    // Measured -3.9e-4.
    assert_within(
        "settlement of the first layer's top / closed form - 1",
        u / closed - 1.0,
        1e-3,
    );

    let text = std::fs::read_to_string(crate::common::problem("fill_layers.toml")).unwrap();
    let at_once = text.replace("active = false\n", "");
    let at_once = at_once[..at_once.find("[[stage]]").unwrap()].to_string()
        + "[solver]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 2\n";
    let (once, once_dir) = run_text(&at_once, &[]);
    assert_eq!(once.unwrap().particles, 120);
    let q1 = particles(once_dir.path());
    let first: Vec<usize> = (0..y0.len()).filter(|&q| y0[q] < 10.0).collect();
    let worst = (first.iter())
        .map(|&q| (y[q] - q1.col("y")[q]).abs() / closed.abs())
        .fold(0.0, f64::max);
    // Measured 2.5e-5.
    assert_within(
        "first layer, in layers vs at once / settlement",
        worst,
        7.5e-5,
    );
}
