//! Tests of the implicit solver as a whole: the assembled tangent against central
//! differences of the residual (with ties, F-bar and absorbing faces), and the ties
//! of weakly supported nodes.

use super::residual::{residual, tangent};
use super::step::StepSystem;
use super::Implicit;
use crate::dim::Vector;
use crate::model::Model;
use crate::scene::Scene;

/// A 2D block on a 4 × 4 grid, fixed base, gravity and a corner load, Newmark:
/// the fixture of the implicit solver's tests (here and in `krylov`).
pub(super) const BLOCK: &str = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [4.0, 4.0]
cells = [4, 4]
shape_function = "linear"
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "rectangle"
min = [0.5, 0.0]
max = [3.0, 2.5]
[[boundary]]
face = "ymin"
condition = "fixed"
[[load]]
kind = "point"
region_min = [2.5, 2.0]
region_max = [3.0, 2.5]
force = [3.0e3, -1.0e3]
[solver]
kind = "implicit"
integrator = "newmark"
end_time = 1.0
dt = 0.01
"#;

/// Absorbing faces for the tangent check: dashpots and springs (thesis 2-63).
const ABSORBING: &str = "[[boundary]]\nface = \"xmin\"\ncondition = \"absorbing\"\nspring_distance = 2.0\n[[boundary]]\nface = \"ymin\"\ncondition = \"absorbing\"\nspring_stiffness = [4.0e4, 1.0e4]\n";

/// max |K − K_fd| / max |K| of the assembled tangent against central
/// differences of the residual (2-37), column by column, at a smooth
/// finite-strain iterate of the block with these overrides; also the number of
/// unknowns, of tied nodes and of particles with plastic strain at the iterate.
fn tangent_error(overrides: &[String], absorbing: bool) -> (f64, usize, usize, usize) {
    let text = if absorbing {
        BLOCK.replace("[solver]", &format!("{ABSORBING}[solver]"))
    } else {
        BLOCK.to_string()
    };
    tangent_error_of::<2>(&text, overrides, absorbing)
}

/// `tangent_error` of any scene, in D dimensions.
fn tangent_error_of<const D: usize>(
    text: &str,
    overrides: &[String],
    absorbing: bool,
) -> (f64, usize, usize, usize) {
    let scene = Scene::parse("block.toml", text, overrides).unwrap();
    let m = Model::<D>::build(&scene).unwrap();
    let mut solver = Implicit::<D>::new(
        scene.config.grid.shape_function,
        scene.config.stages()[0],
        0.0,
    );
    solver.prepare(&m, 0.0, 0.01);
    let sys = &mut solver.system;
    let layer =
        crate::physics::boundary::absorbing::layer(&m.absorbing, &m.grid, &m.particles, 0.0);
    assert_eq!(layer.is_empty(), !absorbing);
    // A smooth, finite-strain iterate (strains of a few per cent).
    let nodes: Vec<usize> = (0..sys.map.len()).map(|a| sys.map.grid_node(a)).collect();
    let mut u: Vec<Vector<D>> = nodes
        .iter()
        .zip(&sys.constraint)
        .map(|(&g, c)| {
            let x = m.grid.node_position(m.grid.node_ijk(g));
            Vector::<D>::from_fn(|d, _| match d {
                _ if c.fixed[d] => 0.0,
                0 => 0.03 * (0.7 * x[1]).sin() + 0.01 * x[0],
                1 => -0.02 * x[0] * x[1] / 4.0,
                _ => 0.02 * (0.9 * x[0]).cos() * x[2] - 0.01 * x[1],
            })
        })
        .collect();
    // With contact between deformable bodies, the nodes of the second body are
    // pushed into the first (`SHIFT`).
    if let Some(fields) = sys.grid.node_fields() {
        let shift = SHIFT.with(|s| s.get());
        for (a, u_a) in u.iter_mut().enumerate() {
            if fields.field(a) > 0 {
                let x = m.grid.node_position(m.grid.node_ijk(nodes[a]));
                u_a[0] += shift[0] * x[0];
                u_a[1] -= shift[1];
            }
        }
    }
    let dofs = sys.dofs.clone();
    dofs.follow_ties(&mut u);
    let tied = dofs.ties.iter().filter(|t| t.is_some()).count();
    let res =
        |sys: &mut StepSystem<D>, u: &[Vector<D>]| dofs.reduce(&residual(&m, sys, u).unwrap());
    res(sys, &u);
    // History of the materials used here: equivalent plastic strain or none.
    let plastic = sys.trial.history.iter().filter(|&&k| k > 0.0).count();
    let n = dofs.free;
    let mut k = vec![0.0; n * n];
    let kt = tangent(&m, sys, false).unwrap();
    let report = sys.report();
    if report.contact_penetration.is_some() {
        CONTACTS.with(|x| x.set((report.sticking, report.slipping)));
    }
    let km = kt.matrix();
    for c in 0..n {
        for (&r, &v) in km.row_idx_of_col_raw(c).iter().zip(km.val_of_col(c)) {
            let r = r as usize;
            k[r * n + c] += v;
            if kt.symmetric() && r != c {
                k[c * n + r] += v;
            }
        }
    }
    if kt.symmetric() {
        lower_equals_full_stiffness(&m, sys);
    }
    let kmax = k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let h = 1e-7;
    let mut worst: f64 = 0.0;
    for col in 0..n {
        let (mut up, mut um) = (u.clone(), u.clone());
        let mut e = vec![0.0; n];
        e[col] = 1.0;
        dofs.apply_correction(&mut up, &e, h);
        dofs.apply_correction(&mut um, &e, -h);
        let (rp, rm) = (res(sys, &up), res(sys, &um));
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * h);
            worst = worst.max((fd - k[row * n + col]).abs());
        }
    }
    (worst / kmax, n, tied, plastic)
}

