//! Regressions of the held-out cell `scenes/held_out/posts_and_deep_bin.yaml` (`clear_table`'s
//! tree on four blocks with two 0.30 m posts among them and a bin with 12 cm walls), each on the
//! sweep scenario that showed it, on real physics through the CLI (`macrotree run --scene …
//! --scenario K --sweep-seed S --json`).

use crate::support::cli;

const TREE: &str = "trees/clear_table.yaml";
const SCENE: &str = "scenes/held_out/posts_and_deep_bin.yaml";

/// Runs scenario `k` of sweep seed `seed`: whether the process succeeded, and its `run --json`
/// report.
fn run(k: u64, seed: u64) -> (std::process::Output, serde_json::Value) {
    let (ks, ss) = (k.to_string(), seed.to_string());
    let out = cli::macrotree(&[
        "run",
        TREE,
        "--scene",
        SCENE,
        "--scenario",
        &ks,
        "--sweep-seed",
        &ss,
        "--json",
    ]);
    let r = serde_json::from_slice(&out.stdout).expect("one JSON report");
    (out, r)
}

/// The `run --json` report of scenario `k` of sweep seed `seed`, asserted successful and free of
/// collisions.
fn clean(k: u64, seed: u64) -> serde_json::Value {
    let (out, r) = run(k, seed);
    assert!(
        out.status.success(),
        "#{k} of seed {seed}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        r["success"], true,
        "#{k} of seed {seed}: {} at {}",
        r["failure_reason"], r["failed_node"]
    );
    assert_eq!(
        r["collisions"].as_array().map(Vec::len),
        Some(0),
        "#{k} of seed {seed}: {}",
        r["collisions"]
    );
    r
}

/// With a post beside the block, the wrist of every straight-down pre-grasp met the post on the
/// way down (`blocked`: "the straight descent onto `b` would touch ur5e/wrist_1_link with
/// post_2 … from every arm configuration above it"), and all three attempts failed. The approach
/// now tilts the tool about its closing axis so the wrist leans away from the post.
#[test]
fn a_pick_beside_a_post_finds_a_pre_grasp_with_one_grasp_per_block() {
    let r = clean(9, 1);
    assert_eq!(
        r["grasp_attempts"], 4,
        "one grasp per block: {}",
        r["grasp_attempts"]
    );
}

/// The second block's carry went straight (in joint space) to a goal on the other elbow branch,
/// swinging the forearm through the stretched arm with the tool far from pointing down, and the
/// block fell out of the fingers on the way (scenario 81 of sweep seed 1: a fifth grasp; once
/// the planned transfer kept the carry's speed, the slower swing dropped it where picking it
/// again brushed the bin wall, `fingers-container` at `reach[descend]` of a successful episode).
/// A transfer now stays on the elbow branch the block was picked on when a goal there is free.
#[test]
fn a_transfer_across_the_elbow_branch_dropped_the_block() {
    let r = clean(81, 1);
    assert_eq!(
        r["grasp_attempts"], 4,
        "one grasp per block: {}",
        r["grasp_attempts"]
    );
}

/// The look-ahead at a pick's descent counted only penetration, so a descent whose wrist passed
/// a post within a millimetre in the kinematic check was taken, and in physics (the arm lagging
/// its setpoint) the wrist touched the post (`arm-obstacle` at `reach[descend]` of a successful
/// episode). The arm's links now keep the clearance margin in that look-ahead.
#[test]
fn pick_descent_grazed_a_post_the_contact_only_look_ahead_passed() {
    clean(6, 1);
}

/// The wound wrist of the final `home` below (joints 4 and 5 at −5.0 and −4.7 rad), as the joint
/// set point stood after the last block of scenario 20 of sweep seed 1.
const WOUND: &str = "[-3.6999495, -1.0183518, 1.3233211, -5.0172462, -4.7120814, -4.165703]";

