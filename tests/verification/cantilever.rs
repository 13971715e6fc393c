//! Large-deflection cantilever, implicit quasi-static (reference README item 3;
//! problems/cantilever.toml; papers/cantilever_elastica/). L = 10 m, depth d = 1 m,
//! E = 12 MPa, ν = 0.2, plane strain, Hencky, clamped at x = 0, vertical dead
//! load P = 100 kN at the free end in 50 load steps.
//!
//! Reference: the elastica EI θ'' = −P cos θ, θ(0) = 0, θ'(L) = 0, solved by
//! shooting on θ'(0) (RK4, bisection; `mpm::analyses::reference::elastica`, also the reference
//! of `mpm bench` for this scene) and checked here against Mattiasson (1981).
//! Bending stiffness: the 2D model is plane strain (ε_zz = 0) with σ_yy ≈ 0 in the
//! beam, so a fibre's modulus is E/(1 − ν²) and EI = E d³/(12 (1 − ν²)): k = 9.6 at
//! full load, not 10. The small-load test below tells the two apart (4 %).
//!
//! A 2D continuum is not an Euler-Bernoulli beam: shear (P/(κGA) = 0.024) and
//! extension (P/EA = 0.008) add 1.4 % to the tip deflection at full load (Reissner's
//! beam, same shooting solver), and the large-deflection continuum a further ≈ 1 %
//! (fibre strains reach 20 % at the root). Both scale as (d/L)². An independent
//! finite-element solution of the same continuum (examples/cantilever_fe, Q9, total
//! Lagrangian, the project's Hencky law) measures the total: +2.38 % in v beyond
//! the classical elastica; the MPM is asserted against it below.
//!
//! The loaded particles (the last particle column, centred at a = L − h/(2 ppc))
//! move as the tip of a cantilever of length a (the rest is unloaded), so the
//! reference is the elastica of length a at k_a = P a²/EI.

// The finite-element reference (examples/cantilever_fe): the same continuum on Q9
// elements, total Lagrangian, the project's Hencky law.
#[allow(dead_code)]
#[path = "../../examples/cantilever_fe/fe.rs"]
mod fe;
use crate::common::{assert_within, run_problem, shape_functions, Table};
use mpm::analyses::reference::elastica::elastica;
use mpm::scene::ShapeFunction;
use strum::IntoEnumIterator;

const L: f64 = 10.0;
const DEPTH: f64 = 1.0;
const E: f64 = 12.0e6;
const NU: f64 = 0.2;
const P_END: f64 = 100.0e3;

/// Plane-strain bending stiffness E/(1 − ν²) · d³/12 (unit thickness).
fn ei() -> f64 {
    ei_of(DEPTH)
}
fn ei_of(depth: f64) -> f64 {
    E / (1.0 - NU * NU) * depth.powi(3) / 12.0
}

/// Plane-strain axial stiffness E/(1 − ν²) · d.
fn ea() -> f64 {
    ea_of(DEPTH)
}
fn ea_of(depth: f64) -> f64 {
    E / (1.0 - NU * NU) * depth
}

/// Shear stiffness κ G A with κ = 5/6 (rectangle), G = E / (2 (1 + ν)).
fn kga() -> f64 {
    kga_of(DEPTH)
}
fn kga_of(depth: f64) -> f64 {
    5.0 / 6.0 * E / (2.0 * (1.0 + NU)) * depth
}

/// Mattiasson (1981), k: (v/L, u/L).
const MATTIASSON: [(f64, f64, f64); 4] = [
    (1.0, 0.30172, 0.05643),
    (2.0, 0.49346, 0.16064),
    (5.0, 0.71379, 0.38763),
    (10.0, 0.81061, 0.55500),
];

