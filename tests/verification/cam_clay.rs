//! Modified Cam-Clay against the closed forms of the critical state (issue 52,
//! item 4; `shared/reference/geotech-targets.py`): triaxial compression from
//! p′0 = 200 kPa with λ = 0.2, κ = 0.04, M = 1.2, isotropically consolidated to
//! p_c0 = OCR p′0. Tension is positive, stresses in Pa.
//!
//! - Undrained (isochoric, F = diag(a^−½, a^−½, a)): at the critical state
//!   p′_f = p′0 (OCR/2)^Λ, Λ = (λ − κ)/λ, q_f = M p′_f; with a constant total
//!   cell pressure σ3 = p′0 (no back pressure) the excess pore pressure is
//!   u = p_total − p′ = p′0 + q/3 − p′. The closed form needs only
//!   ε_v^e + ε_v^p = 0 with the logarithmic laws ε_v^e = κ̃ ln(p/p0),
//!   ε_v^p = (λ̃ − κ̃) ln(p_c/p_c0), which the model uses (J = 1, so τ = σ).
//! - Drained (constant cell pressure, axial compression): the stress path
//!   p′ = p′0 + q/3 meets the critical-state line q = M p′ at p′0/(1 − M/3),
//!   for any elasticity (q/p′ is the same for τ and σ).
//!
//! Single point through the driver, and one MPM cell (explicit) whose nodes
//! all move with a uniform isochoric velocity gradient.

use crate::common::{assert_within, run_text, Table};
use mpm::dim::Mat3;
use mpm::material::driver::{run_from, run_mixed, StressControl};
use mpm::material::modified_cam_clay::{ModifiedCamClay, Preconsolidation};
use mpm::material::undrained::{Undrained, WATER_BULK_MODULUS};
use mpm::material::Material;
use mpm::run::summary::Status;

const P0: f64 = 2.0e5;
const M: f64 = 1.2;

fn model(ocr: f64) -> ModifiedCamClay {
    ModifiedCamClay {
        density: 1800.0,
        lambda: 0.2,
        kappa: 0.04,
        critical_state_ratio: M,
        poisson_ratio: 0.3,
        initial_void_ratio: 1.0,
        preconsolidation: Preconsolidation::Ratio(ocr),
    }
}

/// The isotropic start −p′0 I and its history (p_c0 = OCR p′0).
fn start(m: &ModifiedCamClay) -> (Mat3, Vec<f64>) {
    let sigma = Mat3::identity() * -P0;
    let mut h = vec![0.0; m.n_history()];
    m.initial_history(&sigma, &mut h);
    (sigma, h)
}

/// p′ and q = σ_r − σ_a of a triaxial stress.
fn p_q(s: &Mat3) -> (f64, f64) {
    (-s.trace() / 3.0, s[(0, 0)] - s[(2, 2)])
}

