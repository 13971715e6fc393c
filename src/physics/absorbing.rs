//! Non-reflecting (absorbing) boundaries on grid faces, thesis §2.4.
//!
//! Lysmer–Kuhlemeyer dashpots: the medium cut away beyond the face acts on it with
//! σ_n = −ρ c_d v_n and τ = −ρ c_s v_τ (2-59, 2-60), c_d = √((λ + 2G)/ρ) and
//! c_s = √(G/ρ) (2-61, 2-62) of the material next to the face. Optionally a spring
//! in parallel (Kelvin–Voigt), σ_n = −k_n u_n and τ = −k_s u_τ, carries static loads
//! so that the boundary does not creep under them.
//!
//! As in the thesis (2-63, after Chen et al.), the boundary traction t acts as a
//! body force on the particles in the outermost layer of cells: a particle of
//! volume V_p in the layer of thickness h (the cell size normal to the face) carries
//! f_p = (V_p / h) t(v_p, u_p), which over a layer filled with material adds up to t
//! times the face area. Each particle uses its own material, so layered media get
//! the impedance of each layer. The velocity and displacement at a particle are the
//! grid's: v_p = Σ_I S_Ip v_I, u_p = x_p − X_p (plus Σ_I S_Ip u_I inside an implicit
//! step), so the implicit residual and tangent are exact derivatives of each other.
//!
//! The outward normal of a grid face is ±e_a, so n ⊗ n picks axis a and the
//! dashpot and spring matrices are diagonal in the grid axes: ρ c_d (or k_n) on the
//! normal axis, ρ c_s (or k_s) on the others.
//!
//! Spring stiffness. `spring_distance = R` gives k_n = α_N G/R and k_s = α_T G/R
//! (Liu Jingbo et al. 2006, the viscous-spring artificial boundary; it follows
//! from the outgoing cylindrical (2D) or spherical (3D) wave from a source at
//! distance R), with α_N = 1, α_T = ½ in 2D and α_N = 4/3, α_T = 2/3 in 3D;
//! `spring_stiffness = [k_n, k_s]` gives them directly (force per unit area per
//! unit displacement).

use crate::dim::Vector;
use crate::model::grid::{Face, Grid};
use crate::solver::implicit::newmark::Newmark;
use crate::solver::implicit::tangent::{push_terms, Dofs, Triplets};
use crate::material::{Increment, Material};
use crate::model::particles::Particles;
use crate::scene::{BoundaryConfig, Condition};
use crate::physics::shape::Stencils;
use crate::physics::transfer::{interpolate, NodeMap};

/// How the springs of one absorbing face are given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spring {
    /// Dashpots only.
    None,
    /// k = α G / R with R the distance from the wave source to the face.
    Distance(f64),
    /// Stiffness per unit area, normal and tangential.
    Stiffness { normal: f64, tangential: f64 },
}

