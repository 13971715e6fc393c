//! The `mpm` command: `mpm run SCENE --out DIR [--set KEY=VALUE]...`,
//! `mpm check SCENE [--set KEY=VALUE]...` and `mpm bench SCENE --out DIR [...]`
//! (docs/bench.md).

use clap::{Parser, Subcommand};
use mpm::analyses::bench::{bench, BenchError, BenchOptions};
use mpm::analyses::reference;
use mpm::analyses::strength_reduction::{search, SearchError};
use mpm::run::{run, set_up_check, RunError, RunOptions};
use mpm::scene::{BodyKindName, Scene};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mpm",
    version,
    about = "Material point method: explicit and implicit MPM in 2D plane strain and 3D"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene and write its outputs into DIR.
    Run {
        scene: PathBuf,
        /// Output directory (created if missing).
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Override a scene key: dotted TOML path and a TOML value, e.g. grid.cells=[64,1].
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Number of worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Memory the run may take, in GiB (default: the machine's available memory).
        #[arg(long, value_name = "GIB")]
        memory_limit: Option<f64>,
        /// Continue from a checkpoint written by a run of the same scene (and
        /// --set overrides); see docs/robustness.md.
        #[arg(long, value_name = "CHECKPOINT")]
        restart: Option<PathBuf>,
    },
    /// Validate a scene without running it: everything `mpm run` checks before its
    /// first step (the model is built, the memory estimated).
    Check {
        scene: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Memory the run may take, in GiB (default: the machine's available memory).
        #[arg(long, value_name = "GIB")]
        memory_limit: Option<f64>,
    },
    /// Run a scene over solver configurations and sweeps of Δt (or load steps) and
    /// grid size; write DIR/bench.csv and PNG plots (docs/bench.md).
    Bench(BenchArgs),
    /// Lower and upper limit-analysis bounds (footing, slope) into DIR: see docs/limit_analysis.md.
    Limit {
        scene: PathBuf,
        #[arg(long, default_value = "out")]
        out: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
}

#[derive(clap::Args)]
struct BenchArgs {
    scene: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Override a scene key in every run (as for `mpm run`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
    /// A TOML file with a [bench] table, used instead of the scene's.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Configurations to run, comma-separated (built-in: explicit, direct,
    /// gmres_P and cg_P for P = none, jacobi, block_jacobi, lagged_direct, multigrid, lagged_multigrid).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    configurations: Option<Vec<String>>,
    /// Time steps to sweep (Newmark; quasi-static scenes without load steps).
    #[arg(long, value_delimiter = ',', value_name = "DT")]
    dt: Option<Vec<f64>>,
    /// Load-step counts to sweep (quasi-static).
    #[arg(long = "load-steps", value_delimiter = ',', value_name = "N")]
    load_steps: Option<Vec<usize>>,
    /// Grids to sweep, e.g. 1x16,1x32 (cells per direction).
    #[arg(long, value_delimiter = ',', value_name = "NXxNY")]
    cells: Option<Vec<String>>,
    /// Refinement factors of the scene's grid to sweep (default 1,2).
    #[arg(long, value_delimiter = ',', value_name = "F")]
    refine: Option<Vec<usize>>,
    /// Time limit of one run in seconds (default 3600).
    #[arg(long, value_name = "SECONDS")]
    timeout: Option<f64>,
    /// Worker threads of each run (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

fn run_bench(a: BenchArgs) -> ExitCode {
    let cells = match a.cells.map(|v| v.iter().map(|c| parse_cells(c)).collect()) {
        None => None,
        Some(Ok(c)) => Some(c),
        Some(Err(e)) => {
            eprintln!("error: command line: --cells: {e}");
            return ExitCode::from(2);
        }
    };
    let exe = match std::env::current_exe() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: cannot find the mpm executable to run the configurations: {e}");
            return ExitCode::from(1);
        }
    };
    let opts = BenchOptions {
        scene: a.scene,
        out: a.out,
        overrides: a.overrides,
        config: a.config,
        configurations: a.configurations,
        dt: a.dt,
        load_steps: a.load_steps,
        cells,
        refine: a.refine,
        timeout: a.timeout,
        threads: a.threads,
        exe,
    };
    match bench(&opts) {
        Ok(report) => {
            let ok = report.rows.iter().filter(|r| r.is_ok()).count();
            println!(
                "{} runs ({ok} ok); {} and {} plots in {}",
                report.rows.len(),
                report.csv.display(),
                report.plots.len(),
                opts.out.display()
            );
            ExitCode::SUCCESS
        }
        Err(e @ BenchError::Scene(_)) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

/// `1x16` → [1, 16].
/// `mpm check`'s line per body: its particles as built, their total volume
/// and the box of their domains.
fn print_extents(c: &mpm::scene::SceneConfig, extents: &[mpm::model::BodyExtent]) {
    let per = match c.dimension {
        mpm::scene::Dimension::Axisymmetric => " per radian",
        mpm::scene::Dimension::Cartesian(2) => " per unit thickness",
        _ => "",
    };
    let point = |v: &[f64]| {
        let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
        format!("({})", parts.join(", "))
    };
    for (i, (b, e)) in c.bodies.iter().zip(extents).enumerate() {
        let name = b.name.as_ref().map_or(String::new(), |n| format!(" `{n}`"));
        println!(
            "  body {i}{name} ({}): {} particles, volume {}{per}, box {} – {}",
            b.shape.name(),
            e.particles,
            e.volume,
            point(&e.min),
            point(&e.max)
        );
    }
}

fn parse_cells(s: &str) -> Result<Vec<usize>, String> {
    s.split('x')
        .map(|n| n.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}` is not of the form NXxNY[xNZ] (cells per direction)"))
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Bench(args) => run_bench(args),
        Command::Limit {
            scene,
            out,
            overrides,
        } => limit(&scene, &out, &overrides),
        Command::Check {
            scene,
            overrides,
            memory_limit,
        } => match load(&scene, &overrides).and_then(|s| {
            let opts = RunOptions {
                memory_limit,
                ..Default::default()
            };
            set_up_check(&s, &opts).map(|extents| (s, extents))
        }) {
            Ok((s, extents)) => {
                let c = &s.config;
                let stages: Vec<&str> = c.stages().iter().map(|st| st.kind.name()).collect();
                let rigid = (0..c.bodies.len())
                    .filter(|&i| c.body_kind(i) == BodyKindName::Rigid)
                    .count();
                let kinds = match rigid {
                    0 => String::new(),
                    n => format!(" ({n} rigid)"),
                };
                println!(
                    "{}: ok ({}, {} material(s), {} body(ies){kinds}, {} boundary condition(s), {} load(s), shape function {}, solver stages: {})",
                    s.file,
                    c.dimension.label(),
                    c.materials.len(),
                    c.bodies.len(),
                    c.boundaries.len(),
                    c.loads.len(),
                    c.grid.shape_function.name(),
                    stages.join(" → ")
                );
                print_extents(c, &extents);
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}{}", other_kind_of_file(&scene));
                ExitCode::from(2)
            }
        },
        Command::Run {
            scene,
            out,
            overrides,
            threads,
            memory_limit,
            restart,
        } => {
            if let Some(n) = threads {
                if let Err(e) = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build_global()
                {
                    eprintln!("error: cannot set up {n} threads: {e}");
                    return ExitCode::from(2);
                }
            }
            let scene = match load(&scene, &overrides) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {e}{}", other_kind_of_file(&scene));
                    return ExitCode::from(2);
                }
            };
            // SIGINT and SIGTERM stop the run at the end of a step (run/interrupt.rs).
            if let Err(e) = mpm::run::interrupt::install() {
                eprintln!("error: cannot catch signals: {e}");
                return ExitCode::from(1);
            }
            let opts = RunOptions {
                progress: true,
                memory_limit,
                restart,
                ..Default::default()
            };
            if scene.config.strength_reduction.is_some() && opts.restart.is_some() {
                eprintln!("error: --restart does not apply to a strength-reduction search");
                return ExitCode::from(2);
            }
            if scene.config.strength_reduction.is_some() {
                return match search(&scene, &out, &opts) {
                    Ok(s) => {
                        let [lo, hi] = s.factor_of_safety_bracket.unwrap_or([f64::NAN; 2]);
                        println!(
                            "{}: factor of safety {:.4} (stable at {lo:.4}, fails at {hi:.4}) after {} trials, {:.2} s wall; outputs in {}",
                            scene.file,
                            s.factor_of_safety.unwrap_or(f64::NAN),
                            s.trials.len(),
                            s.wall_seconds,
                            out.display()
                        );
                        ExitCode::SUCCESS
                    }
                    Err(SearchError::Run(e @ RunError::Scene(_))) => {
                        eprintln!("error: {e}");
                        ExitCode::from(2)
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        ExitCode::from(1)
                    }
                };
            }
            match run(&scene, &out, &opts) {
                Ok(s) => {
                    if let Some(r) = &s.resumed_from {
                        println!(
                            "{}: resumed from {} at step {} (t = {:.6e})",
                            scene.file, r.checkpoint, r.step, r.time
                        );
                    }
                    println!(
                        "{}: {} steps to t = {:.6e}, {} particles, {:.2} s wall; outputs in {}",
                        scene.file,
                        s.steps,
                        s.end_time,
                        s.particles,
                        s.wall_seconds,
                        out.display()
                    );
                    ExitCode::SUCCESS
                }
                Err(e @ (RunError::Scene(_) | RunError::Checkpoint(_))) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
                Err(RunError::Interrupted {
                    signal, message, ..
                }) => {
                    eprintln!("{message}");
                    ExitCode::from(128 + signal as u8)
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(1)
                }
            }
        }
    }
}

/// A scene for `mpm run` and `mpm check`: parsed, validated, and its analysis
/// tables checked.
fn load(path: &std::path::Path, overrides: &[String]) -> Result<Scene, mpm::scene::SceneError> {
    reference::checked(Scene::load(path, overrides)?)
}

/// A hint when a scene that `run`/`check` rejects is a limit-analysis file (top-level
/// `problem`) or a bench settings file (only a `[bench]` table); empty otherwise.
fn other_kind_of_file(path: &std::path::Path) -> String {
    let Some(table) = std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
    else {
        return String::new();
    };
    if table.contains_key("problem") {
        format!(
            "\nhint: {} is a limit-analysis file (top-level `problem`): run it with `mpm limit`",
            path.display()
        )
    } else if table.contains_key("bench") && !table.contains_key("dimension") {
        format!(
            "\nhint: {} is a bench settings file: pass it as `mpm bench SCENE --config FILE`",
            path.display()
        )
    } else {
        String::new()
    }
}

fn limit(scene: &std::path::Path, out: &std::path::Path, overrides: &[String]) -> ExitCode {
    use mpm::analyses::limit_analysis::{config::LimitScene, run::run_limit};
    let scene = match LimitScene::load(scene, overrides) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    match run_limit(&scene, out, true) {
        Ok(s) => {
            let finest = s.finest.expect("a run that did not fail solved a level");
            println!(
                "{}: {} between {:.5} and {:.5}; outputs in {}",
                scene.file,
                s.quantity,
                finest.lower_bound,
                finest.upper_bound,
                out.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
