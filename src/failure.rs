//! Typed failures: every failure is a [`Failure`] value — a stable [`FailureKind`], a message a
//! person can act on, the node path where it happened and, when it wraps another failure (a
//! `retry` that used up its attempts, a guard whose condition failed), its cause.
//!
//! A failure is made where it happens, with its kind stated there: a controller's
//! [`start`/`update`](crate::actions::MacroAction), a condition check, the runner's retry,
//! timeout, guard and halt reasons, a substitution, the episode's goal and time-limit checks, the
//! sweep's layout and panic cases. Nothing derives a kind from a message's text.
//!
//! Kinds serialize as their stable names (`grasp_lost`, `timeout`, …; see
//! [`FailureKind::as_str`]), which is what the report's and the sweep's `failure_kind` field
//! holds. A user's node kind declares its own kinds ([`crate::Params::failure_kinds`]) and fails
//! with [`FailureKind::Custom`].
//!
//! ```
//! use macrotree::{Failure, FailureKind};
//!
//! let f = Failure::new(FailureKind::GraspFailed, "grasp failed: fingers stopped at 0.0 mm");
//! assert_eq!(f.kind.as_str(), "grasp_failed");
//! assert_eq!(f.to_string(), "grasp failed: fingers stopped at 0.0 mm");
//! let retry = Failure::new(f.kind, format!("all 3 attempts failed; last: {f}"))
//!     .at("main/retry")
//!     .caused_by(f.clone());
//! assert_eq!(retry.root_cause(), &f);
//! ```

use std::fmt;
use std::sync::Mutex;

use serde::{Serialize, Serializer};

/// The stable kind of a failure, for grouping failures across a sweep and for expectations
/// (`failure_kind:` in a scenario suite). Serialized as [`as_str`](Self::as_str).
///
/// New kinds may be added; match with a wildcard arm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum FailureKind {
    /// `time_limit`: the tree was still running when the episode's simulated-time limit hit.
    TimeLimit,
    /// `unstable`: MuJoCo reported an unstable simulation (the episode is no longer physics).
    Unstable,
    /// `goal_not_met`: the tree succeeded but the goal (the scene's, or the cube in the bowl)
    /// does not hold.
    GoalNotMet,
    /// `grasp_lost`: a held block left the fingers during a motion.
    GraspLost,
    /// `grasp_failed`: the fingers closed without holding the block.
    GraspFailed,
    /// `not_held`: an action that needs a block in the gripper (a `carry`) started without one.
    NotHeld,
    /// `unreachable`: no arm configuration or path reaches the goal (IK or path planning).
    Unreachable,
    /// `blocked`: no clear way (something in the path), or the arm stopped short of its goal.
    Blocked,
    /// `timeout`: a leaf's own time limit or a `timeout` node expired.
    Timeout,
    /// `halted`: the node was preempted while running.
    Halted,
    /// `condition_false`: a condition does not hold.
    ConditionFalse,
    /// `layout`: the sweep could not draw a layout for the scenario.
    Layout,
    /// `panicked`: the episode panicked (a bug; the sweep carries on).
    Panicked,
    /// `substituted`: a test double's scripted failure.
    Substituted,
    /// `substitution`: substitutions that do not fit the tree.
    Substitution,
    /// `goal_moved`: a carry's goal kept moving, and the transfer was re-planned too often.
    GoalMoved,
    /// `inverted`: an `inverter` (or a `not:` condition) failed because its child succeeded.
    Inverted,
    /// `forced`: a `force_failure` node failed as it always does, its child having succeeded.
    Forced,
    /// `overridden`: a failure forced on a leaf from outside the tree (the monitor's "force
    /// failure"), not the leaf's own.
    Overridden,
    /// `max_iterations`: a `for_each` still found a match after its `max_iterations`.
    MaxIterations,
    /// `start_in_collision`: a planned motion cannot start: the arm (or the block it holds) is
    /// already in collision; the message names the pairs.
    StartInCollision,
    /// `goal_in_collision`: every arm configuration that reaches the goal (each IK branch) is in
    /// collision; the message names what blocks them.
    GoalInCollision,
    /// `no_path`: the goal configurations are free but the motion planner found no
    /// collision-free path to any within its budget; the message names what blocked it most.
    NoPath,
    /// `container_full`: a `carry` into a container found no spot on its floor where the block
    /// and the opened fingers clear its walls and the blocks already in it (said before moving).
    ContainerFull,
    /// `collision`: a contact that should not happen (`--collisions fail`): the arm, the fingers
    /// or the held block touched a container, an obstacle or another block; at the leaf running.
    Collision,
    /// `other`: a failure of no more specific kind (an unknown object, an unresolved variable,
    /// a leaf the driver cannot run, …).
    Other,
    /// A kind a user's node kind declared ([`crate::Params::failure_kinds`]): a lower-case
    /// `snake_case` name that is not one of the built-in names.
    Custom(&'static str),
}

