//! `sweep --dataset`: the LeRobot v3.0 layout (checked with pyarrow and ffmpeg by
//! tests/dataset_layout.py), determinism across `--jobs`, `--only-success`, the folder rules,
//! and — when `MACROTREE_LEROBOT_PYTHON` names a Python with `lerobot[dataset]` — loading with
//! LeRobot itself (tests/lerobot_check.py).

use crate::support::cli;
use crate::support::media;

use std::path::{Path, PathBuf};
use std::process::Command;

use cli::{macrotree, s, scratch};

const TREE: &str = "trees/cube_to_bowl.yaml";

fn sweep(args: &[&str]) -> std::process::Output {
    let mut all = vec!["sweep", TREE];
    all.extend_from_slice(args);
    macrotree(&all)
}

/// Every file under `dir` (relative path → bytes), sorted.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push((
                    p.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

fn check_layout(dir: &Path, ffmpeg: &Path) {
    let Some(pyarrow) = media::pyarrow() else { return };
    let out = Command::new("python3")
        .arg("-S")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/dataset_layout.py"))
        .arg(dir)
        .arg(ffmpeg)
        .env("PYTHONPATH", pyarrow)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_dataset_with_two_cameras_has_the_lerobot_layout_and_the_same_bytes_for_any_jobs() {
    let Some(ffmpeg) = media::ffmpeg() else { return };
    if !media::gl() {
        return;
    }
    let dir = scratch("dataset-jobs");
    let (a, b) = (dir.join("a"), dir.join("b"));
    for (out, jobs) in [(&a, "1"), (&b, "2")] {
        let o = sweep(&[
            "--scenarios",
            "3",
            "--seed",
            "5",
            "--jobs",
            jobs,
            "--dataset",
            s(out),
            "--size",
            "96x72",
            "--fps",
            "10",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(stderr.contains("dataset written to"), "{stderr}");
    }
    check_layout(&a, &ffmpeg);
    let (fa, fb) = (files(&a), files(&b));
    assert_eq!(
        fa.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>(),
        fb.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>()
    );
    for ((p, x), (_, y)) in fa.iter().zip(&fb) {
        assert!(x == y, "{} differs between --jobs 1 and --jobs 2", p.display());
    }
    // 3 episodes × 2 cameras, one file each; nothing else besides data and metadata.
    assert_eq!(
        fa.iter()
            .filter(|(p, _)| p.extension().is_some_and(|e| e == "mp4"))
            .count(),
        6
    );
    assert_eq!(fa.len(), 6 + 6);
    // Nothing left next to the datasets (no staging folder).
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
}

#[test]
fn only_success_keeps_the_episodes_that_met_the_goal_in_scenario_order() {
    let Some(ffmpeg) = media::ffmpeg() else { return };
    let dir = scratch("dataset-success");
    let (ds, jsonl) = (dir.join("ds"), dir.join("r.jsonl"));
    // The flagship episodes take 4.9–5.9 s: a 5.3 s limit fails some of them.
    let o = sweep(&[
        "--scenarios",
        "8",
        "--max-sim-time",
        "5.3",
        "--out",
        s(&jsonl),
        "--dataset",
        s(&ds),
        "--cameras",
        "none",
        "--only-success",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let results: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let succeeded: Vec<u64> = results
        .iter()
        .filter(|r| r["success"] == true)
        .map(|r| r["index"].as_u64().unwrap())
        .collect();
    assert!(!succeeded.is_empty() && succeeded.len() < 8, "{succeeded:?}");
    let prov: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("meta/macrotree.json")).unwrap()).unwrap();
    let kept: Vec<u64> = prov["episodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["scenario"].as_u64().unwrap())
        .collect();
    assert_eq!(kept, succeeded);
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("meta/info.json")).unwrap()).unwrap();
    assert_eq!(info["total_episodes"], succeeded.len());
    assert_eq!(info["video_path"], serde_json::Value::Null);
    check_layout(&ds, &ffmpeg);
}

/// `run --frames` names each field as the dataset names its column (`tree.active_leaf`, not
/// `active_leaf`), so one reader serves both; only `sim_time` is its own.
#[test]
fn run_frames_fields_are_the_dataset_column_names() {
    let dir = scratch("frames-names");
    let (ds, frames) = (dir.join("ds"), dir.join("f.jsonl"));
    let o = macrotree(&["run", TREE, "--fps", "25", "--frames", s(&frames)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = sweep(&[
        "--scenarios",
        "1",
        "--fps",
        "25",
        "--dataset",
        s(&ds),
        "--cameras",
        "none",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("meta/info.json")).unwrap()).unwrap();
    let columns = info["features"].as_object().unwrap();
    let text = std::fs::read_to_string(&frames).unwrap();
    let first: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    let fields: Vec<&String> = first.as_object().unwrap().keys().collect();
    for f in &fields {
        assert!(
            *f == "sim_time" || columns.contains_key(f.as_str()),
            "--frames field `{f}` is not a dataset column ({:?})",
            columns.keys().collect::<Vec<_>>()
        );
    }
    for wanted in [
        "tree.active_leaf",
        "tree.active_kind",
        "observation.state",
        "action",
    ] {
        assert!(
            fields.iter().any(|f| *f == wanted),
            "{wanted} missing from {fields:?}"
        );
    }
}

#[test]
fn the_dataset_folder_is_new_empty_or_ours_with_overwrite() {
    let dir = scratch("dataset-dir");
    let ds = dir.join("ds");
    let data_only = |extra: &[&str]| {
        let mut a = vec!["--scenarios", "1", "--dataset", s(&ds), "--cameras", "none"];
        a.extend_from_slice(extra);
        sweep(&a)
    };
    // Someone else's folder is never written into.
    std::fs::create_dir(&ds).unwrap();
    std::fs::write(ds.join("notes.txt"), "mine").unwrap();
    let o = data_only(&[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not empty"));
    assert!(data_only(&["--overwrite"]).status.code() == Some(2));
    assert_eq!(std::fs::read_to_string(ds.join("notes.txt")).unwrap(), "mine");
    std::fs::remove_dir_all(&ds).unwrap();
    // A new folder, then ours again only with --overwrite.
    assert!(data_only(&[]).status.success());
    let o = data_only(&[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--overwrite"));
    assert!(data_only(&["--overwrite"]).status.success());
    assert!(ds.join("meta/info.json").is_file());
    // A symbolic link is never followed.
    let target = dir.join("elsewhere");
    std::fs::create_dir(&target).unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = sweep(&["--scenarios", "1", "--dataset", s(&link), "--cameras", "none"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("symbolic link"));
    assert_eq!(std::fs::read_dir(&target).unwrap().count(), 0);
    // Unknown cameras and a missing parent folder are bad input too.
    let o = sweep(&[
        "--scenarios",
        "1",
        "--dataset",
        s(&dir.join("x")),
        "--cameras",
        "front,eye",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no camera \"eye\""));
    let o = sweep(&[
        "--scenarios",
        "1",
        "--dataset",
        s(&dir.join("no/such/ds")),
        "--cameras",
        "none",
    ]);
    assert_eq!(o.status.code(), Some(2));
    // Only ds, elsewhere and link: no staging folder left behind by the refused runs.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
}

/// LeRobot itself loads the dataset, decodes its videos and gives back exactly what
/// `run --frames` records for the same scenarios. Needs a Python with `lerobot[dataset]==0.6.1`
/// (about 5 GB with torch): set `MACROTREE_LEROBOT_PYTHON` to it (see docs/datasets.md).
#[test]
fn lerobot_loads_the_dataset_and_it_matches_run_frames() {
    let Some(python) = std::env::var_os("MACROTREE_LEROBOT_PYTHON") else {
        eprintln!("skipped: set MACROTREE_LEROBOT_PYTHON to a Python with lerobot[dataset]==0.6.1");
        return;
    };
    let Some(_) = media::ffmpeg() else { return };
    if !media::gl() {
        return;
    }
    let dir = scratch("dataset-lerobot");
    let (ds, frames) = (dir.join("ds"), dir.join("frames"));
    std::fs::create_dir(&frames).unwrap();
    let o = sweep(&["--scenarios", "4", "--dataset", s(&ds), "--size", "160x120"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for k in ["0", "3"] {
        let f = frames.join(format!("scenario-{k}.jsonl"));
        let o = macrotree(&["run", TREE, "--scenario", k, "--fps", "50", "--frames", s(&f)]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let out = Command::new(python)
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/lerobot_check.py"))
        .arg(&ds)
        .arg(&frames)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("2 episodes match run --frames"), "{text}");
}

#[test]
fn a_dataset_frame_rate_that_is_not_a_whole_number_of_control_periods_is_refused() {
    let dir = scratch("dataset-fps");
    let out = dir.join("ds");
    for fps in ["15", "30", "0", "251", "1e9"] {
        let o = sweep(&[
            "--scenarios",
            "1",
            "--dataset",
            s(&out),
            "--cameras",
            "none",
            "--fps",
            fps,
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--fps {fps}: {stderr}");
        assert!(
            stderr.contains("1, 2, 5, 10, 25, 50, 125, 250"),
            "--fps {fps}: {stderr}"
        );
        assert!(!out.exists(), "--fps {fps}: nothing is written");
    }
}

#[test]
fn a_noisy_dataset_records_its_noise_and_is_the_same_bytes_for_any_jobs() {
    let dir = scratch("dataset-noise");
    let (a, b) = (dir.join("a"), dir.join("b"));
    for (out, jobs) in [(&a, "1"), (&b, "2")] {
        let o = sweep(&[
            "--scenarios",
            "3",
            "--seed",
            "2",
            "--jobs",
            jobs,
            "--dataset",
            s(out),
            "--cameras",
            "none",
            "--noise",
            "0.02,10",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(files(&a), files(&b), "--jobs 1 and --jobs 2 wrote the same bytes");
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("meta/macrotree.json")).unwrap()).unwrap();
    let noise = &meta["action_noise"];
    assert_eq!(noise["joint_sigma_rad"], 0.02, "{meta}");
    assert_eq!(noise["gripper_sigma"], 10.0, "{meta}");
}

#[test]
fn noise_out_of_range_or_without_a_dataset_is_refused() {
    let dir = scratch("dataset-noise-bad");
    let out = dir.join("ds");
    for noise in ["0.5", "-0.01", "0.02,300", "nan", "0.01,1,2"] {
        let o = sweep(&[
            "--scenarios",
            "1",
            "--dataset",
            s(&out),
            "--cameras",
            "none",
            "--noise",
            noise,
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--noise {noise}: {stderr}");
        assert!(
            stderr.contains("JOINT_SIGMA[,GRIPPER_SIGMA]"),
            "--noise {noise}: {stderr}"
        );
        assert!(!out.exists());
    }
    let o = sweep(&["--scenarios", "1", "--noise", "0.02"]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}
