//! Motion in cells with tall fixtures, on real MuJoCo: a held block carried past a wall taller
//! than the carry's lift, and the planner's failure reasons reaching a YAML tree's result (kind,
//! node path, and the objects named in the message).

use std::path::Path;
use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::episode::{EpisodeConfig, EpisodeReport, Hitter, NoObserver, run_episode};
use macrotree::factory::Factory;
use macrotree::motion::{HOME_Q, ik_down};
use macrotree::plan::{Loader, Plan};
use macrotree::scene::SceneSpec;
use macrotree::sim::Scene;
use nalgebra::Vector3;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn scene(yaml: &str) -> Scene {
    let spec = SceneSpec::from_str(yaml, "cell.yaml").expect("valid scene");
    Scene::load_spec(&spec).expect("scene (run tools/bootstrap)")
}

fn tree(text: &str) -> Arc<Plan> {
    Arc::new(
        Loader::default()
            .compile_str(text, "tree.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    )
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

/// The flagship cell with a wall `height` metres tall (4 cm thick, 20 cm wide) standing across
/// the straight route between the cube and the bowl.
fn wall_between(height: f64) -> Scene {
    scene(&format!(
        "
objects:
  cube:
    block: {{size: 0.044, mass: 0.05, friction: 1.0}}
    pose: [0.45, -0.22, 0]
  bowl:
    container: {{inner: [0.15, 0.15], wall_height: 0.06}}
    pose: [0.45, 0.22]
  wall:
    obstacle: {{size: [0.20, 0.04, {height}]}}
    pose: [0.45, 0.0]
goal:
  - in: {{object: cube, container: bowl}}
"
    ))
}

#[test]
fn a_held_block_is_carried_past_a_wall_taller_than_the_lift_without_touching_it() {
    // The carry lifts 15 cm; the wall is 30 cm: the straight transfer would sweep the held
    // block and the fingers through it, so the carry plans around (over) it.
    let scene = wall_between(0.30);
    let r = run(&scene, flagship());
    assert!(
        r.outcome.success,
        "{:?} {:?}",
        r.outcome.failure_reason, r.outcome.collisions
    );
    assert!(r.planning.plans >= 1, "{:?}", r.planning);
    assert_eq!(r.planning.plan_failures, 0, "{:?}", r.planning);
    let bad: Vec<_> = r
        .outcome
        .collisions
        .iter()
        .filter(|c| matches!(c.who, Hitter::HeldBlock | Hitter::Fingers))
        .collect();
    assert!(bad.is_empty(), "{bad:?}");
    assert!(
        !r.outcome.collisions.iter().any(|c| c.object == "wall"),
        "{:?}",
        r.outcome.collisions
    );
}

/// `go_around`'s pick, carry and release, once (no retry), the carry given `extra` parameters.
fn carry_around(extra: &str) -> Arc<Plan> {
    tree(&format!(
        "main:
  sequence:
    children:
      - home: {{}}
      - release: {{width: 0.065, retreat: 0}}
      - reach: {{target: cube, offset: [0, 0, 0.12]}}
      - reach: {{target: cube, offset: [0, 0, 0.0], path: cartesian}}
      - grasp: {{}}
      - carry: {{name: around, to: bowl, lift: 0.15, place_height: 0.02, speed: 1.0{extra}}}
      - release: {{retreat: 0.10}}
"
    ))
}

#[test]
fn a_carry_with_a_small_check_budget_ends_in_no_path_naming_the_fixture() {
    // The transfer around `go_around`'s 0.80 m fixture must be searched for (no direct segment
    // is free): 40 collision checks do not find it, the planner's own budget does.
    let cell = scene(&std::fs::read_to_string(Path::new(ROOT).join("scenes/go_around.yaml")).unwrap());
    let r = run(&cell, carry_around(", max_checks: 40"));
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::NoPath),
        "{:?}",
        r.outcome.failure_reason
    );
    assert_eq!(
        r.outcome.failed_node.as_deref(),
        Some("main/sequence/carry[around]")
    );
    let why = r.outcome.failure_reason.unwrap_or_default();
    assert!(why.contains("fixture"), "{why}");
    // The refusal ends with what to change: the leaf's own budget, with its value.
    assert!(
        why.contains("; help: raise the leaf's `max_checks:` (now 40"),
        "{why}"
    );
    assert_eq!(r.planning.plan_failures, 1, "{:?}", r.planning);
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
    let r = run(&cell, carry_around(""));
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert_eq!(r.planning.plan_failures, 0, "{:?}", r.planning);
}

#[test]
fn a_low_wall_needs_no_plan_and_a_tall_one_does() {
    // The contrast that makes the test above mean something: a 5 cm wall is cleared by the
    // carry's own 15 cm lift, the 30 cm one is not.
    let low = run(&wall_between(0.05), flagship());
    assert!(low.outcome.success, "{:?}", low.outcome.failure_reason);
    assert_eq!(low.planning.plans, 0, "{:?}", low.planning);
}

/// Joints putting the pinch at (x, y, z) metres, pointing down, yaw 0, nearest `seed`.
fn down(x: f64, y: f64, z: f64, seed: &[f64; 6]) -> [f64; 6] {
    ik_down(&Vector3::new(x, y, z), 0.0, false, seed).expect("reachable")
}

fn joints(q: &[f64; 6]) -> String {
    q.map(|j| format!("{j}")).join(", ")
}

/// The go-around cell's 0.80 m fixture between two free arm poses on either side of it; the
/// second `move_joints` is named `swing` and carries `extra` parameters.
fn swing_tree(extra: &str) -> (Scene, Arc<Plan>) {
    let cell = scene(
        "
objects:
  cube:
    block: {size: 0.044}
    pose: [0.25, -0.50]
  fixture:
    obstacle: {size: [0.08, 0.08, 0.80]}
    pose: [0.45, 0.0]
",
    );
    let a = down(0.45, -0.25, 0.25, &HOME_Q);
    let b = down(0.45, 0.25, 0.25, &a);
    let text = format!(
        "main:\n  sequence:\n    children:\n      - move_joints: {{name: one side, joints: [{}]}}\n      - move_joints: {{name: swing, joints: [{}]{extra}}}\n",
        joints(&a),
        joints(&b)
    );
    (cell, tree(&text))
}

#[test]
fn no_path_through_a_tree_when_the_check_budget_runs_out_names_the_fixture() {
    let (cell, plan) = swing_tree(", max_checks: 40");
    let r = run(&cell, plan);
    assert!(!r.outcome.success);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::NoPath),
        "{:?}",
        r.outcome.failure_reason
    );
    assert_eq!(
        r.outcome.failed_node.as_deref(),
        Some("main/sequence/move_joints[swing]")
    );
    let why = r.outcome.failure_reason.unwrap_or_default();
    assert!(why.contains("fixture"), "{why}");
    // The refusal ends with what to change: the leaf's own budget, with its value.
    assert!(
        why.contains("; help: raise the leaf's `max_checks:` (now 40"),
        "{why}"
    );
    assert_eq!(r.planning.plan_failures, 1, "{:?}", r.planning);
    // Failed before swinging: nothing was hit.
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
}