/// Spring factors (α_N, α_T) of k = α G / R, 2D and 3D (Liu Jingbo et al. 2006).
pub fn spring_factors(dim: usize) -> (f64, f64) {
    if dim == 2 {
        (1.0, 0.5)
    } else {
        (4.0 / 3.0, 2.0 / 3.0)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct AbsorbingFace {
    pub face: Face,
    pub spring: Spring,
    /// Index of its `[[boundary]]` table (for errors).
    pub boundary: usize,
}

/// Wave properties of one material at rest.
#[derive(Clone, Copy, Debug)]
pub struct Waves {
    /// ρ0 c_d = √(ρ0 (λ + 2G)) (2-59, 2-61).
    pub normal_impedance: f64,
    /// ρ0 c_s = √(ρ0 G) (2-60, 2-62).
    pub shear_impedance: f64,
    /// Shear modulus G (for the spring stiffness α G / R).
    pub shear_modulus: f64,
}

impl Waves {
    pub fn of(m: &dyn Material) -> Waves {
        let g = shear_modulus(m);
        Waves {
            normal_impedance: (m.density() * m.p_wave_modulus()).sqrt(),
            shear_impedance: (m.density() * g).sqrt(),
            shear_modulus: g,
        }
    }
}

/// Small-strain shear modulus of a material: ∂σ_xy/∂ΔF_xy at rest (unstressed,
/// undeformed), from its stress derivative, or by a central difference of its
/// stress update when it has none. For isotropic elasticity this is G.
pub fn shear_modulus(m: &dyn Material) -> f64 {
    let history = vec![0.0; m.n_history()];
    let at_rest = |df| Increment {
        f_old: crate::dim::Mat3::identity(),
        df,
        dt: 0.0,
        stress_old: crate::dim::Mat3::zeros(),
        history_old: &history,
    };
    if let Some(d) = m.stress_derivative(&at_rest(crate::dim::Mat3::identity())) {
        return d[(1, 1)];
    }
    let h = 1e-7;
    let sigma_xy = |s: f64| {
        let mut df = crate::dim::Mat3::identity();
        df[(0, 1)] = s;
        let mut scratch = history.clone();
        m.update(&at_rest(df), &mut scratch)[(0, 1)]
    };
    (sigma_xy(h) - sigma_xy(-h)) / (2.0 * h)
}

/// A particle in the outermost cell layer of one or more absorbing faces: the
/// dashpot and spring coefficients of its body force per grid axis, already
/// multiplied by V_p / h (force per velocity, force per displacement).
#[derive(Clone, Copy, Debug)]
pub struct LayerParticle<const D: usize> {
    pub q: usize,
    pub damping: Vector<D>,
    pub stiffness: Vector<D>,
}

impl<const D: usize> LayerParticle<D> {
    /// Boundary force on the particle, f = −(C v + K u) (2-59, 2-60, 2-63).
    pub fn force(&self, v: &Vector<D>, u: &Vector<D>) -> Vector<D> {
        -(self.damping.component_mul(v) + self.stiffness.component_mul(u))
    }
}

/// The absorbing faces of a scene and the wave properties of its materials.
#[derive(Clone, Debug, Default)]
pub struct Absorbing<const D: usize> {
    pub faces: Vec<AbsorbingFace>,
    pub waves: Vec<Waves>,
}

impl<const D: usize> Absorbing<D> {
    /// From the `[[boundary]]` tables with `condition = "absorbing"`.
    pub fn new(boundaries: &[BoundaryConfig], materials: &[Box<dyn Material>]) -> Self {
        let faces: Vec<AbsorbingFace> = boundaries
            .iter()
            .enumerate()
            .filter(|(_, b)| b.condition == Condition::Absorbing)
            .map(|(i, b)| AbsorbingFace {
                face: Face::parse(&b.face, D).expect("validated face"),
                spring: match (b.spring_distance, &b.spring_stiffness) {
                    (Some(r), _) => Spring::Distance(r),
                    (None, Some(k)) => Spring::Stiffness {
                        normal: k[0],
                        tangential: k[1],
                    },
                    (None, None) => Spring::None,
                },
                boundary: i,
            })
            .collect();
        let waves = if faces.is_empty() {
            Vec::new()
        } else {
            materials.iter().map(|m| Waves::of(m.as_ref())).collect()
        };
        Absorbing { faces, waves }
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Is x in the outermost layer of cells of `face`?
    fn in_layer(grid: &Grid<D>, face: Face, x: &Vector<D>) -> bool {
        let a = face.axis;
        if face.upper {
            grid.max[a] - x[a] < grid.h[a]
        } else {
            x[a] - grid.min[a] < grid.h[a]
        }
    }

    /// Every absorbing face needs material in its outermost cell layer: its
    /// impedance comes from there. Returns the offending `[[boundary]]` index.
    pub fn check_adjacent(&self, grid: &Grid<D>, p: &Particles<D>) -> Result<(), (usize, String)> {
        for f in &self.faces {
            if !p.x.iter().any(|x| Self::in_layer(grid, f.face, x)) {
                return Err((
                    f.boundary,
                    format!(
                        "no material next to the absorbing face {}: its dashpots take ρ c_d and ρ c_s from the particles in the outermost layer of cells (within {} of the face), and there are none",
                        f.face.name(),
                        grid.h[f.face.axis]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Dashpot and spring coefficients per axis of one face for a particle of
    /// material `w` (per unit area).
    fn face_coefficients(&self, f: &AbsorbingFace, w: &Waves) -> (Vector<D>, Vector<D>) {
        let (kn, ks) = match f.spring {
            Spring::None => (0.0, 0.0),
            Spring::Distance(r) => {
                let (an, at) = spring_factors(D);
                (an * w.shear_modulus / r, at * w.shear_modulus / r)
            }
            Spring::Stiffness { normal, tangential } => (normal, tangential),
        };
        let along = |normal: f64, tangential: f64| {
            Vector::<D>::from_fn(|d, _| if d == f.face.axis { normal } else { tangential })
        };
        (along(w.normal_impedance, w.shear_impedance), along(kn, ks))
    }

    /// The particles in the outermost layer of any absorbing face now, in particle
    /// order, with their coefficients (a particle in a corner collects both faces).
    pub fn layer(&self, grid: &Grid<D>, p: &Particles<D>) -> Vec<LayerParticle<D>> {
        if self.is_empty() {
            return Vec::new();
        }
        let mut out = Vec::new();
        for q in 0..p.len() {
            let mut lp = LayerParticle {
                q,
                damping: Vector::<D>::zeros(),
                stiffness: Vector::<D>::zeros(),
            };
            let mut inside = false;
            for f in self
                .faces
                .iter()
                .filter(|f| Self::in_layer(grid, f.face, &p.x[q]))
            {
                let (c, k) = self.face_coefficients(f, &self.waves[p.material[q] as usize]);
                // Traction per unit area → body force on the particle (2-63).
                let scale = p.volume[q] / grid.h[f.face.axis];
                lp.damping += c * scale;
                lp.stiffness += k * scale;
                inside = true;
            }
            if inside {
                out.push(lp);
            }
        }
        out
    }

    /// Explicit solver: add the boundary forces at the start-of-step nodal
    /// velocities `v` (active nodes) to the nodal forces. Scatters in particle order,
    /// so the sum does not depend on the number of threads.
    pub fn add_force(
        &self,
        grid: &Grid<D>,
        p: &Particles<D>,
        map: &NodeMap,
        st: &Stencils<D>,
        v: &[Vector<D>],
        force: &mut [Vector<D>],
    ) {
        for lp in self.layer(grid, p) {
            let q = lp.q;
            let f = lp.force(&interpolate(map, st, q, v), &(p.x[q] - p.x0[q]));
            for e in st.range(q) {
                force[map.local[st.node[e] as usize] as usize] += f * st.weight[e];
            }
        }
    }
}

/// The absorbing boundary within one implicit step: the layer at the step start
/// and the end-of-step nodal velocity as a function of the increment u,
/// v_I(u) = v*_I + rate · u_I (Newmark; rate = γ/(βΔt), 2-33…2-36). Quasi-static
/// steps have no velocity (rate = 0, v* = 0): only the springs act.
#[derive(Clone, Debug, Default)]
pub struct AbsorbingStep<const D: usize> {
    layer: Vec<LayerParticle<D>>,
    /// v*_I: the end-of-step velocity at u = 0.
    velocity_offset: Vec<Vector<D>>,
    /// ∂v_I/∂u_I.
    rate: f64,
}

impl<const D: usize> AbsorbingStep<D> {
    /// `newmark` is `Some((scheme, Δt))` for a dynamic step; `a_n` and `u_tilde` are
    /// the nodal start acceleration and predictor on the active nodes.
    pub fn new(
        absorbing: &Absorbing<D>,
        grid: &Grid<D>,
        p: &Particles<D>,
        a_n: &[Vector<D>],
        u_tilde: &[Vector<D>],
        newmark: Option<(&Newmark, f64)>,
    ) -> Self {
        let layer = absorbing.layer(grid, p);
        if layer.is_empty() {
            return AbsorbingStep::default();
        }
        match newmark {
            Some((nm, dt)) => AbsorbingStep {
                layer,
                velocity_offset: (0..a_n.len())
                    .map(|a| nm.end_velocity(dt, &Vector::<D>::zeros(), &u_tilde[a], &a_n[a]))
                    .collect(),
                rate: nm.velocity_rate(dt),
            },
            None => AbsorbingStep {
                layer,
                velocity_offset: vec![Vector::<D>::zeros(); a_n.len()],
                rate: 0.0,
            },
        }
    }

    pub fn is_empty(&self) -> bool {
        self.layer.is_empty()
    }

    /// Add −f_boundary(u) = Σ_p S_Ip (C_p v_p(u) + K_p u_p(u)) to the residual r(u).
    pub fn add_residual(
        &self,
        map: &NodeMap,
        st: &Stencils<D>,
        p: &Particles<D>,
        u: &[Vector<D>],
        r: &mut [Vector<D>],
    ) {
        if self.is_empty() {
            return;
        }
        let v: Vec<Vector<D>> = (0..u.len())
            .map(|a| self.velocity_offset[a] + u[a] * self.rate)
            .collect();
        for lp in &self.layer {
            let q = lp.q;
            let u_p = p.x[q] - p.x0[q] + interpolate(map, st, q, u);
            let f = lp.force(&interpolate(map, st, q, &v), &u_p);
            for e in st.range(q) {
                r[map.local[st.node[e] as usize] as usize] -= f * st.weight[e];
            }
        }
    }

    /// Tangent of `add_residual`: Σ_p S_Ip S_Jp (rate C_p + K_p), diagonal in the
    /// components, onto the unknowns (tied nodes through their masters; symmetric,
    /// positive semi-definite).
    pub fn add_tangent(&self, map: &NodeMap, st: &Stencils<D>, dofs: &Dofs, t: &mut Triplets) {
        for lp in &self.layer {
            let coefficient = lp.damping * self.rate + lp.stiffness;
            for e1 in st.range(lp.q) {
                let n1 = map.local[st.node[e1] as usize] as usize;
                for e2 in st.range(lp.q) {
                    let n2 = map.local[st.node[e2] as usize] as usize;
                    let w = st.weight[e1] * st.weight[e2];
                    for d in 0..D {
                        let (rows, cols) = (dofs.terms(n1, d, D), dofs.terms(n2, d, D));
                        push_terms(t, &rows, &cols, w * coefficient[d]);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Hencky, LinearElastic, MooneyRivlin, NeoHookean};
    use crate::scene::Scene;
    use crate::model::Model;

    /// The shear modulus read off the stress derivative at rest is G for every
    /// model, and the P-wave modulus of the trait is consistent with it.
    #[test]
    fn shear_modulus_of_every_model() {
        let (e, nu) = (50.0e6, 0.25);
        let g = e / (2.0 * (1.0 + nu));
        let models: Vec<(Box<dyn Material>, f64)> = vec![
            (Box::new(LinearElastic::new(2000.0, e, nu)), g),
            (Box::new(Hencky::new(2000.0, e, nu)), g),
            (Box::new(NeoHookean::new(2000.0, e, nu)), g),
            (
                Box::new(MooneyRivlin::from_thesis(2000.0, 3.0e6, 1.0e6, nu)),
                8.0e6,
            ),
        ];
        for (m, expected) in models {
            let got = shear_modulus(m.as_ref());
            assert!(
                (got / expected - 1.0).abs() < 1e-9,
                "{}: G = {got}, expected {expected}",
                m.model()
            );
            let w = Waves::of(m.as_ref());
            assert!(
                (w.shear_impedance - (2000.0 * expected).sqrt()).abs() < 1e-6 * w.shear_impedance
            );
            assert!(w.normal_impedance > w.shear_impedance);
        }
    }

    const LAYER: &str = r#"dimension = 2
[grid]
min = [0.0, 0.0]
max = [4.0, 2.0]
cells = [8, 4]
[[material]]
name = "m"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 50.0e6
poisson_ratio = 0.25
[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [4.0, 2.0]
particles_per_cell = 3
[[boundary]]
face = "ymin"
condition = "absorbing"
spring_stiffness = [3.0e6, 1.0e6]
[solver]
kind = "explicit"
end_time = 1.0
"#;

    /// (2-63): the body forces on the layer add up to the Lysmer–Kuhlemeyer
    /// traction times the face area, normal and tangential, dashpot and spring.
    #[test]
    fn layer_forces_add_up_to_the_traction_times_the_area() {
        let scene = Scene::parse("layer.toml", LAYER, &[]).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let layer = m.absorbing.layer(&m.grid, &m.particles);
        // 8 cells × 3 × 3 particles in the bottom row of cells.
        assert_eq!(layer.len(), 72);
        let (v, u) = (Vector::<2>::new(0.3, -0.2), Vector::<2>::new(0.01, 0.02));
        let total: Vector<2> = layer.iter().map(|lp| lp.force(&v, &u)).sum();
        let (rho, g): (f64, f64) = (2000.0, 20.0e6);
        let area = 4.0;
        let expected = Vector::<2>::new(
            -((rho * g).sqrt() * v[0] + 1.0e6 * u[0]) * area,
            -((rho * 3.0 * g).sqrt() * v[1] + 3.0e6 * u[1]) * area,
        );
        assert!(
            (total - expected).norm() < 1e-9 * expected.norm(),
            "{total:?} vs {expected:?}"
        );
    }

    /// Springs from the source distance: α G / R with the 2D factors.
    #[test]
    fn spring_from_distance() {
        let text = LAYER.replace(
            "spring_stiffness = [3.0e6, 1.0e6]",
            "spring_distance = 10.0",
        );
        let scene = Scene::parse("layer.toml", &text, &[]).unwrap();
        let m = Model::<2>::build(&scene).unwrap();
        let layer = m.absorbing.layer(&m.grid, &m.particles);
        let k: Vector<2> = layer.iter().map(|lp| lp.stiffness).sum();
        let g = 20.0e6;
        let expected = Vector::<2>::new(0.5 * g / 10.0 * 4.0, 1.0 * g / 10.0 * 4.0);
        assert!((k - expected).norm() < 1e-9 * expected.norm(), "{k:?}");
    }
}
