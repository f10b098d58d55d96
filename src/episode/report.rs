//! [`EpisodeReport`]: the outcome of one episode, as `run --json` prints it.

use serde::Serialize;

use super::{Collision, CubeBowlReport, EpisodeOutcome, LeafCounters};
use super::{EpisodeConfig, Goal};
use crate::actions::Checks;
use crate::failure::{Failure, FailureKind};
use crate::runtime::TreeStatus;
use crate::scene::{ObjectKind, Placement, SceneSpec};
use crate::world::World;
use crate::world::goal::evaluate;

/// What happened in one episode, as `run --json` prints it: its [`EpisodeOutcome`] and what
/// only this run has (the wall time, the layout it started from, the failure's chain of causes).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeReport {
    /// How the episode ended (its fields sit at the top level of the JSON).
    #[serde(flatten)]
    pub outcome: EpisodeOutcome,
    /// Wall-clock time of the episode (tree + physics), seconds.
    pub wall_time_s: f64,
    /// Where the scene's cube and bowl started.
    pub layout: LayoutJson,
    /// The seed.
    pub seed: u64,
    /// What success was judged by ([`Goal::checked`]), e.g. `the tree's result only (the scene
    /// declares no goal)`.
    pub goal_checked: String,
    /// The failure itself, when the episode failed: its kind, message (`failure_reason`), the
    /// node it happened at and its chain of causes (not written to the JSON, which has
    /// `failure_reason`, `failure_kind` and `failed_node`).
    #[serde(skip)]
    pub failure: Option<Failure>,
    /// Motions checked and planned in this episode, and the wall-clock time it took.
    pub planning: crate::actions::PlanningTally,
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

/// Where the scene's cube and bowl ([`World::cube`], [`World::bowl`]) started, as JSON: the
/// `--cube X,Y,YAW --bowl X,Y` of `macrotree run`. Each is absent when the scene has none.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct LayoutJson {
    /// Cube centre x, y (metres) and yaw (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cube: Option<[f64; 3]>,
    /// Bowl centre x, y (metres).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bowl: Option<[f64; 2]>,
}

