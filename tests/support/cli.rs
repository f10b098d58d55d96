//! Running the `macrotree` binary from tests, and scratch folders for what it writes.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_macrotree");

/// Runs `macrotree ARGS…` from the repository root (without `RUST_LOG`) and waits for it.
pub fn macrotree(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .output()
        .expect("runs the binary")
}

/// Runs `macrotree ARGS…` and asserts bad input: exit 2, `needle` on stderr, no panic.
pub fn assert_bad_input(args: &[&str], needle: &str) {
    let out = macrotree(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: stderr lacks {needle:?}: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

/// A fresh, empty folder for this test process (`name` tells the tests of one file apart).
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("macrotree-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as `&str` (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The keys of a sweep summary that measure the run (how long it took, on how many jobs)
/// rather than its results: the same results give different values on every run.
pub const TIMING_KEYS: [&str; 8] = [
    "wall_time_s",
    "jobs",
    "scenarios_per_minute",
    "physics_share",
    "physics_time_s",
    "process_wall_time_s",
    "planning_time_s",
    "planning_share",
];

/// A sweep summary (JSON) without its [`TIMING_KEYS`].
pub fn results_only(mut summary: serde_json::Value) -> serde_json::Value {
    if let Some(o) = summary.as_object_mut() {
        for k in TIMING_KEYS {
            o.remove(k);
        }
    }
    summary
}

/// A sweep summary's text without its timing lines (wall time, physics and planning shares).
pub fn text_without_timings(text: &str) -> String {
    text.lines()
        .filter(|l| {
            !["  wall time", "  physics share", "  planning share"]
                .iter()
                .any(|p| l.starts_with(p))
        })
        .map(|l| format!("{l}\n"))
        .collect()
}
