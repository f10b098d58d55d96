//! Results forced on a leaf from outside the tree: the monitor's "force success / force
//! failure" (Groot2's REPLACE hook), one activation at a time.
//!
//! A forced result replaces what the leaf would answer at its next tick: a running leaf is
//! halted first (its motion stops as if preempted), then answers the forced result; a leaf that
//! is not running answers it when it is next ticked, without reaching the driver. A forced
//! failure has the kind [`overridden`](crate::failure::FailureKind::Overridden), and the node's
//! [`NodeCounts::overridden`](super::NodeCounts::overridden) counts every forced result, so a
//! run's report says which results were not the leaf's own.

use std::fmt;
use std::str::FromStr;

/// The result forced on a leaf's next tick.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ForcedResult {
    /// The leaf succeeds at once.
    Success,
    /// The leaf fails at once (kind `overridden`).
    Failure,
}

impl ForcedResult {
    /// The stable name: `success` or `failure`.
    pub fn as_str(self) -> &'static str {
        match self {
            ForcedResult::Success => "success",
            ForcedResult::Failure => "failure",
        }
    }
}

impl fmt::Display for ForcedResult {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ForcedResult {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "success" => Ok(ForcedResult::Success),
            "failure" => Ok(ForcedResult::Failure),
            other => Err(format!("{other:?}: a forced result is `success` or `failure`")),
        }
    }
}

/// Why a result could not be forced.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ForceError {
    /// No node has this index.
    NoSuchNode(usize),
    /// The node is a composite or decorator: only leaves (actions, conditions, `wait`,
    /// `select`) can be forced; a composite's result follows from its children's.
    NotALeaf(String),
}

impl fmt::Display for ForceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ForceError::NoSuchNode(i) => write!(f, "the tree has no node {i}"),
            ForceError::NotALeaf(path) => write!(
                f,
                "`{path}` is not a leaf: force one of its leaves (a composite's result follows from its children's)"
            ),
        }
    }
}

impl std::error::Error for ForceError {}