/// The stiffness assembled into the lower triangle (where a particle's blocks
/// for nodes before the column's node are not computed) has, bit for bit, the
/// values of the full assembly's lower triangle, ties included.
fn lower_equals_full_stiffness<const D: usize>(m: &Model<D>, sys: &StepSystem<D>) {
    use super::assembly::stiffness::{add_stiffness, particle_tangents};
    use super::assembly::{Storage, Tangent};
    let a = particle_tangents(m, &sys.trial, &sys.stencils, &sys.map, false).unwrap();
    let pattern = super::residual::step_pattern(sys);
    let assemble = |storage| {
        let col_ptr = pattern.col_ptr(storage).unwrap();
        let values = vec![0.0; col_ptr[col_ptr.len() - 1] as usize];
        let mut t = Tangent {
            pattern,
            col_ptr,
            values,
            storage,
        };
        let (map, st, dofs) = (&sys.map, &sys.stencils, &sys.dofs);
        add_stiffness(&mut t, map, st, dofs, &m.particles.volume, &a);
        t
    };
    let (lower, full) = (assemble(Storage::Lower), assemble(Storage::Full));
    let (l, f) = (lower.matrix(), full.matrix());
    for c in 0..l.ncols() {
        let full_col: Vec<(usize, f64)> = f
            .row_idx_of_col_raw(c)
            .iter()
            .map(|&r| r as usize)
            .zip(f.val_of_col(c).iter().copied())
            .filter(|&(r, _)| r >= c)
            .collect();
        let lower_col: Vec<(usize, f64)> = l
            .row_idx_of_col_raw(c)
            .iter()
            .map(|&r| r as usize)
            .zip(l.val_of_col(c).iter().copied())
            .collect();
        assert_eq!(lower_col, full_col, "column {c}");
    }
}

/// The assembled tangent (material + geometric + inertia, 2-40…2-42, and the
/// dashpots and springs of absorbing faces) against central differences of the
/// residual (2-37), column by column, at a non-trivial iterate, for every
/// material, several shape functions and both mass matrices. Two cases tie many
/// weakly supported nodes (a large `min_node_support`), so the tangent is
/// checked through the ties too; three have absorbing faces.
#[test]
fn global_tangent_matches_finite_differences_of_the_residual() {
    for (model, shape, mass, support, absorbing) in [
        ("hencky", "linear", "lumped", 0.0, false),
        ("hencky", "cpdi", "consistent", 0.01, false),
        ("neo_hookean", "bspline2", "lumped", 0.01, false),
        ("linear_elastic", "ugimp", "lumped", 0.01, false),
        ("neo_hookean", "cpgimp", "consistent", 0.01, false),
        ("hencky", "bspline2", "consistent", 0.3, false),
        ("hencky", "ugimp", "lumped", 0.3, false),
        ("hencky", "linear", "lumped", 0.0, true),
        ("linear_elastic", "bspline2", "consistent", 0.01, true),
        ("hencky", "ugimp", "lumped", 0.3, true),
    ] {
        let overrides = vec![
            format!("material.0.model={model}"),
            format!("grid.shape_function={shape}"),
            format!("solver.mass={mass}"),
            format!("solver.min_node_support={support}"),
        ];
        let (error, n, tied, _) = tangent_error(&overrides, absorbing);
        println!(
            "{model} {shape} {mass} absorbing={absorbing}: {n} unknowns, {tied} tied nodes, \
             max |K − K_fd| / max|K| = {error:.2e}"
        );
        assert!(
            error < 1e-6,
            "{model} {shape} {mass}: tangent off by {error:.2e} of its largest entry"
        );
    }
}

