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
//! Compliant base (Joyner & Chen 1975). Beyond a face with an incoming wave
//! (`incoming_velocity`) the face's velocity is the sum of the incoming and
//! the outgoing wave's, v = v_in + v_out, and a plane wave's traction is ρc
//! times its particle velocity, with the sign of its direction: the medium
//! beyond acts on the face with ρc (v_in − v_out) = ρc (2 v_in − v). The
//! dashpots are the −ρc v; the incoming wave adds 2 ρc v_in, a force
//! independent of the motion (an external force; it leaves the implicit
//! tangent alone), so the outgoing wave still leaves. ρc is ρ c_d normal to
//! the face and ρ c_s along it, of the particle's material (the half-space's,
//! in the layer next to the face); v_in is the upgoing wave alone, half the
//! motion of an outcrop of the half-space.
//!
//! Spring stiffness. `spring_distance = R` gives k_n = α_N G/R and k_s = α_T G/R
//! (Liu Jingbo et al. 2006, the viscous-spring artificial boundary; it follows
//! from the outgoing cylindrical (2D) or spherical (3D) wave from a source at
//! distance R), with α_N = 1, α_T = ½ in 2D and α_N = 4/3, α_T = 2/3 in 3D;
//! `spring_stiffness = [k_n, k_s]` gives them directly (force per unit area per
//! unit displacement).

use crate::dim::Vector;
use crate::model::conditions::{Absorbing, AbsorbingFace, Spring, Waves};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{interpolate, NodeMap};

/// Spring factors (α_N, α_T) of k = α G / R, 2D and 3D (Liu Jingbo et al. 2006).
pub fn spring_factors(dim: usize) -> (f64, f64) {
    if dim == 2 {
        (1.0, 0.5)
    } else {
        (4.0 / 3.0, 2.0 / 3.0)
    }
}

/// A particle in the outermost cell layer of one or more absorbing faces: the
/// dashpot and spring coefficients of its body force per grid axis, already
/// multiplied by V_p / h (force per velocity, force per displacement).
#[derive(Clone, Copy, Debug)]
pub struct LayerParticle<const D: usize> {
    pub q: usize,
    pub damping: Vector<D>,
    pub stiffness: Vector<D>,
    /// The incoming wave's force on the particle at the time of the layer,
    /// 2 C v_in (Joyner & Chen 1975; zero off a compliant base).
    pub input: Vector<D>,
}

impl<const D: usize> LayerParticle<D> {
    /// Boundary force on the particle, f = 2 C v_in − (C v + K u) (2-59, 2-60,
    /// 2-63; Joyner & Chen 1975 for the incoming wave).
    pub fn force(&self, v: &Vector<D>, u: &Vector<D>) -> Vector<D> {
        self.input - (self.damping.component_mul(v) + self.stiffness.component_mul(u))
    }
}

