//! [`EpisodeOutcome`]: how an episode ended, the one record that both `run --json`'s
//! [`EpisodeReport`](super::EpisodeReport) and a sweep's
//! [`ScenarioResult`](crate::sweep::ScenarioResult) embed, in the order their JSON lists it.

use serde::Serialize;

use super::{Collision, CubeBowlReport, NodeReport, ObjectReport};
use crate::failure::{Failure, FailureKind};
use crate::world::goal::GoalValue;

/// How an episode ended: the same on every machine for the same tree, scene, seed and actions
/// (no wall-clock times). Lengths in metres, times in seconds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeOutcome {
    /// The episode met its [`Goal`](super::Goal): by default the tree succeeded and the scene's
    /// goal holds; with `Goal::Bowl`, the tree succeeded and the scene's cube rests in its bowl;
    /// with `Goal::Tree`, the tree succeeded.
    pub success: bool,
    /// Final status of the tree: "success", "failure", or "running" when the time limit hit.
    pub tree_status: &'static str,
    /// Why it failed, if it did: the root node's reason (which names the failing leaf or
    /// condition, e.g. "all 3 attempts failed; last: …"), the time limit, or a missed goal.
    pub failure_reason: Option<String>,
    /// Simulated time of the episode, seconds.
    pub sim_time_s: f64,
    /// Grasp leaves started on the arm (a grasp answered by a substitution is not counted).
    pub grasp_attempts: u32,
    /// Leaves preempted while running.
    pub halts: u32,
    /// MuJoCo steps taken.
    pub physics_steps: u64,
    /// The reference tutorial's figures on the scene's cube and bowl, for a scene with a cube
    /// (the flagship's); its fields sit beside these in JSON, and are absent without a cube.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub cube_bowl: Option<CubeBowlReport>,
    /// The scene's name.
    pub scene: String,
    /// Every object's initial and final pose, in scene order.
    pub objects: Vec<ObjectReport>,
    /// Every goal predicate's value at the end, in the scene's order.
    pub goal: Vec<GoalValue>,
    /// Contacts that should not happen (the fingers on a wall, …), in the order first seen.
    pub collisions: Vec<Collision>,
    /// The path of the last leaf (or check) that failed, when the episode failed: the leaf where
    /// the failure started, not the composite or decorator that passed it up (that is the root).
    pub failed_node: Option<String>,
    /// A stable name for the kind of failure (`grasp_lost`, `timeout`, `substituted`, …; see
    /// [`FailureKind`]), for grouping; `None` on success. Serialized as its name.
    pub failure_kind: Option<FailureKind>,
    /// How often every node ran, in plan order (preorder).
    pub nodes: Vec<NodeReport>,
}

impl EpisodeOutcome {
    /// The outcome of an episode that never started (its layout could not be drawn, or it
    /// panicked): failed by `failure`, with nothing simulated.
    pub fn not_run(failure: Failure) -> Self {
        Self {
            success: false,
            tree_status: "failure",
            failure_reason: Some(failure.message),
            sim_time_s: 0.0,
            grasp_attempts: 0,
            halts: 0,
            physics_steps: 0,
            cube_bowl: None,
            scene: String::new(),
            objects: Vec::new(),
            goal: Vec::new(),
            collisions: Vec::new(),
            failed_node: None,
            failure_kind: Some(failure.kind),
            nodes: Vec::new(),
        }
    }

    /// The cube rests in the bowl at the end (the tutorial's `in_bowl` check; false in a scene
    /// without a cube).
    pub fn in_bowl(&self) -> bool {
        self.cube_bowl.as_ref().is_some_and(|c| c.checks.in_bowl)
    }
}
