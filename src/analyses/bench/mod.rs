//! `mpm bench SCENE --out DIR`: run one scene over a set of solver configurations
//! and sweeps of Δt (or load steps) and grid size, each run a child process of the
//! same executable (wall time and peak memory per run; a run that diverges or
//! crashes becomes a row, not the end of the benchmark). Writes `DIR/bench.csv`
//! (one row per run, written as the runs finish), `DIR/runs/NAME/` (the scene that
//! ran and its outputs) and PNG plots. docs/bench.md describes the command, the
//! `[bench]` keys and the columns.

pub(crate) mod child;
pub(crate) mod configurations;
mod plots;
pub(crate) mod row;

use crate::analyses::reference;
use crate::analyses::strength_reduction::SearchSummary;
use crate::model::Model;
use crate::output::{CsvWriter, Table};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::run::summary::Summary;
use crate::scene::overrides;
use crate::scene::validate;
use crate::scene::{BenchConfig, Integrator, Scene, SceneConfig, SceneError, SolverKind, Source};
use crate::solver::explicit::Explicit;
use child::{run_child, Exit};
use configurations::Configuration;
pub use row::{Row, CSV_HEADER};
use std::path::{Path, PathBuf};

/// What the command line gives; `None` fields fall back to the `[bench]` table
/// (or the file given with `config`), then to the defaults.
#[derive(Clone, Debug, Default)]
pub struct BenchOptions {
    pub scene: PathBuf,
    pub out: PathBuf,
    /// `--set` overrides applied to every run.
    pub overrides: Vec<String>,
    /// A separate TOML file with a `[bench]` table (replaces the scene's).
    pub config: Option<PathBuf>,
    pub configurations: Option<Vec<String>>,
    pub dt: Option<Vec<f64>>,
    pub load_steps: Option<Vec<usize>>,
    pub cells: Option<Vec<Vec<usize>>>,
    pub refine: Option<Vec<usize>>,
    pub timeout: Option<f64>,
    /// Worker threads of each run (default: the run's own default, all cores).
    pub threads: Option<usize>,
    /// The `mpm` executable that runs each configuration.
    pub exe: PathBuf,
}

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{0}")]
    Scene(#[from] SceneError),
    #[error("cannot write the benchmark outputs: {0}")]
    Io(#[from] std::io::Error),
    #[error("cannot draw the plots: {0}")]
    Plot(String),
}

/// Default time limit of one run (seconds).
pub const DEFAULT_TIMEOUT: f64 = 3600.0;

/// A point of the time sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
enum TimePoint {
    /// As the configured scene has it (explicit runs: the CFL step).
    Scene,
    Dt(f64),
    LoadSteps(usize),
}

/// The outcome of a benchmark: its rows and the files written.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub rows: Vec<Row>,
    pub csv: PathBuf,
    pub plots: Vec<PathBuf>,
}

