//! Plan → running tree: ticks on simulated time, leaf lifecycle (first tick, halts), per-node
//! statuses, status transitions and `tracing` events.
//!
//! The runtime owns a bonsai [`BT`](bonsai_bt::BT) built from [`Plan::behavior`](crate::plan::Plan::behavior) and answers its
//! leaf calls: ordinary leaves go to a [`LeafDriver`] (the MuJoCo-backed one lives in
//! [`crate::actions`], a scripted one for tests in [`scripted`]); `wait`, probes and yields are
//! handled here. Semantics (leftover dt, retry yield, halt detection, guards) are described in
//! `docs/tick_semantics.md`.
//!
//! ```
//! use std::sync::Arc;
//! use macrotree::plan::Loader;
//! use macrotree::runtime::{TreeRunner, TreeStatus, scripted::ScriptedDriver, LeafOutcome};
//!
//! let plan = Arc::new(Loader::default().compile_str("main: {sequence: {children: [{home: {}}, {wait: {seconds: 0.25}}]}}", "t.yaml").unwrap());
//! let mut driver = ScriptedDriver::new(&plan);
//! driver.script("home", [LeafOutcome::Running, LeafOutcome::Success]);
//! let mut runner = TreeRunner::new(plan);
//! let dt = 0.1;
//! let mut t = 0.0;
//! let mut status = TreeStatus::Running;
//! for _ in 0..10 {
//!     status = runner.tick(t, dt, &mut driver);
//!     t += dt;
//!     if status != TreeStatus::Running { break; }
//! }
//! assert_eq!(status, TreeStatus::Success);
//! assert_eq!(driver.starts("home"), 1);
//! ```

#![warn(missing_docs)]

pub mod blackboard;
pub mod overrides;
mod runner;
pub mod scripted;
pub mod substitute;

use std::fmt;

use serde::Serialize;

use crate::failure::{Failure, FailureKind};
use crate::kinds::Leaf;
use crate::plan::LeafId;

pub use blackboard::Blackboard;
pub use overrides::{ForceError, ForcedResult};
pub use runner::TreeRunner;

/// One blackboard write, as logged (also a `tracing` event, target `macrotree::blackboard`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlackboardWrite {
    /// Tick number.
    pub tick: u64,
    /// Simulated time of that tick, seconds.
    pub sim_time: f64,
    /// The node that wrote (a `select` or a `for_each`).
    pub path: String,
    /// The variable.
    pub var: String,
    /// The value written (`None`: unset, e.g. a `goal_as` for an object without a goal).
    pub value: Option<String>,
}

/// What a `select` (or a `for_each` iteration) found: an object's name and, when it has a goal
/// in the scene, where the goal sends it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Selection {
    /// The selected object.
    pub object: String,
    /// The container or block its goal names, if any.
    pub destination: Option<String>,
}

/// What a driver answers for one tick of a leaf.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LeafOutcome {
    /// Still working; tick me again next tick (uses up the rest of this tick's `dt`).
    Running,
    /// Done; the rest of the tick's `dt` goes to the next node.
    Success,
    /// Could not do it: a failure of a stable kind with a short human-readable message ("IK
    /// failed", "cube slipped"). The runner adds the leaf's kind to the message and its path.
    Failure(Failure),
}

impl LeafOutcome {
    /// A failure of `kind` with `message`.
    pub fn failure(kind: FailureKind, message: impl Into<String>) -> Self {
        LeafOutcome::Failure(Failure::new(kind, message))
    }
}

/// What executes action and condition leaves; the MuJoCo-backed one lives elsewhere, a scripted
/// one in tests ([`scripted::ScriptedDriver`]).
///
/// Drivers only ever see [`Leaf::Action`] and [`Leaf::Condition`] leaves. Conditions must answer
/// Success or Failure in the same tick (a Running answer is turned into a Failure).
pub trait LeafDriver {
    /// Tick leaf `id`; `first` is true on the first tick of a new execution of that leaf (it was
    /// not running before this call: never ticked, finished, or halted).
    fn tick(&mut self, id: LeafId, leaf: &Leaf, first: bool) -> LeafOutcome;
    /// The leaf was Running and has been preempted (guard failed, timeout fired, retry restarted,
    /// race lost, tree ended, or [`TreeRunner::halt_all`]). Stop its motion; the next tick of this
    /// leaf, if any, will have `first == true`.
    fn halt(&mut self, id: LeafId, leaf: &Leaf);
    /// Answers a `select` query against the world: `Ok(None)` when no object matches. Drivers
    /// that know no world cannot select (the default answer is an error).
    fn select_object(&mut self, query: &crate::world::query::Query) -> Result<Option<Selection>, Failure> {
        Err(Failure::other(format!(
            "this driver cannot select objects (query: {})",
            query.describe()
        )))
    }
}

/// Status of the whole tree after a tick.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TreeStatus {
    /// Tick again.
    Running,
    /// The root succeeded; further ticks do nothing and return Success until [`TreeRunner::reset`].
    Success,
    /// The root failed; further ticks do nothing and return Failure until [`TreeRunner::reset`].
    Failure,
}

/// Status of one node (same indices as [`crate::plan::Plan::nodes`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum NodeStatus {
    /// Not run yet (since the last reset).
    #[default]
    Idle,
    /// Running now.
    Running,
    /// Its last execution succeeded.
    Success,
    /// Its last execution failed.
    Failure,
    /// Its last execution was preempted while running.
    Halted,
}

impl NodeStatus {
    /// Lower-case name (`idle`, `running`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            NodeStatus::Idle => "idle",
            NodeStatus::Running => "running",
            NodeStatus::Success => "success",
            NodeStatus::Failure => "failure",
            NodeStatus::Halted => "halted",
        }
    }
}

impl fmt::Display for NodeStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How often one node ran since the tree was (re)started: BehaviorTree.CPP's `TreeObserver`
/// statistics. Deterministic: the same tree, layout and seed give the same counts.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
pub struct NodeCounts {
    /// Executions started (a leaf's first tick, a composite starting to run; a condition
    /// re-checked by a guard counts once per tick).
    pub activations: u32,
    /// Executions that succeeded.
    pub successes: u32,
    /// Executions that failed.
    pub failures: u32,
    /// Executions preempted while running.
    pub halts: u32,
    /// Results forced from outside the tree (the monitor's force buttons), counted in
    /// `successes` or `failures` too; absent from reports when 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub overridden: u32,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

impl NodeCounts {
    /// Adds `other`'s counts (saturating).
    pub fn add(&mut self, other: &NodeCounts) {
        self.activations = self.activations.saturating_add(other.activations);
        self.successes = self.successes.saturating_add(other.successes);
        self.failures = self.failures.saturating_add(other.failures);
        self.halts = self.halts.saturating_add(other.halts);
        self.overridden = self.overridden.saturating_add(other.overridden);
    }
}

/// One node status change, as logged (also emitted as a `tracing` event, target
/// `macrotree::tree`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Transition {
    /// Tick number (1-based, counts [`TreeRunner::tick`] calls that ticked the tree).
    pub tick: u64,
    /// Simulated time passed to that tick, seconds.
    pub sim_time: f64,
    /// Node index in the plan.
    pub node: usize,
    /// Node path.
    pub path: String,
    /// Node kind (`reach`, `retry`, …).
    pub kind: &'static str,
    /// Status before.
    pub from: NodeStatus,
    /// Status after.
    pub to: NodeStatus,
    /// Why, for failures and halts.
    pub reason: Option<String>,
    /// Attempt number of the nearest enclosing `retry` (1-based), if any.
    pub attempt: Option<u32>,
}