/// The same for every shape function (Hencky, lumped mass, light ties), so that
/// a family added to `ShapeFunction` has its tangent checked.
#[test]
fn global_tangent_matches_finite_differences_for_every_shape_function() {
    use strum::IntoEnumIterator;
    for shape in crate::scene::ShapeFunction::iter().map(|s| s.name()) {
        let overrides = vec![
            format!("grid.shape_function={shape}"),
            "solver.min_node_support=0.01".to_string(),
        ];
        let (error, n, tied, _) = tangent_error(&overrides, false);
        println!("{shape}: {n} unknowns, {tied} tied nodes, max |K − K_fd| / max|K| = {error:.2e}");
        assert!(
            error < 1e-6,
            "{shape}: tangent off by {error:.2e} of its largest entry"
        );
    }
}

/// Two rigid bodies pressed into the block: a disk on its top and a box at its
/// right side, moving with prescribed velocities (`super::terms::contact::rigid`).
const RIGID_BODIES: &str = r#"[[material]]
name = "steel"
model = "rigid"
density = 1000.0
[[body]]
name = "disk"
material = "steel"
shape = "disk"
centre = [1.75, 3.2]
radius = 0.75
velocity = [0.5, -1.0]
[[body]]
name = "wall"
material = "steel"
shape = "rectangle"
min = [2.9, 0.5]
max = [3.5, 1.5]
velocity = [-1.0, 0.2]
"#;

/// The tangent with penalty contact against rigid bodies (a curved and a flat
/// face, frictionless and with friction: particles sticking and slipping at
/// the iterate) against central differences of the residual.
#[test]
fn tangent_with_rigid_contact_matches_finite_differences_of_the_residual() {
    let body = BLOCK
        .replace(
            "[[body]]\nmaterial = \"m\"",
            "[[body]]\nname = \"block\"\nmaterial = \"m\"",
        )
        .replace("[[boundary]]", &format!("{RIGID_BODIES}[[boundary]]"));
    // Frictionless with linear hats, with friction for every shape function.
    use strum::IntoEnumIterator;
    let every_shape = crate::scene::ShapeFunction::iter().map(|s| (s.name(), 0.3));
    for (shape, mu) in std::iter::once(("linear", 0.0)).chain(every_shape) {
        let text = body.replace(
            "[solver]",
            &format!("[[contact]]\nfriction_coefficient = {mu}\n[solver]"),
        );
        let overrides = vec![format!("grid.shape_function={shape}")];
        assert_contact_tangent(&text, &overrides, &format!("{shape} μ = {mu}"), mu);
    }
}

/// `tangent_error_of` a scene with contact: the tangent within 1e-6 of central
/// differences, and the iterate with contacts sticking (and, with friction μ,
/// slipping) at it (the last residual is at u − h e).
fn assert_contact_tangent(text: &str, overrides: &[String], label: &str, mu: f64) {
    let (error, n, tied, _) = tangent_error_of::<2>(text, overrides, false);
    let (stick, slip) = CONTACTS.with(|c| c.get());
    println!(
        "{label}: {n} unknowns ({tied} nodes tied), {stick} contacts sticking, {slip} \
         slipping, max |K − K_fd| / max|K| = {error:.2e}"
    );
    assert!(
        stick > 0 && (mu == 0.0 || slip > 0),
        "{label}: {stick} stick, {slip} slip"
    );
    assert!(error < 1e-6, "{label}: tangent off by {error:.2e}");
}

thread_local! {
    /// Particles (or meetings of two deformable bodies) in contact, sticking
    /// and slipping, at the tangent of the last `tangent_error_of` on this
    /// thread.
    static CONTACTS: std::cell::Cell<(usize, usize)> = const { std::cell::Cell::new((0, 0)) };
    /// The iterate of `tangent_error_of` moves the nodes of a second deformable
    /// body by (s₀ x, −s₁) (x the node's abscissa).
    static SHIFT: std::cell::Cell<[f64; 2]> = const { std::cell::Cell::new([0.0, 0.0]) };
}

/// Two deformable blocks, one on the other (`[[contact]]` between them).
const STACK: &str = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [4.0, 4.0]
cells = [8, 8]
shape_function = "linear"
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
name = "base"
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [4.0, 1.5]
particles_per_cell = 2
[[body]]
name = "top"
material = "m"
shape = "rectangle"
min = [0.5, 1.5]
max = [3.0, 2.5]
particles_per_cell = 2
[[contact]]
bodies = ["base", "top"]
friction_coefficient = 0.3
[[boundary]]
face = "ymin"
condition = "fixed"
[solver]
kind = "implicit"
integrator = "newmark"
end_time = 1.0
dt = 0.01
"#;

