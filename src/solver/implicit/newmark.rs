//! Newmark time integration on the grid (thesis 2-33…2-36, stability 2-46), written
//! for the displacement increment u of one step (u = 0 at the step start).

use crate::dim::Vector;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Newmark {
    pub beta: f64,
    pub gamma: f64,
}

impl Newmark {
    /// Predictor ũ = Δt v_n + (½ − β) Δt² a_n (2-36).
    pub fn predictor<const D: usize>(&self, dt: f64, v: &Vector<D>, a: &Vector<D>) -> Vector<D> {
        v * dt + a * ((0.5 - self.beta) * dt * dt)
    }

    /// a_{n+1} = (u − ũ) / (β Δt²) (2-34).
    pub fn acceleration<const D: usize>(
        &self,
        dt: f64,
        u: &Vector<D>,
        u_tilde: &Vector<D>,
    ) -> Vector<D> {
        (u - u_tilde) / (self.beta * dt * dt)
    }

    /// Velocity increment v_{n+1} − v_n = Δt ((1 − γ) a_n + γ a_{n+1}) (2-33, 2-35).
    pub fn velocity_increment<const D: usize>(
        &self,
        dt: f64,
        a: &Vector<D>,
        a_new: &Vector<D>,
    ) -> Vector<D> {
        (a * (1.0 - self.gamma) + a_new * self.gamma) * dt
    }

    /// End-of-step velocity as a function of the increment u:
    /// v_{n+1} = v_n + Δt ((1 − γ) a_n + γ a_{n+1}) with v_n = (ũ − (½ − β) Δt² a_n)/Δt
    /// recovered from the predictor (2-33…2-36).
    pub fn end_velocity<const D: usize>(
        &self,
        dt: f64,
        u: &Vector<D>,
        u_tilde: &Vector<D>,
        a: &Vector<D>,
    ) -> Vector<D> {
        let v = (u_tilde - a * ((0.5 - self.beta) * dt * dt)) / dt;
        v + self.velocity_increment(dt, a, &self.acceleration(dt, u, u_tilde))
    }

    /// ∂v_{n+1}/∂u = γ / (β Δt), the damping coefficient of the tangent.
    pub fn velocity_rate(&self, dt: f64) -> f64 {
        self.gamma / (self.beta * dt)
    }

    /// Inertia coefficient of the tangent, 1 / (β Δt²) (2-40).
    pub fn inertia(&self, dt: f64) -> f64 {
        1.0 / (self.beta * dt * dt)
    }

    /// γ ≥ ½ and β ≥ (γ + ½)²/4 (2-46).
    pub fn unconditionally_stable(&self) -> bool {
        self.gamma >= 0.5 && self.beta >= 0.25 * (self.gamma + 0.5).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector1;

    /// One degree of freedom, ü + ω² u = 0: the trapezoidal rule conserves the
    /// energy ½v² + ½ω²x² exactly and its period error is (ωΔt)²/12 to leading order.
    #[test]
    fn trapezoidal_rule_on_an_oscillator() {
        let nm = Newmark {
            beta: 0.25,
            gamma: 0.5,
        };
        let (omega, dt) = (1.0, 0.1);
        let (mut x, mut v, mut a) = (1.0, 0.0, -1.0);
        let mut crossings = Vec::new();
        for n in 0..2000 {
            // Solve (1/(βΔt²) + ω²) u = ũ/(βΔt²) − ω² x for the increment u.
            let ut = nm.predictor(dt, &Vector1::new(v), &Vector1::new(a))[0];
            let u = (ut * nm.inertia(dt) - omega * omega * x) / (nm.inertia(dt) + omega * omega);
            let a_new = nm.acceleration(dt, &Vector1::new(u), &Vector1::new(ut))[0];
            let x_new = x + u;
            if x > 0.0 && x_new <= 0.0 {
                crossings.push(n as f64 * dt + dt * x / (x - x_new));
            }
            let v_end =
                nm.end_velocity(dt, &Vector1::new(u), &Vector1::new(ut), &Vector1::new(a))[0];
            v += nm.velocity_increment(dt, &Vector1::new(a), &Vector1::new(a_new))[0];
            assert!((v_end - v).abs() < 1e-12, "end velocity {v_end} vs {v}");
            (x, a) = (x_new, a_new);
            let energy = 0.5 * v * v + 0.5 * omega * omega * x * x;
            assert!((energy - 0.5).abs() < 1e-12, "energy {energy} at step {n}");
        }
        let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
        let exact = 2.0 * std::f64::consts::PI;
        let predicted = (omega * dt).powi(2) / 12.0;
        assert!(
            ((period / exact - 1.0) / predicted - 1.0).abs() < 0.01,
            "period error {}",
            period / exact - 1.0
        );
        assert!(nm.unconditionally_stable());
        assert!(!Newmark {
            beta: 0.25,
            gamma: 0.4
        }
        .unconditionally_stable());
        assert!(!Newmark {
            beta: 0.2,
            gamma: 0.5
        }
        .unconditionally_stable());
    }
}
