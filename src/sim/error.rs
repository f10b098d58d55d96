//! Errors of the MuJoCo adapter.

use std::path::PathBuf;

/// Something went wrong while building or running the simulation.
#[derive(Debug)]
pub enum SimError {
    /// A model file is missing.
    MissingAsset {
        /// The file that was looked for.
        path: PathBuf,
        /// What to do about it.
        help: String,
    },
    /// The scene could not be parsed, attached or compiled.
    Scene(String),
    /// The scene's default placement cannot be drawn: its `random:` ranges leave no room for an
    /// object (a scene built in code; a scene file with this problem is refused when read).
    Placement {
        /// The scene's name.
        scene: String,
        /// Why the draw failed.
        reason: crate::scene::PlacementError,
    },
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SimError::MissingAsset { path, help } => {
                write!(f, "missing model file {}: {help}", path.display())
            }
            SimError::Scene(msg) => write!(f, "scene: {msg}"),
            SimError::Placement { scene, reason } => write!(
                f,
                "scene `{scene}`: its default placement cannot be drawn: {reason}; {}",
                reason.hint()
            ),
        }
    }
}

impl std::error::Error for SimError {}