#[test]
fn the_same_swing_with_the_default_budget_goes_around_the_fixture() {
    let (cell, plan) = swing_tree("");
    let r = run(&cell, plan);
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert!(r.planning.plans >= 1, "{:?}", r.planning);
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
}

/// The go-around cell with the arm on one side of the fixture, then a `reach` named `across`
/// to the pinch point on the other side (the swing's goal), with `extra` parameters.
fn reach_across_tree(extra: &str) -> (Scene, Arc<Plan>) {
    let (cell, _) = swing_tree("");
    let a = down(0.45, -0.25, 0.25, &HOME_Q);
    let text = format!(
        "main:\n  sequence:\n    children:\n      - move_joints: {{name: one side, joints: [{}]}}\n      - reach: {{name: across, target: [0.45, 0.25, 0.25], yaw: 0{extra}}}\n",
        joints(&a)
    );
    (cell, tree(&text))
}

#[test]
fn a_reach_with_a_small_check_budget_ends_in_no_path_naming_the_fixture() {
    let (cell, plan) = reach_across_tree(", max_checks: 40");
    let r = run(&cell, plan);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::NoPath),
        "{:?}",
        r.outcome.failure_reason
    );
    assert_eq!(
        r.outcome.failed_node.as_deref(),
        Some("main/sequence/reach[across]")
    );
    let why = r.outcome.failure_reason.unwrap_or_default();
    assert!(why.contains("fixture"), "{why}");
    assert!(r.planning.plan_failures >= 1, "{:?}", r.planning);
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
    // The same reach with the planner's own budget goes around.
    let (cell, plan) = reach_across_tree("");
    let r = run(&cell, plan);
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    assert!(r.planning.plans >= 1, "{:?}", r.planning);
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
}

