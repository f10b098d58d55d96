//! `--shard auto` on a real Slurm: a single-host cluster (`tools/slurm-local`: Debian's
//! slurmctld and slurmd on localhost), a job array submitted with `sbatch` in the form
//! docs/scale_out.md shows, its shards merged with `macrotree report` and compared with the
//! unsharded run. Slurm is a system package: without it the test skips with a note, and in CI
//! (`CI` set; `.ci/run` installs it) it fails.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::support::cli::{BIN, macrotree, results_only, s, scratch, text_without_timings};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A cluster started for this test, stopped when dropped (also when the test fails).
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
}

impl Cluster {
    /// Starts a cluster in `dir` on ports of its own (the test may run beside another cluster).
    fn start(dir: &Path) -> Cluster {
        let port = 20_000 + (std::process::id() % 10_000) * 2;
        let out = Command::new(Path::new(ROOT).join("tools/slurm-local"))
            .args(["start", s(dir)])
            .env("SLURM_LOCAL_PORT", port.to_string())
            .output()
            .expect("tools/slurm-local runs");
        let cluster = Cluster {
            dir: dir.to_path_buf(),
            conf: dir.join("slurm.conf"),
        };
        assert!(
            out.status.success(),
            "tools/slurm-local start failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        cluster
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(Path::new(ROOT).join("tools/slurm-local"))
            .args(["stop", s(&self.dir)])
            .output();
    }
}

/// Slurm's commands and daemons are installed.
fn slurm_installed() -> bool {
    Command::new("sh")
        .args([
            "-c",
            "PATH=\"$PATH:/usr/sbin:/sbin\"; for c in sbatch srun sinfo slurmctld slurmd; do command -v $c >/dev/null || exit 1; done",
        ])
        .status()
        .is_ok_and(|s| s.success())
}

/// The job script of docs/scale_out.md ("A Slurm array"), with this build's binary, a sweep
/// small enough for a test and one CPU per task (the machine may have two).
fn job_script(out: &Path, scenarios: u32) -> String {
    format!(
        r#"#!/bin/bash
#SBATCH --job-name=macrotree-sweep
#SBATCH --array=0-3
#SBATCH --cpus-per-task=1
#SBATCH --time=00:10:00
#SBATCH --output={out}/logs/%A_%a.log
set -euo pipefail
mkdir -p {out}/out
# Each array task runs its share: K from SLURM_ARRAY_TASK_ID, M from SLURM_ARRAY_TASK_COUNT.
srun {bin} sweep trees/cube_to_bowl.yaml --scenarios {scenarios} --seed 1 \
  --jobs "$SLURM_CPUS_PER_TASK" --shard auto \
  --out "{out}/out/sweep-${{SLURM_ARRAY_TASK_ID}}.jsonl"
"#,
        out = s(out),
        bin = BIN,
    )
}

#[test]
fn a_slurm_job_array_of_four_shards_merges_into_the_unsharded_report() {
    if !slurm_installed() {
        assert!(
            std::env::var_os("CI").is_none(),
            "Slurm is missing in CI (.ci/run installs it with tools/slurm-local install)"
        );
        eprintln!("skipped: Slurm is not installed (tools/slurm-local install, as root)");
        return;
    }
    let dir = scratch("slurm-array");
    let cluster = Cluster::start(&dir.join("cluster"));
    let work = dir.join("work");
    std::fs::create_dir_all(work.join("logs")).unwrap();
    let scenarios = 8;
    // The unsharded run first: the reference.
    let all = dir.join("all.jsonl");
    let n = scenarios.to_string();
    let whole = macrotree(&[
        "sweep",
        "trees/cube_to_bowl.yaml",
        "--scenarios",
        &n,
        "--seed",
        "1",
        "--jobs",
        "2",
        "--out",
        s(&all),
    ]);
    assert_eq!(
        whole.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&whole.stderr)
    );
    // The array, submitted from the repository as a user would, waited for (bounded).
    let script = dir.join("sweep.sh");
    std::fs::write(&script, job_script(&work, scenarios)).unwrap();
    let submitted = Command::new("timeout")
        .args(["600", "sbatch", "--wait", s(&script)])
        .current_dir(ROOT)
        .env("SLURM_CONF", &cluster.conf)
        .env(
            "PATH",
            format!("{}:/usr/sbin:/sbin", std::env::var("PATH").unwrap_or_default()),
        )
        .env_remove("RUST_LOG")
        .output()
        .expect("sbatch runs");
    let logs: Vec<(PathBuf, String)> = std::fs::read_dir(work.join("logs"))
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let text = std::fs::read_to_string(&p).unwrap_or_default();
            (p, text)
        })
        .collect();
    assert!(
        submitted.status.success(),
        "sbatch --wait: {}\n{}\nlogs: {logs:#?}",
        String::from_utf8_lossy(&submitted.stdout),
        String::from_utf8_lossy(&submitted.stderr)
    );
    // Four tasks ran, each its own shard K/4 read from Slurm's environment.
    assert_eq!(logs.len(), 4, "{logs:#?}");
    for k in 0..4 {
        let shard = format!("shard {k}/4 (from the environment)");
        assert!(
            logs.iter().any(|(_, t)| t.contains(&shard)),
            "no log says {shard}: {logs:#?}"
        );
    }
    let shards: Vec<PathBuf> = (0..4)
        .map(|k| work.join(format!("out/sweep-{k}.jsonl")))
        .collect();
    let lines: usize = shards
        .iter()
        .map(|p| std::fs::read_to_string(p).unwrap().lines().count())
        .sum();
    assert_eq!(lines, scenarios as usize);
    // Merged, the shards give the unsharded report's results; the times are the four tasks'.
    let mut args = vec!["report", "--json"];
    args.extend(shards.iter().map(|p| s(p)));
    let merged = macrotree(&args);
    let reference = macrotree(&["report", "--json", s(&all)]);
    assert_eq!(
        merged.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    assert_eq!(merged.status.code(), reference.status.code());
    let json = |o: &std::process::Output| -> serde_json::Value {
        serde_json::from_slice(o.stdout.rsplit(|&b| b == b'\n').find(|l| !l.is_empty()).unwrap()).unwrap()
    };
    let summary = json(&merged);
    assert_eq!(results_only(summary.clone()), results_only(json(&reference)));
    assert_eq!(
        text_without_timings(&String::from_utf8_lossy(&merged.stderr)),
        text_without_timings(&String::from_utf8_lossy(&reference.stderr))
    );
    assert_eq!(summary["scenarios"], scenarios);
    // Each task's timing file was written beside its shard: one job each, four side by side.
    assert_eq!(summary["jobs"], 4, "{summary}");
    assert!(
        summary["physics_share"].as_f64().is_some_and(|s| s > 0.0),
        "{summary}"
    );
    drop(cluster);
}