/// Run the benchmark.
pub fn bench(opts: &BenchOptions) -> Result<BenchReport, BenchError> {
    let file = opts.scene.display().to_string();
    let text = crate::scene::read_text(&file, &opts.scene)?;
    let first = reference::checked(Scene::parse(&file, &text, &opts.overrides)?)?;
    let (settings, names_source) = settings(opts, &first)?;
    // Every run: no ParaView frames (they would dominate small runs), the [bench]
    // overrides, then the command line's.
    let mut base_set = vec!["output.frames=0".to_string()];
    base_set.extend(settings.set.iter().cloned());
    base_set.extend(opts.overrides.iter().cloned());
    let base_text = overrides::apply(&file, &text, &base_set)?;
    let base = reference::checked(Scene::parse(&file, &base_text, &[])?)?;
    let dt_critical = critical_dt(&base)?;
    let configs = resolve(&settings, &base, &base_text, dt_critical, names_source)?;
    let grids = grid_points(&base.config.grid.cells, &settings);
    let timeout = settings.timeout.unwrap_or(DEFAULT_TIMEOUT);

    std::fs::create_dir_all(opts.out.join("runs"))?;
    let csv_path = opts.out.join("bench.csv");
    let mut csv = CsvWriter::create(&csv_path, &CSV_HEADER)?;
    let mut rows = Vec::new();
    let mut emit = |row: Row, rows: &mut Vec<Row>| -> std::io::Result<()> {
        csv.row(row.fields())?;
        csv.flush()?;
        println!("{}", progress_line(&row));
        rows.push(row);
        Ok(())
    };
    for config in configs {
        let config = match config {
            Ok(c) => c,
            Err((name, reason)) => {
                emit(skipped(&name, "", reason), &mut rows)?;
                continue;
            }
        };
        // The configured scene is written out, so that a validation error's line
        // and column point into a file one can open.
        let configured_path = opts.out.join("runs").join(format!("{}.toml", config.name));
        let label = configured_path.display().to_string();
        let configured = overrides::unset(&file, &base_text, &config.unset)
            .and_then(|t| overrides::apply(&file, &t, &config.set))
            .and_then(|t| {
                std::fs::write(&configured_path, &t)
                    .map_err(|e| SceneError::plain(&label, format!("cannot write: {e}")))?;
                reference::checked(Scene::parse(&label, &t, &[])?)
            });
        let scene_c = match configured {
            Ok(s) => s,
            Err(e) => {
                let overrides = Configuration::describe(&config.set, &config.unset);
                emit(skipped(&config.name, &overrides, e.to_string()), &mut rows)?;
                continue;
            }
        };
        for cells in &grids {
            for tp in time_points(&scene_c.config, &settings) {
                let row = run_point(opts, &file, &base_text, &config, cells, tp, timeout)?;
                emit(row, &mut rows)?;
            }
        }
    }
    let plots = plots::draw_all(&rows, &opts.out).map_err(BenchError::Plot)?;
    Ok(BenchReport {
        rows,
        csv: csv_path,
        plots,
    })
}

/// The bench settings: the `--config` file's or the scene's `[bench]` table, then
/// the command-line options. Also says where configuration names came from (for
/// error positions).
fn settings(opts: &BenchOptions, scene: &Scene) -> Result<(BenchConfig, NamesSource), SceneError> {
    let (mut b, mut source) = match &opts.config {
        Some(path) => {
            let file = path.display().to_string();
            let text = crate::scene::read_text(&file, path)?;
            let parsed: BenchFile = Source::new(&file, &text, &text, &[]).deserialize()?;
            validate::bench(&parsed.bench, "bench")
                .map_err(|(key, m)| SceneError::at_key(&file, &text, &key, m))?;
            (parsed.bench, NamesSource::File(file, text))
        }
        None => {
            let text = std::fs::read_to_string(&opts.scene).unwrap_or_default();
            let b = scene.config.bench.clone().unwrap_or_default();
            (b, NamesSource::File(scene.file.clone(), text))
        }
    };
    let cli = BenchConfig {
        configurations: opts.configurations.clone(),
        dt: opts.dt.clone(),
        load_steps: opts.load_steps.clone(),
        cells: opts.cells.clone(),
        refine: opts.refine.clone(),
        timeout: opts.timeout,
        ..BenchConfig::default()
    };
    validate::bench(&cli, "").map_err(|(key, m)| {
        let option = key.trim_start_matches('.').split('.').next().unwrap_or("");
        SceneError::plain(
            "command line",
            format!("--{}: {m}", option.replace('_', "-")),
        )
    })?;
    if cli.configurations.is_some() {
        b.configurations = cli.configurations;
        source = NamesSource::CommandLine;
    }
    if cli.cells.is_some() || cli.refine.is_some() {
        b.cells = cli.cells;
        b.refine = cli.refine;
    }
    b.dt = cli.dt.or(b.dt);
    b.load_steps = cli.load_steps.or(b.load_steps);
    b.timeout = cli.timeout.or(b.timeout);
    Ok((b, source))
}

/// A separate bench file holds only a `[bench]` table.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BenchFile {
    bench: BenchConfig,
}

enum NamesSource {
    /// File name and text holding `bench.configurations`.
    File(String, String),
    CommandLine,
}

