//! The command-line contract: exit codes, the `--json` report, located errors for bad input.

use std::process::{Command, Output};

fn macrotree(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_macrotree"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .output()
        .expect("macrotree runs")
}

fn last_json_line(out: &Output) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().expect("stdout has lines");
    serde_json::from_str(line).unwrap_or_else(|e| panic!("last stdout line is not JSON ({e}): {line}"))
}

#[test]
fn run_default_layout_succeeds_with_a_json_report() {
    let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json_line(&out);
    for key in [
        "success",
        "tree_status",
        "sim_time_s",
        "wall_time_s",
        "physics_steps",
        "grasp_attempts",
        "cube_final",
        "bowl_target",
        "checks",
    ] {
        assert!(r.get(key).is_some(), "missing {key} in {r}");
    }
    for key in [
        "grasp_distance",
        "cube_motion_while_closed",
        "cube_lift_while_closed",
        "home_error",
        "in_bowl",
    ] {
        assert!(r["checks"].get(key).is_some(), "missing checks.{key} in {r}");
    }
    assert_eq!(r["success"], true);
    assert_eq!(r["tree_status"], "success");
    assert!(r["sim_time_s"].as_f64().unwrap() > 1.0);
    assert_eq!(r["bowl_target"][0].as_f64().unwrap(), 0.45);
    // Live logs go to stderr: one line per status transition, not per tick.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("grasp"), "no grasp transition logged: {stderr}");
    assert!(
        stderr.lines().count() < 200,
        "too chatty: {} lines",
        stderr.lines().count()
    );
}

#[test]
fn run_reports_task_failure_with_exit_1() {
    // One simulated second is too short for the task: the episode fails with a reason.
    let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "--max-sim-time", "1", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json_line(&out);
    assert_eq!(r["success"], false);
    assert_eq!(r["failure_kind"], "time_limit");
    let reason = r["failure_reason"].as_str().unwrap_or_default();
    assert!(reason.contains("time limit"), "reason: {reason}");
}

/// Regression (hardening, bad numbers): a cube out of the arm's reach, inside the robot's base or
/// off the table used to run (and a cube at 1e10 m "succeeded"); it is refused before anything is
/// simulated, with what is allowed.
#[test]
fn run_refuses_layouts_outside_the_cell_with_exit_2() {
    for (cube, why) in [
        ("1.5,0.0", "off the table"),
        ("0.9,0.0", "from the robot's base"),
        ("0.05,0", "overlaps the robot's base"),
        ("1.1e10,0", "off the table"),
    ] {
        let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "--cube", cube, "--json"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--cube {cube}: {stderr}");
        assert!(
            stderr.contains(why) && stderr.contains("help:"),
            "--cube {cube}: {stderr}"
        );
        assert!(out.stdout.is_empty(), "--cube {cube}: nothing simulated");
    }
    // The cube on top of the bowl overlaps it.
    let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "--cube", "0.45,0.08", "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("`cube` and `bowl` overlap"), "{stderr}");
}

#[test]
fn goal_tree_lets_a_table_placement_succeed_and_bowl_does_not() {
    // The same episode judged two ways: the tree places the cube on the table, so the default
    // goal (cube in the bowl) fails it and `--goal tree` (the tree's own `cube_at`) passes it.
    let judged = |goal: &str| {
        let out = macrotree(&["run", "trees/place_on_table.yaml", "--goal", goal, "--json"]);
        (out.status.code(), last_json_line(&out))
    };
    let (code, tree) = judged("tree");
    assert_eq!(code, Some(0), "{tree}");
    assert_eq!(tree["success"], true);
    assert_eq!(tree["tree_status"], "success");
    assert_eq!(tree["checks"]["in_bowl"], false);
    let (code, bowl) = judged("bowl");
    assert_eq!(code, Some(1), "{bowl}");
    assert_eq!(bowl["success"], false);
    assert_eq!(bowl["tree_status"], "success");
    let reason = bowl["failure_reason"].as_str().unwrap_or_default();
    assert!(reason.contains("not at rest in the bowl"), "reason: {reason}");
    // Same physics either way: the goal only judges.
    assert_eq!(tree["cube_final"], bowl["cube_final"]);
    assert_eq!(tree["physics_steps"], bowl["physics_steps"]);
}