/// The tangent with penalty contact between two deformable bodies (their
/// shared nodes split, a penalty between the nodes of each meeting):
/// frictionless and with friction (meetings sticking and slipping at the
/// iterate), at the meeting's nodes (point bases) and at the surfaces' points
/// (domain bases), against central differences of the residual. The upper body's
/// nodes are pushed 2 mm into the lower one and slid by 1 mm per metre of x,
/// so that μ = 0.3 sticks at small x and slips at large x.
#[test]
fn tangent_with_deformable_contact_matches_finite_differences_of_the_residual() {
    SHIFT.with(|s| s.set([1e-3, 2e-3]));
    // The interface on a node row (y = 1.5) and mid-cell (y = 1.25: the
    // meetings' surface points off the nodes, domain bases).
    let mid_cell = STACK
        .replace("max = [4.0, 1.5]", "max = [4.0, 1.25]")
        .replace("min = [0.5, 1.5]", "min = [0.5, 1.25]");
    let on_node = STACK.to_string();
    // μ = 0.03: a meeting slips once its tangential trial force ε_t |Δ| exceeds
    // μ ε_n g; with ε_t = ε_n/10 (`terms::contact::bodies::TANGENTIAL_PENALTY`) μ = 0.3 left
    // every meeting sticking at this iterate, 0.03 leaves 1–2 sticking and 5–9
    // slipping.
    let cases = [
        (&on_node, "linear", 0.0),
        (&on_node, "linear", 0.03),
        (&on_node, "bspline2", 0.03),
        (&on_node, "cpgimp", 0.0),
        (&on_node, "cpgimp", 0.03),
        (&on_node, "cpdi", 0.03),
        (&mid_cell, "cpgimp", 0.0),
        (&mid_cell, "cpgimp", 0.03),
        (&mid_cell, "cpdi", 0.03),
    ];
    for (text, shape, mu) in cases {
        let overrides = vec![
            format!("grid.shape_function={shape}"),
            format!("contact.0.friction_coefficient={mu}"),
        ];
        let at = if *text == mid_cell {
            "mid-cell"
        } else {
            "on a node row"
        };
        assert_contact_tangent(
            text,
            &overrides,
            &format!("{shape} μ = {mu}, interface {at}"),
            mu,
        );
    }
    SHIFT.with(|s| s.set([0.0, 0.0]));
}

/// The axisymmetric tangent (the hoop couplings of `assembly::stiffness`, the
/// hoop stretch in ΔF and the hoop force in r) against central differences of
/// the residual: the block as a solid of revolution about x = 0 (r = x, the axis
/// nodes held radially), several materials, shape functions, mass matrices and
/// ties.
#[test]
fn axisymmetric_tangent_matches_finite_differences_of_the_residual() {
    let text = BLOCK.replace("dimension = 2", "dimension = \"axisymmetric\"");
    for (model, shape, mass, support) in [
        ("hencky", "linear", "lumped", 0.0),
        ("neo_hookean", "bspline2", "consistent", 0.01),
        ("linear_elastic", "ugimp", "lumped", 0.01),
        ("hencky", "cpgimp", "consistent", 0.3),
        ("hencky", "bspline3", "lumped", 0.01),
        ("hencky", "cpbspline2", "lumped", 0.01),
    ] {
        let overrides = vec![
            format!("material.0.model={model}"),
            format!("grid.shape_function={shape}"),
            format!("solver.mass={mass}"),
            format!("solver.min_node_support={support}"),
        ];
        let (error, n, tied, _) = tangent_error_of::<2>(&text, &overrides, false);
        println!(
            "axisymmetric {model} {shape} {mass}: {n} unknowns, {tied} tied nodes, \
             max |K − K_fd| / max|K| = {error:.2e}"
        );
        assert!(
            error < 1e-6,
            "axisymmetric {model} {shape} {mass}: tangent off by {error:.2e} of its largest entry"
        );
    }
}

/// The axisymmetric F-bar tangent (n = 3, the hoop stretch in ΔJ and in the
/// scaled ΔF̄) against central differences of the residual, elastic and plastic.
#[test]
fn axisymmetric_fbar_tangent_matches_finite_differences_of_the_residual() {
    let text = BLOCK.replace("dimension = 2", "dimension = \"axisymmetric\"");
    for (name, shape, support, extra) in [
        ("hencky", "linear", 0.0, vec![]),
        ("hencky", "bspline2", 0.01, vec![]),
        (
            "mohr_coulomb ψ=0",
            "ugimp",
            0.3,
            vec![
                "material.0.model=mohr_coulomb".to_string(),
                "material.0.cohesion=200.0".to_string(),
                "material.0.friction_angle=20.0".to_string(),
                "material.0.dilation_angle=0.0".to_string(),
            ],
        ),
    ] {
        let mut overrides = extra;
        overrides.extend([
            format!("grid.shape_function={shape}"),
            format!("solver.min_node_support={support}"),
            "solver.fbar=true".to_string(),
            "body.0.particles_per_cell=2".to_string(),
        ]);
        let (error, n, tied, plastic) = tangent_error_of::<2>(&text, &overrides, false);
        println!(
            "axisymmetric F-bar {name} {shape}: {n} unknowns, {tied} tied nodes, {plastic} \
             plastic particles, max |K − K_fd| / max|K| = {error:.2e}"
        );
        if name.starts_with("mohr") {
            assert!(plastic > 0, "{name}: no plastic particle");
        }
        assert!(
            error < 1e-6,
            "axisymmetric F-bar {name} {shape}: {error:.2e}"
        );
    }
}