/// The closed-form undrained (p′_f, q_f, u_f).
fn undrained_target(ocr: f64) -> (f64, f64, f64) {
    let big_lambda = (0.2 - 0.04) / 0.2;
    let p = P0 * (ocr / 2.0f64).powf(big_lambda);
    (p, M * p, P0 + M * p / 3.0 - p)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The total radial stresses held at −p′0 (ΔF_xx = ΔF_yy solved for).
fn cell_pressure() -> [StressControl; 1] {
    [StressControl {
        stress: (0, 0),
        target: -P0,
        free: (0, 0),
        mirror: Some((1, 1)),
    }]
}

/// Axial strain of the undrained tests: ln a = −0.5 (a = 0.61).
const UNDRAINED_LOG_STRAIN: f64 = 0.5;

#[test]
fn cam_clay_undrained_triaxial_reaches_the_critical_state() {
    let steps = 500;
    let path: Vec<Mat3> = (0..=steps)
        .map(|k| {
            let a = (-UNDRAINED_LOG_STRAIN * k as f64 / steps as f64).exp();
            Mat3::from_diagonal(&[a.powf(-0.5), a.powf(-0.5), a].into())
        })
        .collect();
    for (ocr, issue) in [
        (1.0, (114.87, 137.84, 131.08)),
        (2.0, (200.0, 240.0, 80.0)),
        (4.0, (348.22, 417.86, -8.93)),
    ] {
        let m = model(ocr);
        let (sigma, h) = start(&m);
        let r = run_from(&m, &path, 0.0, sigma, h);
        let (p, q) = p_q(r.stress.last().unwrap());
        let u = P0 + q / 3.0 - p;
        let (pt, qt, ut) = undrained_target(ocr);
        eprintln!(
            "undrained OCR {ocr}: p′_f = {:.2} kPa (target {:.2}, issue {}), q_f = {:.2} (target {:.2}, issue {}), u_f = {:.2} (target {:.2}, issue {}) at ln a = −{UNDRAINED_LOG_STRAIN}",
            p / 1e3, pt / 1e3, issue.0, q / 1e3, qt / 1e3, issue.1, u / 1e3, ut / 1e3, issue.2
        );
        assert!(
            rel(pt / 1e3, issue.0) < 5e-5 && rel(qt / 1e3, issue.1) < 5e-5,
            "closed form = the issue's numbers"
        );
        // The issue's bound, 0.5 %.
        assert_within(&format!("OCR {ocr}: p′_f"), rel(p, pt), 5e-3);
        assert_within(&format!("OCR {ocr}: q_f"), rel(q, qt), 5e-3);
        assert_within(
            &format!("OCR {ocr}: u_f (of p′0)"),
            (u - ut).abs() / P0,
            5e-3,
        );
    }
}

/// The same undrained test by the pore water (`material::undrained`, issue 52
/// item 2): constant total cell pressure, the volume left free, K_w/n =
/// 2.2e9/0.4 (about 500 times the skeleton's p/κ̃ = 1e7); the skeleton's
/// effective path reaches the isochoric closed form, with the excess pore
/// pressure in the history (measured 114.90/200.03/348.21 kPa, 137.88/240.04/
/// 417.86, 131.06/79.98/−8.93; |J − 1| ≤ 2.4e-5).
#[test]
fn cam_clay_with_stiff_pore_water_reaches_the_undrained_critical_state() {
    let steps = 500;
    let ratio = (-UNDRAINED_LOG_STRAIN / steps as f64).exp();
    let increments = vec![Mat3::from_diagonal(&[1.0, 1.0, ratio].into()); steps];
    for ocr in [1.0, 2.0, 4.0] {
        let m = Undrained {
            skeleton: Box::new(model(ocr)),
            fluid_bulk_modulus: WATER_BULK_MODULUS / 0.4,
            mobility: 0.0,
        };
        let (sigma, mut h) = start(&model(ocr));
        h.push(0.0); // p_ex
                     // Newton stops at round-off amplified by K_f (4e-12), above 1e-12.
        let r = run_mixed(&m, &increments, &cell_pressure(), 0.0, sigma, h, 1e-10)
            .expect("the undrained path converges");
        let u = m.excess(r.response.history.last().unwrap());
        let effective = r.response.stress.last().unwrap() + Mat3::identity() * u;
        let (p, q) = p_q(&effective);
        let (pt, qt, ut) = undrained_target(ocr);
        let j = r.response.f.last().unwrap().determinant();
        eprintln!(
            "pore water, OCR {ocr}: p′_f = {:.2} kPa (target {:.2}), q_f = {:.2} (target {:.2}), u_f = {:.2} (target {:.2}); J − 1 = {:.1e}",
            p / 1e3, pt / 1e3, q / 1e3, qt / 1e3, u / 1e3, ut / 1e3, j - 1.0
        );
        assert_within(&format!("pore water OCR {ocr}: p′_f"), rel(p, pt), 5e-3);
        assert_within(&format!("pore water OCR {ocr}: q_f"), rel(q, qt), 5e-3);
        assert_within(
            &format!("pore water OCR {ocr}: u_f (of p′0)"),
            (u - ut).abs() / P0,
            5e-3,
        );
    }
}

#[test]
fn cam_clay_drained_triaxial_reaches_the_critical_state() {
    let steps = 1000;
    let axial = 1.2_f64; // ln of the axial stretch reached: −1.2
    let ratio = (-axial / steps as f64).exp();
    let increments = vec![Mat3::from_diagonal(&[1.0, 1.0, ratio].into()); steps];
    let controls = cell_pressure();
    let (pt, qt) = (P0 / (1.0 - M / 3.0), M * P0 / (1.0 - M / 3.0));
    for ocr in [1.0, 2.0, 4.0] {
        let m = model(ocr);
        let (sigma, h) = start(&m);
        let r = run_mixed(&m, &increments, &controls, 0.0, sigma, h, 1e-12)
            .expect("drained path converges");
        let (p, q) = p_q(r.response.stress.last().unwrap());
        let iterations = r.residuals.iter().map(Vec::len).max().unwrap();
        eprintln!(
            "drained OCR {ocr}: p′_f = {:.2} kPa (target {:.2}), q_f = {:.2} (target {:.2}) at ln a = −{axial}; at most {iterations} Newton iterates per increment",
            p / 1e3, pt / 1e3, q / 1e3, qt / 1e3
        );
        assert_within(&format!("drained OCR {ocr}: p′_f"), rel(p, pt), 5e-3);
        assert_within(&format!("drained OCR {ocr}: q_f"), rel(q, qt), 5e-3);
    }
}

/// One MPM cell (3D, explicit): every node is a corner, and the velocity faces
/// prescribe v_I = L x_I with L = ε̇ diag(½, ½, −1), so each particle sees the
/// uniform isochoric gradient L (tr L = 0) for 1 s: ln a = −0.5, the strain of
/// the driver test. One particle starts from the isotropic stress −p′0 I (a
/// particle file's stress columns) and gets p_c0 = OCR p′0 from
/// `Material::initial_history` at set-up. The explicit update
/// F_{n+1} = (I + LΔt) F_n is isochoric only to det(I + LΔt) = 1 − ¾(ε̇Δt)² + …,
/// so the volume drifts by O(ε̇²Δt) over the run: J − 1 = −9.2e-4 at cfl 0.5
/// (p′_f 1.1 % high, beyond the bound), −9.2e-5 … −5.3e-5 at cfl 0.05 (used).
fn one_cell_scene(csv: &std::path::Path, ocr: f64) -> String {
    let rate = UNDRAINED_LOG_STRAIN;
    let face = |face: &str, axis: &str, v: [f64; 3]| {
        format!("[[boundary]]\nface = \"{face}\"\ncondition = \"velocity\"\nvelocity = {v:?}\ncomponents = [\"{axis}\"]\n\n")
    };
    let faces: String = [
        face("xmin", "x", [0.0; 3]),
        face("xmax", "x", [0.5 * rate, 0.0, 0.0]),
        face("ymin", "y", [0.0; 3]),
        face("ymax", "y", [0.0, 0.5 * rate, 0.0]),
        face("zmin", "z", [0.0; 3]),
        face("zmax", "z", [0.0, 0.0, -rate]),
    ]
    .concat();
    format!(
        "dimension = 3\ngravity = [0.0, 0.0, 0.0]\n\n[grid]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\ncells = [1, 1, 1]\n\n\
         [[material]]\nname = \"clay\"\nmodel = \"modified_cam_clay\"\ndensity = 1800.0\nlambda = 0.2\nkappa = 0.04\n\
         critical_state_ratio = {M}\npoisson_ratio = 0.3\ninitial_void_ratio = 1.0\nocr = {ocr:?}\n\n\
         [[body]]\nname = \"sample\"\nmaterial = \"clay\"\nshape = \"particles\"\nfile = {csv:?}\n\n{faces}\
         [solver]\nkind = \"explicit\"\nend_time = 1.0\ncfl = 0.05\n"
    )
}

#[test]
fn cam_clay_undrained_in_one_mpm_cell() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sample.csv");
    std::fs::write(
        &csv,
        format!(
            "x,y,z,volume,sxx,syy,szz,sxy,syz,sxz\n0.3,0.3,0.5,0.001,{s},{s},{s},0,0,0\n",
            s = -P0
        ),
    )
    .unwrap();
    for ocr in [1.0, 2.0, 4.0] {
        let (result, out) = run_text(&one_cell_scene(&csv, ocr), &[]);
        let summary = result.unwrap_or_else(|e| panic!("OCR {ocr}: {e}"));
        assert_eq!(summary.status, Status::Completed);
        let p = Table::read(&out.path().join("particles_final.csv")).unwrap();
        let c = |k: &str| p.col(k)[0];
        let sigma = Mat3::from_diagonal(&[c("sxx"), c("syy"), c("szz")].into());
        let j = c("volume") / c("volume0");
        let (pf, q) = p_q(&sigma);
        let u = P0 + q / 3.0 - pf;
        let (pt, qt, ut) = undrained_target(ocr);
        eprintln!(
            "one MPM cell, OCR {ocr}: p′_f = {:.2} kPa (target {:.2}), q_f = {:.2} (target {:.2}), u_f = {:.2} (target {:.2}); J − 1 = {:.1e}, |σ_xy| = {:.1e}",
            pf / 1e3, pt / 1e3, q / 1e3, qt / 1e3, u / 1e3, ut / 1e3, j - 1.0, c("sxy").abs()
        );
        // The issue's bound, 0.5 % (measured 1.1e-3, 8.4e-4, 6.4e-4 on p′_f;
        // 9.9e-4, 7.5e-4, 5.7e-4 on q_f; 4.1e-4, 5.4e-4, 7.1e-4 on u_f/p′0).
        assert_within(&format!("one cell OCR {ocr}: p′_f"), rel(pf, pt), 5e-3);
        assert_within(&format!("one cell OCR {ocr}: q_f"), rel(q, qt), 5e-3);
        assert_within(
            &format!("one cell OCR {ocr}: u_f (of p′0)"),
            (u - ut).abs() / P0,
            5e-3,
        );
    }
}
