//! Side grasps on real MuJoCo (`reach: {approach: side | auto}`): a block under a shelf board,
//! where the 2F-85 cannot come from above, grasped from the side, pulled out and held without
//! touching the shelf; set down upright on a pedestal; `approach: auto` choosing the side under
//! the board and the top where it is free; a block too deep under the board refused before
//! anything moves; a side-held block refused a set-down on the table before anything moves;
//! a side-held block slid in under the upper board onto a spot of the lower one, and a block
//! held from above refused there; and the loader's checks of `approach` with the other
//! parameters.

use macrotree::App;
use macrotree::FailureKind;
use macrotree::env::{Action, EnvConfig, MacroEnv, Reset, Status, StepResult};
use macrotree::plan::Loader;
use macrotree::scene::SceneSpec;
use macrotree::sim::Scene;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Front edge of the lower board (its top 0.12 m high), metres.
const BOARD_FRONT: f64 = 0.57;
/// Height of the lower board's top, metres.
const BOARD_TOP: f64 = 0.12;
/// Half a block's edge, metres.
const HALF: f64 = 0.02;

/// A two-level shelf (boards 0.10 m deep, the lower one's top 0.12 m high, the upper one's
/// underside 0.22 m: 6 cm above a 4 cm block), `low` on the lower board (at `low_x`, turned
/// 10°), `free` on the table, a 3 cm pedestal with the `stage` spot on it, an `on_table` spot
/// and a `shelved` spot on the lower board.
fn shelf(low_x: f64) -> MacroEnv {
    let yaml = format!(
        "
objects:
  post_left: {{obstacle: {{size: [0.02, 0.02, 0.24]}}, pose: [0.58, 0.23]}}
  post_right: {{obstacle: {{size: [0.02, 0.02, 0.24]}}, pose: [0.58, -0.23]}}
  low_board: {{obstacle: {{size: [0.10, 0.44, 0.02]}}, pose: [0.62, 0.0], z: 0.10}}
  top_board: {{obstacle: {{size: [0.10, 0.44, 0.02]}}, pose: [0.62, 0.0], z: 0.22}}
  pedestal: {{obstacle: {{size: [0.03, 0.03, 0.10]}}, pose: [0.48, -0.33]}}
  low: {{block: {{size: 0.04}}, pose: [{low_x}, 0.06, deg(10)], on: low_board}}
  free: {{block: {{size: 0.04}}, pose: [0.40, -0.12]}}
spots:
  stage: [0.48, -0.33]
  on_table: [0.40, 0.15]
  shelved: {{at: [0.60, -0.10], on: low_board}}
"
    );
    let spec = SceneSpec::from_str(&yaml, "shelf.yaml").unwrap_or_else(|d| panic!("{}", d[0]));
    let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
    MacroEnv::new(&App::new(), scene, None, EnvConfig::default()).expect("env")
}

/// Runs `text` (a leaf) and checks it succeeded without an unwanted contact.
fn ok(env: &mut MacroEnv, text: &str) -> StepResult {
    let r = env.step(&Action::Leaf(text.to_string())).expect("a valid leaf");
    assert_eq!(r.status, Status::Success, "{text}: {:?}", r.failure);
    assert!(r.collisions.is_empty(), "{text}: {:?}", r.collisions);
    r
}

fn tool_axis(env: &MacroEnv) -> Vector3<f64> {
    env.cell().world().pinch_rot * Vector3::z()
}

fn block(env: &MacroEnv, name: &str) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let w = env.cell().world();
    let i = w.index_of(name).expect("block");
    (w.objects[i].pos, w.objects[i].quat)
}

/// The angle between the block's nearest-to-vertical axis and the world vertical, radians.
fn tilt(q: &UnitQuaternion<f64>) -> f64 {
    let r: Matrix3<f64> = *q.to_rotation_matrix().matrix();
    (0..3)
        .map(|k| r[(2, k)].abs())
        .fold(0.0, f64::max)
        .clamp(-1.0, 1.0)
        .acos()
}