/// A Mohr-Coulomb material with c small against the stresses of the tangent
/// checks' iterate (plastic there), dilation angle ψ.
fn mohr_coulomb_keys(psi: f64) -> Vec<String> {
    vec![
        "material.0.model=mohr_coulomb".to_string(),
        "material.0.cohesion=200.0".to_string(),
        "material.0.friction_angle=20.0".to_string(),
        format!("material.0.dilation_angle={psi}"),
    ]
}

/// The F-bar tangent (`assembly::fbar::fbar_triplets`: each particle couples to the
/// nodes of every particle in its cell) against central differences of the
/// F-bar residual, with linear and smooth shape functions, through ties, and
/// with Mohr-Coulomb in a plastic state (c small against the stresses of the
/// iterate, ψ = 0 and ψ > 0). 2 × 2 particles per cell (as in the slope).
#[test]
fn global_tangent_with_fbar_matches_finite_differences_of_the_residual() {
    let mohr_coulomb = mohr_coulomb_keys;
    let hencky = vec!["material.0.model=hencky".to_string()];
    for (name, material, shape, support) in [
        ("hencky", hencky.clone(), "linear", 0.0),
        ("hencky", hencky.clone(), "bspline2", 0.01),
        ("hencky", hencky.clone(), "ugimp", 0.3),
        ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "linear", 0.0),
        ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "bspline2", 0.01),
        ("mohr_coulomb ψ=10", mohr_coulomb(10.0), "ugimp", 0.3),
    ] {
        let mut overrides = material;
        overrides.extend([
            format!("grid.shape_function={shape}"),
            format!("solver.min_node_support={support}"),
            "solver.fbar=true".to_string(),
            "body.0.particles_per_cell=2".to_string(),
        ]);
        let (error, n, tied, plastic) = tangent_error(&overrides, false);
        println!(
            "F-bar {name} {shape}: {n} unknowns, {tied} tied nodes, {plastic} plastic \
             particles, max |K − K_fd| / max|K| = {error:.2e}"
        );
        if name.starts_with("mohr") {
            assert!(plastic > 0, "F-bar {name} {shape}: no plastic particle");
        }
        assert!(
            error < 1e-6,
            "F-bar {name} {shape}: tangent off by {error:.2e} of its largest entry"
        );
    }
    // 3D: ΔF scaled as a whole (n = 3).
    for (name, material, shape) in [
        ("hencky", hencky.clone(), "linear"),
        ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "bspline2"),
    ] {
        let mut overrides = material;
        overrides.extend([
            format!("grid.shape_function={shape}"),
            "solver.fbar=true".to_string(),
        ]);
        let (error, n, tied, plastic) = tangent_error_of::<3>(BLOCK_3D, &overrides, false);
        println!(
            "F-bar 3D {name} {shape}: {n} unknowns, {tied} tied nodes, {plastic} plastic \
             particles, max |K − K_fd| / max|K| = {error:.2e}"
        );
        assert!(error < 1e-6, "F-bar 3D {name} {shape}: {error:.2e}");
        if name.starts_with("mohr") {
            assert!(plastic > 0, "F-bar 3D {name} {shape}: no plastic particle");
        }
    }
}

/// The tangent with a stress linear within the particle domains (`[grid]
/// domain_stress = "linear"`: each particle couples to the nodes of its
/// least-squares neighbours, `assembly::linear_stress`) against central
/// differences of the residual: 2D and 3D, both families, with ties, both
/// mass matrices, elastic and plastic.
#[test]
fn linear_domain_stress_tangent_matches_finite_differences_of_the_residual() {
    let cases_2d = [
        ("hencky", "cpgimp", "lumped", 0.0),
        ("neo_hookean", "cpbspline2", "consistent", 0.01),
        ("hencky", "cpbspline2", "lumped", 0.3),
        ("linear_elastic", "cpgimp", "consistent", 0.3),
    ];
    for (model, shape, mass, support) in cases_2d {
        let overrides = vec![
            format!("material.0.model={model}"),
            format!("grid.shape_function={shape}"),
            format!("solver.mass={mass}"),
            format!("solver.min_node_support={support}"),
            "grid.domain_stress=linear".to_string(),
        ];
        let (error, n, tied, _) = tangent_error(&overrides, false);
        println!(
            "linear domain stress {model} {shape} {mass}: {n} unknowns, {tied} tied nodes, \
             max |K − K_fd| / max|K| = {error:.2e}"
        );
        assert!(
            error < 1e-6,
            "{model} {shape} {mass}: tangent off by {error:.2e}"
        );
    }
    let mut plastic_case = mohr_coulomb_keys(0.0);
    plastic_case.push("grid.shape_function=cpbspline2".into());
    for (name, mut overrides) in [
        (
            "hencky cpgimp",
            vec!["grid.shape_function=cpgimp".to_string()],
        ),
        ("mohr_coulomb cpbspline2", plastic_case),
    ] {
        overrides.push("grid.domain_stress=linear".to_string());
        let (error, n, tied, plastic) = tangent_error_of::<3>(BLOCK_3D, &overrides, false);
        println!(
            "linear domain stress 3D {name}: {n} unknowns, {tied} tied nodes, {plastic} plastic \
             particles, max |K − K_fd| / max|K| = {error:.2e}"
        );
        assert!(error < 1e-6, "3D {name}: tangent off by {error:.2e}");
        if name.starts_with("mohr") {
            assert!(plastic > 0, "3D {name}: no plastic particle");
        }
    }
}

