//! `bench`, `schema --out`, `graph --out` refuse bad input with exit 2; `bench`'s replay ends in
//! the episode's exact final state; `run --realtime` / `--speed X` pace simulated time against
//! the wall clock (compared as ratios within one test, never as absolute wall times).

use std::sync::Arc;

use crate::support::cli;

use cli::{macrotree, s, scratch};

const TREE: &str = "trees/cube_to_bowl.yaml";

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn assert_exit_2(args: &[&str], says: &str) {
    let out = macrotree(args);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(says), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn bench_schema_and_graph_refuse_bad_input_with_exit_2() {
    let dir = scratch("exit2");
    let missing_dir = dir.join("no/such/folder/out.txt");
    let bad_tree = dir.join("bad.yaml");
    std::fs::write(&bad_tree, "main: {reach: {targt: cube}}\n").unwrap();
    assert_exit_2(
        &["bench", s(&dir.join("missing.yaml")), "--repeat", "1"],
        "missing.yaml",
    );
    assert_exit_2(
        &["bench", s(&bad_tree), "--repeat", "1"],
        "unknown parameter `targt`",
    );
    assert_exit_2(
        &["bench", TREE, "--repeat", "1", "--cube", "1e7,0"],
        "off the table",
    );
    assert_exit_2(&["schema", "--out", s(&missing_dir)], "out.txt");
    assert_exit_2(&["schema", "--out", s(&dir)], s(&dir));
    assert_exit_2(&["graph", TREE, "--out", s(&missing_dir)], "out.txt");
    assert_exit_2(&["graph", TREE, "--out", s(&dir)], s(&dir));
    assert_exit_2(
        &["graph", s(&bad_tree), "--out", s(&dir.join("g.dot"))],
        "unknown parameter `targt`",
    );
    assert!(
        !dir.join("g.dot").exists(),
        "a graph of an invalid tree was written"
    );
    // The same commands with good arguments work (the refusals above are about the arguments).
    let out = macrotree(&["graph", TREE, "--out", s(&dir.join("g.dot"))]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        std::fs::read_to_string(dir.join("g.dot"))
            .unwrap()
            .starts_with("digraph")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// 64-bit FNV-1a of `bits` (little-endian bytes), as `bench` documents its `state_fingerprint`.
fn fnv1a_hex(bits: &[u64]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bits.iter().flat_map(|v| v.to_le_bytes()) {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

#[test]
fn bench_replay_ends_in_the_episodes_exact_final_state() {
    let out = macrotree(&["bench", TREE, "--repeat", "1", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).expect("JSON");
    assert_eq!(
        v["replay_matches_episode"],
        serde_json::Value::Bool(true),
        "{stdout}"
    );
    // The same episode in this process ends in the same state, bit for bit.
    let scene = macrotree::sim::Scene::load().expect("scene");
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .load(std::path::Path::new(TREE))
            .expect("valid"),
    );
    let config = macrotree::episode::EpisodeConfig::default();
    let mut cell =
        macrotree::actions::Cell::new(&scene, &macrotree::sim::Layout::default(), config.control_period);
    let r = macrotree::episode::run_in_cell(
        &mut cell,
        plan,
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut macrotree::episode::NoObserver,
    );
    assert!(r.outcome.success);
    assert_eq!(
        v["state_fingerprint"].as_str(),
        Some(fnv1a_hex(&cell.sim().state_fingerprint()).as_str()),
        "{stdout}"
    );
    assert_eq!(v["physics_steps"].as_u64(), Some(r.outcome.physics_steps));
}

/// Runs `run TREE --json EXTRA…`; the episode's wall time (seconds, as the report measures it:
/// from the first tick to the last, without process start-up) and its simulated time (seconds).
fn timed_run(tree: &str, extra: &[&str]) -> (f64, f64) {
    let mut args = vec!["run", tree, "--json"];
    args.extend_from_slice(extra);
    let out = macrotree(&args);
    assert_ne!(out.status.code(), Some(2), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).expect("JSON");
    (
        v["wall_time_s"].as_f64().expect("wall_time_s"),
        v["sim_time_s"].as_f64().expect("sim_time_s"),
    )
}

#[test]
fn realtime_and_speed_pace_simulated_time_against_the_wall_clock() {
    let dir = scratch("pacing");
    let tree = dir.join("wait.yaml");
    std::fs::write(&tree, "main: {wait: {seconds: 3}}\n").unwrap();
    let (free, sim) = timed_run(s(&tree), &[]);
    let (realtime, sim_rt) = timed_run(s(&tree), &["--realtime"]);
    let (fast, sim_fast) = timed_run(s(&tree), &["--speed", "4"]);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "{sim:.3} s simulated: episode wall time unpaced {free:.3} s, --realtime {realtime:.3} s, --speed 4 {fast:.3} s"
    );
    assert!((2.99..3.1).contains(&sim), "{sim} s simulated");
    assert_eq!((sim, sim), (sim_rt, sim_fast), "pacing changes nothing simulated");
    // Pacing never runs ahead of the clock: at least sim / speed of wall time …
    assert!(realtime >= 0.99 * sim, "--realtime took {realtime} s for {sim} s");
    assert!(fast >= 0.99 * sim / 4.0, "--speed 4 took {fast} s for {sim} s");
    // … and does not lag far behind it (ratios, generous for a shared machine).
    assert!(realtime / sim < 1.5, "--realtime took {realtime} s for {sim} s");
    assert!(fast / (sim / 4.0) < 2.0, "--speed 4 took {fast} s for {sim} s");
    // Unpaced it is far faster than real time; four times the speed, about a quarter of the time.
    assert!(
        realtime / free > 5.0,
        "--realtime {realtime} s vs unpaced {free} s"
    );
    let ratio = realtime / fast;
    assert!((2.5..4.5).contains(&ratio), "realtime / speed 4 = {ratio}");
}