#[test]
fn a_block_under_a_board_is_grasped_from_the_side_pulled_out_held_and_set_down_upright() {
    let mut env = shelf(0.60);
    let (start, _) = block(&env, "low");
    ok(&mut env, "release: {width: 0.065, retreat: 0}");
    ok(
        &mut env,
        "reach: {target: low, approach: side, offset: [0, 0, 0.12]}",
    );
    // The tool is level, pointing into the face turned to the robot (the block is turned 10°),
    // 12 cm in front of the block at its centre's height.
    let axis = tool_axis(&env);
    let into = Vector3::new(10f64.to_radians().cos(), 10f64.to_radians().sin(), 0.0);
    assert!(axis.z.abs() < 0.01, "tool axis {axis} is not level");
    assert!(axis.dot(&into) > 0.999, "tool axis {axis}, face normal {into}");
    let p = env.cell().world().pinch_pos;
    assert!(
        ((p - start) + 0.12 * into).norm() < 0.005,
        "pinch {p}, block {start}"
    );
    ok(&mut env, "reach: {target: low, approach: side, path: cartesian}");
    ok(&mut env, "grasp: {object: low}");
    // Pulled out 12 cm the way the hand came and 1 cm up (the offset is in the approach frame).
    ok(
        &mut env,
        "reach: {target: low, approach: side, offset: [0, 0.01, 0.12], path: cartesian}",
    );
    ok(&mut env, "grasped: {object: low}");
    let (out, q) = block(&env, "low");
    assert!(
        out.x + HALF * 2f64.sqrt() < BOARD_FRONT,
        "the block at {out} is still over the board"
    );
    assert!(
        out.z > BOARD_TOP + HALF + 0.005,
        "the block at {out} was not lifted off the board"
    );
    assert!(
        tilt(&q) < 3f64.to_radians(),
        "tilted {:.1}° in the grasp",
        tilt(&q).to_degrees()
    );
    // Set down on the pedestal, held from the side: it ends upright on the spot, let go.
    ok(&mut env, "place: {spot: stage}");
    let (end, q) = block(&env, "low");
    assert!(
        (end.xy() - nalgebra::Vector2::new(0.48, -0.33)).norm() < 0.01,
        "the block rests at {end}, not on the stage"
    );
    assert!(
        (end.z - (0.10 + HALF)).abs() < 0.004,
        "the block's centre is at {} m",
        end.z
    );
    assert!(
        tilt(&q) < 3f64.to_radians(),
        "set down tilted {:.1}°",
        tilt(&q).to_degrees()
    );
    let r = env.step(&Action::Leaf("grasped: {object: low}".into())).unwrap();
    assert_eq!(r.status, Status::Failure, "the fingers let go of it");
}

#[test]
fn approach_auto_goes_from_the_side_under_a_board_and_from_above_where_the_top_is_free() {
    let mut env = shelf(0.60);
    ok(
        &mut env,
        "reach: {target: low, approach: auto, offset: [0, 0, 0.12]}",
    );
    let axis = tool_axis(&env);
    assert!(
        axis.z.abs() < 0.01,
        "under the board: tool axis {axis} should be level"
    );
    // The straight approach goes on from the side: the tool follows the way it points.
    ok(&mut env, "reach: {target: low, approach: auto, path: cartesian}");
    let (low, _) = block(&env, "low");
    let p = env.cell().world().pinch_pos;
    assert!(
        (p - low).norm() < 0.005,
        "pinch {p} is not at the block's centre {low}"
    );
    assert!(tool_axis(&env).z.abs() < 0.01);

    env.reset(&Reset::Default).unwrap();
    ok(
        &mut env,
        "reach: {target: free, approach: auto, offset: [0, 0, 0.12]}",
    );
    let axis = tool_axis(&env);
    assert!(
        axis.z < -0.999,
        "on the open table: tool axis {axis} should point down"
    );
    ok(&mut env, "reach: {target: free, approach: auto, path: cartesian}");
    ok(&mut env, "grasp: {object: free}");
    ok(&mut env, "grasped: {object: free}");
}

#[test]
fn a_block_too_deep_under_the_board_for_the_hand_is_refused_before_anything_moves() {
    // Its centre 6.5 cm behind the board's front edge: the gripper's base (5.5 cm behind the
    // pinch, 3.75 cm below its axis) would have to enter the board, from any face.
    let mut env = shelf(0.635);
    let before = env.observe().joint_pos;
    let r = env
        .step(&Action::Leaf(
            "reach: {target: low, approach: side, offset: [0, 0, 0.12]}".into(),
        ))
        .unwrap();
    assert_eq!(r.status, Status::Failure);
    let f = r.failure.expect("a failure");
    assert_eq!(f.kind, FailureKind::Unreachable, "{f}");
    assert!(
        f.message
            .contains("no face of low can be approached from the side")
            && f.message.contains("low_board"),
        "{f}"
    );
    assert!(r.collisions.is_empty());
    assert_arm_still(&before, &env.observe().joint_pos);
}

