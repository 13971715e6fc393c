//! The cost of contact between bodies in an explicit step (issue 14): one step of
//! a 2D scene of ten horizontal stripes that alternate between two velocity fields
//! (stripes of one field have no contact between them, so they share a field), so
//! that about a tenth of the active nodes are contact nodes, against the same scene
//! without `[[contact]]` (one field). The contact pass costs the difference.

use criterion::{criterion_group, criterion_main, Criterion};
use mpm::model::Model;
use mpm::scene::Scene;

/// The stripes scene with `n` cells per direction; `contact`: the two fields'
/// stripes in contact with each other.
fn scene(n: usize, contact: bool) -> String {
    let mut s = format!(
        "dimension = 2\ngravity = [0.0, -9.81]\n\n[grid]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\n\
         cells = [{n}, {n}]\nshape_function = \"cpgimp\"\n\n[[material]]\nname = \"m\"\n\
         model = \"neo_hookean\"\ndensity = 1000.0\nyoungs_modulus = 1.0e6\npoisson_ratio = 0.3\n\n"
    );
    for k in 0..10 {
        let name = if k % 2 == 0 {
            format!("a{k}")
        } else {
            format!("b{k}")
        };
        s += &format!(
            "[[body]]\nname = \"{name}\"\nmaterial = \"m\"\nshape = \"rectangle\"\n\
             min = [0.0, {}]\nmax = [1.0, {}]\n\n",
            k as f64 / 10.0,
            (k + 1) as f64 / 10.0
        );
    }
    if contact {
        for a in (0..10).step_by(2) {
            for b in (1..10).step_by(2) {
                s += &format!(
                    "[[contact]]\nbodies = [\"a{a}\", \"b{b}\"]\nfriction_coefficient = 0.3\n\n"
                );
            }
        }
    }
    s += "[[boundary]]\nface = \"ymin\"\ncondition = \"fixed\"\n\n\
          [[boundary]]\nface = \"xmin\"\ncondition = \"roller\"\n\n\
          [[boundary]]\nface = \"xmax\"\ncondition = \"roller\"\n\n\
          [solver]\nkind = \"explicit\"\nend_time = 1.0\ncfl = 0.5\n";
    s
}

fn step(c: &mut Criterion) {
    let n = 100;
    let mut group = c.benchmark_group("explicit_step_stripes_100x100");
    group.sample_size(20);
    for contact in [false, true] {
        let scene = Scene::parse("stripes.toml", &scene(n, contact), &[]).unwrap();
        let mut model = Model::<2>::build(&scene).unwrap();
        let solver = scene.config.stages()[0].clone();
        let mut stepper = mpm::solver::stepper::<2>(scene.config.grid.shape_function, &solver, 0.0);
        let dt = stepper.dt(&model);
        // Settle into contact first, so that the contact nodes are active.
        for k in 0..20 {
            stepper.step(&mut model, k as f64 * dt, dt, k).unwrap();
        }
        let name = if contact { "contact" } else { "one_field" };
        let mut k = 20;
        group.bench_function(name, |b| {
            b.iter(|| {
                stepper.step(&mut model, k as f64 * dt, dt, k).unwrap();
                k += 1;
            })
        });
        println!(
            "{name}: {} particles, {} active nodes in the last step",
            model.particles.len(),
            stepper.active_nodes()
        );
    }
    group.finish();
}

criterion_group!(benches, step);
criterion_main!(benches);