impl LayoutJson {
    /// The cube's and the bowl's starting poses in `placement` (one pose per object of `scene`).
    pub fn of(placement: &Placement, scene: &SceneSpec) -> Self {
        let pose = |i: usize| placement.poses[i];
        Self {
            cube: scene.legacy_cube().map(|c| {
                let p = pose(c);
                [p.x, p.y, p.yaw.to_degrees()]
            }),
            bowl: scene.legacy_bowl().map(|b| [pose(b).x, pose(b).y]),
        }
    }
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
        Self {
            outcome: EpisodeOutcome {
                success,
                tree_status,
                failure_reason: failure.as_ref().map(|f| f.message.clone()),
                sim_time_s: world.time,
                grasp_attempts: counters.grasp_attempts,
                halts: counters.halts,
                physics_steps,
                cube_bowl: CubeBowlReport::of(world, checks),
                scene: world.scene.name.clone(),
                objects: Vec::new(),
                goal,
                collisions: Vec::new(),
                failed_node: None,
                failure_kind: failure.as_ref().map(|f| f.kind),
                nodes: Vec::new(),
            },
            wall_time_s,
            layout: LayoutJson::default(),
            seed: config.seed,
            goal_checked: config.goal.checked(&world.scene.goal),
            failure,
            planning: Default::default(),
        }
    }

    /// Adds every object's initial (`start`) and final (`end`) pose and the collisions seen; an
    /// unstable simulation is a failure whatever the tree said. (The caller sets
    /// [`layout`](Self::layout) from the placement the episode started from.)
    pub fn add_scene(
        &mut self,
        start: &World,
        end: &World,
        collisions: Vec<Collision>,
        unstable: Option<Failure>,
    ) {
        self.outcome.objects = (0..end.objects.len())
            .map(|i| ObjectReport {
                name: end.name(i).to_string(),
                kind: end.spec(i).kind(),
                initial: pose(start, i),
                end: pose(end, i),
            })
            .collect();
        self.outcome.collisions = collisions;
        if let Some(why) = unstable {
            self.outcome.success = false;
            self.set_failure(why);
        }
    }

    /// Marks the episode failed by `failure`: its reason and kind.
    pub fn set_failure(&mut self, failure: Failure) {
        self.outcome.failure_reason = Some(failure.message.clone());
        self.outcome.failure_kind = Some(failure.kind);
        self.failure = Some(failure);
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;
    use crate::actions::ChecksRecorder;
    use crate::world::tests_support::{HALF, resting};

    /// The reports of one episode that ended in `w` with the tree's success, judged by `goal`.
    fn judged(w: &World, goal: Goal) -> EpisodeReport {
        let config = EpisodeConfig {
            goal,
            ..EpisodeConfig::default()
        };
        let checks = ChecksRecorder::default().finish(w);
        EpisodeReport::new(
            TreeStatus::Success,
            false,
            &config,
            w,
            checks,
            LeafCounters::default(),
            0,
            0.0,
            None,
        )
    }

    /// Regression (issue 18): `cube_in_bowl` (and `--goal bowl`, which the tutorial's `in_bowl`
    /// check decides) measured the cube along world axes while the scene's `in` goal (`--goal
    /// scene`) measures it in the container's frame, so for a turned bowl the two goals gave
    /// opposite verdicts on the same episode.
    #[test]
    fn goal_bowl_and_goal_scene_agree_for_a_turned_container() {
        let mut w = resting();
        // The bowl turned 45°; the cube 0.05 m along both of the bowl's own axes from its centre
        // (room: 0.075 − 0.022 = 0.053 m), i.e. 0.0707 m from it along world y.
        w.objects[1].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_4);
        let b = w.objects[1].pos;
        let mut inside = w.clone();
        inside.objects[0].pos = Vector3::new(b.x, b.y + 0.05 * std::f64::consts::SQRT_2, 0.01 + HALF);
        // Past the wall along the bowl's axes (0.06 m), 0.0 m off along world x.
        let mut outside = w.clone();
        outside.objects[0].pos = Vector3::new(b.x, b.y + 0.06 * std::f64::consts::SQRT_2 + 0.02, 0.01 + HALF);
        for (w, expected) in [(&inside, true), (&outside, false)] {
            let bowl = judged(w, Goal::Bowl);
            let scene = judged(w, Goal::Scene);
            assert_eq!(
                bowl.outcome.success, scene.outcome.success,
                "--goal bowl and --goal scene disagree"
            );
            assert_eq!(bowl.outcome.success, expected);
            assert_eq!(bowl.outcome.in_bowl(), expected);
            assert_eq!(scene.outcome.goal[0].holds, expected, "{:?}", scene.outcome.goal);
        }
    }

    #[test]
    fn a_scene_without_a_bowl_reports_no_bowl_target_and_a_true_layout() {
        let mut w = resting();
        w.scene = std::sync::Arc::new(
            SceneSpec::from_str(
                "objects:\n  cube: {block: {size: 0.044}, pose: [0.45, -0.18, deg(30)]}\n  post: {obstacle: {size: [0.05, 0.05, 0.1]}, pose: [0.45, 0.1]}\n",
                "no_bowl.yaml",
            )
            .unwrap(),
        );
        let mut r = judged(&w, Goal::Scene);
        r.layout = LayoutJson::of(&Placement::fixed(&w.scene).unwrap(), &w.scene);
        let json = serde_json::to_value(&r).unwrap();
        assert!(json.get("bowl_target").is_none(), "{json}");
        assert_eq!(json["cube_final"], serde_json::json!([0.45, -0.18, HALF]));
        let cube = json["layout"]["cube"].as_array().unwrap();
        assert_eq!(cube[0], 0.45);
        assert!((cube[2].as_f64().unwrap() - 30.0).abs() < 1e-9, "{json}");
        assert!(json["layout"].get("bowl").is_none(), "{json}");
        assert_eq!(json["checks"]["in_bowl"], false);
        // Two blocks: no cube either.
        w.scene = std::sync::Arc::new(
            SceneSpec::from_str(
                "objects:\n  a: {block: {size: 0.044}, pose: [0.45, -0.18]}\n  b: {block: {size: 0.044}, pose: [0.45, 0.08]}\n",
                "two.yaml",
            )
            .unwrap(),
        );
        let mut r = judged(&w, Goal::Scene);
        r.layout = LayoutJson::of(&Placement::fixed(&w.scene).unwrap(), &w.scene);
        let json = serde_json::to_value(&r).unwrap();
        assert!(
            json.get("cube_final").is_none() && json.get("bowl_target").is_none(),
            "{json}"
        );
        assert_eq!(json["layout"], serde_json::json!({}));
        assert!(
            json.get("checks").is_none(),
            "the tutorial's checks without a cube: {json}"
        );
    }

    #[test]
    fn the_flagship_report_lists_its_cube_and_bowl_fields_between_the_counts_and_the_scene() {
        let r = judged(&resting(), Goal::Scene);
        let json = serde_json::to_string(&r.outcome).unwrap();
        let keys: Vec<&str> = [
            "success",
            "tree_status",
            "failure_reason",
            "sim_time_s",
            "grasp_attempts",
            "halts",
            "physics_steps",
            "cube_final",
            "bowl_target",
            "checks",
            "scene",
            "objects",
            "goal",
            "collisions",
            "failed_node",
            "failure_kind",
            "nodes",
        ]
        .into_iter()
        .collect();
        let at: Vec<usize> = keys
            .iter()
            .map(|k| {
                json.find(&format!("\"{k}\":"))
                    .unwrap_or_else(|| panic!("no {k}: {json}"))
            })
            .collect();
        assert!(at.windows(2).all(|w| w[0] < w[1]), "{json}");
    }
}
