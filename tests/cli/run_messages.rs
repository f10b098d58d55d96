//! What `macrotree run` says, checked on real physics: the success message follows the goal
//! actually checked, a timeout says what the leaf waited for and which node failed, log fields
//! are rounded, and `-v` shows each motion plan.

use crate::support::cli;
use cli::{macrotree, s, scratch};

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn with_goal_tree_the_message_does_not_claim_the_scenes_goal() {
    let dir = scratch("newcomer-goal");
    let tree = dir.join("home.yaml");
    std::fs::write(&tree, "main: {home: {}}\n").unwrap();
    let out = macrotree(&["run", s(&tree), "--goal", "tree"]);
    assert_eq!(out.status.code(), Some(0));
    let err = text(&out.stderr);
    assert!(
        err.contains("episode succeeded: the tree succeeded (goal checked: the tree's own conditions)"),
        "{err}"
    );
    assert!(
        !err.contains("cube in bowl"),
        "the cube is not in the bowl: {err}"
    );
    let stdout = text(&out.stdout);
    assert!(stdout.contains("success judged by --goal tree"), "{stdout}");
    // With the default goal the same tree fails: the scene's goal does not hold.
    let out = macrotree(&["run", s(&tree)]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn a_timeout_says_what_the_leaf_waited_for_and_which_node_failed() {
    let dir = scratch("newcomer-timeout");
    let tree = dir.join("grasp.yaml");
    std::fs::write(
        &tree,
        "main:\n  sequence:\n    children:\n      - grasp: {name: close, timeout: 0.05}\n",
    )
    .unwrap();
    let out = macrotree(&["run", s(&tree), "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = text(&out.stdout);
    let report: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    let reason = report["failure_reason"].as_str().unwrap();
    assert!(
        reason.starts_with("grasp: timeout after 0.05 s: gripper still closing, width 0."),
        "{reason}"
    );
    let width: f64 = reason
        .split("width ")
        .nth(1)
        .and_then(|w| w.split(' ').next())
        .and_then(|w| w.parse().ok())
        .unwrap();
    assert!(
        width > 0.0 && width < 0.085,
        "a real width, between closed and open: {reason}"
    );
    let err = text(&out.stderr);
    // With --json the summary for people is on stderr (stdout holds only the report).
    assert!(err.contains("  failed node: main/sequence/grasp[close]"), "{err}");
    assert!(err.contains("node=main/sequence/grasp[close]"), "{err}");
}

#[test]
fn log_fields_are_rounded_and_verbose_shows_the_motion_plans() {
    let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "-v"]);
    assert_eq!(out.status.code(), Some(0));
    let err = text(&out.stderr);
    let done = err
        .lines()
        .find(|l| l.contains("episode succeeded"))
        .expect("success line");
    let t = done
        .split("sim_time_s=")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap();
    assert!(t.split('.').nth(1).is_none_or(|d| d.len() <= 3), "{done}");
    assert!(
        done.contains("the tree succeeded and the scene's goal holds: cube in bowl"),
        "{done}"
    );
    let plans: Vec<&str> = err.lines().filter(|l| l.contains("plan: ")).collect();
    assert!(plans.len() >= 6, "one plan per motion: {err}");
    assert!(
        plans
            .iter()
            .any(|l| l.contains("straight line of 0.4") && l.contains("IK branch")),
        "{plans:?}"
    );
    assert!(
        plans
            .iter()
            .all(|l| l.contains(" s to pinch (") && l.contains("tool yaw"))
    );
    // Without -v, no plans.
    let quiet = macrotree(&["run", "trees/cube_to_bowl.yaml"]);
    assert!(!text(&quiet.stderr).contains("plan: "));
}
