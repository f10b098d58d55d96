//! `sweep --resume`: an interrupted sweep's file is completed to exactly the bytes and summary of
//! an uninterrupted run, and results of another sweep are refused (issue 13, item 4).

use std::path::Path;
use std::process::Output;

use crate::support::cli;
use cli::*;
const TREE: &str = "trees/cube_to_bowl.yaml";

/// The `--json` summary without what depends on the machine and the run (wall time, jobs).
fn summary(out: &Output) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    for k in TIMING_KEYS {
        assert!(v.get(k).is_some(), "the summary has {k}");
    }
    results_only(v)
}

fn sweep(extra: &[&str], out: &Path, more: &[&str]) -> Output {
    let mut args = vec!["sweep", TREE, "--json", "--out", s(out)];
    args.extend_from_slice(extra);
    args.extend_from_slice(more);
    macrotree(&args)
}

#[test]
fn sweep_resume_completes_a_truncated_file_byte_identically() {
    let dir = scratch("truncated");
    // About half the scenarios of this sweep fail (the slip fault makes them retry, and the time
    // limit is short), so the summary lists failures too.
    for shard in [None, Some("1/3")] {
        let mut opts = vec![
            "--scenarios",
            "24",
            "--seed",
            "11",
            "--fault",
            "slip",
            "--max-sim-time",
            "6.8",
        ];
        opts.extend(shard.iter().flat_map(|s| ["--shard", *s]));
        let full = dir.join("full.jsonl");
        let uninterrupted = sweep(&opts, &full, &["--jobs", "2"]);
        assert_eq!(uninterrupted.status.code(), Some(1), "some scenarios fail");
        assert!(!summary(&uninterrupted)["failures"].as_array().unwrap().is_empty());
        let bytes = std::fs::read(&full).unwrap();
        let lines = bytes.iter().filter(|&&b| b == b'\n').count();
        assert!(lines >= 8, "{lines}");

        // Interrupted in the middle of a line, and at a line boundary.
        let mid_line = bytes.len() / 2 + 7;
        let at_boundary = bytes[..bytes.len() / 3]
            .iter()
            .rposition(|&b| b == b'\n')
            .unwrap()
            + 1;
        for cut in [mid_line, at_boundary, 0] {
            let part = dir.join("part.jsonl");
            std::fs::write(&part, &bytes[..cut]).unwrap();
            let resumed = sweep(&opts, &part, &["--jobs", "1", "--resume"]);
            let stderr = String::from_utf8_lossy(&resumed.stderr);
            assert_eq!(resumed.status.code(), uninterrupted.status.code(), "{stderr}");
            let kept = bytes[..cut].iter().filter(|&&b| b == b'\n').count();
            assert!(
                stderr.contains(&format!("{kept} of {lines} scenario(s) already done")),
                "{stderr}"
            );
            assert!(
                std::fs::read(&part).unwrap() == bytes,
                "{shard:?}, cut at {cut}: the resumed file differs from the uninterrupted one"
            );
            assert_eq!(
                summary(&resumed),
                summary(&uninterrupted),
                "{shard:?}, cut at {cut}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_resume_refuses_results_of_another_sweep() {
    let dir = scratch("foreign");
    let file = dir.join("r.jsonl");
    let base = ["--scenarios", "10", "--seed", "4"];
    let out = sweep(&base, &file, &[]);
    assert_eq!(out.status.code(), Some(0));
    let bytes = std::fs::read(&file).unwrap();
    let half = &bytes[..bytes.len() / 2];
    for (opts, why) in [
        (vec!["--scenarios", "10", "--seed", "5"], "sweep seed"),
        (
            vec!["--scenarios", "10", "--seed", "4", "--fault", "nudge"],
            "fault",
        ),
        (
            vec!["--scenarios", "10", "--seed", "4", "--shard", "1/2"],
            "expected scenario 1",
        ),
        // Every line names the sweep's scenario count, time limit and tree.
        (vec!["--scenarios", "2", "--seed", "4"], "10 scenarios, not 2"),
        (
            vec!["--scenarios", "10", "--seed", "4", "--max-sim-time", "2"],
            "--max-sim-time 60, not 2",
        ),
    ] {
        std::fs::write(&file, half).unwrap();
        let out = sweep(&opts, &file, &["--resume"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{opts:?}: {stderr}");
        assert!(
            stderr.contains("cannot resume") && stderr.contains(why),
            "{opts:?}: {stderr}"
        );
        assert_eq!(
            std::fs::read(&file).unwrap(),
            half,
            "{opts:?}: the file was changed"
        );
    }
    // Another tree: named in every line.
    std::fs::write(&file, half).unwrap();
    let mut args = vec![
        "sweep",
        "trees/place_on_table.yaml",
        "--out",
        s(&file),
        "--resume",
    ];
    args.extend_from_slice(&base);
    let out = macrotree(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("tree \"trees/cube_to_bowl.yaml\", not \"trees/place_on_table.yaml\""),
        "{stderr}"
    );
    // A line that is not a result at all.
    std::fs::write(&file, b"{\"index\":0}\n").unwrap();
    let out = sweep(&base, &file, &["--resume"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 1"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_resume_without_a_file_runs_the_whole_sweep() {
    let dir = scratch("fresh");
    let file = dir.join("r.jsonl");
    let out = sweep(&["--scenarios", "3"], &file, &["--resume"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&file).unwrap();
    assert_eq!(text.lines().count(), 3);
    let out = macrotree(&["sweep", TREE, "--scenarios", "3", "--resume"]);
    assert_eq!(out.status.code(), Some(2), "--resume needs --out");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_resumed_sweeps_timing_file_holds_every_run_that_wrote_its_lines() {
    let dir = scratch("resume-timing");
    let opts = ["--scenarios", "6", "--seed", "3"];
    let full = dir.join("full.jsonl");
    assert_eq!(sweep(&opts, &full, &["--jobs", "2"]).status.code(), Some(0));
    let bytes = std::fs::read(&full).unwrap();
    let three = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(2)
        .unwrap()
        .0
        + 1;
    let part = dir.join("part.jsonl");
    let timing = dir.join("part.jsonl.timing.json");
    let earlier = serde_json::json!({"runs": [{
        "lines": 3, "jobs": 1, "wall_time_s": 100.0, "process_wall_time_s": 101.0,
        "physics_time_s": 50.0, "planning_time_s": 1.0
    }]});
    for (covers_the_kept_lines, written) in [
        (true, earlier.clone()),
        (false, {
            let mut e = earlier.clone();
            e["runs"][0]["lines"] = 2.into();
            e
        }),
    ] {
        std::fs::write(&part, &bytes[..three]).unwrap();
        std::fs::write(&timing, written.to_string()).unwrap();
        let resumed = sweep(&opts, &part, &["--jobs", "2", "--resume"]);
        assert_eq!(
            resumed.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&resumed.stderr)
        );
        let t: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&timing).unwrap()).unwrap();
        let runs = t["runs"].as_array().unwrap();
        let report = macrotree(&["report", "--json", s(&part)]);
        let merged: serde_json::Value =
            serde_json::from_str(String::from_utf8_lossy(&report.stdout).lines().last().unwrap()).unwrap();
        if covers_the_kept_lines {
            // The earlier run, then this one: together they made the file.
            assert_eq!(runs.len(), 2, "{t}");
            assert_eq!(runs[0], earlier["runs"][0]);
            assert_eq!(runs[1]["lines"], 3);
            assert_eq!(runs[1]["jobs"], 2);
            let wall = merged["wall_time_s"].as_f64().unwrap();
            assert!(wall > 100.0, "the runs' wall times add up: {wall}");
            assert_eq!(merged["jobs"], 2);
        } else {
            // A timing file that does not describe the kept lines is not carried on, and the
            // report does not pretend to know the file's times.
            assert_eq!(runs.len(), 1, "{t}");
            assert_eq!(runs[0]["lines"], 3);
            let text = String::from_utf8_lossy(&report.stderr);
            assert!(text.contains("shares: unknown"), "{text}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
