//! P2G and G2P kernels per shape function, 2D and 3D. Throughput is reported in
//! particles per second (criterion's "elements").
//!
//! P2G = shape-function evaluation + active-node map + nodal mass, momentum and
//! force. G2P = interpolation of nodal velocity and acceleration to particles and
//! the velocity gradient (what the explicit step does per particle).
//! `scatter_p2g` and `scatter_g2p` are the same work on the explicit step's box
//! of nodes (`solver::explicit::node_box`, the families it serves): the box and the tile
//! order, the coloured scatter of mass, momentum and force; the 1D factors
//! evaluated again per particle and the same three sums.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mpm::dim::{restrict, Mat3, Tensor, Vector};
use mpm::model::grid::Grid;
use mpm::model::particles::Particles;
use mpm::physics::shape::{ShapeFunction, Stencils};
use mpm::physics::transfer::{gradient, interpolate, mass_momentum, nodal_force, NodeMap};
use mpm::solver::explicit::node_box::{NodeBox, Points, Stencil};
use rayon::prelude::*;

const SHAPES: [ShapeFunction; 6] = [
    ShapeFunction::Linear,
    ShapeFunction::Ugimp,
    ShapeFunction::Cpgimp,
    ShapeFunction::Cpdi,
    ShapeFunction::Bspline2,
    ShapeFunction::Bspline3,
];

/// A block of particles, 2 per cell direction, filling the inner half of a grid of
/// `n` cells per direction, slightly sheared so that CPDI domains are not axis-aligned.
fn setup<const D: usize>(n: usize, shape: ShapeFunction) -> (Grid<D>, Particles<D>) {
    let grid = Grid::<D>::new(
        Vector::<D>::zeros(),
        Vector::<D>::repeat(1.0),
        [n; D],
        shape.degree(),
    );
    let mut p = Particles::<D>::default();
    let h = 1.0 / n as f64;
    let per_dir = n; // 2 per cell over half the grid
    let total = per_dir.pow(D as u32);
    for k in 0..total {
        let mut rem = k;
        let x = Vector::<D>::from_fn(|_, _| {
            let i = rem % per_dir;
            rem /= per_dir;
            0.25 + (i as f64 + 0.5) * h / 2.0
        });
        p.push(
            x,
            Vector::<D>::repeat(0.1),
            1.0,
            (h / 2.0).powi(D as i32),
            Vector::<D>::repeat(h / 4.0),
            0,
            0,
            0,
        );
    }
    let mut f = Mat3::identity();
    f[(0, 1)] = 0.1;
    p.f.iter_mut().for_each(|mut slot| slot.set(&f));
    let s = Mat3::new(1.0, 0.2, 0.0, 0.2, -1.0, 0.0, 0.0, 0.0, 0.5);
    p.stress.iter_mut().for_each(|mut slot| slot.set(&s));
    (grid, p)
}

fn bench_dim<const D: usize>(c: &mut Criterion, n: usize) {
    let mut group = c.benchmark_group(format!("transfer_{D}d"));
    group.sample_size(10);
    for shape in SHAPES {
        let (grid, p) = setup::<D>(n, shape);
        group.throughput(Throughput::Elements(p.len() as u64));
        let mut st = Stencils::<D>::default();
        let mut map = NodeMap::default();
        let gravity = Vector::<D>::zeros();
        group.bench_with_input(
            BenchmarkId::new("p2g", shape.name()),
            &shape,
            |b, &shape| {
                b.iter(|| {
                    st.compute(shape, &grid, &p.x, &p.half_length0, &p.f);
                    map.build(&st, grid.node_count());
                    let (m, mv) = mass_momentum(&map, &st, &p, None);
                    let f = nodal_force(&map, &st, &p, &gravity, &|_| 0.0);
                    (m.len(), mv.len(), f.len())
                })
            },
        );
        st.compute(shape, &grid, &p.x, &p.half_length0, &p.f);
        map.build(&st, grid.node_count());
        let nodal: Vec<Vector<D>> = (0..map.len())
            .map(|a| Vector::<D>::repeat(a as f64 * 1e-3))
            .collect();
        group.bench_with_input(BenchmarkId::new("g2p", shape.name()), &shape, |b, _| {
            b.iter(|| {
                (0..p.len())
                    .into_par_iter()
                    .map(|q| {
                        let v = interpolate(&map, &st, q, &nodal);
                        let a = interpolate(&map, &st, q, &nodal);
                        let l: Tensor<D> = gradient(&map, &st, q, &nodal);
                        v.sum() + a.sum() + l.trace()
                    })
                    .sum::<f64>()
            })
        });
        if NodeBox::<D>::serves(shape) {
            scatter_benches(&mut group, shape, &grid, &p);
        }
    }
    group.finish();
}