#[test]
fn elastica_solver_matches_mattiasson() {
    for (k, v_pub, u_pub) in MATTIASSON {
        let (v, u, t) = elastica(k, 0.0, 0.0);
        println!(
            "k = {k:>4}: v/L {v:.5} (Mattiasson {v_pub:.5}), u/L {u:.5} (Mattiasson {u_pub:.5}), tip angle {t:.4}"
        );
        // The table has five decimals: it is exact to 5e-6.
        assert_within(&format!("k = {k}: v/L − Mattiasson"), v - v_pub, 1e-5);
        assert_within(&format!("k = {k}: u/L − Mattiasson"), u - u_pub, 1e-5);
    }
    // Small loads: linear Euler-Bernoulli, and Timoshenko with the shear term.
    let k = 1e-3;
    let (v, _, _) = elastica(k, 0.0, 0.0);
    assert_within(
        "small k: v/L against k/3, relative",
        v / (k / 3.0) - 1.0,
        4e-7, // measured −1.1e-7: the elastica's departure from the linear beam
    );
    let a_s = 2e-4;
    let (v, _, _) = elastica(k, 0.0, a_s);
    assert_within(
        "small k with shear: v/L against k/3 + a_s, relative",
        v / (k / 3.0 + a_s) - 1.0,
        4e-7, // measured −1.7e-7
    );
    // The stiffness choice at full load (k = 10 with E, 9.6 with E/(1 − ν²)), and the
    // size of extension and shear (Reissner's beam) at k = 9.6.
    let k_ps = P_END * L * L / ei();
    let (v10, u10, _) = elastica(P_END * L * L / (E * DEPTH.powi(3) / 12.0), 0.0, 0.0);
    let (v96, u96, _) = elastica(k_ps, 0.0, 0.0);
    let (vr, ur, _) = elastica(k_ps, P_END / ea(), P_END / kga());
    println!("full load: k = 10 (E): v/L {v10:.5}, u/L {u10:.5}; k = {k_ps:.2} (E/(1-nu^2)): v/L {v96:.5}, u/L {u96:.5}");
    println!(
        "  with extension and shear: v/L {vr:.5} ({:+.2} %), u/L {ur:.5} ({:+.2} %)",
        100.0 * (vr / v96 - 1.0),
        100.0 * (ur / u96 - 1.0)
    );
    assert!((k_ps - 9.6).abs() < 1e-12);
}

struct Run {
    particles: Table,
    wall: f64,
    /// Reference x of the loaded column's lower bound (X0 ≥ this carries the load).
    x_load: f64,
    /// Arc length of the loaded point: a = L − h/(2 ppc).
    a: f64,
}

/// Run problems/cantilever.toml with `cells_per_depth` cells through the depth,
/// `ppc` particles per cell direction, end load `force` in `steps` load steps.
fn cantilever(
    shape: &str,
    cells_per_depth: usize,
    ppc: usize,
    force: f64,
    steps: usize,
) -> Result<Run, String> {
    beam(DEPTH, shape, cells_per_depth, ppc, force, steps)
}

/// The same scene with beam depth `depth` (L = 10 m; the grid keeps its extent
/// and `cells_per_depth` cells through the depth).
fn beam(
    depth: f64,
    shape: &str,
    cells_per_depth: usize,
    ppc: usize,
    force: f64,
    steps: usize,
) -> Result<Run, String> {
    beam_with(depth, shape, cells_per_depth, ppc, force, steps, &[])
}

/// `beam` with extra scene overrides.
fn beam_with(
    depth: f64,
    shape: &str,
    cells_per_depth: usize,
    ppc: usize,
    force: f64,
    steps: usize,
    extra: &[&str],
) -> Result<Run, String> {
    let h = depth / cells_per_depth as f64;
    let x_load = L - h / ppc as f64;
    let per_metre = (cells_per_depth as f64 / depth).round() as usize;
    let args = [
        format!("grid.shape_function={shape}"),
        format!("grid.cells=[{},{}]", 11 * per_metre, 12 * per_metre),
        format!("body.0.max=[{L:?},{depth:?}]"),
        format!("body.0.particles_per_cell={ppc}"),
        format!("load.0.region_min=[{x_load:?},0.0]"),
        format!("load.0.region_max=[{L:?},{depth:?}]"),
        format!("load.0.force=[0.0,{:?}]", -force),
        format!("solver.load_steps={steps}"),
        "output.frames=0".into(),
    ];
    let mut args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    args.extend(extra);
    let (result, dir) = run_problem("cantilever.toml", &args);
    let summary =
        result.map_err(|e| format!("{shape} d = {depth} {cells_per_depth}x{ppc}: {e}"))?;
    Ok(Run {
        particles: Table::read(&dir.path().join("particles_final.csv")).unwrap(),
        wall: summary.wall_seconds,
        x_load,
        a: L - 0.5 * h / ppc as f64,
    })
}

