//! The compliant base (Joyner & Chen 1975; `incoming_velocity` on an
//! absorbing face, `physics::boundary::absorbing`): vertically propagating
//! shear waves in a column one cell wide whose sides hold the vertical
//! velocity at zero, so that the motion is one-dimensional shear, the free
//! field itself (the documented alternative to free-field side boundaries,
//! docs/absorbing.md). The incoming wave is a triangle pulse of particle
//! velocity v_in(t) = V (0 → 1 at T/2 → 0 at T), T = 0.04 s.
//!
//! - A pulse that enters through the base, reflects at the free top and comes
//!   back leaves through the base: the energy left in the column after it has
//!   gone is ≤ 5 % of the energy it brought (the issue's bound).
//! - Site response of a layer (H = 10 m, V_s = 100 m/s, ρ = 1800) on rock
//!   (V_r = 400 m/s, ρ = 2400; 5 m of it in the model over the compliant
//!   base): the ratio of the Fourier transform of the surface velocity to the
//!   outcrop motion 2 v_in is the closed-form transfer function
//!   1/|cos kH + i α sin kH|, k = ω/V_s, α = ρ_s V_s/(ρ_r V_r) = 0.1875, with
//!   its peaks at f_n = (2n − 1) V_s/(4H) = 2.5, 7.5, 12.5 Hz and 1/α = 5.33 at
//!   each (undamped). The record runs until the ringing has died away (a
//!   round trip in the layer keeps (1 − α)/(1 + α) = 0.68 of the amplitude:
//!   2 % after the 4 s of ten round trips), so its transform is evaluated at
//!   any frequency with no window.

use crate::common::{assert_within, one_thread, problem, Table};
use mpm::model::Model;
use mpm::scene::Scene;
use std::f64::consts::PI;

const V: f64 = 0.01;
const T: f64 = 0.04;

/// v_in(t) of the triangle pulse, in closed form.
fn incoming(t: f64) -> f64 {
    match t {
        t if t <= 0.0 || t >= T => 0.0,
        t if t <= T / 2.0 => V * t / (T / 2.0),
        t => V * (T - t) / (T / 2.0),
    }
}

/// A column [0, 0.25] × [0, height] of 0.25 m cells, the sides holding v_y = 0,
/// the compliant base on ymin; `bodies` the [[material]] and [[body]] tables.
fn column(height: f64, bodies: &str, solver: &str, output: &str) -> String {
    let cells = (height / 0.25).round() as usize;
    format!(
        r#"dimension = 2
[grid]
min = [0.0, 0.0]
max = [0.25, {height:?}]
cells = [1, {cells}]
{bodies}
[[boundary]]
face = "ymin"
condition = "absorbing"
incoming_velocity = [{V:?}, 0.0]
time_history = [[0.0, 0.0], [{half:?}, 1.0], [{T:?}, 0.0]]
[[boundary]]
face = "xmin"
condition = "velocity"
velocity = [0.0, 0.0]
components = ["y"]
[[boundary]]
face = "xmax"
condition = "velocity"
velocity = [0.0, 0.0]
components = ["y"]
[solver]
{solver}
[output]
frames = 0
{output}
"#,
        half = T / 2.0
    )
}

/// An elastic material (ν = 0) of density ρ and shear velocity c, and a body of
/// it over [y0, y1].
fn layer(name: &str, rho: f64, c: f64, y0: f64, y1: f64) -> String {
    let e = 2.0 * rho * c * c;
    format!(
        "[[material]]\nname = \"{name}\"\nmodel = \"linear_elastic\"\ndensity = {rho:?}\nyoungs_modulus = {e:?}\npoisson_ratio = 0.0\n\
         [[body]]\nmaterial = \"{name}\"\nshape = \"rectangle\"\nmin = [0.0, {y0:?}]\nmax = [0.25, {y1:?}]\nparticles_per_cell = 2\n"
    )
}

const EXPLICIT: &str = "kind = \"explicit\"";
const NEWMARK: &str = "kind = \"implicit\"\nintegrator = \"newmark\"\ndt = 0.002";

/// A 20 m column of soil (ρ = 1800, c = 100 m/s): the energy at 0.1 s (the
/// pulse, 4 m long, wholly inside) against A ρ c ∫ v_in² dt = A ρ c V² T/3,
/// and the energy left at 0.55 s (the pulse's tail left the base at 0.44 s; a
/// reflection would be at most 11 m up) over the energy at 0.1 s.
#[test]
fn a_pulse_leaves_through_the_compliant_base() {
    let (rho, c) = (1800.0, 100.0);
    let brought = 0.25 * rho * c * V * V * T / 3.0;
    // Measured: explicit 4.5e-3, Newmark 5.9e-3 (the issue's bound, 5e-2, is
    // looser than 3 times these).
    for (solver, reflected) in [(EXPLICIT, 1.2e-2), (NEWMARK, 1.5e-2)] {
        let text = column(
            20.0,
            &layer("soil", rho, c, 0.0, 20.0),
            &format!("{solver}\nend_time = 0.55"),
            "history_interval = 0.05",
        );
        let (result, dir) = crate::common::run_text(&text, &[]);
        result.unwrap();
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let energy_at = |t: f64| {
            let row = (0..h.col("t").len())
                .min_by(|&a, &b| {
                    (h.col("t")[a] - t)
                        .abs()
                        .total_cmp(&(h.col("t")[b] - t).abs())
                })
                .unwrap();
            h.col("kinetic")[row] + h.col("strain")[row]
        };
        let (inside, left) = (energy_at(0.1), energy_at(0.55));
        println!(
            "{solver}: pulse energy {inside:.4e} (closed form {brought:.4e}), left {left:.3e}"
        );
        // Measured: explicit −5.0e-3, Newmark −1.0e-2 (Δt = 2 ms: 20 steps over
        // the pulse).
        assert_within(
            &format!("{solver}: pulse energy / closed form − 1"),
            inside / brought - 1.0,
            0.02,
        );
        assert_within(
            &format!("{solver}: energy left / brought"),
            left / inside,
            reflected,
        );
    }
}

