//! One Newton iteration of the implicit solver, split into its costs, each
//! measured through the solver's own functions on the step system it builds
//! (`StepSettings::prepare`, `residual`, `tangent`, `DirectSolver`):
//! - `pattern`: the step's sparsity pattern (node graph and compressed columns),
//!   built once per step at its first assembly;
//! - `tangent`: the assembly of one iteration into that pattern (particle
//!   tangents A_p and the scatter of their terms);
//! - `factorize_first` (symbolic + numeric, a fresh solver) and
//!   `factorize_refactor` (numeric only, the pattern unchanged);
//! - `numeric_llt`: faer's numeric Cholesky alone, with the solver's ordering,
//!   parallelism (chosen by the factor's density) and fresh buffers, the
//!   yardstick of the others; `numeric_llt_sequential` and
//!   `numeric_llt_two_tasks`: the same on one thread and with two faer tasks;
//! - `solve`;
//! - `iteration_first`: the whole path of the first iteration of a step whose
//!   stencils changed, as Newton takes it (`newton::factorized_tangent`:
//!   pattern, then ordering + symbolic factorization beside the tangent's
//!   assembly, numeric factorization into the solver's kept buffers, and the
//!   solve, which rides with the factorization's check);
//! - `iteration_later`: a later one, or the first of a step that keeps the
//!   pattern (tangent, refactorization and solve);
//! - `iteration_first_of_run`: the first, with a fresh solver.
//!
//! Problems: the block of problems/bench/block.toml (uGIMP, 2×2 particles per
//! cell, self-weight on a fixed base) in 2D on 64² and 160² cells and in 3D on
//! 12³ and 20³ cells (2×2×2 particles per cell), each at the first iteration of
//! load step 2 (after one converged step of the real solver: non-zero stress,
//! particles moved, each touching 3^D nodes as in the rest of a run; at the
//! initial lattice they touch 2^D). Small 3D blocks by default; set
//! `MPM_BENCH_LARGE=1` for 160² and 20³ (several minutes); `MPM_BENCH_DIM=2`
//! (or 3) for one dimension only.
//!
//! `MPM_BENCH_ALTERNATE=R` first prints the targets' ratios from R interleaved
//! rounds of the yardstick, a first and a later iteration (medians).
//!
//! Run: `cargo bench --bench implicit -- --noplot` (see docs/performance.md).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::SymmetricOrdering;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky,
};
use faer::Side;
use mpm::dim::Vector;
use mpm::model::Model;
use mpm::output::matrix_market::{write_sparse, write_vector};
use mpm::scene::{DirectOrdering, Scene};
use mpm::solver::implicit::assembly::stiffness::particle_tangents;
use mpm::solver::implicit::assembly::{Pattern, Storage, Tangent};
use mpm::solver::implicit::newton::factorized_tangent;
use mpm::solver::implicit::residual::{ordering, residual, tangent};
use mpm::solver::implicit::step::{StepSettings, StepSystem};
use mpm::solver::implicit::Implicit;
use mpm::solver::linear::direct::{
    cholesky_parallelism, parallelism, DirectSolver, Ordering, Structure,
};
use mpm::solver::linear::ordering::{fill_reducing, node_amd, node_metis};
use mpm::solver::linear::Index;
use mpm::solver::stepper::Stepper;
use std::hint::black_box;
use std::time::Instant;

const BLOCK_2D: &str = include_str!("../problems/bench/block.toml");

/// The block in 3D: the 2D scene's settings on a cube.
const BLOCK_3D: &str = r#"
dimension = 3
gravity = [0.0, 0.0, -10.0]

[grid]
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 10.0]
cells = [20, 20, 20]
shape_function = "ugimp"

[[material]]
name = "soil"
model = "hencky"
density = 80.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3

[[body]]
name = "block"
material = "soil"
shape = "box"
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 10.0]
particles_per_cell = 2

[[boundary]]
face = "zmin"
condition = "fixed"