impl FailureKind {
    /// Every built-in kind (all but [`Custom`](Self::Custom)).
    pub const BUILTIN: [FailureKind; 26] = [
        FailureKind::TimeLimit,
        FailureKind::Unstable,
        FailureKind::GoalNotMet,
        FailureKind::GraspLost,
        FailureKind::GraspFailed,
        FailureKind::NotHeld,
        FailureKind::Unreachable,
        FailureKind::Blocked,
        FailureKind::Timeout,
        FailureKind::Halted,
        FailureKind::ConditionFalse,
        FailureKind::Layout,
        FailureKind::Panicked,
        FailureKind::Substituted,
        FailureKind::Substitution,
        FailureKind::GoalMoved,
        FailureKind::Inverted,
        FailureKind::Forced,
        FailureKind::Overridden,
        FailureKind::MaxIterations,
        FailureKind::StartInCollision,
        FailureKind::GoalInCollision,
        FailureKind::NoPath,
        FailureKind::ContainerFull,
        FailureKind::Collision,
        FailureKind::Other,
    ];

    /// The stable name (`time_limit`, `grasp_lost`, …, or a custom kind's own name).
    pub fn as_str(self) -> &'static str {
        match self {
            FailureKind::TimeLimit => "time_limit",
            FailureKind::Unstable => "unstable",
            FailureKind::GoalNotMet => "goal_not_met",
            FailureKind::GraspLost => "grasp_lost",
            FailureKind::GraspFailed => "grasp_failed",
            FailureKind::NotHeld => "not_held",
            FailureKind::Unreachable => "unreachable",
            FailureKind::Blocked => "blocked",
            FailureKind::Timeout => "timeout",
            FailureKind::Halted => "halted",
            FailureKind::ConditionFalse => "condition_false",
            FailureKind::Layout => "layout",
            FailureKind::Panicked => "panicked",
            FailureKind::Substituted => "substituted",
            FailureKind::Substitution => "substitution",
            FailureKind::GoalMoved => "goal_moved",
            FailureKind::Inverted => "inverted",
            FailureKind::Forced => "forced",
            FailureKind::Overridden => "overridden",
            FailureKind::MaxIterations => "max_iterations",
            FailureKind::StartInCollision => "start_in_collision",
            FailureKind::GoalInCollision => "goal_in_collision",
            FailureKind::NoPath => "no_path",
            FailureKind::ContainerFull => "container_full",
            FailureKind::Collision => "collision",
            FailureKind::Other => "other",
            FailureKind::Custom(name) => name,
        }
    }

    /// The built-in kind named `name`, if there is one.
    pub fn builtin(name: &str) -> Option<FailureKind> {
        Self::BUILTIN.into_iter().find(|k| k.as_str() == name)
    }

    /// Checks a name a user's node kind declares for its own failures: 1 to
    /// [`MAX_CUSTOM_NAME`] characters of `a-z`, `0-9` and `_`, starting with a letter, and not a
    /// built-in name.
    ///
    /// # Errors
    /// What is wrong with the name, and what to do.
    pub fn check_custom_name(name: &str) -> Result<(), String> {
        if let Some(k) = Self::builtin(name) {
            return Err(format!(
                "failure kind `{name}` is built in: fail with `FailureKind::{k:?}` instead of declaring it"
            ));
        }
        let valid = !name.is_empty()
            && name.len() <= MAX_CUSTOM_NAME
            && name.starts_with(|c: char| c.is_ascii_lowercase())
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if valid {
            Ok(())
        } else {
            Err(format!(
                "failure kind {name:?} is not a stable name: use 1 to {MAX_CUSTOM_NAME} characters of a-z, 0-9 and _, starting with a letter"
            ))
        }
    }

    /// The kind named `name` as read back from a file (a sweep being resumed): a built-in kind,
    /// or a custom one if the name is valid ([`check_custom_name`](Self::check_custom_name)).
    /// At most [`MAX_CUSTOM_KINDS`] distinct custom names are kept per process.
    ///
    /// # Errors
    /// An invalid name, or too many distinct custom names.
    pub fn parse(name: &str) -> Result<FailureKind, String> {
        if let Some(k) = Self::builtin(name) {
            return Ok(k);
        }
        Self::check_custom_name(name)?;
        static NAMES: Mutex<Vec<&'static str>> = Mutex::new(Vec::new());
        let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&known) = names.iter().find(|&&n| n == name) {
            return Ok(FailureKind::Custom(known));
        }
        if names.len() >= MAX_CUSTOM_KINDS {
            return Err(format!(
                "failure kind `{name}`: more than {MAX_CUSTOM_KINDS} distinct custom failure kinds"
            ));
        }
        // Bounded above: at most MAX_CUSTOM_KINDS short names live for the whole process.
        let leaked: &'static str = Box::leak(name.to_string().into_boxed_str());
        names.push(leaked);
        Ok(FailureKind::Custom(leaked))
    }
}

