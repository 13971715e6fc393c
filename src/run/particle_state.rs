//! A run's particles as flat arrays (checkpoints, and the end state a
//! strength-reduction trial hands to the next).

use crate::dim::{Mat3, Tensor, Vector};
use crate::model::particles::{History, Particles};
use crate::model::tensors::{Layout, Tensors};
use serde::{Deserialize, Serialize};

/// The particles as flat arrays: vectors D values each, 3×3 matrices 9 values
/// each in column order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParticleState {
    pub count: usize,
    pub x: Vec<f64>,
    pub x0: Vec<f64>,
    pub v: Vec<f64>,
    pub mass: Vec<f64>,
    pub volume: Vec<f64>,
    pub volume0: Vec<f64>,
    pub f: Vec<f64>,
    pub stress: Vec<f64>,
    pub half_length0: Vec<f64>,
    pub body: Vec<u32>,
    pub material: Vec<u32>,
    pub load: Vec<f64>,
    pub history_offset: Vec<u32>,
    pub history_len: Vec<u16>,
    pub history: Vec<f64>,
    /// APIC's B_p, D × D values per particle (column-major), or none.
    #[serde(default)]
    pub affine: Vec<f64>,
}

fn flat_vectors<const D: usize>(v: &[Vector<D>]) -> Vec<f64> {
    v.iter().flat_map(|a| a.iter().copied()).collect()
}

/// Nine values per tensor (column-major), whatever the particles' packing.
fn flat_matrices(m: &Tensors) -> Vec<f64> {
    m.iter()
        .flat_map(|a| a.data.0.into_iter().flatten())
        .collect()
}

fn vectors<const D: usize>(v: &[f64]) -> Vec<Vector<D>> {
    v.chunks_exact(D)
        .map(Vector::<D>::from_column_slice)
        .collect()
}

fn matrices(v: &[f64], layout: Layout) -> Tensors {
    Tensors::from_matrices(layout, v.chunks_exact(9).map(Mat3::from_column_slice))
}

impl ParticleState {
    pub fn of<const D: usize>(p: &Particles<D>) -> ParticleState {
        ParticleState {
            count: p.len(),
            x: flat_vectors(&p.x),
            x0: flat_vectors(&p.x0),
            v: flat_vectors(&p.v),
            mass: p.mass.clone(),
            volume: p.volume.clone(),
            volume0: p.volume0.clone(),
            f: flat_matrices(&p.f),
            stress: flat_matrices(&p.stress),
            half_length0: flat_vectors(&p.half_length0),
            body: p.body.clone(),
            material: p.material.clone(),
            load: flat_vectors(&p.load),
            history_offset: p.history.offset.clone(),
            history_len: p.history.len.clone(),
            history: p.history.data.clone(),
            affine: p.affine.iter().flat_map(|b| b.iter().copied()).collect(),
        }
    }

    /// The particles, if every array has the length `count` asks for.
    pub fn particles<const D: usize>(&self) -> Result<Particles<D>, String> {
        let n = self.count;
        let lengths = [
            ("x", self.x.len(), n * D),
            ("x0", self.x0.len(), n * D),
            ("v", self.v.len(), n * D),
            ("mass", self.mass.len(), n),
            ("volume", self.volume.len(), n),
            ("volume0", self.volume0.len(), n),
            ("f", self.f.len(), n * 9),
            ("stress", self.stress.len(), n * 9),
            ("half_length0", self.half_length0.len(), n * D),
            ("body", self.body.len(), n),
            ("material", self.material.len(), n),
            ("history_offset", self.history_offset.len(), n),
            ("history_len", self.history_len.len(), n),
        ];
        // The loads and the affine moments are kept only where a scene has them.
        let optional = [
            ("load", self.load.len(), n * D),
            ("affine", self.affine.len(), n * D * D),
        ];
        for (name, got, want) in optional {
            if got != 0 && got != want {
                return Err(format!(
                    "particles.{name} has {got} values, 0 or {want} expected for {n} particles"
                ));
            }
        }
        for (name, got, want) in lengths {
            if got != want {
                return Err(format!(
                    "particles.{name} has {got} values, {want} expected for {n} particles"
                ));
            }
        }
        Ok(Particles {
            x: vectors(&self.x),
            x0: vectors(&self.x0),
            v: vectors(&self.v),
            mass: self.mass.clone(),
            volume: self.volume.clone(),
            volume0: self.volume0.clone(),
            f: matrices(&self.f, Layout::gradient(D)),
            stress: matrices(&self.stress, Layout::stress(D)),
            half_length0: vectors(&self.half_length0),
            body: self.body.clone(),
            material: self.material.clone(),
            load: vectors(&self.load),
            // Recomputed from the positions (`Model::update_pore_pressure`).
            pore_pressure: Vec::new(),
            history: History {
                offset: self.history_offset.clone(),
                len: self.history_len.clone(),
                data: self.history.clone(),
            },
            affine: (self.affine.chunks_exact(D * D))
                .map(Tensor::<D>::from_column_slice)
                .collect(),
        })
    }
}
