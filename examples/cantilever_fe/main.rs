//! Finite-element reference for the large-deflection cantilever (problems/cantilever.toml,
//! papers/cantilever_elastica/): the same plane-strain Hencky continuum on a mesh of
//! 9-node quadrilaterals, total Lagrangian, Newton with the exact tangent (fe.rs).
//!
//!   cargo run --release --example cantilever_fe -- [NX NY] [--strip W] [--steps N]
//!       [--force P] [--depth D] [--csv]
//!
//! NX × NY elements (default 40 × 4). Load: a dead vertical force P (default 100 kN)
//! in N equal steps (default 50), as a uniform traction on the end section, or with
//! `--strip W` as a uniform body force on the end strip X ≥ L − W (the MPM scene's
//! loaded particle column: W = h/ppc, 1/12 m at 4 cells through the depth and 3 ppc).
//! Prints, at each load level, the load-weighted mean tip deflection v (down) and
//! axial displacement u (towards the clamp), the mid-line tip node's, and the
//! classical and Reissner elastica of the load's arm a (L, or L − W/2). `--csv`
//! prints only the load levels as CSV (papers/cantilever_elastica/elastica.py reads it).
//! With the environment variable FE_DEBUG set, each Newton iteration's ‖r‖ and ‖Δu‖
//! go to stderr.

#[path = "fe.rs"]
mod fe;

use fe::{Beam, Cantilever, TipLoad};
use mpm::analyses::reference::elastica::elastica;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let (mut strip, mut steps, mut force, mut depth) = (None, 50usize, 100.0e3, 1.0);
    let mut csv = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--csv" {
            csv = true;
            continue;
        }
        let mut value = |name: &str| -> f64 {
            it.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| fail(&format!("{name} needs a number")))
        };
        match a.as_str() {
            "--strip" => strip = Some(value("--strip")),
            "--steps" => steps = value("--steps") as usize,
            "--force" => force = value("--force"),
            "--depth" => depth = value("--depth"),
            s => positional.push(
                s.parse::<usize>()
                    .unwrap_or_else(|_| fail(&format!("unknown argument {s}"))),
            ),
        }
    }
    let (nx, ny) = match positional[..] {
        [] => (40, 4),
        [nx, ny] if nx > 0 && ny > 0 => (nx, ny),
        _ => fail("give both NX and NY (positive)"),
    };
    if steps == 0 {
        fail("--steps must be positive");
    }
    let beam = Beam {
        length: 10.0,
        depth,
        youngs_modulus: 12.0e6,
        poisson_ratio: 0.2,
    };
    let load = match strip {
        None => TipLoad::EndSection,
        Some(w) if w > 0.0 && w <= beam.length => TipLoad::Strip { width: w },
        Some(w) => fail(&format!("--strip {w}: need 0 < W <= L")),
    };
    let nu = beam.poisson_ratio;
    let e_ps = beam.youngs_modulus / (1.0 - nu * nu);
    let ei = e_ps * depth.powi(3) / 12.0;
    let ea = e_ps * depth;
    let kga = 5.0 / 6.0 * beam.youngs_modulus / (2.0 * (1.0 + nu)) * depth;
    let arm = load.arm(beam.length);

    let model = Cantilever::new(&beam, nx, ny, load);
    if csv {
        let levels = model.solve(force, steps).unwrap_or_else(|e| fail(&e));
        println!("force,v,u,v_mid,u_mid,iterations");
        for l in &levels {
            println!(
                "{:e},{:e},{:e},{:e},{:e},{}",
                l.force, l.v, l.u, l.v_mid, l.u_mid, l.iterations
            );
        }
        return;
    }
    println!(
        "FE cantilever: {nx} x {ny} Q9 elements, {} free dofs, load {load:?}, arm a = {arm:.6} m, \
         P = {force:.4e} N in {steps} steps",
        model.n_free()
    );
    let start = std::time::Instant::now();
    let levels = model.solve(force, steps).unwrap_or_else(|e| fail(&e));
    let wall = start.elapsed().as_secs_f64();
    println!(
        "{:>9} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} {:>3}",
        "P (kN)",
        "k_a",
        "v (m)",
        "u (m)",
        "v_mid",
        "u_mid",
        "v/a",
        "u/a",
        "dv_el %",
        "dv_re %",
        "it"
    );
    for l in &levels {
        let k = l.force * arm * arm / ei;
        let (v_c, _, _) = elastica(k, 0.0, 0.0);
        let (v_r, _, _) = elastica(k, l.force / ea, l.force / kga);
        println!(
            "{:>9.3} {:>6.3} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {:>+8.3} {:>+8.3} {:>3}",
            l.force / 1e3,
            k,
            l.v,
            l.u,
            l.v_mid,
            l.u_mid,
            l.v / arm,
            l.u / arm,
            100.0 * (l.v / (v_c * arm) - 1.0),
            100.0 * (l.v / (v_r * arm) - 1.0),
            l.iterations
        );
    }
    let last = levels.last().expect("at least one step");
    let k = last.force * arm * arm / ei;
    let (v_c, u_c, _) = elastica(k, 0.0, 0.0);
    let (v_r, u_r, _) = elastica(k, last.force / ea, last.force / kga);
    let k10 = last.force * arm * arm / (beam.youngs_modulus * depth.powi(3) / 12.0);
    let (v_10, u_10, _) = elastica(k10, 0.0, 0.0);
    println!(
        "final: v = {:.6} m, u = {:.6} m ({wall:.2} s)",
        last.v, last.u
    );
    for (name, v_ref, u_ref) in [
        (
            format!("classical elastica, EI plane strain (k = {k:.4})"),
            v_c,
            u_c,
        ),
        (
            format!("classical elastica, EI = E d^3/12 (k = {k10:.4})"),
            v_10,
            u_10,
        ),
        ("Reissner (extension + shear)".to_string(), v_r, u_r),
    ] {
        println!(
            "  vs {name}: v/a {:.5} ({:+.3} %), u/a {:.5} ({:+.3} %)",
            v_ref,
            100.0 * (last.v / (v_ref * arm) - 1.0),
            u_ref,
            100.0 * (last.u / (u_ref * arm) - 1.0)
        );
    }
}

fn fail(msg: &str) -> ! {
    eprintln!("cantilever_fe: {msg}");
    std::process::exit(2)
}