/// After the last block the wrist stood wound a turn from home (scenario 20 of sweep seed 1,
/// before the servos' inertia feed-forward changed where the episode ends), the straight way
/// home swept the gripper through the forearm, and the planner's default budget (20 000 checks)
/// ran out in that narrow passage (`no_path` at the final `home`). A joint move without its own
/// budget now searches once more, with a new seed and three times the checks.
///
/// Plans start from the joint set point and are seeded by their index in the episode, so the
/// passage is rebuilt without the episode: three round trips between the wound wrist and home
/// in the same cell, whose sixth plan (the last `home`) is the search that ran out.
#[test]
fn final_home_ran_out_of_planner_budget_with_the_wrist_wound_a_turn_from_home() {
    let dir = cli::scratch("held-out-posts");
    let path = dir.join("wound_wrist.yaml");
    let trip = format!("      - move_joints: {{joints: {WOUND}}}\n      - home: {{}}\n");
    let tree = format!(
        "description: three round trips to a wound wrist\nmain:\n  sequence:\n    children:\n{}",
        trip.repeat(3)
    );
    std::fs::write(&path, tree).unwrap();
    let out = cli::macrotree(&["run", cli::s(&path), "--scene", SCENE, "--json"]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON report");
    assert_eq!(r["tree_status"], "success", "{}", r["failure_reason"]);
    assert_eq!(
        r["collisions"].as_array().map(Vec::len),
        Some(0),
        "{}",
        r["collisions"]
    );
    let p = &r["planning"];
    assert!(
        p["plan_failures"].as_u64() == Some(1) && p["plans"].as_u64() == Some(7),
        "the sixth plan (the last way home) runs out and its second search finds it: {p}"
    );
}

/// The block slipped from the fingers early in a carry and slid on after landing; the next
/// approach was chosen for where it lay then, and the descent, found to run the upper arm 2.4 mm
/// into a post once the block had slid 3 cm further, ran anyway (`arm-obstacle` at
/// `reach[descend]`). A descent onto an object that would run the arm's links into something else
/// is now refused before it moves (`blocked`), and the retry approaches the block again.
#[test]
fn descent_ran_the_arm_into_a_post_after_the_block_slid_on() {
    let (_, r) = run(89, 2);
    assert_eq!(
        r["collisions"].as_array().map(Vec::len),
        Some(0),
        "{}",
        r["collisions"]
    );
}

/// The last attempt's reach, a direct 4.66 rad swing to the other elbow branch with the pinch
/// 0.64 m out, ended its trajectory 16 mm short (the stretched arm lagging), and closed in at
/// under 0.05 rad/s: counted "at rest", it failed `blocked` ("the arm stopped 3.0 mm short of its
/// goal") 0.3 s later while still converging. A resting arm is blocked only when its error stops
/// halving. The same false `blocked` had cost a quarter of this cell's episodes a retry.
#[test]
fn a_reach_still_closing_in_on_its_goal_is_not_called_blocked() {
    clean(89, 2);
    // Scenario 2's first reach above a block stopped "2.0 mm short" and its attempt was retried;
    // now no reach fails on the way.
    let r = clean(2, 2);
    let failed: Vec<&str> = r["nodes"]
        .as_array()
        .expect("per-node counts")
        .iter()
        .filter(|n| n["path"].as_str().is_some_and(|p| p.contains("reach[")) && n["failures"] != 0)
        .filter_map(|n| n["path"].as_str())
        .collect();
    assert!(failed.is_empty(), "reaches that failed: {failed:?}");
}

/// A wall-clock cap far below what a search needs ends the leaf with `no_path` ("planning
/// stopped at its time cap"), before the arm moves. The way from home to the wound wrist in this
/// cell is a long search (about 5 700 collision checks, about 50 ms on the 2-core CI machine;
/// with a 10 s cap this test fails, the move planned and made), so a 1 ms cap is outrun on any
/// machine this runs on.
#[test]
fn a_move_with_a_one_millisecond_plan_time_cap_ends_in_no_path_at_the_cap() {
    let dir = cli::scratch("held-out-posts-cap");
    let path = dir.join("capped.yaml");
    let tree = format!(
        "description: a capped search\nmain:\n  sequence:\n    children:\n      - move_joints: {{name: wind, joints: {WOUND}, plan_time_cap: 0.001}}\n"
    );
    std::fs::write(&path, tree).unwrap();
    let out = cli::macrotree(&["run", cli::s(&path), "--scene", SCENE, "--json"]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON report");
    assert_eq!(r["tree_status"], "failure", "{r}");
    assert_eq!(r["failure_kind"], "no_path", "{}", r["failure_reason"]);
    assert_eq!(r["failed_node"], "main/sequence/move_joints[wind]");
    let why = r["failure_reason"].as_str().unwrap_or_default();
    assert!(why.contains("time cap"), "{why}");
    assert!(
        r["planning"]["plan_failures"].as_u64() >= Some(1),
        "{}",
        r["planning"]
    );
    // Failed before moving: nothing was hit.
    assert_eq!(
        r["collisions"].as_array().map(Vec::len),
        Some(0),
        "{}",
        r["collisions"]
    );
}
