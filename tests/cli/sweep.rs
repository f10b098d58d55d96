//! The `macrotree sweep` binary: exit codes, the `--json` summary as the last stdout line, the
//! JSONL file, and a failure's printed command reproducing it through `macrotree run`.

use std::process::Output;

use crate::support::cli;
use cli::macrotree;

const TREE: &str = "trees/cube_to_bowl.yaml";

fn last_json_line(out: &Output) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().expect("some stdout");
    serde_json::from_str(last).unwrap_or_else(|e| panic!("last line is not JSON ({e}): {last}"))
}

#[test]
fn a_successful_sweep_exits_0_with_a_json_summary_and_jsonl() {
    let dir = std::env::temp_dir().join(format!("macrotree-sweep-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out_file = dir.join("ok.jsonl");
    let out = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "4",
        "--seed",
        "2024",
        "--jobs",
        "2",
        "--json",
        "--out",
        out_file.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr: {stderr}");
    assert!(!stderr.contains("INFO"), "logs are quiet by default: {stderr}");
    let s = last_json_line(&out);
    for key in [
        "scenarios",
        "successes",
        "success_rate",
        "median_sim_time_s",
        "p95_sim_time_s",
        "wall_time_s",
        "scenarios_per_minute",
        "failures",
        "success_rate_ci95",
        "attempts_histogram",
    ] {
        assert!(s.get(key).is_some(), "summary lacks {key}: {s}");
    }
    // The share of the workers' time spent in mj_step, measured inside this run: a fraction,
    // and consistent with its parts.
    let share = s["physics_share"].as_f64().expect("physics_share");
    let physics = s["physics_time_s"].as_f64().unwrap();
    let process = s["process_wall_time_s"].as_f64().unwrap();
    let jobs = s["jobs"].as_f64().unwrap();
    assert!(share > 0.0 && share <= 1.0, "{s}");
    assert!(
        process >= s["wall_time_s"].as_f64().unwrap(),
        "the process includes the sweep: {s}"
    );
    assert!((share - physics / (jobs * process)).abs() < 1e-9, "{s}");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("physics share "),
        "the human summary (on stderr with --json) shows it too"
    );
    assert_eq!(s["scenarios"], 4);
    assert_eq!(s["successes"], 4);
    assert_eq!(s["success_rate"], 1.0);
    assert_eq!(s["failures"].as_array().map(Vec::len), Some(0));
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&out_file)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON line"))
        .collect();
    assert_eq!(lines.len(), 4);
    for (i, l) in lines.iter().enumerate() {
        assert_eq!(l["index"], i as u64);
        assert_eq!(l["sweep_seed"], 2024);
        for key in [
            "seed",
            "layout",
            "success",
            "failure_reason",
            "sim_time_s",
            "grasp_attempts",
            "checks",
        ] {
            assert!(l.get(key).is_some(), "line {i} lacks {key}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failures_exit_1_and_their_printed_command_reproduces_them() {
    // One simulated second is too short for the task: every scenario fails.
    let out = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "2",
        "--seed",
        "9",
        "--max-sim-time",
        "1",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let s = last_json_line(&out);
    assert_eq!(s["successes"], 0);
    let failures = s["failures"].as_array().expect("failures");
    assert_eq!(failures.len(), 2);
    let f = &failures[1];
    assert_eq!(f["index"], 1);
    assert!(f["reason"].as_str().unwrap().contains("time limit"), "{f}");
    assert_eq!(f["cube"].as_array().map(Vec::len), Some(3));
    assert_eq!(f["bowl"].as_array().map(Vec::len), Some(2));
    let cmd = f["reproduce"].as_str().expect("reproduce");
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        text.contains(cmd),
        "the human summary (on stderr with --json) prints the command too"
    );
    // Run the printed command as printed, from the repository, with a shell (the binary under
    // test is not on PATH, so the command names it by its path), and compare its report with
    // the sweep's.
    let words: Vec<&str> = cmd.split_whitespace().collect();
    let bin = std::path::Path::new(cli::BIN).canonicalize().unwrap();
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .canonicalize()
        .unwrap();
    let expected = bin.strip_prefix(&repo).unwrap_or(&bin).display().to_string();
    assert_eq!(&words[..2], [expected.as_str(), "run"], "{cmd}");
    let again = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("{cmd} --json"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .output()
        .expect("runs the printed command");
    assert_eq!(again.status.code(), Some(1), "{cmd}");
    let r = last_json_line(&again);
    let sweep = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "2",
        "--seed",
        "9",
        "--max-sim-time",
        "1",
        "--shard",
        "1/2",
        "--out",
        "/dev/stdout",
    ]);
    let line = String::from_utf8_lossy(&sweep.stdout)
        .lines()
        .next()
        .expect("a JSONL line")
        .to_string();
    let l: serde_json::Value = serde_json::from_str(&line).unwrap();
    for key in [
        "sim_time_s",
        "physics_steps",
        "cube_final",
        "checks",
        "grasp_attempts",
        "seed",
        "failure_reason",
    ] {
        assert_eq!(r[key], l[key], "{key} differs between `{cmd}` and the sweep");
    }
}

#[test]
fn bad_input_exits_2_with_a_clear_message() {
    let cases: [(&[&str], &str); 4] = [
        (&["sweep", TREE, "--scenarios", "3", "--shard", "3/2"], "K/M"),
        (&["sweep", TREE, "--scenarios", "0"], "0"),
        (&["sweep", "no/such/tree.yaml", "--scenarios", "3"], "tree.yaml"),
        (
            &["sweep", TREE, "--scenarios", "3", "--fault", "gremlins"],
            "slip",
        ),
    ];
    for (args, needle) in cases {
        let out = macrotree(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: message lacks {needle:?}: {stderr}"
        );
    }
}