/// A small 3D block for the F-bar tangent check, 2 × 2 × 2 particles per cell.
const BLOCK_3D: &str = r#"dimension = 3
[grid]
min = [0.0, 0.0, 0.0]
max = [3.0, 3.0, 3.0]
cells = [3, 3, 3]
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "box"
min = [0.5, 0.0, 0.0]
max = [2.5, 2.0, 1.5]
particles_per_cell = 2
[[boundary]]
face = "ymin"
condition = "fixed"
[solver]
kind = "implicit"
integrator = "newmark"
end_time = 1.0
dt = 0.01
"#;

/// Tied nodes follow a linear field exactly, so every particle's gradient of
/// a linear nodal field is exact (linear consistency survives the ties), and
/// masters are never tied themselves.
#[test]
fn ties_keep_linear_fields_exact() {
    use strum::IntoEnumIterator;
    for shape in crate::scene::ShapeFunction::iter().map(|s| s.name()) {
        // The block's edges cut the cells anywhere: many weakly supported nodes.
        let overrides = vec![
            format!("grid.shape_function={shape}"),
            "grid.cells=[8,8]".to_string(),
            "body.0.min=[0.61,0.77]".to_string(),
            "body.0.max=[3.93,2.38]".to_string(),
            "body.0.particles_per_cell=2".to_string(),
            "load.0.region_min=[3.5,2.0]".to_string(),
            "load.0.region_max=[3.93,2.38]".to_string(),
            "solver.min_node_support=0.2".to_string(),
        ];
        let scene = Scene::parse("block.toml", BLOCK, &overrides).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let mut solver = Implicit::<2>::new(
            scene.config.grid.shape_function,
            scene.config.stages()[0],
            0.0,
        );
        solver.prepare(&m, 0.0, 1.0);
        let sys = &solver.system;
        let ties = &sys.dofs.ties;
        let tied = ties.iter().filter(|t| t.is_some()).count();
        assert!(tied > 0, "{shape}: no tied node at min_node_support 0.2");
        for t in ties.iter().flatten() {
            assert!(ties[t.master[0]].is_none() && ties[t.master[1]].is_none());
        }
        let a = crate::dim::Tensor::<2>::new(0.013, -0.021, 0.008, 0.017);
        let b = Vector::<2>::new(0.3, -0.1);
        let linear = |g: u32| {
            let x = m.grid.node_position(m.grid.node_ijk(g as usize));
            a * x + b
        };
        let mut u: Vec<Vector<2>> = sys.map.active.iter().map(|&g| linear(g)).collect();
        let exact = u.clone();
        for (ua, t) in u.iter_mut().zip(ties) {
            if t.is_some() {
                *ua = Vector::<2>::new(9.0, 9.0); // overwritten by the tie
            }
        }
        sys.dofs.follow_ties(&mut u);
        let node_error = u
            .iter()
            .zip(&exact)
            .map(|(x, y)| (x - y).norm())
            .fold(0.0, f64::max);
        let grad_error = (0..m.particles.len())
            .map(|q| {
                (crate::physics::transfer::gradient(&sys.map, &sys.stencils, q, &u) - a).amax()
            })
            .fold(0.0, f64::max);
        println!(
            "{shape}: {tied} of {} nodes tied; node error {node_error:.1e}, gradient error {grad_error:.1e}",
            u.len()
        );
        assert!(node_error < 1e-14 && grad_error < 1e-12, "{shape}");
    }
}