[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 4

[output]
frames = 0
"#;

/// A model after one converged load step and the step system of the next step
/// at its first iterate (u = 0), as the solver sets it up.
struct Problem<const D: usize> {
    name: String,
    model: Model<D>,
    sys: StepSystem<D>,
}

impl<const D: usize> Problem<D> {
    fn new(name: &str, text: &str, cells: &str) -> Problem<D> {
        let scene = Scene::parse("block.toml", text, &[format!("grid.cells={cells}")])
            .expect("valid scene");
        let stage = scene.config.stages()[0];
        let shape = scene.config.grid.shape_function;
        let dt = stage.implicit_dt();
        let mut model = Model::<D>::build(&scene).expect("model");
        let mut solver = Implicit::<D>::new(shape, stage, 0.0);
        solver.step(&mut model, 0.0, dt, 0).expect("converged");
        let settings = StepSettings::new(shape, stage, 0.0);
        let mut sys = StepSystem::new(stage.mass());
        let mut accel = Vec::new();
        settings.prepare(&model, &mut sys, &mut accel, dt, dt);
        let u = vec![Vector::<D>::zeros(); sys.map.len()];
        residual(&model, &mut sys, &u).expect("residual");
        Problem {
            name: format!("{name}_step2"),
            model,
            sys,
        }
    }

    /// The pattern of the step, built anew.
    fn pattern(&self) -> Pattern {
        let s = &self.sys;
        let cells = s.trial.fbar.as_ref().map(|f| &f.cells);
        let p = Pattern::new(&s.map, &s.stencils, &s.dofs, cells, None, &[]);
        p.csc(Storage::Lower).unwrap();
        p
    }
}

/// faer's numeric LLᵀ alone into fresh buffers, with the direct solver's
/// parallelism (`par`: `direct::cholesky_parallelism`), sequential or with two tasks.
fn numeric_llt(
    sym: &SymbolicCholesky<Index>,
    a: faer::sparse::SparseColMatRef<Index, f64>,
    par: faer::Par,
) -> Vec<f64> {
    let mut values = vec![0.0; sym.len_val()];
    let req = sym.factorize_numeric_llt_scratch::<f64>(par, Default::default());
    numeric_llt_into(sym, a, par, &mut values, &mut MemBuffer::new(req));
    values
}

/// faer's numeric LLᵀ into the given factor buffer and workspace.
fn numeric_llt_into(
    sym: &SymbolicCholesky<Index>,
    a: faer::sparse::SparseColMatRef<Index, f64>,
    par: faer::Par,
    values: &mut [f64],
    mem: &mut MemBuffer,
) {
    sym.factorize_numeric_llt(
        values,
        a,
        Side::Lower,
        Default::default(),
        par,
        MemStack::new(mem),
        Default::default(),
    )
    .expect("positive definite");
}

fn bench_problem<const D: usize>(c: &mut Criterion, p: &mut Problem<D>) {
    let m = &p.model;
    p.sys.pattern = Default::default();
    let k = tangent(m, &p.sys, false).expect("tangent");
    assert!(k.symmetric());
    let n = k.matrix().nrows();
    let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    let order = ordering(&p.sys, &k);
    let mut solver = DirectSolver::new();
    let method = solver
        .factorize(k.matrix(), Structure::Symmetric, order)
        .expect("factorize");
    let symbolic = |perm: Option<&[usize]>| {
        let fwd: Option<Vec<Index>> = perm.map(|p| p.iter().map(|&i| i as Index).collect());
        let inv = perm.map(|p| {
            let mut inv: Vec<Index> = vec![0; p.len()];
            p.iter()
                .enumerate()
                .for_each(|(new, &old)| inv[old] = new as Index);
            inv
        });
        let ordering = match (&fwd, &inv) {
            (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, n)),
            _ => SymmetricOrdering::Amd,
        };
        let sym = factorize_symbolic_cholesky(
            k.matrix().symbolic(),
            Side::Lower,
            ordering,
            CholeskySymbolicParams::default(),
        )
        .expect("symbolic");
        sym
    };
    // The orderings side by side: time to compute, nnz(L), and faer's numeric
    // LLᵀ with each (one call).
    let pattern = p.sys.pattern.get().expect("pattern");
    let clock = Instant::now();
    let node_amd_perm = node_amd(&pattern.graph());
    let t_node_amd = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let metis_perm = node_metis(&pattern.graph());
    let t_metis = clock.elapsed().as_secs_f64();
    for (label, perm, t_order) in [
        ("METIS", Some(metis_perm.as_slice()), t_metis),
        ("scalar AMD", None, 0.0),
        ("node AMD", Some(node_amd_perm.as_slice()), t_node_amd),
    ] {
        let clock = Instant::now();
        let sym = symbolic(perm);
        let t_symbolic = clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        numeric_llt(&sym, k.matrix(), cholesky_parallelism(&sym));
        let t_numeric = clock.elapsed().as_secs_f64();
        eprintln!(
            "{}: {label}: ordering {t_order:.3} s, symbolic (incl. ordering for scalar AMD) \
             {t_symbolic:.3} s, nnz(L) {}, numeric {t_numeric:.3} s",
            p.name,
            sym.len_val()
        );
    }
    let sym = symbolic(match order {
        Ordering::Given(perm) => Some(perm),
        Ordering::Amd => None,
    });
    eprintln!(
        "{}: {} particles, {} active nodes, {n} unknowns, nnz(lower K) {}, nnz(L) {}, method {}",
        p.name,
        m.particles.len(),
        p.sys.map.len(),
        k.values.len(),
        sym.len_val(),
        method.name(),
    );
    if let Some(dir) = std::env::var_os("MPM_EXPORT_TANGENTS") {
        export(std::path::Path::new(&dir), &p.name, k.matrix(), &b).expect("export");
    }
    if let Some(rounds) = std::env::var("MPM_BENCH_ALTERNATE")
        .ok()
        .and_then(|r| r.parse::<usize>().ok())
        .filter(|&r| r > 0)
    {
        alternate(p, &k, &sym, &b, rounds);
    }
    let mut group = c.benchmark_group(format!("implicit/{}", p.name));
    group.sample_size(10);
    group.throughput(Throughput::Elements(n as u64));
    let sys = &p.sys;
    group.bench_function("pattern", |bch| bch.iter(|| black_box(p.pattern().nodes())));
    group.bench_function("tangent", |bch| {
        bch.iter(|| black_box(tangent(m, sys, false).expect("tangent").values.len()))
    });
    group.bench_function("tangent_part/particle_tangents", |bch| {
        bch.iter(|| {
            black_box(
                particle_tangents(m, &sys.trial, &sys.stencils, &sys.map, false)
                    .expect("A")
                    .values
                    .len(),
            )
        })
    });
    group.bench_function("factorize_first", |bch| {
        bch.iter(|| {
            let mut s = DirectSolver::new();
            black_box(
                s.factorize(k.matrix(), Structure::Symmetric, order)
                    .expect("factorize"),
            )
        })
    });
    group.bench_function("factorize_refactor", |bch| {
        bch.iter(|| {
            black_box(
                solver
                    .factorize(k.matrix(), Structure::Symmetric, order)
                    .expect("ok"),
            )
        })
    });
    group.bench_function("numeric_llt", |bch| {
        bch.iter(|| black_box(numeric_llt(&sym, k.matrix(), cholesky_parallelism(&sym)).len()))
    });
    group.bench_function("numeric_llt_sequential", |bch| {
        bch.iter(|| black_box(numeric_llt(&sym, k.matrix(), faer::Par::Seq).len()))
    });
    group.bench_function("numeric_llt_two_tasks", |bch| {
        bch.iter(|| black_box(numeric_llt(&sym, k.matrix(), parallelism()).len()))
    });
    group.bench_function("solve", |bch| {
        bch.iter(|| black_box(solver.solve(&b).expect("solve")))
    });
    let mut fresh = sys.clone();
    // The direct path from scratch on a given matrix (what the CHOLMOD
    // comparison times: ordering, analysis, factorization, solve).
    group.bench_function("direct", |bch| {
        bch.iter(|| {
            let perm = fill_reducing::<D>(&pattern.graph(), DirectOrdering::Auto);
            let mut s = DirectSolver::new();
            s.factorize(k.matrix(), Structure::Symmetric, Ordering::Given(&perm))
                .expect("factorize");
            black_box(s.solve(&b).expect("solve"))
        })
    });
    // The first iteration of a step whose stencils changed: a new pattern,
    // ordering and symbolic factorization; the solver's buffers are those of
    // the earlier steps, as in a run.
    let mut kept = DirectSolver::new();
    kept.factorize(k.matrix(), Structure::Symmetric, order)
        .expect("factorize");
    group.bench_function("iteration_first", |bch| {
        bch.iter(|| {
            fresh.pattern = Default::default();
            kept.forget_pattern();
            black_box(
                factorized_tangent(m, &fresh, &mut kept, &b)
                    .expect("factorize")
                    .2,
            )
        })
    });
    // The first iteration of a run: fresh buffers too.
    group.bench_function("iteration_first_of_run", |bch| {
        bch.iter(|| {
            fresh.pattern = Default::default();
            let mut s = DirectSolver::new();
            black_box(
                factorized_tangent(m, &fresh, &mut s, &b)
                    .expect("factorize")
                    .2,
            )
        })
    });
    group.bench_function("iteration_later", |bch| {
        bch.iter(|| {
            black_box(
                factorized_tangent(m, sys, &mut solver, &b)
                    .expect("factorize")
                    .2,
            )
        })
    });
    group.finish();
}