/// The configurations to run, in order: user-defined ones by name first, then the
/// built-in ones. A built-in configuration that does not apply to the scene is an
/// `Err((name, reason))` (a skipped row); an unknown name is an input error.
#[allow(clippy::type_complexity)]
fn resolve(
    b: &BenchConfig,
    base: &Scene,
    base_text: &str,
    dt_critical: f64,
    source: NamesSource,
) -> Result<Vec<Result<Configuration, (String, String)>>, SceneError> {
    let names = b
        .configurations
        .clone()
        .unwrap_or_else(|| configurations::default_names(&base.config));
    let mut out = Vec::new();
    for (i, name) in names.iter().enumerate() {
        if let Some(c) = b.custom.iter().find(|c| &c.name == name) {
            out.push(Ok(Configuration {
                name: c.name.clone(),
                set: c.set.clone(),
                unset: c.unset.clone(),
            }));
            continue;
        }
        match configurations::builtin(name, &base.config, base_text, dt_critical) {
            Some(r) => out.push(r.map_err(|reason| (name.clone(), reason))),
            None => {
                let mut known = configurations::builtin_names();
                known.extend(b.custom.iter().map(|c| c.name.clone()));
                let message = format!(
                    "unknown configuration `{name}`; known: {}",
                    known.join(", ")
                );
                return Err(match &source {
                    NamesSource::File(file, text) => SceneError::at_key(
                        file,
                        text,
                        &format!("bench.configurations.{i}"),
                        message,
                    ),
                    NamesSource::CommandLine => {
                        SceneError::plain("command line", format!("--configurations: {message}"))
                    }
                });
            }
        }
    }
    Ok(out)
}

/// The grids: `cells`, or the scene's cells times each `refine` factor (default 1
/// and 2) in every direction that has more than one cell (all directions if none has).
fn grid_points(base: &[usize], b: &BenchConfig) -> Vec<Vec<usize>> {
    if let Some(c) = &b.cells {
        return c.clone();
    }
    let all = base.iter().all(|&n| n == 1);
    let factors = b.refine.clone().unwrap_or_else(|| vec![1, 2]);
    factors
        .iter()
        .map(|f| {
            base.iter()
                .map(|&n| if n > 1 || all { n * f } else { n })
                .collect()
        })
        .collect()
}

/// The time sweep of a configured scene: Δt for Newmark, load steps (or Δt) for
/// quasi-static runs, none for explicit and staged runs. Defaults: the scene's own
/// value and half the step.
fn time_points(s: &SceneConfig, b: &BenchConfig) -> Vec<TimePoint> {
    let Some(solver) = &s.solver else {
        return vec![TimePoint::Scene];
    };
    let dt = solver.implicit_dt();
    let dts = |v: &Option<Vec<f64>>| {
        v.clone()
            .unwrap_or_else(|| vec![dt, dt / 2.0])
            .into_iter()
            .map(TimePoint::Dt)
            .collect()
    };
    match (solver.kind, solver.integrator()) {
        (SolverKind::Explicit, _) => vec![TimePoint::Scene],
        (SolverKind::Implicit, Integrator::Newmark) => dts(&b.dt),
        (SolverKind::Implicit, Integrator::QuasiStatic) => {
            let steps = b.load_steps.clone().or_else(|| {
                b.dt.is_none()
                    .then_some(solver.load_steps?)
                    .map(|n| vec![n, 2 * n])
            });
            match steps {
                Some(v) => v.into_iter().map(TimePoint::LoadSteps).collect(),
                None => dts(&b.dt),
            }
        }
    }
}

fn cells_label(cells: &[usize]) -> String {
    cells
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join("x")
}

fn skipped(name: &str, overrides: &str, reason: String) -> Row {
    Row {
        configuration: name.to_string(),
        overrides: overrides.to_string(),
        status: format!("skipped: {reason}"),
        ..Row::default()
    }
}

