//! Bond updates per second of a peridynamic body (issue 51, "Performance"): one
//! evaluation of `physics::peridynamics::bond_forces` on a lattice body of
//! horizon m = 3 (the break check against s0, then each particle's sum over its
//! intact bonds), for the PMB and the correspondence laws, in 2D (200², 560,000
//! bonds) and 3D (40³, 3.9 million bonds), under a small uniform stretch that
//! breaks none. Criterion's throughput is in bonds per second: a "bond update"
//! is one bond's force found and applied to both its ends in one step (the
//! per-particle sums visit each bond from both ends, so twice its pair force).
//! The bytes per bond of `model::peridynamics::bonds::Bonds` beyond the
//! particle data are printed before the runs.
//!
//! `short_range`: one evaluation of `physics::peridynamics::short_range::forces`
//! on the 2D 200² PMB lattice cut in two along its middle (no bond across),
//! the right part pressed 0.2 Δx into the left: the search among the exposed
//! particles (faces and the cut) and the repulsion of the pressed pairs, in
//! exposed particles per second.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mpm::dim::Vector;
use mpm::material::bond::correspondence::{Correspondence, ZERO_ENERGY_CONTROL};
use mpm::material::bond::short_range::{self, ShortRange};
use mpm::material::bond::{pmb::Pmb, BondLaw, Space};
use mpm::material::linear_elastic::LinearElastic;
use mpm::model::peridynamics::bonds::Bonds;
use mpm::model::peridynamics::state::StressState;
use mpm::model::peridynamics::PdBody;
use mpm::physics::peridynamics::bond_forces;
use mpm::physics::peridynamics::short_range::forces;

const E: f64 = 70e9;
const NU: f64 = 0.25;
const DX: f64 = 1e-3;
/// Uniform stretch of the deformed positions, below the critical stretch.
const STRETCH: f64 = 1e-4;
const S0: f64 = 1e-2;

/// n^D lattice points of spacing DX.
fn lattice<const D: usize>(n: usize) -> Vec<Vector<D>> {
    (0..n.pow(D as u32))
        .map(|q| Vector::<D>::from_fn(|d, _| ((q / n.pow(d as u32)) % n) as f64 * DX))
        .collect()
}

fn space(d: usize) -> Space {
    if d == 3 {
        Space::ThreeD
    } else {
        Space::PlaneStrain
    }
}

fn pmb(d: usize) -> BondLaw {
    BondLaw::Pmb(Pmb::new(space(d), E, 3.0 * DX).with_critical_stretch(S0))
}

fn correspondence(d: usize) -> BondLaw {
    // P-wave modulus of E and ν.
    let m = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    BondLaw::Correspondence(
        Correspondence::new(space(d), m, 3.0 * DX, ZERO_ENERGY_CONTROL).with_critical_stretch(S0),
    )
}

fn body<const D: usize>(x: &[Vector<D>], law: BondLaw) -> PdBody<D> {
    let v = vec![DX.powi(D as i32); x.len()];
    let b = PdBody::new(0, (0..x.len()).collect(), x, v, law);
    match law {
        BondLaw::Correspondence(_) => {
            let elastic = LinearElastic::new(1.0, E, NU);
            b.with_stress(StressState::at_rest(Box::new(elastic), x.len()))
        }
        _ => b,
    }
}

/// Bytes of `bonds` per bond, its vectors at their lengths.
fn bytes_per_bond(bonds: &Bonds) -> f64 {
    let bytes = std::mem::size_of_val(&bonds.first[..])
        + std::mem::size_of_val(&bonds.upper[..])
        + std::mem::size_of_val(&bonds.length[..])
        + std::mem::size_of_val(&bonds.intact[..])
        + std::mem::size_of_val(&bonds.below_offset[..])
        + std::mem::size_of_val(&bonds.below_bond[..])
        + std::mem::size_of_val(&bonds.below_end[..])
        + std::mem::size_of_val(&bonds.exposed[..]);
    bytes as f64 / bonds.len() as f64
}

fn run<const D: usize>(c: &mut Criterion, n: usize) {
    let x = lattice::<D>(n);
    let y: Vec<Vector<D>> = x.iter().map(|p| p * (1.0 + STRETCH)).collect();
    let mut group = c.benchmark_group(format!("bond_forces_{D}d_{n}"));
    group.sample_size(10);
    for (name, law) in [("pmb", pmb(D)), ("correspondence", correspondence(D))] {
        let mut b = body(&x, law);
        let bonds = b.bonds.len();
        eprintln!(
            "{D}D {n}^{D} {name}: {} particles, {bonds} bonds, {:.1} bytes per bond",
            x.len(),
            bytes_per_bond(&b.bonds)
        );
        group.throughput(Throughput::Elements(bonds as u64));
        group.bench_function(BenchmarkId::from_parameter(name), |bench| {
            bench.iter(|| bond_forces(&mut b, &y, 1e-8))
        });
        assert!(b.bonds.intact.iter().all(|&i| i), "no bond breaks");
    }
    group.finish();
}

fn bonds(c: &mut Criterion) {
    run::<2>(c, 200);
    run::<3>(c, 40);
}

fn short_range(c: &mut Criterion) {
    let n = 200;
    let x = lattice::<2>(n);
    let right = |i: usize| i % n >= n / 2;
    let law = pmb(2);
    let cut = Bonds::build_where(&x, law.horizon(), |i, j| right(i) == right(j));
    let v = vec![DX * DX; x.len()];
    let repulsion = ShortRange::new(short_range::FACTOR, law.micromodulus(), law.horizon());
    let mut b = PdBody::with_bonds(0, (0..x.len()).collect(), &x, v, law, cut)
        .with_short_range(Some(repulsion));
    b.start_x = (x.iter().enumerate())
        .map(|(i, p)| p - Vector::<2>::new(if right(i) { 0.2 * DX } else { 0.0 }, 0.0))
        .collect();
    let exposed = b.bonds.exposed.iter().filter(|&&e| e).count();
    let bodies = [b];
    let pressed = forces(&bodies)[0].as_ref().map_or(0, |f| {
        f.iter().filter(|f| **f != Vector::<2>::zeros()).count()
    });
    eprintln!("short range 2D {n}^2: {exposed} exposed particles, {pressed} pressed");
    assert!(pressed > 0, "the cut is pressed");
    let mut group = c.benchmark_group(format!("short_range_2d_{n}"));
    group.sample_size(10);
    group.throughput(Throughput::Elements(exposed as u64));
    group.bench_function("cut_pressed", |bench| bench.iter(|| forces(&bodies)));
    group.finish();
}

criterion_group!(benches, bonds, short_range);
criterion_main!(benches);
