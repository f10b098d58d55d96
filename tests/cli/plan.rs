//! `macrotree plan`: one motion-planning query in a scene from the command line — a path found
//! around `go_around`'s fixture, each typed reason there is none, the same path for the same
//! seed, and bad input refused with exit 2.

use crate::support::cli;
use cli::*;

const SCENE: &str = "scenes/go_around.yaml";

/// Runs `plan … --json`: the exit code and the parsed report.
fn plan_json(args: &[&str]) -> (i32, serde_json::Value) {
    let mut all = vec!["plan", SCENE, "--json"];
    all.extend_from_slice(args);
    let out = macrotree(&all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    let report = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{args:?}: stdout is not one JSON object ({e}): {stderr}"));
    (out.status.code().unwrap_or(-1), report)
}

fn joints(v: &serde_json::Value) -> [f64; 6] {
    let a = v.as_array().expect("six joints");
    std::array::from_fn(|k| a[k].as_f64().expect("a number"))
}

fn arg(q: &[f64; 6]) -> String {
    let v: Vec<String> = q.iter().map(|x| format!("{x:?}")).collect();
    format!("--from={}", v.join(","))
}

/// The configuration over the cube's side of the fixture that `plan` itself reaches.
fn over_the_cube() -> [f64; 6] {
    let (code, r) = plan_json(&["--to-point", "0.40,-0.24,0.15"]);
    assert_eq!(code, 0, "{r}");
    joints(&r["plan"]["goal"])
}

#[test]
fn plan_goes_around_the_fixture_and_ends_at_the_point() {
    let from = over_the_cube();
    let (code, r) = plan_json(&[&arg(&from), "--to-point", "0.45,0.24,0.15", "--yaw", "30"]);
    assert_eq!(code, 0, "{r}");
    assert_eq!(r["success"], true);
    let p = &r["plan"];
    // The straight joint motion would sweep the arm through the 0.80 m column: searched.
    assert_eq!(p["direct"], false, "{r}");
    assert!(p["nodes"].as_u64().unwrap() > 2, "{r}");
    assert!(r["collision_checks"].as_u64().unwrap() > 0, "{r}");
    let w = p["waypoints"].as_array().unwrap();
    assert!(w.len() >= 3, "a detour has corners: {r}");
    assert_eq!(joints(&w[0]), from);
    let end = macrotree::motion::fk(&joints(w.last().unwrap()));
    let pinch = end.translation.vector;
    let miss = (pinch - nalgebra::Vector3::new(0.45, 0.24, 0.15)).norm();
    assert!(miss < 1e-4, "the path ends {:.2} mm from the point", miss * 1e3);
    // Pointing down.
    let z = end.rotation * nalgebra::Vector3::z();
    assert!(z.z < -0.999, "tool axis {z:?}");
    assert!(p["duration_s"].as_f64().unwrap() > 0.0);
}

#[test]
fn plan_gives_the_same_path_for_the_same_seed() {
    let from = over_the_cube();
    let a = &arg(&from);
    let (_, mut x) = plan_json(&[a, "--to-point", "0.45,0.24,0.15", "--seed", "7"]);
    let (_, mut y) = plan_json(&[a, "--to-point", "0.45,0.24,0.15", "--seed", "7"]);
    for r in [&mut x, &mut y] {
        r.as_object_mut().unwrap().remove("planning_time_s");
    }
    assert_eq!(x, y);
}

#[test]
fn plan_names_each_reason_there_is_no_motion() {
    // The tool inside the fixture: every IK branch collides, and the reason names the fixture.
    let (code, r) = plan_json(&["--to-point", "0.45,0.0,0.10"]);
    assert_eq!(
        (code, r["failure_kind"].as_str()),
        (1, Some("goal_in_collision")),
        "{r}"
    );
    assert!(r["message"].as_str().unwrap().contains("fixture"), "{r}");
    // Beyond the arm's reach: no IK solution, said with the distance.
    let (code, r) = plan_json(&["--to-point", "1.5,0,0.1"]);
    assert_eq!(
        (code, r["failure_kind"].as_str()),
        (1, Some("unreachable")),
        "{r}"
    );
    assert!(r["message"].as_str().unwrap().contains("reach"), "{r}");
    // The forearm pointing down through the table: the start is in collision, with the pairs.
    let (code, r) = plan_json(&[
        "--from=-1.5708,0,1.5708,-1.5708,-1.5708,0",
        "--to-point",
        "0.45,0.24,0.15",
    ]);
    assert_eq!(
        (code, r["failure_kind"].as_str()),
        (1, Some("start_in_collision")),
        "{r}"
    );
    assert!(r["message"].as_str().unwrap().contains("table"), "{r}");
    // A budget too small for the search around the fixture: the search ran out.
    let from = over_the_cube();
    let (code, r) = plan_json(&[&arg(&from), "--to-point", "0.45,0.24,0.15", "--max-checks", "50"]);
    assert_eq!((code, r["failure_kind"].as_str()), (1, Some("no_path")), "{r}");
    assert!(r.get("plan").is_none(), "{r}");
}

#[test]
fn plan_refuses_bad_input_with_exit_2() {
    for (args, needle) in [
        (
            vec!["--to-joints", "0,0,0,0,0,9"],
            "joint 6 is 9 rad, outside its limits",
        ),
        (vec!["--to-joints", "0,0,0,0,0"], "six joint angles"),
        (vec!["--to-point", "0.4,0.1,nan"], "not a finite number"),
        (vec!["--to-point", "0.4,0.1,1e9"], "within ±2 m"),
        (vec!["--to-point", "0.4,0.1,0.2", "--yaw", "400"], "within ±360°"),
        (
            vec!["--to-point", "0.4,0.1,0.2", "--margin", "0.5"],
            "metres from 0 to 0.1",
        ),
        (vec!["--to-point", "0.4,0.1,0.2", "--max-checks", "0"], "0"),
        (vec![], "--to-joints"),
        (
            vec!["--to-point", "0.4,0.1,0.2", "--to-joints", "0,0,0,0,0,0"],
            "cannot be used with",
        ),
    ] {
        let mut all = vec!["plan", SCENE];
        all.extend_from_slice(&args);
        assert_bad_input(&all, needle);
    }
    // A scene file with an error: located, exit 2.
    let dir = scratch("plan");
    let bad = dir.join("bad.yaml");
    std::fs::write(&bad, "objects:\n  cube:\n    block: {size: 7}\n").unwrap();
    let out = macrotree(&["plan", s(&bad), "--to-point", "0.4,0.1,0.2"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.yaml:3:"), "{stderr}");
}
