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
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SimError::MissingAsset { path, help } => {
                write!(f, "missing model file {}: {help}", path.display())
            }
            SimError::Scene(msg) => write!(f, "scene: {msg}"),
        }
    }
}

impl std::error::Error for SimError {}