impl Run {
    /// Mean displacement (down, towards the clamp) of the particles with X0 in [lo, hi].
    fn mean_displacement(&self, lo: f64, hi: f64) -> (f64, f64) {
        let p = &self.particles;
        let (x0, y0, x, y) = (p.col("X0"), p.col("Y0"), p.col("x"), p.col("y"));
        let sel: Vec<usize> = (0..x0.len())
            .filter(|&i| x0[i] >= lo && x0[i] <= hi)
            .collect();
        let n = sel.len() as f64;
        (
            -sel.iter().map(|&i| y[i] - y0[i]).sum::<f64>() / n,
            -sel.iter().map(|&i| x[i] - x0[i]).sum::<f64>() / n,
        )
    }

    fn tip(&self) -> (f64, f64) {
        self.mean_displacement(self.x_load, L)
    }
}

/// Small load (P = 100 N, tip deflection 3 mm, one step): the clamp holds and the
/// deflection along the beam is the linear Timoshenko beam's with the plane-strain
/// modulus, v(x) = P/EI (a x²/2 − x³/6) + P x/(κGA). With E instead of E/(1 − ν²) the
/// bending deflection would be 4.2 % larger (1/(1 − ν²)), so this also settles the
/// stiffness choice.
/// Runs with the solver as it is (no cell crossing at this load).
#[test]
fn small_load_clamp_and_plane_strain_stiffness() {
    let force = 100.0;
    // Measured (4 cells/depth, 3 ppc): B-spline +0.57 % against Timoshenko, uGIMP and
    // CPDI (identical on the undeformed, grid-aligned lattice) −2.09 %.
    for family in ShapeFunction::iter() {
        let tol = match family {
            ShapeFunction::Bspline2 => 0.01,
            ShapeFunction::Ugimp | ShapeFunction::Cpdi => 0.045,
            ShapeFunction::Linear | ShapeFunction::Cpgimp => 0.045,
            ShapeFunction::Bspline3 | ShapeFunction::Cpbspline2 => 0.01,
        };
        let shape = family.name();
        let run = cantilever(shape, 4, 3, force, 1).unwrap_or_else(|e| panic!("{e}"));
        let a = run.a;
        let timoshenko =
            |x: f64| force / ei() * (a * x * x / 2.0 - x.powi(3) / 6.0) + force * x / kga();
        let (v_tip, _) = run.tip();
        let v_e = force * a.powi(3) / (3.0 * E * DEPTH.powi(3) / 12.0);
        let err = v_tip / timoshenko(a) - 1.0;
        println!(
            "{shape:>8}: tip {v_tip:.5e} m, Timoshenko (E/(1-nu^2)) {:.5e} ({:+.2} %), \
             Euler-Bernoulli with E {v_e:.5e} ({:+.2} %), {:.2} s",
            timoshenko(a),
            100.0 * err,
            100.0 * (v_tip / v_e - 1.0),
            run.wall
        );
        assert_within(&format!("{shape}: tip error"), err, tol);
        // The clamp: the first particle column does not move, and the deflection
        // along the beam follows the clamped beam (each particle column against the
        // beam at its X0).
        let h = DEPTH / 4.0;
        let (v_root, u_root) = run.mean_displacement(0.0, h / 3.0);
        assert!(
            v_root.abs() < 1e-3 * v_tip && u_root.abs() < 1e-3 * v_tip,
            "{shape}: root column moved ({v_root:.3e}, {u_root:.3e})"
        );
        let mut worst: f64 = 0.0;
        for c in 0..30 {
            let (lo, hi) = (c as f64 * h / 3.0, (c + 1) as f64 * h / 3.0);
            let (v, _) = run.mean_displacement(lo, hi);
            worst = worst.max((v - timoshenko(0.5 * (lo + hi))).abs());
        }
        println!("          largest deviation from the beam over 0 < x < 2.5 m: {worst:.2e} m");
        assert!(
            worst < 0.04 * timoshenko(2.5),
            "{shape}: root region off by {worst}"
        );
    }
}

