//! The stress state of a correspondence body's particles
//! (`material::bond::correspondence`): its own material (the particles carry
//! the zero-stress material on the grid, `SceneConfig::particle_materials`),
//! and per particle F, the Cauchy stress and the material's history, as an
//! MPM particle has them. Checkpointed with the broken bonds.

use crate::dim::Mat3;
use crate::material::Material;

#[derive(Clone, Debug)]
pub struct StressState {
    pub material: Box<dyn Material>,
    pub f: Vec<Mat3>,
    pub stress: Vec<Mat3>,
    /// `n_history` values per particle.
    pub history: Vec<f64>,
    pub n_history: usize,
    /// The step-start history during a stress update (a buffer kept between
    /// steps).
    pub history_old: Vec<f64>,
}

impl StressState {
    /// n particles at rest (F = I, no stress) with the material's initial
    /// history.
    pub fn at_rest(material: Box<dyn Material>, n: usize) -> StressState {
        let n_history = material.n_history();
        let mut history = vec![0.0; n * n_history];
        for h in history.chunks_mut(n_history.max(1)).take(n) {
            material.initial_history(&Mat3::zeros(), h);
        }
        StressState {
            material,
            f: vec![Mat3::identity(); n],
            stress: vec![Mat3::zeros(); n],
            history,
            n_history,
            history_old: Vec::new(),
        }
    }

    /// The state as numbers, per particle F (9), σ (9) and the history, for
    /// checkpoints.
    pub fn numbers(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.f.len() * (18 + self.n_history));
        for i in 0..self.f.len() {
            out.extend(self.f[i].iter());
            out.extend(self.stress[i].iter());
            out.extend(&self.history[i * self.n_history..(i + 1) * self.n_history]);
        }
        out
    }

    /// The state of `numbers` of the same body.
    pub fn restore(&mut self, numbers: &[f64]) -> Result<(), String> {
        let per = 18 + self.n_history;
        if numbers.len() != self.f.len() * per {
            return Err(format!(
                "it holds {} stress numbers of a correspondence body, the body has {} \
                 particles of {per}",
                numbers.len(),
                self.f.len()
            ));
        }
        for (i, chunk) in numbers.chunks(per).enumerate() {
            self.f[i] = Mat3::from_column_slice(&chunk[..9]);
            self.stress[i] = Mat3::from_column_slice(&chunk[9..18]);
            let h = &mut self.history[i * self.n_history..(i + 1) * self.n_history];
            h.copy_from_slice(&chunk[18..]);
        }
        Ok(())
    }
}
