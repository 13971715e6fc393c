//! One Newton iteration of the implicit solver, split into its costs: tangent
//! assembly, sparse factorization (first call = symbolic + numeric, and a
//! refactorization with the same pattern = numeric only) and the solve.
//!
//! The matrix is the one the solver sees at the first Newton iteration of the
//! first load step of a quasi-static run: stencils at the initial positions, trial
//! state at u = 0, consistent tangent A_p = ∂P/∂ΔF, no inertia term.
//!
//! Scenes: the column of problems/column.toml refined to 1×N cells (uGIMP, 2×2
//! particles per cell, 4N particles; its matrix is banded, so there is almost no
//! fill-in), and the square block of problems/bench/block.toml on 64×64 cells
//! under self-weight with a fixed base (16,384 particles, 2D coupling, real
//! fill-in). The solver's own pieces build the matrix: `stencils_and_nodes`, its
//! numbering of the unknowns and its particle tangents.
//!
//! At the initial lattice the particles sit where the outer uGIMP weights vanish,
//! so each particle touches 2×2 nodes instead of 3×3 and the first-step matrix
//! is much sparser than later ones. The `*_step2` variants therefore advance the
//! real solver by one load step first and measure the first iteration of step 2,
//! which is what the remaining 19 of the 20 load steps look like.
//!
//! Run: `cargo bench --bench implicit -- --noplot` (see docs/performance.md).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat, Triplet};
use faer::Side;
use mpm::dim::Vector;
use mpm::material::{Increment, StressDerivative};
use mpm::model::Model;
use mpm::physics::deformation::Trial;
use mpm::physics::shape::{ShapeFunction, Stencils};
use mpm::physics::transfer::{external_force, stencils_and_nodes, NodeMap};
use mpm::scene::Scene;
use mpm::solver::implicit::assembly::stiffness::{
    particle_tangents, stiffness_triplets, Pk1Derivative,
};
use mpm::solver::implicit::assembly::Dofs;
use mpm::solver::implicit::step::number_unknowns;
use mpm::solver::implicit::Implicit;
use mpm::solver::linear::direct::{DirectSolver, Structure};
use mpm::solver::stepper::Stepper;
use rayon::prelude::*;
use std::hint::black_box;

const COLUMN: &str = include_str!("../problems/column.toml");

/// The 10 m × 10 m block of problems/bench/block.toml (uGIMP, 2×2 particles per
/// cell, self-weight, fixed base), here on 64×64 cells in 20 load steps.
const BLOCK: &str = include_str!("../problems/bench/block.toml");

/// Everything one Newton iteration works on, built with the public API.
struct Problem {
    name: String,
    scene: Scene,
    model: Model<2>,
    shape: ShapeFunction,
    dt: f64,
    load_steps: usize,
}

impl Problem {
    fn new(name: String, file: &str, text: &str, overrides: &[String]) -> Problem {
        let scene = Scene::parse(file, text, overrides).expect("valid scene");
        let c = &scene.config;
        assert_eq!(c.dimension, 2);
        Problem {
            name,
            shape: c.grid.shape_function,
            dt: c.stages()[0].implicit_dt(),
            load_steps: c.stages()[0].load_steps.unwrap_or(1),
            model: Model::<2>::build(&scene).expect("model"),
            scene,
        }
    }

    fn column(n: usize) -> Problem {
        Problem::new(
            format!("column_{n}"),
            "problems/column.toml",
            COLUMN,
            &[format!("grid.cells=[1,{n}]")],
        )
    }

    fn block() -> Problem {
        Problem::new(
            "block_64x64".into(),
            "problems/bench/block.toml",
            BLOCK,
            &["grid.cells=[64,64]".into(), "solver.load_steps=20".into()],
        )
    }

    /// The same problem after `steps` converged load steps of the real solver: the
    /// matrix of the first Newton iteration of load step `steps + 1` (non-zero
    /// stress, F ≠ I, particles moved).
    fn after_steps(mut self, steps: usize) -> Problem {
        let mut solver = Implicit::<2>::new(self.shape, self.scene.config.stages()[0], 0.0);
        for step in 0..steps {
            solver
                .step(&mut self.model, step as f64 * self.dt, self.dt, step)
                .expect("converged");
        }
        self.name = format!("{}_step{}", self.name, steps + 1);
        self
    }
}

/// Work buffers of the assembly, reused between iterations like the solver does.
#[derive(Default)]
struct Workspace {
    stencils: Stencils<2>,
    map: NodeMap,
    trial: Trial,
    u: Vec<Vector<2>>,
}

/// Stencils at the step-start positions and the active-node map.
fn stencils_and_map(p: &Problem, w: &mut Workspace) {
    stencils_and_nodes(&p.model, p.shape, &mut w.stencils, &mut w.map);
}