/// `scatter_p2g` and `scatter_g2p` of one family (module doc).
fn scatter_benches<const D: usize>(
    group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>,
    shape: ShapeFunction,
    grid: &Grid<D>,
    p: &Particles<D>,
) {
    let mut nb = NodeBox::<D>::default();
    let mut nodes: Vec<(f64, Vector<D>, Vector<D>)> = Vec::new();
    let gravity = Vector::<D>::zeros();
    group.bench_with_input(
        BenchmarkId::new("scatter_p2g", shape.name()),
        &shape,
        |b, &shape| {
            b.iter(|| {
                nb.locate(shape, grid, &p.x, &[]);
                nodes.clear();
                nodes.resize(
                    nb.nodes(),
                    (0.0, Vector::<D>::zeros(), Vector::<D>::zeros()),
                );
                let source = |q: usize, _: &Stencil<D>| {
                    let stress: Tensor<D> = restrict::<D>(&p.stress.get(q)) * p.volume[q];
                    (p.mass[q], p.v[q] * p.mass[q], gravity * p.mass[q], stress)
                };
                nb.scatter(
                    shape,
                    grid,
                    Points::of(p),
                    &mut nodes,
                    source,
                    |n, s, w, g| {
                        n.0 += s.0 * w;
                        n.1 += s.1 * w;
                        n.2 += s.2 * w - s.3 * g;
                    },
                );
                nodes.len()
            })
        },
    );
    nb.locate(shape, grid, &p.x, &[]);
    let nodal: Vec<Vector<D>> = (0..nb.nodes())
        .map(|b| Vector::<D>::repeat(b as f64 * 1e-3))
        .collect();
    group.bench_with_input(
        BenchmarkId::new("scatter_g2p", shape.name()),
        &shape,
        |b, &shape| {
            b.iter(|| {
                (0..p.len())
                    .into_par_iter()
                    .map(|q| {
                        let st = nb.stencil(shape, grid, &p.x[q], &p.half_length0[q], &p.f.get(q));
                        let (mut v, mut a, mut l) = (
                            Vector::<D>::zeros(),
                            Vector::<D>::zeros(),
                            Tensor::<D>::zeros(),
                        );
                        st.expect("inside the grid")
                            .for_each(&nb.stride, |b, w, g| {
                                v += nodal[b] * w;
                                a += nodal[b] * w;
                                l += nodal[b] * g.transpose();
                            });
                        v.sum() + a.sum() + l.trace()
                    })
                    .sum::<f64>()
            })
        },
    );
}

/// P2G split into its parts (2D, linear and CPDI): shape-function evaluation, the
/// active-node map (sequential), and the nodal gathers.
fn p2g_parts(c: &mut Criterion) {
    let mut group = c.benchmark_group("p2g_parts_2d");
    group.sample_size(10);
    for shape in [ShapeFunction::Linear, ShapeFunction::Cpdi] {
        let (grid, p) = setup::<2>(256, shape);
        group.throughput(Throughput::Elements(p.len() as u64));
        let mut st = Stencils::<2>::default();
        let mut map = NodeMap::default();
        group.bench_function(BenchmarkId::new("stencils", shape.name()), |b| {
            b.iter(|| st.compute(shape, &grid, &p.x, &p.half_length0, &p.f))
        });
        group.bench_function(BenchmarkId::new("node_map", shape.name()), |b| {
            b.iter(|| map.build(&st, grid.node_count()))
        });
        let gravity = Vector::<2>::zeros();
        group.bench_function(BenchmarkId::new("gathers", shape.name()), |b| {
            b.iter(|| {
                let (m, mv) = mass_momentum(&map, &st, &p, None);
                let f = nodal_force(&map, &st, &p, &gravity, &|_| 0.0);
                (m.len(), mv.len(), f.len())
            })
        });
    }
    group.finish();
}

fn transfer(c: &mut Criterion) {
    bench_dim::<2>(c, 256); // 65,536 particles
    bench_dim::<3>(c, 40); // 64,000 particles
}

criterion_group!(benches, transfer, p2g_parts);
criterion_main!(benches);