/// Volumetric locking in bending, and F-bar. With ν = 0.499 plane-strain bending
/// is nearly isochoric (ε_yy ≈ −ε_xx), which bilinear interpolation with 2 × 2
/// particles per cell cannot follow: the small-load tip deflection (Timoshenko,
/// as in `small_load_clamp_and_plane_strain_stiffness`, with ν = 0.499) comes out
/// far too small. Measured with 2, 4, 8, 16 cells through the depth: −95, −86,
/// −61, −30 % without F-bar (slow convergence), +15, +1.8, −0.8, −1.4 % with it
/// (down to the 1 % at which the 2D continuum and its clamp differ from the beam;
/// with ν = 0.2 the same runs give −2.8, −0.9, −0.3 % without F-bar and +10.6,
/// +2.3, +0.5 % with it). Checked on 2 and 4 cells: locked below −80 %, F-bar
/// within 20 % and 3 %, its error falling at a rate above 2. The residual
/// tolerance is 1e-8: with K/G ≈ 250 the round-off floor of this 100 N load
/// reaches 1e-9 on finer grids.
#[test]
fn nearly_incompressible_beam_locks_without_fbar() {
    let nu = 0.499;
    let force = 100.0;
    let tip_error = |cells: usize, fbar: &str| {
        let run = beam_with(
            DEPTH,
            "linear",
            cells,
            2,
            force,
            1,
            &[
                "material.0.poisson_ratio=0.499",
                fbar,
                "solver.residual_tolerance=1e-8",
            ],
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let a = run.a;
        let ei = E / (1.0 - nu * nu) * DEPTH.powi(3) / 12.0;
        let kga = 5.0 / 6.0 * E / (2.0 * (1.0 + nu)) * DEPTH;
        let timoshenko = force * a.powi(3) / (3.0 * ei) + force * a / kga;
        run.tip().0 / timoshenko - 1.0
    };
    let locked = [2, 4].map(|c| tip_error(c, "solver.fbar=false"));
    let fbar = [2, 4].map(|c| tip_error(c, "solver.fbar=true"));
    let rate = (fbar[0].abs() / fbar[1].abs()).log2();
    println!(
        "ν = 0.499, 2 and 4 cells per depth: tip error without F-bar {:+.2} %, {:+.2} %; \
         with F-bar {:+.2} %, {:+.2} % (rate {rate:.2})",
        100.0 * locked[0],
        100.0 * locked[1],
        100.0 * fbar[0],
        100.0 * fbar[1]
    );
    assert!(locked.iter().all(|e| *e < -0.8), "locks without F-bar");
    assert!(
        fbar[0].abs() < 0.2 && fbar[1].abs() < 0.03,
        "F-bar: {fbar:?}"
    );
    assert!(rate > 2.0, "F-bar error falls at rate {rate:.2}");
}

/// Full load (k = 9.6), 50 load steps: the tip of the loaded column against the
/// elastica. Required (issue): within 2 %. Against the elastica as the reference
/// item tabulates it (Mattiasson 1981, k = P L²/(E I) with E = 12 MPa, so k = 10 at
/// the tip) it is within the reference's 2 % in v and u (measured v +1.94 /
/// +1.75 / +1.75 %, u +0.19 / −0.05 / −0.17 %), asserted within 4 % (v) and
/// 0.5 % (u), about twice what is measured: that agreement is partly an offset
/// of two effects (plane strain stiffens the bending by 1/(1 − ν²), shear and
/// extension soften it), so a change of the discretisation can move v across
/// the 2 % with nothing wrong; the FE continuum below holds the line. The 2D
/// continuum with L/d = 10 is not the inextensible, shear-rigid classical
/// elastica: it is asserted within 2 % of Reissner's beam (the elastica with
/// extension and shear, the beam model of a 2D continuum; measured v +1.08 %,
/// u +1.46 % at most) and within 5 % of the classical elastica (measured
/// +2.50 % at most). The slender beam below shows the classical 2 % where the
/// classical elastica applies.
///
/// Measured (4 cells/depth, 3 ppc, min_node_support 1e-2): v +2.50 % (B-spline),
/// +2.31 % (uGIMP), +2.31 % (CPDI) against the classical elastica, +1.08 / +0.89 /
/// +0.89 % against Reissner's beam; u +1.82 / +1.58 / +1.47 % (classical).
/// The gap to the classical elastica does not shrink with h (8 cells/depth: +2.4 %)
/// and scales as (d/L)² (next test): it is the continuum, not the discretisation.
///
/// The same continuum by finite elements (examples/cantilever_fe, 40 × 4 Q9, load
/// on the same end strip; `fe_reference_is_mesh_converged`) settles it: the FE tip
/// is +2.38 % / +1.46 % (v / u) beyond the classical elastica, and each MPM run is
/// asserted within 0.5 % (v) and 0.75 % (u) of it. Measured MPM − FE: v +0.12 /
/// −0.06 / −0.06 %, u +0.37 / +0.13 / +0.02 % (B-spline / uGIMP / CPDI).
#[test]
fn full_load_tip_matches_the_elastica() {
    let mut failures = Vec::new();
    let (v_fe, u_fe) = fe_tip(40, 4, DEPTH / 12.0);
    // Measured with linear hats: v +0.66 %, u +5.49 % against the FE continuum
    // (the cell-crossing error of standard MPM).
    let hats = "standard MPM misses the FE continuum's u by 5.5 %";
    for shape in shape_functions(&[(ShapeFunction::Linear, hats)])
        .iter()
        .map(|s| s.name())
    {
        let run = match cantilever(shape, 4, 3, P_END, 50) {
            Ok(r) => r,
            Err(e) => {
                println!("{e}");
                failures.push(e);
                continue;
            }
        };
        let a = run.a;
        let k = P_END * a * a / ei();
        let (v_c, u_c, _) = elastica(k, 0.0, 0.0);
        let (v_r, u_r, _) = elastica(k, P_END / ea(), P_END / kga());
        let (v, u) = run.tip();
        let (ev_c, eu_c) = (v / (v_c * a) - 1.0, u / (u_c * a) - 1.0);
        let (ev_r, eu_r) = (v / (v_r * a) - 1.0, u / (u_r * a) - 1.0);
        println!(
            "{shape:>8}: v {v:.4} m, u {u:.4} m; elastica v {:.4} ({:+.2} %), u {:.4} ({:+.2} %); \
             with extension and shear v {:.4} ({:+.2} %), u {:.4} ({:+.2} %); {:.2} s",
            v_c * a,
            100.0 * ev_c,
            u_c * a,
            100.0 * eu_c,
            v_r * a,
            100.0 * ev_r,
            u_r * a,
            100.0 * eu_r,
            run.wall
        );
        if ev_r.abs() > 0.02 || eu_r.abs() > 0.02 || ev_c.abs() > 0.05 {
            failures.push(format!(
                "{shape}: v {:+.2} % / u {:+.2} % (Reissner; tolerance 2 %), v {:+.2} % (elastica; 5 %)",
                100.0 * ev_r,
                100.0 * eu_r,
                100.0 * ev_c
            ));
        }
        // The reference item's elastica as tabulated (Mattiasson 1981): k = P a² / (E I)
        // with E = 12 MPa as given (k = 10 at the tip), i.e. without the plane-strain
        // factor 1/(1 − ν²) that stiffens the 2D continuum by 4 %.
        let k_e = P_END * a * a / (E * DEPTH.powi(3) / 12.0);
        let (v_e, u_e, _) = elastica(k_e, 0.0, 0.0);
        let (ev_e, eu_e) = (v / (v_e * a) - 1.0, u / (u_e * a) - 1.0);
        println!(
            "          against the tabulated elastica with E I (k = {k_e:.3}): v {:+.2} %, u {:+.2} %",
            100.0 * ev_e,
            100.0 * eu_e
        );
        if ev_e.abs() > 0.04 || eu_e.abs() > 0.005 {
            failures.push(format!(
                "{shape}: v {:+.2} %, u {:+.2} % against the tabulated elastica (k with E I; \
                 tolerances 4 %, 0.5 %)",
                100.0 * ev_e,
                100.0 * eu_e
            ));
        }
        let (ev_fe, eu_fe) = (v / v_fe - 1.0, u / u_fe - 1.0);
        println!(
            "          against the FE continuum (v {v_fe:.4} m, u {u_fe:.4} m): v {:+.2} %, u {:+.2} %",
            100.0 * ev_fe,
            100.0 * eu_fe
        );
        if ev_fe.abs() > 0.005 || eu_fe.abs() > 0.0075 {
            failures.push(format!(
                "{shape}: v {:+.2} %, u {:+.2} % against the FE reference (tolerances 0.5 %, 0.75 %)",
                100.0 * ev_fe,
                100.0 * eu_fe
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A slender beam, L/d = 20 (d = 0.5 m) at the same k = 9.6 (P = 12.5 kN): the
/// continuum effects (extension, shear, finite fibre strains) are four times
/// smaller, and the tip is within 2 % of the classical elastica (measured: CPDI
/// 2 ppc, 25 load steps: v +0.71 %, u +0.84 %, and +0.36 % / +0.75 % against
/// Reissner's beam; 50 load steps give the same v to 1e-5 m).
#[test]
fn slender_beam_tip_matches_the_classical_elastica() {
    let depth: f64 = 0.5;
    let force = P_END * depth.powi(3);
    let run = beam(depth, "cpdi", 4, 2, force, 25).unwrap_or_else(|e| panic!("{e}"));
    let a = run.a;
    let k = force * a * a / ei_of(depth);
    let (v_c, u_c, _) = elastica(k, 0.0, 0.0);
    let (v_r, u_r, _) = elastica(k, force / ea_of(depth), force / kga_of(depth));
    let (v, u) = run.tip();
    let (ev, eu) = (v / (v_c * a) - 1.0, u / (u_c * a) - 1.0);
    println!(
        "L/d = 20, k = {k:.3}: v {v:.4} m, u {u:.4} m; elastica v {:.4} ({:+.2} %), u {:.4} ({:+.2} %); \
         Reissner v {:+.2} %, u {:+.2} %; {:.2} s",
        v_c * a,
        100.0 * ev,
        u_c * a,
        100.0 * eu,
        100.0 * (v / (v_r * a) - 1.0),
        100.0 * (u / (u_r * a) - 1.0),
        run.wall
    );
    assert!(
        ev.abs() < 0.02 && eu.abs() < 0.02,
        "v {:+.2} %, u {:+.2} % against the classical elastica",
        100.0 * ev,
        100.0 * eu
    );
}

/// The beam of problems/cantilever.toml for the finite-element reference.
fn fe_beam() -> fe::Beam {
    fe::Beam {
        length: L,
        depth: DEPTH,
        youngs_modulus: E,
        poisson_ratio: NU,
    }
}

/// Full-load (v, u) of the finite-element reference on nx × ny Q9 elements, the
/// force spread over the end strip the MPM's loaded particle column fills
/// (width h/ppc), averaged with the load's weights (the MPM averages the loaded
/// particles).
fn fe_tip(nx: usize, ny: usize, strip: f64) -> (f64, f64) {
    let model = fe::Cantilever::new(&fe_beam(), nx, ny, fe::TipLoad::Strip { width: strip });
    let last = *model
        .solve(P_END, 50)
        .unwrap_or_else(|e| panic!("FE {nx}x{ny}: {e}"))
        .last()
        .unwrap();
    (last.v, last.u)
}

/// The FE tangent is the derivative of its internal force: central differences
/// at a bent, stretched state (large rotation: the tip turned by ~1 rad).
#[test]
fn fe_tangent_matches_finite_differences() {
    let model = fe::Cantilever::new(&fe_beam(), 3, 2, fe::TipLoad::EndSection);
    let n = model.n_free();
    // Free dofs: node-major, (u_x, u_y); nodes column by column, X = 5 (i + 1)/3.
    let rows = 5;
    let x: Vec<f64> = (0..n)
        .map(|d| {
            let node = d / 2 + rows;
            let (xi, yi) = (
                (node / rows) as f64 * 10.0 / 6.0,
                (node % rows) as f64 * 0.25,
            );
            let theta = 0.1 * xi;
            let wobble = 1e-2 * ((d * 7 % 11) as f64 - 5.0);
            // Rigid rotation by θ(X) about (X, 0), plus a small irregular field.
            let (s, c) = theta.sin_cos();
            let disp = [-yi * s, yi * (c - 1.0)];
            disp[d % 2]
                + if d % 2 == 0 {
                    -0.3 * xi * xi / 10.0
                } else {
                    -0.5 * xi * xi / 10.0
                }
                + wobble
        })
        .collect();
    let (_, k) = model.internal(&x, true);
    let mut dense = vec![vec![0.0; n]; n];
    for &(r, c, v) in &k {
        dense[r][c] += v;
    }
    let scale = dense.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let fd_error = |eps: f64| {
        let mut worst: f64 = 0.0;
        for c in 0..n {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[c] += eps;
            xm[c] -= eps;
            let (fp, _) = model.internal(&xp, false);
            let (fm, _) = model.internal(&xm, false);
            for r in 0..n {
                let fd = (fp[r] - fm[r]) / (2.0 * eps);
                worst = worst.max((fd - dense[r][c]).abs() / scale);
            }
        }
        worst
    };
    // Central differences: the error falls as ε² for the exact derivative (it
    // would stall at the tangent's own error otherwise).
    let (e5, e6) = (fd_error(1e-5), fd_error(1e-6));
    // Symmetry (hyperelastic: P = ∂W/∂F).
    let asym = (0..n)
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| (dense[r][c] - dense[c][r]).abs() / scale)
        .fold(0.0f64, f64::max);
    println!(
        "FE tangent vs central differences (of max |K|): {e5:.2e} (ε = 1e-5 m), {e6:.2e} \
         (ε = 1e-6 m); asymmetry {asym:.2e}"
    );
    assert!(
        e6 < 1e-5 && e5 > 50.0 * e6,
        "tangent off: {e5:.2e}, {e6:.2e}"
    );
    assert!(asym < 1e-10, "tangent asymmetric by {asym:.2e}");
}

/// The FE reference is mesh-converged: 20 × 2 and 40 × 4 Q9 elements agree to
/// 0.1 % at full load (measured −0.04 % v, −0.06 % u; the converged value,
/// 160 × 16, differs from 40 × 4 by 0.01 %: papers/cantilever_elastica/), and its
/// gap to the classical elastica is the (d/L)² continuum effect the MPM shows.
#[test]
fn fe_reference_is_mesh_converged() {
    let strip = DEPTH / 12.0;
    let a = L - 0.5 * strip;
    let (v2, u2) = fe_tip(20, 2, strip);
    let (v4, u4) = fe_tip(40, 4, strip);
    let (dv, du) = (v2 / v4 - 1.0, u2 / u4 - 1.0);
    let k = P_END * a * a / ei();
    let (v_c, u_c, _) = elastica(k, 0.0, 0.0);
    let (v_r, u_r, _) = elastica(k, P_END / ea(), P_END / kga());
    let ev_c = v4 / (v_c * a) - 1.0;
    println!(
        "FE 40x4: v {v4:.5} m, u {u4:.5} m; 20x2 differs by {:+.3} %, {:+.3} %; \
         classical elastica v {:+.2} %, u {:+.2} %; Reissner v {:+.2} %, u {:+.2} %",
        100.0 * dv,
        100.0 * du,
        100.0 * ev_c,
        100.0 * (u4 / (u_c * a) - 1.0),
        100.0 * (v4 / (v_r * a) - 1.0),
        100.0 * (u4 / (u_r * a) - 1.0)
    );
    assert!(
        dv.abs() < 1e-3 && du.abs() < 1e-3,
        "not converged: {dv:.2e}, {du:.2e}"
    );
    // Converged FE: +2.38 % beyond the classical elastica (the MPM's +2.3…2.5 %).
    assert!((0.02..0.03).contains(&ev_c), "FE vs elastica {ev_c:+.4}");
}