#[test]
fn max_checks_out_of_range_is_a_located_tree_error() {
    for leaf in [
        "move_joints: {joints: [0, -1.57, 1.57, -1.57, -1.57, 0], max_checks: 0}",
        "reach: {target: cube, max_checks: 0}",
        "carry: {to: bowl, max_checks: 0}",
        "place: {point: [0.4, 0.1], max_checks: 0}",
        "home: {max_checks: 10000001}",
    ] {
        let text = format!("main:\n  {leaf}\n");
        let errs = Loader::default()
            .compile_str(&text, "budget.yaml")
            .expect_err("an out-of-range max_checks is rejected");
        let msg = errs[0].to_string();
        assert!(msg.contains("budget.yaml:2:"), "{leaf}: {msg}");
        assert!(msg.contains("max_checks"), "{leaf}: {msg}");
    }
}

#[test]
fn plan_time_cap_out_of_range_is_a_located_tree_error() {
    for leaf in [
        "move_joints: {joints: [0, -1.57, 1.57, -1.57, -1.57, 0], plan_time_cap: 0}",
        "reach: {target: cube, plan_time_cap: 0.0001}",
        "carry: {to: bowl, plan_time_cap: 61}",
        "place: {point: [0.4, 0.1], plan_time_cap: -1}",
        "home: {plan_time_cap: .inf}",
    ] {
        // The error points at the value (line 2, after the two spaces of indentation).
        let column = 3 + leaf.find("plan_time_cap: ").unwrap() + "plan_time_cap: ".len();
        let text = format!("main:\n  {leaf}\n");
        let errs = Loader::default()
            .compile_str(&text, "cap.yaml")
            .expect_err("an out-of-range plan_time_cap is rejected");
        let msg = errs[0].to_string();
        assert!(msg.contains(&format!("cap.yaml:2:{column}")), "{leaf}: {msg}");
        assert!(msg.contains("planning time cap"), "{leaf}: {msg}");
    }
    // In range: accepted, and carried to the leaf's planning budget.
    let text = "main:\n  reach: {target: cube, plan_time_cap: 0.25, max_checks: 500}\n";
    Loader::default()
        .compile_str(text, "cap.yaml")
        .expect("a plan_time_cap in range is accepted");
}

#[test]
fn goal_in_collision_through_a_tree_names_the_fixture_and_the_node() {
    // Joints that put the gripper inside the fixture.
    let (cell, _) = swing_tree("");
    let inside = down(0.45, 0.0, 0.30, &HOME_Q);
    let plan = tree(&format!(
        "main:\n  sequence:\n    children:\n      - home: {{}}\n      - move_joints: {{name: into fixture, joints: [{}]}}\n",
        joints(&inside)
    ));
    let r = run(&cell, plan);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::GoalInCollision),
        "{:?}",
        r.outcome.failure_reason
    );
    assert_eq!(
        r.outcome.failed_node.as_deref(),
        Some("main/sequence/move_joints[into fixture]")
    );
    let why = r.outcome.failure_reason.unwrap_or_default();
    assert!(why.contains("fixture"), "{why}");
    assert!(why.contains("; help: the joint angles themselves put"), "{why}");
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
}

#[test]
fn unreachable_through_a_tree_names_the_node_and_why() {
    let cell = Scene::load().expect("scene");
    let plan =
        tree("main:\n  sequence:\n    children:\n      - reach: {name: too far, target: [0.95, 0.0, 0.2]}\n");
    let r = run(&cell, plan);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::Unreachable),
        "{:?}",
        r.outcome.failure_reason
    );
    assert_eq!(
        r.outcome.failed_node.as_deref(),
        Some("main/sequence/reach[too far]")
    );
    assert!(r.outcome.failure_reason.unwrap_or_default().contains("beyond"));
}