#[test]
fn approach_side_needs_a_block_and_a_stand_off_and_auto_only_a_stand_off() {
    let load = |body: &str| {
        Loader::default()
            .compile_str(&format!("main:\n  reach: {body}\n"), "tree.yaml")
            .map(|_| ())
            .map_err(|d| d.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n"))
    };
    load("{target: cube, approach: side, offset: [0, 0.01, 0.1]}")
        .expect("side with an approach-frame offset");
    load("{target: cube, approach: auto, offset: [0, 0, 0.1]}").expect("auto with a stand-off");
    let cases = [
        (
            "{target: [0.4, 0.1, 0.1], approach: side}",
            "needs a block to approach",
        ),
        ("{target: bowl, approach: auto}", "needs a block to approach"),
        (
            "{target: cube, approach: side, offset: [0, 0, -0.02]}",
            "cannot be negative",
        ),
        (
            "{target: cube, approach: auto, offset: [0.02, 0, 0.1]}",
            "must be a stand-off",
        ),
        ("{target: cube, approach: side, yaw: deg(30)}", "leave `yaw` out"),
        ("{target: cube, approach: sideways}", "top"),
    ];
    for (body, want) in cases {
        let e = load(body).expect_err(body);
        assert!(e.contains(want), "{body}: {e}");
        assert!(e.contains("tree.yaml:2:"), "{body}: not located: {e}");
    }
}

/// Set down on a spot on the table (`place`, or `carry` into a bin), a block held from the side
/// put the gripper's base into what was under it (the base reaches 3.75 cm below the tool axis, a
/// 4 cm block only 2 cm): the leaf moved, and the arm hit the table or the bin. It is now refused
/// before anything moves, `goal_in_collision`, with what to do instead.
#[test]
fn a_side_held_block_carried_onto_the_table_put_the_gripper_into_it() {
    let mut env = shelf(0.60);
    hold_low_from_the_side(&mut env);
    let before = env.observe().joint_pos;
    let r = env.step(&Action::Leaf("place: {spot: on_table}".into())).unwrap();
    assert_eq!(r.status, Status::Failure);
    let f = r.failure.expect("a failure");
    assert_eq!(f.kind, FailureKind::GoalInCollision, "{f}");
    assert!(
        f.message.contains("held from the side cannot be set down")
            && f.message.contains("table")
            && f.message.contains("grasp it again from above"),
        "{f}"
    );
    assert!(r.collisions.is_empty(), "{:?}", r.collisions);
    assert_arm_still(&before, &env.observe().joint_pos);
    // Onto the pedestal, narrower than the block, the same hold sets it down.
    ok(&mut env, "place: {spot: stage}");
}

/// Grasps `low` from the side and pulls it out 12 cm the way the hand came, 1 cm up.
fn hold_low_from_the_side(env: &mut MacroEnv) {
    ok(env, "release: {width: 0.065, retreat: 0}");
    ok(env, "reach: {target: low, approach: side, offset: [0, 0, 0.12]}");
    ok(env, "reach: {target: low, approach: side, path: cartesian}");
    ok(env, "grasp: {object: low}");
    ok(
        env,
        "reach: {target: low, approach: side, offset: [0, 0.01, 0.12], path: cartesian}",
    );
}

/// Asserts the arm's joints moved less than 0.01 rad from `before` to `after`.
fn assert_arm_still(before: &[f64], after: &[f64]) {
    let moved = before
        .iter()
        .zip(after)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(moved < 0.01, "the arm moved {moved} rad");
}

#[test]
fn a_side_held_block_is_slid_in_under_the_upper_board_and_set_down_on_its_spot() {
    let mut env = shelf(0.60);
    hold_low_from_the_side(&mut env);
    // Back under the upper board, 16 cm along the board: slid in along the hand's approach just
    // above the spot, set down, let go, the hand backed out the way it came.
    ok(&mut env, "place: {spot: shelved, retreat: 0.12}");
    let (end, q) = block(&env, "low");
    assert!(
        (end.xy() - nalgebra::Vector2::new(0.60, -0.10)).norm() < 0.01,
        "the block rests at {end}, not on the spot"
    );
    assert!(
        (end.z - (BOARD_TOP + HALF)).abs() < 0.004,
        "the block's centre is at {} m, not on the lower board",
        end.z
    );
    assert!(
        tilt(&q) < 3f64.to_radians(),
        "set down tilted {:.1}°",
        tilt(&q).to_degrees()
    );
    let p = env.cell().world().pinch_pos;
    assert!(
        p.x < BOARD_FRONT - 0.05,
        "the hand is still under the board: pinch at {p}"
    );
    assert!(
        p.z < 0.22,
        "the hand backed out level, not up through the board: pinch at {p}"
    );
    let r = env.step(&Action::Leaf("grasped: {object: low}".into())).unwrap();
    assert_eq!(r.status, Status::Failure, "the fingers let go of it");
    let r = env
        .step(&Action::Leaf("at: {object: low, spot: shelved}".into()))
        .unwrap();
    assert_eq!(r.status, Status::Success, "the `at` condition holds on the board");
}

#[test]
fn a_block_held_from_above_is_refused_a_spot_under_a_board_with_what_to_do() {
    let mut env = shelf(0.60);
    ok(&mut env, "release: {width: 0.065, retreat: 0}");
    ok(&mut env, "reach: {target: free, offset: [0, 0, 0.12]}");
    ok(&mut env, "reach: {target: free, path: cartesian}");
    ok(&mut env, "grasp: {object: free}");
    let (before, _) = block(&env, "free");
    let r = env.step(&Action::Leaf("place: {spot: shelved}".into())).unwrap();
    assert_eq!(r.status, Status::Failure);
    let f = r.failure.expect("a failure");
    assert_eq!(f.kind, FailureKind::GoalInCollision, "{f:?}");
    assert!(
        f.message.contains("under `top_board`") && f.message.contains("approach: side"),
        "{}",
        f.message
    );
    // Refused before anything moved: the block is where the grasp left it.
    let (after, _) = block(&env, "free");
    assert!(
        (after - before).norm() < 0.002,
        "the block moved from {before} to {after}"
    );
    let r = env.step(&Action::Leaf("grasped: {object: free}".into())).unwrap();
    assert_eq!(r.status, Status::Success, "still held");
}