/// One run: configure, validate (a rejected scene is a skipped row), count the
/// unknowns, run the child, read its outputs.
fn run_point(
    opts: &BenchOptions,
    file: &str,
    base_text: &str,
    config: &Configuration,
    cells: &[usize],
    tp: TimePoint,
    timeout: f64,
) -> Result<Row, BenchError> {
    let mut set = config.set.clone();
    let mut unset = config.unset.clone();
    set.push(format!("grid.cells={cells:?}").replace(' ', ""));
    let mut dir = format!("{}_{}", config.name, cells_label(cells));
    match tp {
        TimePoint::Scene => {}
        TimePoint::Dt(dt) => {
            set.push(format!("solver.dt={dt:?}"));
            unset.push("solver.load_steps".into());
            dir += &format!("_dt{dt}");
        }
        TimePoint::LoadSteps(n) => {
            set.push(format!("solver.load_steps={n}"));
            unset.push("solver.dt".into());
            dir += &format!("_ls{n}");
        }
    }
    let mut row = Row {
        configuration: config.name.clone(),
        overrides: Configuration::describe(&set, &unset),
        cells: cells_label(cells),
        run_dir: format!("runs/{dir}"),
        ..Row::default()
    };
    let run_dir = opts.out.join(&row.run_dir);
    if run_dir.exists() {
        std::fs::remove_dir_all(&run_dir)?;
    }
    std::fs::create_dir_all(&run_dir)?;
    let scene_path = run_dir.join("scene.toml");
    let label = scene_path.display().to_string();
    let text =
        overrides::unset(file, base_text, &unset).and_then(|t| overrides::apply(file, &t, &set))?;
    std::fs::write(&scene_path, &text)?;
    let scene = match Scene::parse(&label, &text, &[]).and_then(reference::checked) {
        Ok(s) => s,
        Err(e) => {
            row.status = format!("skipped: {e}");
            return Ok(row);
        }
    };
    let cfg = &scene.config;
    row.solver = solver_label(cfg).to_string();
    match tp {
        TimePoint::Dt(dt) => row.dt = Some(dt),
        TimePoint::LoadSteps(n) => {
            row.load_steps = Some(n);
            row.dt = Some(cfg.total_time() / n as f64);
        }
        TimePoint::Scene => {}
    }
    match unknowns(&scene) {
        Ok((particles, unknowns)) => {
            row.particles = Some(particles);
            row.unknowns = Some(unknowns);
        }
        Err(e) => {
            row.status = format!("skipped: {e}");
            return Ok(row);
        }
    }
    let mut args = vec![
        "run".to_string(),
        scene_path.display().to_string(),
        "--out".into(),
        run_dir.display().to_string(),
    ];
    if let Some(n) = opts.threads {
        args.extend(["--threads".to_string(), n.to_string()]);
    }
    let child = run_child(&opts.exe, &args, &run_dir, timeout)?;
    row.wall_seconds = Some(child.wall_seconds);
    row.peak_mib = Some(child.peak_mib);
    read_outputs(&mut row, &run_dir);
    row.status = status(child.exit, &run_dir, timeout);
    if row.is_ok() {
        // The reference's files are beside the scene the bench was given.
        match reference::from_scene(cfg, file) {
            Ok(Some(measure)) => match measure.error(&run_dir) {
                Ok(e) => row.error = Some(e),
                Err(m) => row.note = format!("no error: {m}"),
            },
            Ok(None) => {}
            Err((key, m)) => row.note = format!("no error: {key}: {m}"),
        }
    }
    Ok(row)
}

/// explicit, newmark, quasi_static (the integrator's name) or staged.
fn solver_label(cfg: &SceneConfig) -> &'static str {
    match &cfg.solver {
        None => "staged",
        Some(s) if s.kind == SolverKind::Explicit => s.kind.name(),
        Some(s) => s.integrator().name(),
    }
}

/// Counts from summary.json and newton.csv (also after a divergence: both are
/// written up to the failure).
fn read_outputs(row: &mut Row, dir: &Path) {
    match read_summary(dir) {
        Some(ChildSummary::Run(s)) => {
            row.steps = Some(s.steps as u64);
            row.run_seconds = Some(s.wall_seconds);
            row.newton_iterations = s.solver.newton_iterations.map(|n| n as u64);
            row.cutbacks = s.solver.cutbacks.map(|n| n as u64);
            if row.dt.is_none() && s.steps > 0 {
                // Explicit runs: the mean step (the last one is cut to the end time).
                row.dt = Some(s.end_time / s.steps as f64);
            }
        }
        Some(ChildSummary::Search(s)) => {
            row.steps = Some(s.steps as u64);
            row.run_seconds = Some(s.wall_seconds);
            row.newton_iterations = Some(s.newton_iterations as u64);
        }
        None => {}
    }
    if let Ok(newton) = Table::read(&dir.join("newton.csv")) {
        row.krylov_iterations = krylov_total(&newton);
    }
}

