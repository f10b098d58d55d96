//! Collisions count, typed: a tree that lowers the open gripper straight onto the bowl's wall
//! touches it in every episode (a Cartesian `reach` runs its straight line whatever it meets), so
//! `--collisions fail` ends the episode with kind `collision` at that leaf, the sweep summary
//! counts it by kind, and a scenario file's `expect: {max_collisions: N}` passes or fails on it.

use crate::support::cli;

use cli::{macrotree, s, scratch};

/// Opens the gripper, goes above the bowl's +x wall (the built-in `cube_bowl` scene: bowl at
/// (0.45, 0.08), 0.15 m inside, walls 0.06 m high) with the pads apart along the wall (tool yaw
/// 90°: at yaw 0 the open fingers would straddle the thin wall), and lowers the tool straight
/// onto it.
const INTO_THE_WALL: &str = "\
description: lowers the open gripper onto the bowl's wall
main:
  sequence:
    name: into the wall
    children:
      - release: {name: open, width: 0.085, retreat: 0}
      - reach: {name: above the wall, target: [0.53, 0.08, 0.20], yaw: deg(90)}
      - reach: {name: onto the wall, target: [0.53, 0.08, 0.03], yaw: deg(90), path: cartesian, speed: 0.1}
";

/// The built-in cell with the bowl fixed where the tree goes (sweeps draw only the cube).
const CELL: &str = "\
objects:
  cube: {block: {size: 0.044}, pose: [0.45, -0.18], random: {x: [0.40, 0.50], y: [-0.25, -0.15]}}
  bowl: {container: {inner: [0.15, 0.15], wall_height: 0.06}, pose: [0.45, 0.08]}
goal:
  - in: {object: cube, container: bowl}
";

/// The tree and the scene, in `dir`.
fn write_tree(dir: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let tree = dir.join("into_the_wall.yaml");
    std::fs::write(&tree, INTO_THE_WALL).unwrap();
    let scene = dir.join("cell.yaml");
    std::fs::write(&scene, CELL).unwrap();
    (tree, scene)
}

fn json(out: &std::process::Output) -> serde_json::Value {
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.trim()).unwrap_or_else(|e| {
        panic!(
            "{e}: stdout {text}\nstderr {}",
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

#[test]
fn collisions_fail_ends_the_episode_with_kind_collision_at_the_leaf_running() {
    let dir = scratch("collision-fail");
    let (tree, scene) = write_tree(&dir);
    // Counted (the default): the episode goes on; the report lists the contact, typed.
    let out = macrotree(&["run", s(&tree), "--scene", s(&scene), "--goal", "tree", "--json"]);
    let counted = json(&out);
    let collisions = counted["collisions"].as_array().expect("collisions");
    assert!(!collisions.is_empty(), "the fingers land on the wall: {counted}");
    let first = &collisions[0];
    assert_eq!(first["kind"], "container", "{first}");
    assert!(
        ["fingers", "arm"].contains(&first["who"].as_str().unwrap()),
        "{first}"
    );
    assert_eq!(first["object"], "bowl", "{first}");
    assert!(
        first["node"].as_str().unwrap().contains("onto the wall"),
        "{first}"
    );
    assert!(counted["failure_kind"].is_null() || counted["failure_kind"] != "collision");
    // `--collisions fail`: the first one is the episode's failure, where it was seen.
    let out = macrotree(&[
        "run",
        s(&tree),
        "--goal",
        "tree",
        "--collisions",
        "fail",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "a failed episode: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let failed = json(&out);
    assert_eq!(failed["success"], false);
    assert_eq!(failed["failure_kind"], "collision", "{failed}");
    let node = failed["failed_node"].as_str().expect("a node");
    assert!(node.contains("onto the wall"), "{node}");
    assert!(
        failed["failure_reason"].as_str().unwrap().contains("bowl"),
        "{failed}"
    );
    // It stops at the contact: earlier than the counted episode ends.
    assert!(failed["sim_time_s"].as_f64().unwrap() <= counted["sim_time_s"].as_f64().unwrap());
}

#[test]
fn sweep_summaries_count_collisions_by_kind_and_the_reproduction_keeps_the_policy() {
    let dir = scratch("collision-sweep");
    let (tree, scene) = write_tree(&dir);
    let jsonl = dir.join("out.jsonl");
    let out = macrotree(&[
        "sweep",
        s(&tree),
        "--scene",
        s(&scene),
        "--scenarios",
        "2",
        "--jobs",
        "1",
        "--goal",
        "tree",
        "--collisions",
        "fail",
        "--out",
        s(&jsonl),
        "--json",
    ]);
    let summary = json(&out);
    let c = &summary["collisions"];
    assert_eq!(c["episodes"], 2, "{summary}");
    let by_kind = c["by_kind"].as_object().unwrap();
    let total: u64 = by_kind.values().map(|v| v.as_u64().unwrap()).sum();
    assert_eq!(c["total"].as_u64().unwrap(), total);
    assert!(by_kind.keys().all(|k| k.ends_with("-container")), "{by_kind:?}");
    assert_eq!(summary["successes"], 0);
    let f = &summary["failures"][0];
    assert_eq!(f["kind"], "collision");
    assert!(
        f["reproduce"].as_str().unwrap().ends_with("--collisions fail"),
        "{f}"
    );
    // The JSONL lines carry the typed entries and the policy, and a resume reads them back.
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let first = text.lines().next().unwrap();
    let line: serde_json::Value = serde_json::from_str(first).unwrap();
    assert_eq!(line["collisions"][0]["kind"], "container");
    assert_eq!(line["collision_policy"], "fail");
    std::fs::write(&jsonl, format!("{first}\n")).unwrap();
    let out = macrotree(&[
        "sweep",
        s(&tree),
        "--scene",
        s(&scene),
        "--scenarios",
        "2",
        "--jobs",
        "1",
        "--goal",
        "tree",
        "--collisions",
        "fail",
        "--out",
        s(&jsonl),
        "--resume",
        "--json",
    ]);
    let resumed = json(&out);
    assert_eq!(
        resumed["scenarios"],
        2,
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(resumed["collisions"]["episodes"], 2);
    assert_eq!(
        std::fs::read_to_string(&jsonl).unwrap(),
        text,
        "the resumed file is the same"
    );
}

#[test]
fn max_collisions_in_a_scenario_file_passes_and_fails() {
    let dir = scratch("collision-suite");
    write_tree(&dir);
    let file = |name: &str, max: u64| {
        let p = dir.join(name);
        std::fs::write(
            &p,
            format!(
                "tree: into_the_wall.yaml\nscene: cell.yaml\ncount: 1\ngoal: tree\nexpect:\n  min_success_rate: 0\n  max_collisions: {max}\n"
            ),
        )
        .unwrap();
        p
    };
    let strict = file("strict.yaml", 0);
    let out = macrotree(&["test", s(&strict)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_ne!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("FAIL at most 0 collision(s)"), "{text}");
    assert!(
        text.contains("collisions: ") && text.contains("-container"),
        "{text}"
    );
    let lenient = file("lenient.yaml", 50);
    let out = macrotree(&["test", s(&lenient)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("ok   at most 50 collision(s)"), "{text}");
}