/// Cubic B-splines on a block resting on the fixed base: the third layer of nodes
/// above the base is tied to the first two, u₂ = 3 u₁ − 2 u₀ (u'' = 0 at the
/// face), which keeps linear fields exact; no weak-node ties here.
#[test]
fn natural_end_ties_at_the_fixed_base() {
    let overrides = vec![
        "grid.shape_function=bspline3".to_string(),
        "grid.cells=[8,8]".to_string(),
        "solver.min_node_support=0".to_string(),
    ];
    let scene = Scene::parse("block.toml", BLOCK, &overrides).unwrap();
    let m = Model::<2>::build(&scene).unwrap();
    let mut solver = Implicit::<2>::new(
        scene.config.grid.shape_function,
        scene.config.stages()[0],
        0.0,
    );
    solver.prepare(&m, 0.0, 1.0);
    let sys = &solver.system;
    let ties = &sys.dofs.ties;
    let mut tied = 0;
    for (a, t) in ties.iter().enumerate() {
        let Some(t) = t else { continue };
        tied += 1;
        let ijk = |n: usize| m.grid.node_ijk(sys.map.active[n] as usize);
        assert_eq!(t.coef, [3.0, -2.0]);
        assert_eq!(
            (ijk(a)[1], ijk(t.master[0])[1], ijk(t.master[1])[1]),
            (2, 1, 0)
        );
        assert!(ties[t.master[0]].is_none() && ties[t.master[1]].is_none());
    }
    // The block spans x ∈ [0.5, 3]: nodes 0…6 along x touch it.
    assert!(tied >= 5, "{tied} natural ties");
    let a = crate::dim::Tensor::<2>::new(0.013, -0.021, 0.008, 0.017);
    let linear = |g: u32| a * m.grid.node_position(m.grid.node_ijk(g as usize));
    let exact: Vec<Vector<2>> = sys.map.active.iter().map(|&g| linear(g)).collect();
    let mut u = exact.clone();
    sys.dofs.follow_ties(&mut u);
    let error = u
        .iter()
        .zip(&exact)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    assert!(
        error < 1e-14,
        "linear field off by {error:.1e} after the ties"
    );
}

/// The assembled tangent is the same, bit for bit, on one thread and on two
/// (each column's values are summed by one task in a fixed order), with ties,
/// absorbing faces and the consistent mass; and the F-bar tangent too.
#[test]
fn tangent_does_not_depend_on_the_number_of_threads() {
    let text = BLOCK.replace("[solver]", &format!("{ABSORBING}[solver]"));
    for fbar in [false, true] {
        let overrides = vec![
            "grid.cells=[24,24]".to_string(),
            "grid.shape_function=bspline2".to_string(),
            "body.0.min=[0.0,0.0]".to_string(),
            "body.0.max=[3.93,2.38]".to_string(),
            "solver.mass=consistent".to_string(),
            "solver.min_node_support=0.3".to_string(),
            format!("solver.fbar={fbar}"),
        ];
        let scene = Scene::parse("block.toml", &text, &overrides).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let values = |threads: usize| {
            crate::parallel::on_threads(threads, || {
                let mut solver = Implicit::<2>::new(
                    scene.config.grid.shape_function,
                    scene.config.stages()[0],
                    0.0,
                );
                solver.prepare(&m, 0.0, 0.01);
                let sys = &mut solver.system;
                let u: Vec<Vector<2>> = (0..sys.map.len())
                    .map(|a| Vector::<2>::new(1e-3 * (a as f64).sin(), -1e-3))
                    .collect();
                residual(&m, sys, &u).unwrap();
                let k = tangent(&m, sys, false).unwrap();
                let tied = sys.dofs.ties.iter().flatten().count();
                (k.values.clone(), k.symmetric(), tied)
            })
        };
        let (one, symmetric, tied) = values(1);
        let (two, _, _) = values(2);
        println!(
            "F-bar {fbar}: {} values, symmetric {symmetric}, {tied} tied",
            one.len()
        );
        assert!(tied > 0 && one.len() > 10_000);
        assert_eq!(symmetric, !fbar);
        assert!(
            one == two,
            "F-bar {fbar}: values differ between 1 and 2 threads"
        );
    }
}

/// The step's pattern is kept for the next step only when it is the one the
/// next step would build: same stencil nodes, unknowns, ties and F-bar cells.
#[test]
fn a_pattern_is_kept_only_while_it_fits() {
    use super::assembly::Pattern;
    let overrides = vec!["solver.fbar=true".to_string()];
    let scene = Scene::parse("block.toml", BLOCK, &overrides).unwrap();
    let mut m = Model::<2>::build(&scene).unwrap();
    let mut solver = Implicit::<2>::new(
        scene.config.grid.shape_function,
        scene.config.stages()[0],
        0.0,
    );
    solver.prepare(&m, 0.0, 0.01);
    let sys = &solver.system;
    let cells = sys.trial.fbar.as_ref().map(|f| &f.cells);
    let pattern = Pattern::new(&sys.map, &sys.stencils, &sys.dofs, cells, None, &[]);
    assert!(pattern.fits(&sys.stencils, &sys.dofs, cells, None, &[]));
    // Another node in one stencil, another unknown, other cells: a new pattern.
    let mut moved = sys.stencils.clone();
    moved.node[0] += 1;
    assert!(!pattern.fits(&moved, &sys.dofs, cells, None, &[]));
    let mut dofs = sys.dofs.clone();
    dofs.free -= 1;
    assert!(!pattern.fits(&sys.stencils, &dofs, cells, None, &[]));
    assert!(!pattern.fits(&sys.stencils, &sys.dofs, None, None, &[]));
    // Through the solver: the next step keeps the pattern while the particles
    // stay put, and builds a new one after one crosses into another cell.
    let _ = solver.system.pattern.set(pattern);
    solver.prepare(&m, 0.01, 0.01);
    assert!(solver.system.pattern.get().is_some(), "kept");
    m.particles.x[0][0] += 1.0;
    solver.prepare(&m, 0.02, 0.01);
    assert!(solver.system.pattern.get().is_none(), "dropped");
}

