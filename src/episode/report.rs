//! [`EpisodeReport`]: the outcome of one episode, as `run --json` prints it.

use serde::Serialize;

use super::{Collision, LeafCounters};
use super::{EpisodeConfig, Goal};
use crate::actions::Checks;
use crate::failure::{Failure, FailureKind};
use crate::runtime::TreeStatus;
use crate::scene::ObjectKind;
use crate::world::World;
use crate::world::goal::{GoalValue, evaluate};

/// What happened in one episode. Lengths in metres, times in seconds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeReport {
    /// The episode met its [`Goal`]: by default the tree succeeded and the cube rests in the
    /// bowl; with `Goal::Tree`, the tree succeeded.
    pub success: bool,
    /// Final status of the tree: "success", "failure", or "running" when the time limit hit.
    pub tree_status: &'static str,
    /// Why it failed, if it did: the root node's reason (which names the failing leaf or
    /// condition, e.g. "all 3 attempts failed; last: …"), the time limit, or a missed goal.
    pub failure_reason: Option<String>,
    /// Simulated time of the episode.
    pub sim_time_s: f64,
    /// Wall-clock time of the episode (tree + physics), seconds.
    pub wall_time_s: f64,
    /// MuJoCo steps taken.
    pub physics_steps: u64,
    /// Grasp leaves started on the arm (a grasp answered by a substitution is not counted).
    pub grasp_attempts: u32,
    /// Leaves preempted while running.
    pub halts: u32,
    /// Final cube centre [x, y, z].
    pub cube_final: [f64; 3],
    /// Bowl target [x, y, z].
    pub bowl_target: [f64; 3],
    /// The reference tutorial's checks.
    pub checks: Checks,
    /// The layout: cube [x, y, yaw_deg] and bowl [x, y].
    pub layout: LayoutJson,
    /// The seed.
    pub seed: u64,
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
    /// The failure itself, when the episode failed: its kind, message (`failure_reason`), the
    /// node it happened at and its chain of causes (not written to the JSON, which has
    /// `failure_reason`, `failure_kind` and `failed_node`).
    #[serde(skip)]
    pub failure: Option<Failure>,
    /// How often every node ran, in plan order (preorder).
    pub nodes: Vec<NodeReport>,
}

/// One node's counts in a report: how often it started, succeeded, failed and was halted.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct NodeReport {
    /// The node path.
    pub path: String,
    /// Its counts.
    #[serde(flatten)]
    pub counts: crate::runtime::NodeCounts,
}

impl NodeReport {
    /// Every node of `runner`'s plan with its counts, in plan order.
    pub fn of(runner: &crate::runtime::TreeRunner) -> Vec<NodeReport> {
        runner
            .plan()
            .nodes
            .iter()
            .zip(runner.node_counts())
            .map(|(n, c)| NodeReport {
                path: n.path.clone(),
                counts: *c,
            })
            .collect()
    }
}

/// One object's initial and final pose: `[x, y, z, yaw]` in metres and degrees (a block's yaw
/// is of its side faces, in [−45°, 45°)).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ObjectReport {
    /// The object's name.
    pub name: String,
    /// What it is.
    pub kind: ObjectKind,
    /// Pose when the episode started.
    pub initial: [f64; 4],
    /// Pose when it ended.
    #[serde(rename = "final")]
    pub end: [f64; 4],
}

fn pose(w: &World, i: usize) -> [f64; 4] {
    let p = w.objects[i].pos;
    [p.x, p.y, p.z, w.yaw(i).to_degrees()]
}

/// A layout as JSON.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LayoutJson {
    /// Cube centre x, y (metres) and yaw (degrees).
    pub cube: [f64; 3],
    /// Bowl centre x, y (metres).
    pub bowl: [f64; 2],
}

impl EpisodeReport {
    /// Assembles a report.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        status: TreeStatus,
        timed_out: bool,
        config: &EpisodeConfig,
        world: &World,
        checks: Checks,
        counters: LeafCounters,
        physics_steps: u64,
        wall_time_s: f64,
        tree_failure: Option<Failure>,
    ) -> Self {
        let tree_status = match status {
            TreeStatus::Success => "success",
            TreeStatus::Failure => "failure",
            TreeStatus::Running => "running",
        };
        let goal = evaluate(world);
        let goal_ok = match config.goal {
            Goal::Scene => goal.iter().all(|g| g.holds),
            Goal::Bowl => checks.in_bowl,
            Goal::Tree => true,
        };
        let success = status == TreeStatus::Success && goal_ok;
        let failure = if success {
            None
        } else if timed_out {
            Some(Failure::new(
                FailureKind::TimeLimit,
                format!(
                    "time limit: the tree was still running after {:.1} s of simulated time",
                    config.max_sim_time
                ),
            ))
        } else if status == TreeStatus::Success && config.goal == Goal::Bowl {
            Some(Failure::new(
                FailureKind::GoalNotMet,
                "the tree succeeded but the cube is not at rest in the bowl",
            ))
        } else if status == TreeStatus::Success {
            let missed: Vec<&str> = goal
                .iter()
                .filter(|g| !g.holds)
                .map(|g| g.predicate.as_str())
                .collect();
            Some(Failure::new(
                FailureKind::GoalNotMet,
                format!(
                    "the tree succeeded but the scene's goal does not hold: not {}",
                    missed.join(", not ")
                ),
            ))
        } else {
            Some(tree_failure.unwrap_or_else(|| Failure::other("the tree failed")))
        };
        let l = &config.layout;
        Self {
            success,
            tree_status,
            failure_reason: failure.as_ref().map(|f| f.message.clone()),
            sim_time_s: world.time,
            wall_time_s,
            physics_steps,
            grasp_attempts: counters.grasp_attempts,
            halts: counters.halts,
            cube_final: world.cube_pos.into(),
            bowl_target: world.bowl_target.into(),
            checks,
            layout: LayoutJson {
                cube: [l.cube_xy[0], l.cube_xy[1], l.cube_yaw.to_degrees()],
                bowl: l.bowl_xy,
            },
            seed: config.seed,
            scene: world.scene.name.clone(),
            objects: Vec::new(),
            goal,
            collisions: Vec::new(),
            failed_node: None,
            failure_kind: failure.as_ref().map(|f| f.kind),
            failure,
            nodes: Vec::new(),
        }
    }

    /// Adds every object's initial (`start`) and final (`end`) pose and the collisions seen; an
    /// unstable simulation is a failure whatever the tree said.
    pub fn add_scene(
        &mut self,
        start: &World,
        end: &World,
        collisions: Vec<Collision>,
        unstable: Option<Failure>,
    ) {
        self.objects = (0..end.objects.len())
            .map(|i| ObjectReport {
                name: end.name(i).to_string(),
                kind: end.spec(i).kind(),
                initial: pose(start, i),
                end: pose(end, i),
            })
            .collect();
        self.collisions = collisions;
        if let Some(why) = unstable {
            self.success = false;
            self.set_failure(why);
        }
    }

    /// Marks the episode failed by `failure`: its reason and kind.
    pub fn set_failure(&mut self, failure: Failure) {
        self.failure_reason = Some(failure.message.clone());
        self.failure_kind = Some(failure.kind);
        self.failure = Some(failure);
    }
}
