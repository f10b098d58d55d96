//! The planner under the shipped leaves, on physics: the unchanged flagship tree in cells where
//! its direct motions would hit a tall post, and the planner's failure reasons reached through a
//! tree.

use std::path::Path;
use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::episode::{EpisodeConfig, EpisodeReport, NoObserver, run_episode};
use macrotree::factory::Factory;
use macrotree::plan::{Loader, Plan};
use macrotree::scene::SceneSpec;
use macrotree::sim::Scene;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The flagship cell (44 mm cube, 15 cm tray "bowl") with a 30 cm post at `post`, the cube at
/// `cube` and the bowl at `bowl` (x, y metres).
fn cell_with_post(cube: [f64; 2], bowl: [f64; 2], post: [f64; 2]) -> Scene {
    let yaml = format!(
        "
objects:
  cube:
    block: {{size: 0.044, mass: 0.05, friction: 1.0}}
    pose: [{}, {}, 0]
  bowl:
    container: {{inner: [0.15, 0.15], wall_height: 0.06}}
    pose: [{}, {}]
  post:
    obstacle: {{size: [0.06, 0.06, 0.30]}}
    pose: [{}, {}]
goal:
  - in: {{object: cube, container: bowl}}
",
        cube[0], cube[1], bowl[0], bowl[1], post[0], post[1]
    );
    let spec = SceneSpec::from_str(&yaml, "post.yaml").expect("valid scene");
    Scene::load_spec(&spec).expect("scene (run tools/bootstrap)")
}

fn flagship() -> Arc<Plan> {
    Arc::new(
        Loader::default()
            .load(&Path::new(ROOT).join("trees/cube_to_bowl.yaml"))
            .unwrap_or_else(|d| panic!("{}", d[0])),
    )
}

fn run(scene: &Scene, plan: Arc<Plan>) -> EpisodeReport {
    run_episode(
        scene,
        plan,
        &Factory::builtin(),
        &EpisodeConfig::default(),
        &mut NoObserver,
    )
}

fn hit_the_post(r: &EpisodeReport) -> bool {
    r.outcome.collisions.iter().any(|c| c.what.contains("post"))
}

#[test]
fn home_plans_a_detour_around_a_tall_post_beside_its_direct_swing() {
    // The post stands where the arm swings back home from the bowl: the gripper would clip it.
    let scene = cell_with_post([0.45, -0.18], [0.45, 0.17], [0.28, 0.485]);
    let r = run(&scene, flagship());
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert!(r.planning.plans >= 1, "{:?}", r.planning);
    assert_eq!(r.planning.plan_failures, 0);
    assert!(!hit_the_post(&r), "{:?}", r.outcome.collisions);
    // The same episode again: the same plans, the same physics.
    let again = run(&scene, flagship());
    assert_eq!(again.planning.counts(), r.planning.counts());
    assert_eq!(again.outcome.objects, r.outcome.objects);
    assert_eq!(again.outcome.physics_steps, r.outcome.physics_steps);
}

#[test]
fn a_held_block_is_carried_to_an_arm_pose_whose_set_down_clears_the_post() {
    // A post 10 cm from the transfer line: the carry's usual pre-place configuration puts the
    // wrist over it, and the straight set-down would drive the wrist into it (the episode
    // without the planner hit the post).
    let scene = cell_with_post([0.45, -0.2], [0.45, 0.2], [0.35, 0.0]);
    let r = run(&scene, flagship());
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert!(r.planning.plans >= 1, "{:?}", r.planning);
    assert!(!hit_the_post(&r), "{:?}", r.outcome.collisions);
    assert_eq!(r.planning.straight_contacts, 0, "{:?}", r.planning);
}

#[test]
fn a_free_cell_runs_without_the_planner() {
    // The flagship cell: every motion is checked and none needs planning.
    let scene = Scene::load().expect("scene");
    let r = run(&scene, flagship());
    assert!(r.outcome.success);
    assert_eq!(r.planning.plans, 0, "{:?}", r.planning);
    assert!(r.planning.motions_checked >= 6, "{:?}", r.planning);
}

/// A tree of one `move_joints` to `joints` (radians), judged by the tree alone.
fn move_joints(joints: [f64; 6]) -> Arc<Plan> {
    let text = format!(
        "main:\n  sequence:\n    children:\n      - home: {{}}\n      - move_joints: {{joints: [{}]}}\n",
        joints.map(|j| format!("{j}")).join(", ")
    );
    Arc::new(
        Loader::default()
            .compile_str(&text, "move.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    )
}

#[test]
fn goal_in_collision_through_a_tree_names_the_table() {
    // Shoulder lowered until the forearm and gripper lie in the table.
    let scene = Scene::load().expect("scene");
    let into_table = [
        -std::f64::consts::FRAC_PI_2,
        0.4,
        0.0,
        -std::f64::consts::FRAC_PI_2,
        -std::f64::consts::FRAC_PI_2,
        0.0,
    ];
    let r = run(&scene, move_joints(into_table));
    assert!(!r.outcome.success);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::GoalInCollision),
        "{:?}",
        r.outcome.failure_reason
    );
    let why = r.outcome.failure_reason.unwrap_or_default();
    assert!(why.contains("table"), "{why}");
    assert_eq!(r.planning.plans, 1);
    assert_eq!(r.planning.plan_failures, 1);
    // Failed before moving: the arm never reached the table.
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
}

#[test]
fn unreachable_through_a_tree_says_why() {
    let scene = Scene::load().expect("scene");
    let text = "main:\n  sequence:\n    children:\n      - reach: {target: [0.95, 0.0, 0.2]}\n";
    let plan = Arc::new(
        Loader::default()
            .compile_str(text, "far.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    let r = run(&scene, plan);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::Unreachable),
        "{:?}",
        r.outcome.failure_reason
    );
    assert!(r.outcome.failure_reason.unwrap_or_default().contains("beyond"));
}