/// A smooth iterate of a step, `scale` times a field of strains of about a
/// per cent, zero at the prescribed components, tied nodes following their
/// masters.
fn smooth_iterate(m: &Model<2>, sys: &StepSystem<2>, scale: f64) -> Vec<Vector<2>> {
    let mut u: Vec<Vector<2>> = (0..sys.map.len())
        .zip(&sys.constraint)
        .map(|(a, c)| {
            let x = m.grid.node_position(m.grid.node_ijk(sys.map.grid_node(a)));
            let mut v = Vector::<2>::new(0.02 * (0.7 * x[1]).sin(), -0.01 * x[0] * x[1] / 4.0);
            for d in 0..2 {
                if c.fixed[d] {
                    v[d] = 0.0;
                }
            }
            v * scale
        })
        .collect();
    sys.dofs.follow_ties(&mut u);
    u
}

/// The bits of nodal vectors, to compare them exactly.
fn bits(v: &[Vector<2>]) -> Vec<u64> {
    v.iter()
        .flat_map(|x| x.iter().map(|c| c.to_bits()))
        .collect()
}

/// A residual away from the iterate (`probe_residual`, the Krylov solver's
/// difference products) has the bits of `residual` at the same point, and
/// leaves the step's iterate where it was: after a probe the tangent and the
/// terms' report are those before it, bit for bit (`terms`, the iterate).
/// With F-bar, a linear domain stress, absorbing faces, friction against
/// rigid bodies and between two deformable bodies (contacts at the iterate).
#[test]
fn a_probe_is_the_residual_and_leaves_the_iterate() {
    use super::residual::probe_residual;
    let rigid = BLOCK
        .replace(
            "[[body]]\nmaterial = \"m\"",
            "[[body]]\nname = \"block\"\nmaterial = \"m\"",
        )
        .replace("[[boundary]]", &format!("{RIGID_BODIES}[[boundary]]"))
        .replace(
            "[solver]",
            "[[contact]]\nfriction_coefficient = 0.3\n[solver]",
        );
    let absorbing = BLOCK.replace("[solver]", &format!("{ABSORBING}[solver]"));
    let cases: [(&str, &str, Vec<&str>, bool); 5] = [
        ("F-bar", BLOCK, vec!["solver.fbar=true"], false),
        (
            "linear domain stress",
            BLOCK,
            vec!["grid.shape_function=cpgimp", "grid.domain_stress=linear"],
            false,
        ),
        ("absorbing faces", &absorbing, vec![], false),
        (
            "rigid bodies",
            &rigid,
            vec!["grid.shape_function=cpgimp"],
            true,
        ),
        (
            "two deformable bodies",
            STACK,
            vec![
                "grid.shape_function=cpgimp",
                "contact.0.friction_coefficient=0.03",
            ],
            true,
        ),
    ];
    for (name, text, overrides, contact) in cases {
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        let scene = Scene::parse("block.toml", text, &overrides).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let stage = scene.config.stages()[0];
        let mut solver = Implicit::<2>::new(scene.config.grid.shape_function, stage, 0.0);
        solver.prepare(&m, 0.0, 0.01);
        let sys = &mut solver.system;
        let (u, w) = (smooth_iterate(&m, sys, 1.0), smooth_iterate(&m, sys, 1.5));
        residual(&m, sys, &u).unwrap();
        let k = tangent(&m, sys, false).unwrap().values;
        let report = sys.report();
        assert!(
            !contact || report.sticking + report.slipping > 0,
            "{name}: no contact at the iterate"
        );
        let probed = probe_residual(&m, sys, &w).unwrap();
        assert!(sys.iterate() == u.as_slice(), "{name}: the iterate moved");
        let after: Vec<u64> = (tangent(&m, sys, false).unwrap().values.iter())
            .map(|x| x.to_bits())
            .collect();
        let before: Vec<u64> = k.iter().map(|x| x.to_bits()).collect();
        assert!(after == before, "{name}: the tangent changed");
        assert_eq!(sys.report(), report, "{name}: the terms' state changed");
        let evaluated = residual(&m, sys, &w).unwrap();
        assert!(
            bits(&probed) == bits(&evaluated),
            "{name}: the probe differs from the residual"
        );
        println!(
            "{name}: {} unknowns, probe = residual bit for bit",
            sys.dofs.free
        );
    }
}
