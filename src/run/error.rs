//! How a run ends when it does not complete: a scene or output error, an
//! unusable checkpoint, a divergence or a signal (the last two with the
//! summary.json they wrote).

use crate::run::summary::Summary;
use crate::scene::SceneError;

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Scene(#[from] SceneError),
    #[error("cannot write outputs: {0}")]
    Io(#[from] std::io::Error),
    /// A checkpoint to restart from that cannot be used (unreadable, of another
    /// format version, damaged, or of another scene).
    #[error("{0}")]
    Checkpoint(String),
    /// The run stopped early; its summary (also in summary.json) says where.
    #[error("{message}")]
    Diverged {
        message: String,
        summary: Box<Summary>,
    },
    /// A signal stopped the run at the end of a step; its outputs so far are
    /// written (`interrupt.rs`).
    #[error("{message}")]
    Interrupted {
        signal: i32,
        message: String,
        summary: Box<Summary>,
    },
}