/// Dashpot and spring coefficients per axis of one face for a particle of
/// material `w` (per unit area).
fn face_coefficients<const D: usize>(f: &AbsorbingFace, w: &Waves) -> (Vector<D>, Vector<D>) {
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
/// order, with their coefficients (a particle in a corner collects both faces)
/// and the force of the incoming waves at time `t`.
pub fn layer<const D: usize>(
    absorbing: &Absorbing<D>,
    grid: &Grid<D>,
    p: &Particles<D>,
    t: f64,
) -> Vec<LayerParticle<D>> {
    if absorbing.is_empty() {
        return Vec::new();
    }
    // 2 v_in(t) of each face (zero without an incoming wave; empty, and not
    // allocated, without any).
    let mut twice_incoming = Vec::new();
    if !absorbing.incoming.is_empty() {
        twice_incoming = vec![Vector::<D>::zeros(); absorbing.faces.len()];
        for w in &absorbing.incoming {
            twice_incoming[w.face] = w.at(t) * 2.0;
        }
    }
    let mut out = Vec::new();
    for q in 0..p.len() {
        let mut lp = LayerParticle {
            q,
            damping: Vector::<D>::zeros(),
            stiffness: Vector::<D>::zeros(),
            input: Vector::<D>::zeros(),
        };
        let mut inside = false;
        for (i, f) in (absorbing.faces.iter().enumerate())
            .filter(|(_, f)| grid.in_outer_layer(f.face, &p.x[q]))
        {
            let (c, k) = face_coefficients::<D>(f, &absorbing.waves[p.material[q] as usize]);
            // Traction per unit area → body force on the particle (2-63).
            let scale = p.volume[q] / grid.h[f.face.axis];
            lp.damping += c * scale;
            lp.stiffness += k * scale;
            if let Some(v2) = twice_incoming.get(i) {
                lp.input += c.component_mul(v2) * scale;
            }
            inside = true;
        }
        if inside {
            out.push(lp);
        }
    }
    out
}

/// out_I += sign · Σ_p S_Ip f_p over the layer particles, with f_p = −(C v_p + K u_p),
/// v_p = Σ_I S_Ip v_I and u_p the particle's displacement (`displacement(q)`).
/// Scatters in particle order, so the sum does not depend on the number of
/// threads.
fn add_layer_forces<const D: usize>(
    layer: &[LayerParticle<D>],
    map: &NodeMap,
    st: &Stencils<D>,
    v: &[Vector<D>],
    displacement: impl Fn(usize) -> Vector<D>,
    sign: f64,
    out: &mut [Vector<D>],
) {
    for lp in layer {
        let q = lp.q;
        let f = lp.force(&interpolate(map, st, q, v), &displacement(q));
        for e in st.range(q) {
            out[map.local_of(st, e)] += f * (st.weight(e) * sign);
        }
    }
}

/// Explicit solver: add the boundary forces at the start-of-step nodal velocities
/// `v` (active nodes) and the incoming waves at the step start `t` to the nodal
/// forces.
#[allow(clippy::too_many_arguments)]
pub fn add_force<const D: usize>(
    absorbing: &Absorbing<D>,
    grid: &Grid<D>,
    p: &Particles<D>,
    map: &NodeMap,
    st: &Stencils<D>,
    v: &[Vector<D>],
    t: f64,
    force: &mut [Vector<D>],
) {
    let layer = layer(absorbing, grid, p, t);
    // u_p = x_p − X_p.
    let displacement = |q: usize| p.x[q] - p.x0[q];
    add_layer_forces(&layer, map, st, v, displacement, 1.0, force);
}

/// The absorbing boundary within one implicit step: the layer at the step start
/// and the end-of-step nodal velocity as a function of the increment u,
/// v_I(u) = v*_I + rate · u_I (Newmark: rate = γ/(βΔt), 2-33…2-36, given by the
/// solver). Quasi-static steps have no velocity (rate = 0, v* = 0): only the
/// springs act.
#[derive(Clone, Debug, Default)]
pub struct AbsorbingStep<const D: usize> {
    pub layer: Vec<LayerParticle<D>>,
    /// v*_I: the end-of-step velocity at u = 0.
    pub velocity_offset: Vec<Vector<D>>,
    /// ∂v_I/∂u_I.
    pub rate: f64,
}

impl<const D: usize> AbsorbingStep<D> {
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
        // u_p = x_p − X_p + Σ_I S_Ip u_I: the displacement at the end of the step.
        let displacement = |q: usize| p.x[q] - p.x0[q] + interpolate(map, st, q, u);
        add_layer_forces(&self.layer, map, st, &v, displacement, -1.0, r);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::scene::Scene;

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
        let layer = layer(&m.absorbing, &m.grid, &m.particles, 0.0);
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
        let layer = layer(&m.absorbing, &m.grid, &m.particles, 0.0);
        let k: Vector<2> = layer.iter().map(|lp| lp.stiffness).sum();
        let g = 20.0e6;
        let expected = Vector::<2>::new(0.5 * g / 10.0 * 4.0, 1.0 * g / 10.0 * 4.0);
        assert!((k - expected).norm() < 1e-9 * expected.norm(), "{k:?}");
    }
}