/// A child's summary.json: a run's, or a strength-reduction search's.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum ChildSummary {
    Run(Box<Summary>),
    Search(Box<SearchSummary>),
}

fn read_summary(dir: &Path) -> Option<ChildSummary> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// Krylov iterations summed over newton.csv: the first column whose name starts with
/// `krylov` (written by the matrix-free path); None if there is none.
pub fn krylov_total(newton: &Table) -> Option<u64> {
    let name = newton.header.iter().find(|h| h.starts_with("krylov"))?;
    let total: f64 = newton.columns[name].iter().filter(|x| x.is_finite()).sum();
    Some(total.round() as u64)
}

/// ok / diverged: message / failed: … / timeout: …
fn status(exit: Exit, dir: &Path, timeout: f64) -> String {
    let stderr = std::fs::read_to_string(dir.join("stderr.txt")).unwrap_or_default();
    let last = stderr
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
        .trim()
        .trim_start_matches("error: ")
        .to_string();
    let message = || -> String {
        match read_summary(dir) {
            Some(ChildSummary::Run(s)) => s.message,
            Some(ChildSummary::Search(s)) => s.message,
            None => None,
        }
        .unwrap_or_else(|| last.clone())
    };
    match exit {
        Exit::Code(0) => "ok".into(),
        Exit::Code(1) => format!("diverged: {}", message()),
        Exit::Code(c) => format!("failed: exit code {c}: {last}"),
        Exit::Signal(9) => "failed: killed by signal 9 (out of memory?)".into(),
        Exit::Signal(s) => format!("failed: killed by signal {s}"),
        Exit::TimedOut => format!("timeout: stopped after {timeout} s"),
    }
}

/// Particles and unknowns at the first step: the size of the first Newton system
/// for implicit runs (`solver::implicit::unknowns`, of the first implicit stage),
/// D × active nodes for explicit ones.
fn unknowns(scene: &Scene) -> Result<(usize, usize), SceneError> {
    match scene.config.dimension.spatial() {
        2 => unknowns_dim::<2>(scene),
        _ => unknowns_dim::<3>(scene),
    }
}

fn unknowns_dim<const D: usize>(scene: &Scene) -> Result<(usize, usize), SceneError> {
    let m = Model::<D>::build(scene)?;
    let shape = scene.config.grid.shape_function;
    let stages = scene.config.stages();
    let n = match stages.iter().find(|s| s.kind == SolverKind::Implicit) {
        Some(s) => crate::solver::implicit::unknowns(&m, shape, s),
        None => {
            let (mut st, mut map) = (Stencils::<D>::default(), NodeMap::default());
            crate::physics::transfer::stencils_and_nodes(&m, shape, &mut st, &mut map);
            D * map.len()
        }
    };
    Ok((m.particles.len(), n))
}

/// The explicit critical step of the base scene at t = 0 (for implicit
/// configurations of explicit scenes).
fn critical_dt(scene: &Scene) -> Result<f64, SceneError> {
    Ok(match scene.config.dimension.spatial() {
        2 => Explicit::critical_dt(&Model::<2>::build(scene)?),
        _ => Explicit::critical_dt(&Model::<3>::build(scene)?),
    })
}

fn progress_line(r: &Row) -> String {
    let num = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map(f).unwrap_or("-".into());
    format!(
        "{:<22} {:>9} {:>10} unknowns {:>8}  error {:>9}  {:>8} s  {:>7} MiB  newton {:>5}  {}",
        r.configuration,
        r.cells,
        match (r.load_steps, r.dt) {
            (Some(n), _) => format!("ls {n}"),
            (None, Some(dt)) => format!("dt {dt:.3e}"),
            _ => String::new(),
        },
        r.unknowns.map_or("-".into(), |n| n.to_string()),
        num(r.error, &|e| format!("{e:.3e}")),
        num(r.wall_seconds, &|w| format!("{w:.2}")),
        num(r.peak_mib, &|m| format!("{m:.1}")),
        r.newton_iterations.map_or("-".into(), |n| n.to_string()),
        r.status
    )
}
