//! `mpm bench` end to end on a tiny column (problems/column.toml, 1×4 and 1×8 cells,
//! 4 load steps): bench.csv has its columns and one row per run; the error column
//! equals σ_yy's normalised L2 error against −ρg(l0 − Y) computed here from each
//! run's particles_final.csv; a configuration the validator rejects is a `skipped`
//! row with the file, line and column; a run whose Newton iteration fails is a
//! `diverged` row; the four plots are PNG files. Bad bench input stops with the
//! file, key, line and column.

use crate::common::{problem, Table};
use std::path::Path;
use std::process::Command;

const BENCH: &str = r#"
[bench]
configurations = ["direct", "gmres_jacobi", "one_newton_iteration", "no_iterations"]

[[bench.configuration]]
name = "one_newton_iteration"
set = ["solver.max_iterations=1", "solver.max_cutbacks=0"]

[[bench.configuration]]
name = "no_iterations"
set = ["solver.max_iterations=0"]
"#;

fn mpm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_mpm"))
        .args(args)
        .output()
        .expect("mpm runs")
}

/// σ_yy error of one run, computed here (independently of mpm::analyses::reference).
fn column_error(particles: &Path) -> f64 {
    let p = Table::read(particles).unwrap();
    let (y0, syy, v0) = (p.col("Y0"), p.col("syy"), p.col("volume0"));
    let rho_g = 80.0 * 10.0;
    let (mut sum, mut volume) = (0.0, 0.0);
    for i in 0..y0.len() {
        sum += v0[i] * (syy[i] + rho_g * (50.0 - y0[i])).powi(2);
        volume += v0[i];
    }
    (sum / volume).sqrt() / (rho_g * 50.0)
}

/// A PNG: signature, an IHDR chunk of the plot's size, IEND at the end.
fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    assert_eq!(&bytes[12..16], b"IHDR");
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (1000, 650), "{}", path.display());
    assert_eq!(&bytes[bytes.len() - 8..bytes.len() - 4], b"IEND");
}

