//! The `mpm` command: `mpm run SCENE --out DIR [--set KEY=VALUE]...` and
//! `mpm check SCENE [--set KEY=VALUE]...`.

use clap::{Parser, Subcommand};
use mpm::run::{run, RunError, RunOptions};
use mpm::scene::Scene;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mpm",
    version,
    about = "Material point method: explicit MPM in 2D plane strain and 3D"
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
    },
    /// Validate a scene without running it.
    Check {
        scene: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
    /// Lower and upper limit-analysis bounds (footing, slope) into DIR: see docs/limit_analysis.md.
    Limit {
        scene: PathBuf,
        #[arg(long, default_value = "out")]
        out: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Limit {
            scene,
            out,
            overrides,
        } => limit(&scene, &out, &overrides),
        Command::Check { scene, overrides } => match Scene::load(&scene, &overrides) {
            Ok(s) => {
                let c = &s.config;
                let stages: Vec<String> = c
                    .stages()
                    .iter()
                    .map(|st| format!("{:?}", st.kind).to_lowercase())
                    .collect();
                println!(
                    "{}: ok ({}D, {} material(s), {} body(ies), {} boundary condition(s), {} load(s), shape function {}, solver stages: {})",
                    s.file,
                    c.dimension,
                    c.materials.len(),
                    c.bodies.len(),
                    c.boundaries.len(),
                    c.loads.len(),
                    c.grid.shape_function.name(),
                    stages.join(" → ")
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        Command::Run {
            scene,
            out,
            overrides,
            threads,
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
            let scene = match Scene::load(&scene, &overrides) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            match run(&scene, &out, &RunOptions { progress: true }) {
                Ok(s) => {
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
                Err(e @ RunError::Scene(_)) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(1)
                }
            }
        }
    }
}

fn limit(scene: &std::path::Path, out: &std::path::Path, overrides: &[String]) -> ExitCode {
    use mpm::limit_analysis::{config::LimitScene, run::run_limit};
    let scene = match LimitScene::load(scene, overrides) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    match run_limit(&scene, out, true) {
        Ok(s) => {
            println!(
                "{}: {} between {:.5} and {:.5}; outputs in {}",
                scene.file,
                s["quantity"].as_str().unwrap_or(""),
                s["lower_bound"].as_f64().unwrap_or(f64::NAN),
                s["upper_bound"].as_f64().unwrap_or(f64::NAN),
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
