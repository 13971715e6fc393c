//! Checkpoints: everything a run needs to continue exactly where it was, written
//! between two steps (`[output] checkpoint_interval` in simulation time,
//! `checkpoint_wall_seconds` on the wall clock, and on SIGINT/SIGTERM), and read
//! back by `mpm run SCENE --restart CHECKPOINT`.
//!
//! A checkpoint holds the scene text as run (overrides applied), the dimension,
//! the stage, time, step, last Δt, load factor and strength-reduction factor,
//! every particle field (x, X, v, m, V, V0, F, σ, the CPDI/GIMP half-lengths
//! whose images F r⁰ are the domain vectors, body, material, loads, history
//! variables), the broken bonds of peridynamic bodies, the stepper's state across steps (`solver::stepper::SolverState`:
//! Newmark accelerations, the implicit contact's tangential forces and contact
//! points, counts) and the recorders' state (the streamed CSVs as
//! written so far, the frame list, when the next row and frame are due).
//!
//! Format: two lines of JSON. The first is a header
//! `{"format":"mpm checkpoint","version":V,"body_bytes":N,"body_fnv1a64":"…"}`;
//! the second, the body, is N bytes whose FNV-1a 64-bit hash is the one given,
//! so a truncated or altered file is refused rather than half read. JSON through
//! serde_json (already a dependency for summary.json) keeps the file
//! self-describing and readable with any tool; its writer prints each f64 as the
//! shortest decimal that reads back to the same bits (ryu) and its
//! `float_roundtrip` reader parses it back to those bits, so every number
//! round-trips exactly (a test checks subnormals, ±0 and extremes). JSON has no
//! NaN or infinity (serde_json writes null): a checkpoint of such a state is
//! refused when read (a run stops on a non-finite state before, `check_state`).

use crate::output::atomic::write_atomically;
use crate::run::error::RunError;
pub use crate::run::particle_state::ParticleState;
use crate::run::recorders::RecorderState;
use crate::run::summary::StageSummary;
use crate::scene::Scene;
use crate::solver::stepper::SolverState;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// What a checkpoint file says it is.
pub const FORMAT: &str = "mpm checkpoint";
/// The layout of the body; a build reads only its own version.
pub const VERSION: u32 = 3;
/// How many checkpoints a run keeps (the older ones it wrote are removed).
pub const KEEP: usize = 2;

#[derive(Debug, Serialize, Deserialize)]
struct Header {
    format: String,
    version: u32,
    body_bytes: usize,
    body_fnv1a64: String,
}

/// The state of a run between two steps.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The scene file's name and its text as run, overrides applied.
    pub scene_file: String,
    pub scene_text: String,
    pub dimension: usize,
    /// Index of the stage under way (0 for a scene with one [solver]).
    pub stage: usize,
    /// Time the stage started at (the quasi-static load factor counts from it).
    pub stage_start: f64,
    /// The run's step count when the stage started.
    pub stage_first_step: usize,
    /// The stages already finished, as summary.json reports them.
    pub stages_done: Vec<StageSummary>,
    pub time: f64,
    pub step: usize,
    /// The last step's Δt (0 before the stage's first step).
    pub dt: f64,
    /// The quasi-static load factor λ of an implicit quasi-static stage, for the
    /// reader (the solver recomputes it from the time).
    pub load_factor: Option<f64>,
    /// The strengths' divisor in force (1: as given).
    pub strength_factor: f64,
    /// Work of gravity and loads since the start.
    pub external_work: f64,
    /// The critical time step of the model as built (summary.json).
    pub dt_critical: f64,
    /// The simulation time the next checkpoint is due at.
    pub next_checkpoint: f64,
    pub particles: ParticleState,
    /// Per peridynamic body, the ids of its broken bonds, ascending
    /// (`model::peridynamics::Peridynamics::broken_bonds`); empty without one.
    pub broken_bonds: Vec<Vec<u32>>,
    /// Per peridynamic body, its correspondence stress state
    /// (`Peridynamics::stress_states`: F, σ and history per particle; empty
    /// for a bond-based body).
    #[serde(default)]
    pub peridynamic_stress: Vec<Vec<f64>>,
    /// A staged scene's particles by their index as built, in the order of
    /// `particles` (`model::staging`); None in a scene that stages nothing.
    #[serde(default)]
    pub staged_particles: Option<Vec<u32>>,
    pub solver: SolverState,
    pub recorders: RecorderState,
}

/// FNV-1a, 64 bits (Fowler, Noll, Vo): a checksum of the body against
/// truncation and damage (not against tampering).
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The file name of the checkpoint after `step`.
pub fn file_name(step: usize) -> String {
    format!("checkpoint_{step:09}.json")
}

