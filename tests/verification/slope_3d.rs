//! The Griffiths & Lane (1999) slope in 3D (`problems/slope_3d.toml`): its
//! cross-section extruded along y between rollers. Without F-bar the 3D run is
//! the plane-strain run: the prism fill, the K0 state, Mohr–Coulomb's 3D return
//! mapping in a plane-strain state and GMRES with the geometric multigrid must
//! reproduce the 2D slope solved by the direct solver, particle by particle.

use crate::common::*;

/// Two cells across W = 2 m at h = 1 m (the 2D CI grid).
const THIN: [&str; 3] = [
    "grid.cells=[40,2,12]",
    "grid.max=[40.0,2.0,12.0]",
    "body.0.extent=[0.0,2.0]",
];

#[test]
fn the_extruded_slope_on_rollers_is_the_plane_strain_slope() {
    // One trial, F = 1.3 (the slope stands, with a plastic zone at the toe),
    // no F-bar (the 3D F-bar also scales the out-of-plane stretch), Newton to
    // 1e-10. The 3D run: GMRES to 1e-10 with multigrid down to ≤ 500 coarse
    // unknowns (so the hierarchy has levels: the default 3000 would factorize
    // this small problem whole). Measured: displacements within 1.3e-12 and
    // stresses within 2.2e-13 of their largest; 6 Newton iterations each, 89
    // GMRES iterations in 3D.
    let text = std::fs::read_to_string(problem("slope_griffiths_lane.toml")).unwrap();
    let search = text.find("[strength_reduction]").unwrap();
    let output = text.find("[output]").unwrap();
    let text_2d = format!("{}{}", &text[..search], &text[output..]);
    let common = [
        "solver.fbar=false",
        "solver.strength_reduction_factor=1.3",
        "solver.residual_tolerance=1e-10",
    ];
    let mut set_2d = vec!["grid.cells=[40,12]"];
    set_2d.extend(common);
    let (r2, dir2) = run_text(&text_2d, &set_2d);
    r2.expect("the 2D slope stands");
    let mut set_3d: Vec<&str> = THIN.to_vec();
    set_3d.extend(common);
    set_3d.extend([
        "solver.multigrid_coarse_unknowns=500",
        "solver.krylov_tolerance=1e-10",
    ]);
    let (r3, dir3) = run_problem("slope_3d.toml", &set_3d);
    let s3 = r3.expect("the 3D slope stands");
    let (newton, krylov) = (
        s3.solver.newton_iterations.unwrap(),
        s3.solver.krylov_iterations.unwrap(),
    );
    assert!(
        krylov > 2 * newton,
        "multigrid should iterate: {krylov} for {newton}"
    );

    let p2 = Table::read(&dir2.path().join("particles_final.csv")).unwrap();
    let p3 = Table::read(&dir3.path().join("particles_final.csv")).unwrap();
    let key = |x: f64, z: f64| ((x * 1e6).round() as i64, (z * 1e6).round() as i64);
    let plane: std::collections::HashMap<_, usize> = (0..p2.len())
        .map(|q| (key(p2.col("X0")[q], p2.col("Y0")[q]), q))
        .collect();
    let (mut du, mut u_max, mut uy, mut ds, mut s_max) = (0f64, 0f64, 0f64, 0f64, 0f64);
    for q in 0..p3.len() {
        let k = plane[&key(p3.col("X0")[q], p3.col("Z0")[q])];
        let u2 = [
            p2.col("x")[k] - p2.col("X0")[k],
            p2.col("y")[k] - p2.col("Y0")[k],
        ];
        let u3 = [
            p3.col("x")[q] - p3.col("X0")[q],
            p3.col("z")[q] - p3.col("Z0")[q],
        ];
        for d in 0..2 {
            du = du.max((u2[d] - u3[d]).abs());
            u_max = u_max.max(u2[d].abs());
        }
        uy = uy.max((p3.col("y")[q] - p3.col("Y0")[q]).abs());
        // 2D (x, y, out of plane) = 3D (x, z, y).
        for (c2, c3) in [
            ("sxx", "sxx"),
            ("syy", "szz"),
            ("szz", "syy"),
            ("sxy", "sxz"),
        ] {
            ds = ds.max((p2.col(c2)[k] - p3.col(c3)[q]).abs());
            s_max = s_max.max(p2.col(c2)[k].abs());
        }
    }
    println!(
        "3D slope against 2D: displacement {:.2e}, out-of-plane {:.2e}, stress {:.2e} \
         (relative); {newton} Newton, {krylov} GMRES iterations",
        du / u_max,
        uy / u_max,
        ds / s_max
    );
    assert_eq!(p3.len(), 4 * p2.len(), "four particle layers across W");
    assert!(du < 1e-9 * u_max && uy < 1e-9 * u_max && ds < 1e-9 * s_max);
}
