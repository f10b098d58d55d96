//! Bounds of the numeric options, through the binary: out of range is exit 2 with the range,
//! never a panic or a hang, and shard indices are computed, never listed (issue 13, items 11, 12).

use std::time::{Duration, Instant};

use crate::support::cli;
use cli::*;
const TREE: &str = "trees/cube_to_bowl.yaml";

#[test]
fn speed_is_bounded() {
    // 1e-22 panicked converting to a Duration; 1e-18 slept forever.
    for bad in ["1e-22", "1e-18", "0", "-2", "1000.5", "inf", "nan"] {
        assert_bad_input(
            &["run", TREE, &format!("--speed={bad}")],
            "must be between 0.01 and 1000 times real time",
        );
    }
    let out = macrotree(&["run", TREE, "--speed", "1000"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn max_sim_time_is_bounded() {
    for bad in ["3600.001", "1e300", "0", "-1", "nan"] {
        for cmd in ["run", "bench", "sweep"] {
            let opt = format!("--max-sim-time={bad}");
            let mut args = vec![cmd, TREE, &opt];
            if cmd == "sweep" {
                args.extend(["--scenarios", "1"]);
            }
            assert_bad_input(&args, "must be more than 0 and at most 3600 seconds");
        }
    }
    assert_bad_input(&["run", TREE, "--max-sim-time", "7200"], "at most 3600 seconds");
}

#[test]
fn scenarios_are_bounded() {
    let started = Instant::now();
    for bad in ["100000000", "10000001", "18446744073709551615", "0"] {
        assert_bad_input(&["sweep", TREE, "--scenarios", bad], "between 1 and 10000000");
    }
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "refusing took {:?}",
        started.elapsed()
    );
}

#[test]
fn shard_indices_are_computed_not_listed() {
    // A shard of one scenario out of the largest sweep, and one of the largest shard count:
    // both run at once (the index list was built by filtering every index).
    for (shard, index) in [("9999999/10000000", 9_999_999u64), ("0/18446744073709551615", 0)] {
        let started = Instant::now();
        let out = macrotree(&[
            "sweep",
            TREE,
            "--scenarios",
            "10000000",
            "--shard",
            shard,
            "--json",
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        let s: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
        assert_eq!(s["scenarios"], 1, "{shard}");
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "{shard} took {:?}",
            started.elapsed()
        );
        let out = macrotree(&[
            "sweep",
            TREE,
            "--scenarios",
            "10000000",
            "--shard",
            shard,
            "--max-sim-time",
            "0.5",
            "--json",
        ]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        let s: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
        assert_eq!(s["failures"][0]["index"], index, "{shard}");
    }
}

#[test]
fn empty_shard_is_an_error() {
    assert_bad_input(&["sweep", TREE, "--scenarios", "3", "--shard", "5/8"], "is empty");
    assert_bad_input(
        &[
            "sweep",
            TREE,
            "--scenarios",
            "10",
            "--shard",
            "18446744073709551614/18446744073709551615",
        ],
        "is empty",
    );
}
