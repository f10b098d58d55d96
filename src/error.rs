//! [`Error`]: what the library's public entry points ([`crate::App`], [`crate::kinds`])
//! answer when they cannot do what was asked, with a stable [`kind`](Error::kind) and a human
//! message.

use std::fmt;

use crate::yaml::Diagnostic;

/// A failure of a public entry point. Match on the variant, or group by [`Error::kind`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Error {
    /// A tree file could not be read or is invalid; each diagnostic is located
    /// (`file:line:column`) and says what to do.
    Tree {
        /// The tree file (or the name given to a tree read from text).
        file: String,
        /// What is wrong, in source order.
        diagnostics: Vec<Diagnostic>,
    },
    /// A scene file could not be read or is invalid.
    Scene {
        /// The scene file.
        file: String,
        /// What is wrong, in source order.
        diagnostics: Vec<Diagnostic>,
    },
    /// The simulator could not be built for the scene (missing robot assets, MuJoCo refused the
    /// model).
    Simulator {
        /// What went wrong.
        message: String,
    },
    /// A node kind could not be registered (invalid or duplicate name, incomplete doc).
    Registry {
        /// The kind being registered.
        kind: String,
        /// Why it was refused.
        message: String,
    },
    /// An episode's settings are out of range (a non-positive control period or time limit, …).
    Config {
        /// What is out of range, and the accepted range.
        message: String,
    },
    /// An environment action or reset was refused before anything was simulated (a NaN, a
    /// joint out of its limits, an unknown subtree, a step after the simulation became
    /// unstable); the message says which value and the accepted range.
    Action {
        /// What is wrong, and what is accepted.
        message: String,
    },
    /// A step was stopped by its caller (Ctrl-C) at the start of a control period; the running
    /// action was halted there and the environment must be reset before it steps again.
    Interrupted {
        /// Where it stopped.
        message: String,
    },
}

impl Error {
    /// A stable, machine-readable name of the failure: `invalid_tree`, `invalid_scene`,
    /// `simulator`, `registry`, `config` or `invalid_action`.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Tree { .. } => "invalid_tree",
            Error::Scene { .. } => "invalid_scene",
            Error::Simulator { .. } => "simulator",
            Error::Registry { .. } => "registry",
            Error::Config { .. } => "config",
            Error::Action { .. } => "invalid_action",
            Error::Interrupted { .. } => "interrupted",
        }
    }

    /// The human message (what [`Display`](fmt::Display) prints): for invalid files, every
    /// diagnostic followed by a summary line.
    pub fn message(&self) -> String {
        self.to_string()
    }

    /// The located diagnostics of an invalid tree or scene (empty for other kinds).
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            Error::Tree { diagnostics, .. } | Error::Scene { diagnostics, .. } => diagnostics,
            _ => &[],
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Tree { file, diagnostics } | Error::Scene { file, diagnostics } => {
                for d in diagnostics {
                    writeln!(f, "{d}")?;
                }
                let what = if matches!(self, Error::Tree { .. }) {
                    "tree"
                } else {
                    "scene"
                };
                write!(
                    f,
                    "error: the {what} {file} is invalid ({} error(s))",
                    diagnostics.len()
                )
            }
            Error::Simulator { message } => write!(f, "error: cannot build the simulation: {message}"),
            Error::Registry { kind, message } => {
                write!(f, "error: cannot register node kind `{kind}`: {message}")
            }
            Error::Config { message } | Error::Action { message } | Error::Interrupted { message } => {
                write!(f, "error: {message}")
            }
        }
    }
}

impl std::error::Error for Error {}