#[test]
fn bench_writes_rows_errors_statuses_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("bench.toml");
    std::fs::write(&config, BENCH).unwrap();
    let out = dir.path().join("out");
    let scene = problem("column.toml");
    let result = mpm(&[
        "bench",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--cells",
        "1x4,1x8",
        "--load-steps",
        "4",
        "--threads",
        "1",
    ]);
    let stdout = String::from_utf8_lossy(&result.stdout);
    println!("{stdout}{}", String::from_utf8_lossy(&result.stderr));
    assert!(result.status.success(), "mpm bench failed");

    let csv = Table::read(&out.join("bench.csv")).unwrap();
    let expected = "configuration,overrides,solver,dt,load_steps,cells,particles,unknowns,\
        error,wall_seconds,run_seconds,peak_mib,steps,newton_iterations,newton_per_step,\
        krylov_iterations,krylov_per_newton,cutbacks,status,note,run_dir";
    assert_eq!(csv.header.join(","), expected);
    let name = csv.text_column("configuration").unwrap();
    let status = csv.text_column("status").unwrap();
    let rows = |c: &str| -> Vec<usize> { (0..csv.len()).filter(|&i| name[i] == c).collect() };

    // The direct solver: two grids, errors as computed here, iteration counts.
    let direct = rows("direct");
    assert_eq!(direct.len(), 2);
    let run_dir = csv.text_column("run_dir").unwrap();
    for &i in &direct {
        assert_eq!(status[i], "ok");
        let error = column_error(&out.join(&run_dir[i]).join("particles_final.csv"));
        let reported = csv.col("error")[i];
        println!("{}: error {reported:.6e}, here {error:.6e}", run_dir[i]);
        assert!(
            (reported / error - 1.0).abs() < 1e-12,
            "{reported} vs {error}"
        );
        assert_eq!(csv.col("load_steps")[i], 4.0);
        assert_eq!(csv.col("dt")[i], 0.25);
        assert_eq!(csv.col("steps")[i], 4.0);
        let newton = csv.col("newton_iterations")[i];
        assert!((4.0..=32.0).contains(&newton), "{newton} Newton iterations");
        assert_eq!(csv.col("newton_per_step")[i], newton / 4.0);
        assert!(csv.col("wall_seconds")[i] > 0.0 && csv.col("peak_mib")[i] > 1.0);
    }
    // Finer grid: more particles and unknowns, smaller error (the column converges).
    let (a, b) = (direct[0], direct[1]);
    assert_eq!(csv.text_column("cells").unwrap()[b], "1x8");
    assert_eq!(
        (csv.col("particles")[a], csv.col("particles")[b]),
        (16.0, 32.0)
    );
    // 1 cell wide, rollers: only y components are free; nodes 0…4 (0…8) up the
    // column, the base fixed in y: 2 × 4 (2 × 8) unknowns.
    assert_eq!(
        (csv.col("unknowns")[a], csv.col("unknowns")[b]),
        (8.0, 16.0)
    );
    assert!(csv.col("error")[b] < csv.col("error")[a]);

    // Krylov: skipped with the validator's message until the Newton–Krylov path
    // exists, then it runs.
    for i in rows("gmres_jacobi") {
        let s = &status[i];
        assert!(
            s == "ok" || (s.starts_with("skipped: ") && s.contains("linear_solver")),
            "{s}"
        );
        if s != "ok" {
            assert!(s.contains("gmres_jacobi.toml:"), "no file:line:col in {s}");
        }
    }
    // One Newton iteration and no cut-back: the run stops with the diagnosis.
    let diverged = rows("one_newton_iteration");
    assert_eq!(diverged.len(), 2);
    for i in diverged {
        assert!(
            status[i].starts_with("diverged: ") && status[i].contains("Newton did not converge"),
            "{}",
            status[i]
        );
        assert!(csv.col("error")[i].is_nan(), "no error for a diverged run");
    }
    // max_iterations = 0 is rejected by the scene validator: one skipped row that
    // points into the configured scene.
    let skipped = rows("no_iterations");
    assert_eq!(skipped.len(), 1);
    let s = &status[skipped[0]];
    assert!(
        s.starts_with("skipped: ")
            && s.contains("no_iterations.toml:")
            && s.contains("solver.max_iterations")
            && s.contains("must be at least 1"),
        "{s}"
    );

    for png in [
        "error_vs_wall",
        "newton_per_step",
        "krylov_per_newton",
        "residual_history",
    ] {
        assert_png(&out.join(format!("{png}.png")));
    }
}

#[test]
fn bad_bench_input_names_file_key_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let scene = problem("column.toml");
    let run = |bench: &str, extra: &[&str]| {
        let config = dir.path().join("bench.toml");
        std::fs::write(&config, bench).unwrap();
        let out = dir.path().join("out");
        let mut args = vec![
            "bench",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
        ];
        args.extend(extra);
        let r = mpm(&args);
        assert_eq!(r.status.code(), Some(2), "expected an input error");
        String::from_utf8_lossy(&r.stderr).to_string()
    };
    let e = run("[bench]\nload_steps = [4]\ndt = [0.5, -1.0]\n", &[]);
    assert!(
        e.contains("bench.toml:3:") && e.contains("key `bench.dt.1`"),
        "{e}"
    );
    let e = run("[bench]\nconfigurations = [\"direct\", \"lu\"]\n", &[]);
    assert!(
        e.contains("bench.toml:2:") && e.contains("unknown configuration `lu`"),
        "{e}"
    );
    let e = run("[bench]\nrepeat = 3\n", &[]);
    assert!(e.contains("bench.toml:2:1") && e.contains("repeat"), "{e}");
    let e = run("[bench]\n", &["--refine", "0"]);
    assert!(e.contains("--refine") && e.contains("at least 1"), "{e}");
}