/// Regression: a tree that failed through a condition (no action failed) was reported with the
/// bare reason "the tree failed"; the report now carries the root's reason.
#[test]
fn failure_reason_names_the_failed_condition_not_just_the_tree() {
    let out = macrotree(&["run", "tests/fixtures/cli/carry_without_a_grasp.yaml", "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let r = last_json_line(&out);
    assert_eq!(r["tree_status"], "failure");
    let reason = r["failure_reason"].as_str().unwrap_or_default();
    assert_eq!(reason, "condition failed: cube_grasped: not satisfied");
    assert_eq!(r["failure_kind"], "condition_false");
}

#[test]
fn invalid_tree_exits_2_with_a_located_message() {
    let out = macrotree(&["run", "tests/fixtures/cli/misspelled_param.yaml"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("misspelled_param.yaml:4:"),
        "no file:line:col in: {stderr}"
    );
    assert!(stderr.contains("ofset"), "does not name the bad key: {stderr}");
    let out = macrotree(&[
        "validate",
        "tests/fixtures/cli/misspelled_param.yaml",
        "trees/cube_to_bowl.yaml",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let out = macrotree(&["validate", "trees/cube_to_bowl.yaml"]);
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn bad_arguments_and_missing_files_exit_2_without_panicking() {
    for args in [
        vec!["run", "trees/cube_to_bowl.yaml", "--cube", "0.4"],
        vec!["run", "trees/cube_to_bowl.yaml", "--bowl", "x,y"],
        vec!["run", "trees/cube_to_bowl.yaml", "--max-sim-time", "-1"],
        vec!["run", "no/such/tree.yaml"],
        vec!["run"],
    ] {
        let out = macrotree(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
        assert!(!stderr.trim().is_empty(), "{args:?}: no message");
    }
}

#[test]
fn a_command_line_yaw_that_looks_like_radians_is_refused_and_one_with_its_unit_runs() {
    let tree = "tests/fixtures/cli/gripper_open.yaml";
    let out = macrotree(&["run", tree, "--cube", "0.45,-0.1,0.785", "--goal", "tree"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("looks like radians (45°)") && err.contains("0.785rad"),
        "{err}"
    );
    let out = macrotree(&[
        "run",
        tree,
        "--cube",
        "0.45,-0.1,0.785rad",
        "--goal",
        "tree",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let yaw = last_json_line(&out)["layout"]["cube"][2].as_f64().unwrap();
    assert!(
        (yaw - 0.785f64.to_degrees()).abs() < 1e-9,
        "reported in degrees: {yaw}"
    );
}

#[test]
fn missing_models_exit_2_and_say_how_to_get_them() {
    let out = Command::new(env!("CARGO_BIN_EXE_macrotree"))
        .args(["run", "trees/cube_to_bowl.yaml"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("MACROTREE_MENAGERIE", "/nonexistent/menagerie")
        .output()
        .expect("macrotree runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("tools/bootstrap"), "{stderr}");
}

#[test]
fn bench_prints_the_ratio_and_simulated_time() {
    let out = macrotree(&["bench", "trees/cube_to_bowl.yaml", "--repeat", "1", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json_line(&out);
    for key in [
        "episode_wall_time_s",
        "replay_wall_time_s",
        "ratio",
        "sim_time_s",
        "physics_steps",
        "ik_us_per_solve",
    ] {
        assert!(r[key].as_f64().is_some(), "missing {key} in {r}");
    }
    assert_eq!(r["success"], true);
    // The replay runs exactly the episode's physics steps.
    assert!(r["physics_steps"].as_u64().unwrap() > 1000);
}

/// Issue 18: a scene without a bowl has no `bowl_target` (it was the sentinel
/// `[100, 100, 0]`), and `run` prints no cube or bowl line for what the scene does not have.
#[test]
fn a_scene_without_a_bowl_reports_no_bowl_target_and_prints_no_bowl_line() {
    let run = |scene: &str| {
        let out = macrotree(&[
            "run",
            "tests/fixtures/cli/gripper_open.yaml",
            "--scene",
            scene,
            "--json",
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "stderr: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // The human summary: with --json it goes to stderr (stdout holds only the JSON), after
        // the episode's log lines (which name the scene), from its SUCCESS/FAILURE line on.
        let human: Vec<String> = String::from_utf8_lossy(&out.stderr)
            .lines()
            .skip_while(|l| !(l.starts_with("SUCCESS") || l.starts_with("FAILURE")))
            .map(str::to_string)
            .collect();
        assert!(
            !human.is_empty(),
            "no summary: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        (last_json_line(&out), human.join("\n"))
    };
    // One block, no container: the cube is reported, no bowl anywhere.
    let (r, text) = run("tests/fixtures/cli/cube_no_bowl.yaml");
    assert!(r.get("bowl_target").is_none(), "{r}");
    assert!(!r.to_string().contains("100.0"), "the sentinel is back: {r}");
    assert_eq!(r["cube_final"].as_array().map(Vec::len), Some(3), "{r}");
    assert_eq!(r["layout"]["cube"][0], 0.45, "{r}");
    assert!(r["layout"].get("bowl").is_none(), "{r}");
    assert!(text.contains("cube final ("), "{text}");
    assert!(
        !text.contains("bowl"),
        "a bowl line for a scene without one:\n{text}"
    );
    // Two blocks, no container: neither a cube nor a bowl.
    let (r, human) = run("tests/fixtures/cli/two_blocks.yaml");
    assert!(
        r.get("bowl_target").is_none() && r.get("cube_final").is_none(),
        "{r}"
    );
    assert_eq!(r["layout"], serde_json::json!({}), "{r}");
    assert!(
        !human.contains("cube") && !human.contains("bowl"),
        "cube/bowl lines for a scene without them:\n{human}"
    );
    assert!(human.contains("block a: final"), "{human}");
}

/// The report's `layout` is where the cube and the bowl really started, for any scene and any
/// way of placing them (it used to repeat the built-in default for other scenes).
#[test]
fn the_reports_layout_is_where_the_cube_and_bowl_started() {
    let out = macrotree(&[
        "run",
        "tests/fixtures/cli/gripper_open.yaml",
        "--cube",
        "0.5,-0.2,30",
        "--bowl",
        "0.4,0.1",
        "--goal",
        "tree",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json_line(&out);
    let cube: Vec<f64> = r["layout"]["cube"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(&cube[..2], &[0.5, -0.2]);
    assert!((cube[2] - 30.0).abs() < 1e-9, "{r}");
    assert_eq!(r["layout"]["bowl"], serde_json::json!([0.4, 0.1]));
    // A scene with its own poses: the cube's pose from the file.
    let out = macrotree(&[
        "run",
        "tests/fixtures/cli/gripper_open.yaml",
        "--scene",
        "tests/fixtures/cli/cube_no_bowl.yaml",
        "--cube",
        "0.4,-0.25",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json_line(&out);
    assert_eq!(r["layout"]["cube"], serde_json::json!([0.4, -0.25, 0.0]), "{r}");
}

/// `--goal bowl` on a scene without a cube and a bowl could never succeed: it is refused with
/// exit 2 before anything is simulated, by `run` and by `sweep`.
#[test]
fn goal_bowl_is_refused_for_a_scene_without_a_cube_and_a_bowl() {
    for args in [
        &["run", "tests/fixtures/cli/gripper_open.yaml"][..],
        &[
            "sweep",
            "tests/fixtures/cli/gripper_open.yaml",
            "--scenarios",
            "1",
        ][..],
    ] {
        let mut args = args.to_vec();
        args.extend([
            "--scene",
            "tests/fixtures/cli/cube_no_bowl.yaml",
            "--goal",
            "bowl",
        ]);
        let out = macrotree(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("--goal bowl")
                && stderr.contains("1 blocks and 0 containers")
                && stderr.contains("help:"),
            "{args:?}: {stderr}"
        );
        assert!(out.stdout.is_empty(), "{args:?}: nothing simulated");
    }
}