/// The targets' ratios from interleaved timings (a noisy machine moves whole
/// criterion groups): `rounds` times in turn faer's numeric LLᵀ into fresh
/// buffers (the yardstick), the first iteration of a step whose stencils
/// changed and a later iteration; prints the medians and the ratios.
fn alternate<const D: usize>(
    p: &Problem<D>,
    k: &Tangent,
    sym: &SymbolicCholesky<Index>,
    b: &[f64],
    rounds: usize,
) {
    let (m, sys) = (&p.model, &p.sys);
    let mut fresh = sys.clone();
    let mut solver = DirectSolver::new();
    factorized_tangent(m, sys, &mut solver, b).expect("factorize");
    let mut kept = DirectSolver::new();
    factorized_tangent(m, sys, &mut kept, b).expect("factorize");
    let time = |f: &mut dyn FnMut()| {
        let clock = Instant::now();
        f();
        clock.elapsed().as_secs_f64()
    };
    // The yardstick also into kept buffers (faer at its fastest, no page faults).
    let par = cholesky_parallelism(sym);
    let mut values = vec![0.0; sym.len_val()];
    let mut mem = MemBuffer::new(sym.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
    let (mut yard, mut yard_kept) = (Vec::new(), Vec::new());
    let (mut first, mut later) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        yard.push(time(&mut || {
            black_box(numeric_llt(sym, k.matrix(), par));
        }));
        yard_kept.push(time(&mut || {
            numeric_llt_into(sym, k.matrix(), par, &mut values, &mut mem);
            black_box(&values);
        }));
        first.push(time(&mut || {
            fresh.pattern = Default::default();
            kept.forget_pattern();
            black_box(factorized_tangent(m, &fresh, &mut kept, b).expect("first"));
        }));
        later.push(time(&mut || {
            black_box(factorized_tangent(m, sys, &mut solver, b).expect("later"));
        }));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (y, f, l) = (median(&mut yard), median(&mut first), median(&mut later));
    let yk = median(&mut yard_kept);
    eprintln!(
        "{}: {rounds} alternating rounds, medians: numeric LLT {:.1} ms (kept buffers {:.1} \
         ms), first iteration {:.1} ms ({:.2}x; {:.2}x kept), later iteration {:.1} ms \
         ({:.2}x; {:.2}x kept)",
        p.name,
        y * 1e3,
        yk * 1e3,
        f * 1e3,
        f / y,
        f / yk,
        l * 1e3,
        l / y,
        l / yk
    );
}

/// Writes the lower triangle of K as a symmetric Matrix Market file
/// (`NAME.mtx`) and the right-hand side (`NAME_rhs.mtx`), for
/// scripts/cholmod/compare.sh.
fn export(
    dir: &std::path::Path,
    name: &str,
    k: faer::sparse::SparseColMatRef<Index, f64>,
    b: &[f64],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_sparse(&dir.join(format!("{name}.mtx")), k, true)?;
    write_vector(&dir.join(format!("{name}_rhs.mtx")), b)
}

fn implicit(c: &mut Criterion) {
    let large = std::env::var_os("MPM_BENCH_LARGE").is_some();
    let (cells_2d, cells_3d) = if large {
        ("[160,160]", "[20,20,20]")
    } else {
        ("[64,64]", "[12,12,12]")
    };
    let name_2d = format!(
        "block2d_{}",
        cells_2d.trim_matches(['[', ']']).replace(',', "x")
    );
    let name_3d = format!(
        "block3d_{}",
        cells_3d.trim_matches(['[', ']']).replace(',', "x")
    );
    let dim = std::env::var("MPM_BENCH_DIM").unwrap_or_default();
    if dim != "3" {
        bench_problem(c, &mut Problem::<2>::new(&name_2d, BLOCK_2D, cells_2d));
    }
    if dim != "2" {
        bench_problem(c, &mut Problem::<3>::new(&name_3d, BLOCK_3D, cells_3d));
    }
}

criterion_group!(benches, implicit);
criterion_main!(benches);