/// The solver's numbering of the unknowns (weakly supported nodes tied).
fn dofs(p: &Problem, w: &Workspace) -> Dofs {
    let min_node_support = p.scene.config.stages()[0].min_node_support();
    number_unknowns(&p.model, &w.stencils, &w.map, min_node_support).1
}

/// Trial state at u = 0 (the first iterate of a quasi-static step).
fn trial_at_zero(p: &Problem, w: &mut Workspace) {
    let m = &p.model;
    w.u.clear();
    w.u.resize(w.map.len(), Vector::<2>::zeros());
    let inverted = w
        .trial
        .evaluate(&m.particles, &m.materials, &w.stencils, &w.map, &w.u, p.dt);
    assert!(inverted.is_none());
}

/// A_p = ∂P/∂ΔF of every particle at the trial state.
fn pk1_derivatives(p: &Problem, w: &Workspace) -> Vec<Pk1Derivative> {
    particle_tangents(&p.model, &w.trial, false).expect("analytic tangent")
}

/// ∂σ/∂ΔF of every particle alone (the material part of `pk1_derivatives`).
fn stress_derivatives(p: &Problem, w: &Workspace) -> Vec<StressDerivative> {
    let x = &p.model.particles;
    let history_old = x.history.slots(&x.history.data);
    (0..x.len())
        .into_par_iter()
        .with_min_len(512)
        .map(|q| {
            let inc = Increment {
                f_old: x.f[q],
                df: w.trial.df[q],
                dt: 0.0,
                stress_old: x.stress[q],
                history_old: history_old[q],
            };
            p.model.materials[x.material[q] as usize]
                .stress_derivative(&inc)
                .expect("analytic tangent")
        })
        .collect()
}

/// The whole assembly of one Newton iteration.
fn assemble(p: &Problem, w: &mut Workspace) -> (Dofs, Vec<(usize, usize, f64)>, Structure) {
    stencils_and_map(p, w);
    let dofs = dofs(p, w);
    trial_at_zero(p, w);
    let a = pk1_derivatives(p, w);
    let (triplets, symmetric) =
        stiffness_triplets(&w.map, &w.stencils, &dofs, &p.model.particles.volume, &a);
    let structure = Structure::of(symmetric);
    (dofs, triplets, structure)
}

/// Right-hand side of the first iteration of the first step: −r(0) = f_ext at the
/// first load factor (the internal force vanishes at zero initial stress), free
/// components. For the `*_step2` variants it is just a realistic vector (the solve
/// time does not depend on it).
fn rhs(p: &Problem, w: &Workspace, dofs: &Dofs) -> Vec<f64> {
    let m = &p.model;
    let g = m.gravity / p.load_steps as f64;
    let f = external_force(&w.map, &w.stencils, &m.particles, &g, &|_| 0.0);
    dofs.reduce(&f)
}

/// The lower triangle of K in CSC form, as the direct solver builds it from the
/// triplets (duplicates summed).
fn lower_csc(n: usize, triplets: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let lower: Vec<Triplet<usize, usize, f64>> = triplets
        .iter()
        .filter(|t| t.0 >= t.1)
        .map(|&(r, c, v)| Triplet::new(r, c, v))
        .collect();
    SparseColMat::try_new_from_triplets(n, n, &lower).expect("csc")
}

/// faer's symbolic Cholesky with AMD ordering (what `DirectSolver` computes once
/// per pattern).
fn symbolic(a: &SparseColMat<usize, f64>) -> SymbolicCholesky<usize> {
    factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams::default(),
    )
    .expect("symbolic")
}