impl Checkpoint {
    /// Write the checkpoint atomically to `path`.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let body = serde_json::to_vec(self).map_err(std::io::Error::other)?;
        let header = Header {
            format: FORMAT.into(),
            version: VERSION,
            body_bytes: body.len(),
            body_fnv1a64: format!("{:016x}", fnv1a64(&body)),
        };
        let header = serde_json::to_vec(&header).map_err(std::io::Error::other)?;
        write_atomically(path, |w| {
            w.write_all(&header)?;
            w.write_all(b"\n")?;
            w.write_all(&body)?;
            w.write_all(b"\n")
        })
    }

    /// Read a checkpoint, refusing (with a message naming the file) one that is
    /// not a checkpoint, of another format version, truncated or damaged.
    pub fn read(path: &Path) -> Result<Checkpoint, String> {
        let name = path.display();
        let bytes =
            std::fs::read(path).map_err(|e| format!("cannot read checkpoint {name}: {e}"))?;
        let not_one = || format!("{name} is not an mpm checkpoint (no header line)");
        let split = bytes.iter().position(|&b| b == b'\n').ok_or_else(not_one)?;
        let header: Header = serde_json::from_slice(&bytes[..split]).map_err(|_| not_one())?;
        if header.format != FORMAT {
            return Err(not_one());
        }
        if header.version != VERSION {
            return Err(format!(
                "checkpoint {name} has format version {}, this build reads version {VERSION} only",
                header.version
            ));
        }
        let body = &bytes[split + 1..];
        let body = body.strip_suffix(b"\n").unwrap_or(body);
        if body.len() != header.body_bytes {
            return Err(format!(
                "checkpoint {name} is truncated or damaged: its body has {} bytes, the header says {}",
                body.len(),
                header.body_bytes
            ));
        }
        if format!("{:016x}", fnv1a64(body)) != header.body_fnv1a64 {
            return Err(format!(
                "checkpoint {name} is damaged: its body does not match the header's checksum"
            ));
        }
        serde_json::from_slice(body).map_err(|e| format!("checkpoint {name} cannot be read: {e}"))
    }
}

/// The checkpoints a run has written, oldest first; all but the last [`KEEP`]
/// are removed as new ones come.
#[derive(Debug, Default)]
pub struct Kept(Vec<PathBuf>);

impl Kept {
    pub fn push(&mut self, path: PathBuf) {
        if self.0.last() != Some(&path) {
            self.0.push(path);
        }
        while self.0.len() > KEEP {
            std::fs::remove_file(self.0.remove(0)).ok();
        }
    }
}

/// A checkpoint to continue from, and where it was read.
pub(super) struct Resume {
    pub checkpoint: Checkpoint,
    pub path: PathBuf,
}

/// The checkpoint at `path`, if it was written by a run of this scene (the same
/// text after overrides, hence the same dimension) and this build can read it.
pub(super) fn matching_checkpoint(scene: &Scene, path: &Path) -> Result<Checkpoint, RunError> {
    let ck = Checkpoint::read(path).map_err(RunError::Checkpoint)?;
    let name = path.display();
    if ck.dimension != scene.config.dimension.spatial() {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} is of a {}D run, {} is {}D",
            ck.dimension,
            scene.file,
            scene.config.dimension.spatial()
        )));
    }
    if ck.scene_text != scene.text {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} was written by a run of another scene ({}, or other --set \
             overrides): restart with the scene text and overrides it was written with",
            ck.scene_file
        )));
    }
    Ok(ck)
}

/// The particles of a checkpoint, which must be as many as the scene builds.
pub(super) fn restored_particles<const D: usize>(
    ck: &Checkpoint,
    path: &Path,
    built: usize,
) -> Result<crate::model::particles::Particles<D>, RunError> {
    let name = path.display();
    let p = (ck.particles.particles::<D>())
        .map_err(|e| RunError::Checkpoint(format!("checkpoint {name}: {e}")))?;
    if p.len() != built {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} holds {} particles, the scene builds {built}",
            p.len()
        )));
    }
    Ok(p)
}

/// A staged scene's particles as the checkpoint of stage `ck.stage` has
/// them: the bodies activated up to that stage added to the model as built,
/// then the particles it names kept, in its order (`Model::restore_staging`);
/// their state is restored next (`restored_particles`).
pub(super) fn restore_staging<const D: usize>(
    ck: &Checkpoint,
    path: &Path,
    cfg: &crate::scene::SceneConfig,
    model: &mut crate::model::Model<D>,
) -> Result<(), RunError> {
    if model.staging.is_none() {
        return Ok(());
    }
    let name = path.display();
    let Some(built) = &ck.staged_particles else {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} does not list the particles of this staged scene"
        )));
    };
    (model.restore_staging(&cfg.activated_by_stage(ck.stage), built))
        .map_err(|e| RunError::Checkpoint(format!("checkpoint {name}: {e}")))
}

/// The peridynamic bodies' bonds of a checkpoint: the scene rebuilds them
/// intact from the reference positions, the checkpoint says which are broken.
pub(super) fn restore_bonds<const D: usize>(
    ck: &Checkpoint,
    path: &Path,
    model: &mut crate::model::Model<D>,
) -> Result<(), RunError> {
    let Some(pd) = &mut model.peridynamics else {
        return Ok(());
    };
    (pd.restore_broken(&ck.broken_bonds))
        .and_then(|()| pd.restore_stress(&ck.peridynamic_stress))
        .map_err(|e| RunError::Checkpoint(format!("checkpoint {}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_to_the_same_bits() {
        let values = [
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            5e-324,
            -2.225073858507201e-308,
            f64::MAX,
            f64::MIN,
            0.1 + 0.2,
            1.0 / 3.0,
            std::f64::consts::PI * 1e-17,
            9007199254740993.0,
        ];
        let text = serde_json::to_string(&values.to_vec()).unwrap();
        let back: Vec<f64> = serde_json::from_str(&text).unwrap();
        for (a, b) in values.iter().zip(&back) {
            assert_eq!(a.to_bits(), b.to_bits(), "{a:e} read back as {b:e}");
        }
        // Pseudo-random bit patterns across the exponent range.
        let mut s = 0x9e37_79b9_7f4a_7c15_u64;
        let random: Vec<f64> = (0..20000)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                f64::from_bits(s)
            })
            .filter(|x| x.is_finite())
            .collect();
        let back: Vec<f64> =
            serde_json::from_str(&serde_json::to_string(&random).unwrap()).unwrap();
        assert!(random
            .iter()
            .zip(&back)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn the_checksum_is_fnv1a() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