/// The surface velocity (mean over the particles of the top cell) at every
/// step of a run of `scene`, with the times.
fn surface_record(scene: &Scene) -> (Vec<f64>, Vec<f64>) {
    one_thread(|| {
        let mut m = Model::<2>::build(scene).unwrap();
        let stage = scene.config.stages()[0];
        let mut solver = mpm::solver::stepper::<2>(scene.config.grid.shape_function, stage, 0.0);
        let top = m.particles.x0.iter().map(|x| x[1]).fold(f64::MIN, f64::max);
        let surface: Vec<usize> = (0..m.particles.len())
            .filter(|&q| m.particles.x0[q][1] > top - 0.2)
            .collect();
        let mean_vx = |m: &Model<2>| {
            surface.iter().map(|&q| m.particles.v[q][0]).sum::<f64>() / surface.len() as f64
        };
        let (mut t, mut step) = (0.0, 0);
        let (mut times, mut v) = (vec![0.0], vec![0.0]);
        while t < stage.end_time - 1e-12 {
            let dt = solver.dt(&m).min(stage.end_time - t);
            solver.step(&mut m, t, dt, step).unwrap();
            t += dt;
            step += 1;
            times.push(t);
            v.push(mean_vx(&m));
        }
        (times, v)
    })
}

/// |∫ x(t) e^{−iωt} dt| by the trapezoidal rule over the samples.
fn spectrum(times: &[f64], x: &[f64], f: f64) -> f64 {
    let w = 2.0 * PI * f;
    let (mut re, mut im) = (0.0, 0.0);
    for k in 1..times.len() {
        let dt = times[k] - times[k - 1];
        for (t, y) in [(times[k - 1], x[k - 1]), (times[k], x[k])] {
            re += 0.5 * dt * y * (w * t).cos();
            im -= 0.5 * dt * y * (w * t).sin();
        }
    }
    (re * re + im * im).sqrt()
}

/// The largest |H| in [lo, hi] on a grid of 0.002 Hz, refined by the parabola
/// through the best sample and its neighbours: (frequency, amplification).
fn peak(h: &impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let n = ((hi - lo) / 0.002).round() as usize;
    let fs: Vec<f64> = (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .collect();
    let hs: Vec<f64> = fs.iter().map(|&f| h(f)).collect();
    let k = (1..n).max_by(|&a, &b| hs[a].total_cmp(&hs[b])).unwrap();
    let (a, b, c) = (hs[k - 1], hs[k], hs[k + 1]);
    let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
    let step = fs[1] - fs[0];
    (fs[k] + shift * step, b - 0.25 * (a - c) * shift)
}

/// The peaks of the measured transfer function against the closed form:
/// f_n within `frequency[n − 1]`, the amplification α |H| − 1 within
/// `amplification[n − 1]`.
fn check_site_response(solver: &str, frequency: [f64; 3], amplification: [f64; 3]) {
    let (h_layer, rho_s, v_s, rho_r, v_r) = (10.0, 1800.0, 100.0, 2400.0, 400.0);
    let alpha = rho_s * v_s / (rho_r * v_r);
    // problems/site_response.toml is that column; its solver replaced by `solver`.
    let table = format!("solver={{{},end_time=4.0}}", solver.replace('\n', ","));
    let scene = Scene::load(&problem("site_response.toml"), &[table]).unwrap();
    let (times, v) = surface_record(&scene);
    let vin: Vec<f64> = times.iter().map(|&t| incoming(t)).collect();
    let transfer = |f: f64| spectrum(&times, &v, f) / (2.0 * spectrum(&times, &vin, f));
    for n in 1..=3 {
        let exact = (2 * n - 1) as f64 * v_s / (4.0 * h_layer);
        let (f, peak_value) = peak(&transfer, 0.8 * exact, 1.2 * exact);
        let what = |q: &str| format!("{solver}: peak {n}: {q}");
        assert_within(
            &what("f_n / closed form − 1"),
            f / exact - 1.0,
            frequency[n - 1],
        );
        assert_within(
            &what("α |H| − 1"),
            peak_value * alpha - 1.0,
            amplification[n - 1],
        );
    }
}

/// Measured: f_n / closed form − 1 = 4.4e-4, −1.6e-3, −5.5e-3 (the grid's
/// dispersion: 32 cells per wavelength at f_3); α |H| − 1 = 8.1e-4, 9.2e-3,
/// 1.8e-2. The issue's 1 % on f_3 is tighter than 3 times the measured value.
/// Takes 7 s (release).
#[test]
fn site_response_of_a_layer_on_rock_explicit() {
    check_site_response(EXPLICIT, [1.5e-3, 5e-3, 1e-2], [5e-3, 3e-2, 5e-2]);
}

/// Trapezoidal Newmark at Δt = 2 ms (40 steps per period at f_3, whose
/// period it lengthens by (ωΔt)²/12 = 0.2 %). Measured: f_n / closed form − 1
/// = 5.5e-4, −2.3e-3, −7.6e-3; α |H| − 1 = 1.2e-3, 1.2e-2, 2.2e-2. Takes 12 s
/// (release).
#[test]
fn site_response_of_a_layer_on_rock_newmark() {
    check_site_response(NEWMARK, [1.5e-3, 6e-3, 1e-2], [5e-3, 3e-2, 6e-2]);
}