/// faer's numeric LLᵀ alone, with a given symbolic factorization.
fn numeric_llt(sym: &SymbolicCholesky<usize>, a: &SparseColMat<usize, f64>) -> Vec<f64> {
    let par = faer::get_global_parallelism();
    let mut values = vec![0.0; sym.len_val()];
    let req = sym.factorize_numeric_llt_scratch::<f64>(par, Default::default());
    let mut mem = MemBuffer::new(req);
    sym.factorize_numeric_llt(
        &mut values,
        a.as_ref(),
        Side::Lower,
        Default::default(),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .expect("positive definite");
    values
}

fn bench_problem(c: &mut Criterion, p: &Problem) {
    let mut w = Workspace::default();
    let (dofs, triplets, structure) = assemble(p, &mut w);
    let b = rhs(p, &w, &dofs);
    let n = dofs.free;
    let lower = lower_csc(n, &triplets);
    let sym = symbolic(&lower);
    let (nnz_lower, nnz_factor) = (lower.compute_nnz(), sym.len_val());
    let mut solver = DirectSolver::new();
    let method = solver
        .factorize(n, &triplets, structure)
        .expect("factorize");
    eprintln!(
        "{}: {} particles, {:.2} nodes per particle, {} active nodes, {} unknowns, {} triplets, {:?}, method {}, \
         nnz(lower K) {}, nnz(L) {} (fill ratio {:.2})",
        p.name,
        p.model.particles.len(),
        w.stencils.count.iter().map(|&k| k as f64).sum::<f64>() / p.model.particles.len() as f64,
        w.map.len(),
        n,
        triplets.len(),
        structure,
        method.name(),
        nnz_lower,
        nnz_factor,
        nnz_factor as f64 / nnz_lower as f64
    );

    let mut group = c.benchmark_group(format!("implicit/{}", p.name));
    group.sample_size(10);
    group.throughput(Throughput::Elements(p.model.particles.len() as u64));

    // (a) Assembly, whole and in parts.
    group.bench_function("assembly", |bch| {
        bch.iter(|| black_box(assemble(p, &mut w).1.len()))
    });
    group.bench_function(BenchmarkId::new("assembly_part", "stencils_map"), |bch| {
        bch.iter(|| stencils_and_map(p, &mut w))
    });
    group.bench_function(BenchmarkId::new("assembly_part", "trial"), |bch| {
        bch.iter(|| trial_at_zero(p, &mut w))
    });
    group.bench_function(BenchmarkId::new("assembly_part", "pk1_derivative"), |bch| {
        bch.iter(|| black_box(pk1_derivatives(p, &w).len()))
    });
    group.bench_function(
        BenchmarkId::new("assembly_part", "stress_derivative_only"),
        |bch| bch.iter(|| black_box(stress_derivatives(p, &w).len())),
    );
    let a = pk1_derivatives(p, &w);
    group.bench_function(BenchmarkId::new("assembly_part", "triplets"), |bch| {
        bch.iter(|| {
            let (t, s) =
                stiffness_triplets(&w.map, &w.stencils, &dofs, &p.model.particles.volume, &a);
            black_box((t.len(), s))
        })
    });

    // (b) Factorization: first call (symbolic + numeric) and refactorization.
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function("factorize_first", |bch| {
        bch.iter(|| {
            let mut s = DirectSolver::new();
            black_box(s.factorize(n, &triplets, structure).expect("factorize"))
        })
    });
    group.bench_function("factorize_refactor", |bch| {
        bch.iter(|| {
            black_box(
                solver
                    .factorize(n, &triplets, structure)
                    .expect("factorize"),
            )
        })
    });
    assert_eq!(solver.symbolic_count(), 1, "the pattern was reused");

    // Where the factorization time goes: faer alone, outside `DirectSolver`
    // (which adds the pattern comparison and a probe solve with three products).
    if structure == Structure::Symmetric {
        group.bench_function(
            BenchmarkId::new("factorize_part", "triplets_to_csc"),
            |bch| bch.iter(|| black_box(lower_csc(n, &triplets).compute_nnz())),
        );
        // What-if: the same CSC matrix when the pattern and the value order
        // (faer's argsort) are cached, i.e. only the values are scattered.
        let pairs: Vec<Pair<usize, usize>> = triplets
            .iter()
            .filter(|t| t.0 >= t.1)
            .map(|&(row, col, _)| Pair { row, col })
            .collect();
        let (pattern, order) =
            SymbolicSparseColMat::try_new_from_indices(n, n, &pairs).expect("pattern");
        group.bench_function(
            BenchmarkId::new("factorize_part", "csc_from_cached_order"),
            |bch| {
                bch.iter(|| {
                    let values: Vec<f64> = triplets
                        .iter()
                        .filter(|t| t.0 >= t.1)
                        .map(|t| t.2)
                        .collect();
                    let a = SparseColMat::new_from_argsort(pattern.clone(), &order, &values)
                        .expect("csc");
                    black_box(a.compute_nnz())
                })
            },
        );
        group.bench_function(BenchmarkId::new("factorize_part", "symbolic_amd"), |bch| {
            bch.iter(|| black_box(symbolic(&lower).len_val()))
        });
        group.bench_function(BenchmarkId::new("factorize_part", "numeric_llt"), |bch| {
            bch.iter(|| black_box(numeric_llt(&sym, &lower).len()))
        });
    }

    // (c) Solve with the factors.
    group.bench_function("solve", |bch| {
        bch.iter(|| black_box(solver.solve(&b).expect("solve")))
    });
    group.finish();
}

fn implicit(c: &mut Criterion) {
    for n in [64, 256, 1024] {
        bench_problem(c, &Problem::column(n));
    }
    bench_problem(c, &Problem::column(1024).after_steps(1));
    bench_problem(c, &Problem::block());
    bench_problem(c, &Problem::block().after_steps(1));
}

criterion_group!(benches, implicit);
criterion_main!(benches);