/// The longest custom failure kind name, characters.
pub const MAX_CUSTOM_NAME: usize = 40;

/// The most distinct custom failure kinds [`FailureKind::parse`] keeps in one process.
pub const MAX_CUSTOM_KINDS: usize = 256;

impl fmt::Display for FailureKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for FailureKind {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// A failure: its kind, a message a person can act on (what `Display` prints), the path of the
/// node where it happened (when known) and the failure it wraps, if any.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Failure {
    /// The stable kind.
    pub kind: FailureKind,
    /// What happened, with the measured values (`grasp failed: fingers stopped at 0.0 mm …`).
    pub message: String,
    /// The path of the node it happened at (`main/retry/grasp`), once the runner knows it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub node: Option<String>,
    /// The failure this one wraps (the last attempt's failure for a `retry`, the condition's for
    /// a guard).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cause: Option<Box<Failure>>,
}

impl Failure {
    /// A failure of `kind` with `message`, at no node yet and with no cause.
    pub fn new(kind: FailureKind, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
            node: None,
            cause: None,
        }
    }

    /// A failure of kind [`FailureKind::Other`] (nothing more specific applies).
    pub fn other(message: impl Into<String>) -> Self {
        Self::new(FailureKind::Other, message)
    }

    /// The same failure, at the node `path` (kept if it already names one).
    pub fn at(mut self, path: impl Into<String>) -> Self {
        if self.node.is_none() {
            self.node = Some(path.into());
        }
        self
    }

    /// The same failure, wrapping `cause`.
    pub fn caused_by(mut self, cause: Failure) -> Self {
        self.cause = Some(Box::new(cause));
        self
    }

    /// The innermost failure of the chain of causes (`self` when it has none).
    pub fn root_cause(&self) -> &Failure {
        let mut f = self;
        while let Some(c) = &f.cause {
            f = c;
        }
        f
    }

    /// The same failure with what to change appended to its message (`…; help: raise
    /// \`lift:\` …`), as a loader diagnostic ends with its `help:`.
    pub fn with_help(mut self, help: &str) -> Self {
        self.message = format!("{}; help: {help}", self.message);
        self
    }

    /// The same failure with its message prefixed (`grasp: ` + message).
    pub fn prefixed(mut self, prefix: &str) -> Self {
        self.message = format!("{prefix}{}", self.message);
        self
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Failure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.cause
            .as_deref()
            .map(|c| c as &(dyn std::error::Error + 'static))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_names_are_distinct_and_round_trip() {
        let mut names: Vec<&str> = FailureKind::BUILTIN.iter().map(|k| k.as_str()).collect();
        for k in FailureKind::BUILTIN {
            assert_eq!(FailureKind::builtin(k.as_str()), Some(k));
            assert_eq!(FailureKind::parse(k.as_str()), Ok(k));
            assert_eq!(serde_json::to_string(&k).unwrap(), format!("\"{}\"", k.as_str()));
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), FailureKind::BUILTIN.len());
    }

    #[test]
    fn the_names_of_before_typed_failures_are_kept() {
        // The JSONL of every sweep written before failures were typed holds these names.
        for name in [
            "time_limit",
            "unstable",
            "goal_not_met",
            "grasp_lost",
            "grasp_failed",
            "unreachable",
            "blocked",
            "timeout",
            "halted",
            "condition_false",
            "layout",
            "panicked",
            "substituted",
            "substitution",
            "other",
        ] {
            assert!(FailureKind::builtin(name).is_some(), "{name}");
        }
    }

    #[test]
    fn custom_names_are_checked() {
        assert!(FailureKind::check_custom_name("pushed_off").is_ok());
        for bad in ["", "Pushed", "1st", "pushed-off", "timeout", &"x".repeat(41)] {
            assert!(FailureKind::check_custom_name(bad).is_err(), "{bad:?}");
        }
        assert!(
            FailureKind::check_custom_name("grasp_lost")
                .unwrap_err()
                .contains("FailureKind::GraspLost")
        );
        let k = FailureKind::parse("pushed_off").unwrap();
        assert_eq!(k, FailureKind::Custom("pushed_off"));
        assert_eq!(k.as_str(), "pushed_off");
        assert!(FailureKind::parse("Pushed Off").is_err());
    }

    #[test]
    fn a_failure_displays_its_message_and_chains_its_cause() {
        let inner = Failure::new(FailureKind::GraspLost, "grasp lost during transfer").at("main/carry");
        let outer = Failure::new(inner.kind, format!("all 2 attempts failed; last: {inner}"))
            .at("main")
            .caused_by(inner.clone());
        assert_eq!(
            outer.to_string(),
            "all 2 attempts failed; last: grasp lost during transfer"
        );
        assert_eq!(outer.root_cause(), &inner);
        assert_eq!(outer.clone().at("elsewhere").node.as_deref(), Some("main"));
        let source = std::error::Error::source(&outer).unwrap().to_string();
        assert_eq!(source, "grasp lost during transfer");
    }
}
