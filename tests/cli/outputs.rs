//! Output files of the CLI (`run --record`, `sweep --out`, `schema --out`, `graph --out`): never
//! through a link or onto a device, never over an input, checked before the run, and every write
//! error reported with exit 2 (issue 13, files).

use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Output};

use crate::support::cli;
use cli::*;
const TREE: &str = "trees/cube_to_bowl.yaml";

/// The binary with a file size limit of `kib` KiB (writes past it fail with EFBIG).
fn macrotree_with_file_limit(kib: u32, args: &[&str]) -> Output {
    // dash counts `ulimit -f` in 512-byte blocks, bash in KiB: ask dash-style for `kib` KiB.
    let script = format!("trap '' XFSZ; ulimit -f {}; exec \"$0\" \"$@\"", kib * 2);
    Command::new("/bin/sh")
        .arg("-c")
        .arg(script)
        .arg(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .output()
        .expect("runs the binary")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Asserts `out` is a refusal before anything ran: exit 2, the reason on stderr, no report.
fn assert_refused_before_running(out: &Output, reason: &str) {
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(stderr.contains(reason), "stderr lacks {reason:?}: {stderr}");
    assert!(!stderr.contains("replay written"), "{stderr}");
    assert!(out.stdout.is_empty(), "ran anyway: {}", text(&out.stdout));
}

#[test]
fn record_never_replaces_a_device_or_symlink() {
    let dir = scratch("record-special");
    // A symbolic link to a file: refused, neither the link nor its target touched.
    let target = dir.join("target.txt");
    std::fs::write(&target, "keep me").unwrap();
    let link = dir.join("link.html");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = macrotree(&["run", TREE, "--record", s(&link)]);
    assert_refused_before_running(&out, "symbolic link");
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");

    // A FIFO: refused (writing would block; replacing it would destroy it).
    let fifo = dir.join("pipe.html");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let out = macrotree(&["run", TREE, "--record", s(&fifo)]);
    assert_refused_before_running(&out, "FIFO");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());

    // A device node (a private copy of /dev/null, where the system allows making one).
    let dev = dir.join("null.html");
    if Command::new("mknod")
        .args([s(&dev), "c", "1", "3"])
        .status()
        .is_ok_and(|st| st.success())
    {
        let out = macrotree(&["run", TREE, "--record", s(&dev)]);
        assert_refused_before_running(&out, "device");
        assert!(
            std::fs::symlink_metadata(&dev)
                .unwrap()
                .file_type()
                .is_char_device()
        );
    } else {
        eprintln!("mknod is not permitted here: the device case is covered by sweep --out /dev/full");
    }

    // A folder.
    let out = macrotree(&["run", TREE, "--record", s(&dir)]);
    assert_refused_before_running(&out, "folder");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_never_follows_a_symlink_at_the_temporary_path() {
    let dir = scratch("record-tmp-link");
    let path = dir.join("replay.html");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "keep me").unwrap();
    std::os::unix::fs::symlink(&victim, dir.join("replay.html.tmp")).unwrap();
    let out = macrotree(&["run", TREE, "--record", s(&path)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me");
    let html = std::fs::read_to_string(&path).unwrap();
    assert!(
        html.starts_with("<!DOCTYPE html>") || html.contains("<html"),
        "not a replay"
    );
    // Nothing else was left next to it.
    assert_eq!(entries(&dir), ["replay.html", "replay.html.tmp", "victim.txt"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_write_error_exits_2_and_leaves_no_temporary_file() {
    let dir = scratch("record-efbig");
    let path = dir.join("replay.html");
    // The replay is megabytes; 64 KiB is not enough.
    let out = macrotree_with_file_limit(64, &["run", TREE, "--record", s(&path)]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(
        stderr.contains("cannot write") && stderr.contains(s(&path)),
        "{stderr}"
    );
    assert!(!stderr.contains("replay written"), "{stderr}");
    assert_eq!(entries(&dir), Vec::<String>::new(), "temporary file left behind");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_location_is_checked_before_the_run() {
    let dir = scratch("checked-first");
    let missing = dir.join("no/such/folder/x.html");
    let out = macrotree(&["run", TREE, "--record", s(&missing)]);
    assert_refused_before_running(&out, "does not exist");
    let out = macrotree(&["sweep", TREE, "--scenarios", "50", "--out", s(&missing)]);
    assert_refused_before_running(&out, "does not exist");
    let out = macrotree(&["schema", "--out", s(&missing)]);
    assert_refused_before_running(&out, "does not exist");
    let out = macrotree(&["sweep", TREE, "--scenarios", "50", "--out", s(&dir)]);
    assert_refused_before_running(&out, "folder");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn out_and_record_never_overwrite_an_input_file() {
    let dir = scratch("inputs");
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    let tree = dir.join("t.yaml");
    let lib = dir.join("lib/pick_place.yaml");
    std::fs::copy("trees/library_pick_place.yaml", &tree).unwrap();
    std::fs::copy("trees/lib/pick_place.yaml", &lib).unwrap();
    let tree_text = std::fs::read(&tree).unwrap();
    let lib_text = std::fs::read(&lib).unwrap();
    let hard = dir.join("hard.yaml");
    std::fs::hard_link(&tree, &hard).unwrap();

    for (args, what) in [
        (vec!["run", s(&tree), "--record", s(&tree)], "the tree"),
        (vec!["run", s(&tree), "--record", s(&lib)], "an included file"),
        (
            vec!["run", s(&tree), "--record", s(&hard)],
            "a hard link to the tree",
        ),
        (
            vec!["sweep", s(&tree), "--scenarios", "3", "--out", s(&tree)],
            "the tree",
        ),
        (vec!["graph", s(&tree), "--out", s(&lib)], "an included file"),
    ] {
        let out = macrotree(&args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
        assert!(stderr.contains("input of this command"), "{what}: {stderr}");
        assert!(out.stdout.is_empty(), "{what}: ran anyway");
    }
    assert_eq!(std::fs::read(&tree).unwrap(), tree_text);
    assert_eq!(std::fs::read(&lib).unwrap(), lib_text);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn overwriting_another_file_is_said_on_stderr() {
    let dir = scratch("overwrite");
    let path = dir.join("schema.json");
    let out = macrotree(&["schema", "--out", s(&path)]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        !text(&out.stderr).contains("overwriting"),
        "nothing was there yet"
    );
    std::fs::write(&path, "old").unwrap();
    let out = macrotree(&["schema", "--out", s(&path)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains(&format!("overwriting existing {}", s(&path))),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        std::fs::read_to_string("schema/tree.schema.json").unwrap()
    );
    assert_eq!(entries(&dir), ["schema.json"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_out_dev_full_is_refused_before_running() {
    let out = macrotree(&["sweep", TREE, "--scenarios", "20", "--out", "/dev/full"]);
    assert_refused_before_running(&out, "device");
}

#[test]
fn sweep_stops_at_the_first_write_error_and_keeps_whole_lines() {
    let dir = scratch("sweep-efbig");
    let full = dir.join("full.jsonl");
    let args = |out: &Path| {
        vec![
            "sweep".to_string(),
            TREE.into(),
            "--scenarios".into(),
            "40".into(),
            "--seed".into(),
            "3".into(),
            "--jobs".into(),
            "2".into(),
            "--out".into(),
            s(out).into(),
        ]
    };
    let a = args(&full);
    let out = macrotree(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let complete = std::fs::read(&full).unwrap();
    assert!(
        complete.len() > 16 * 1024,
        "the test needs more than 16 KiB of results"
    );

    let cut = dir.join("cut.jsonl");
    let a = args(&cut);
    let out = macrotree_with_file_limit(8, &a.iter().map(String::as_str).collect::<Vec<_>>());
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(
        stderr.contains("cannot write") && stderr.contains("--resume"),
        "{stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "a summary was printed: {}",
        text(&out.stdout)
    );
    let partial = std::fs::read(&cut).unwrap();
    assert!(!partial.is_empty() && partial.len() < complete.len());
    assert_eq!(partial.last(), Some(&b'\n'), "the last line is whole");
    assert!(
        complete.starts_with(&partial),
        "the lines written are those of the full sweep"
    );
    for line in text(&partial).lines() {
        serde_json::from_str::<serde_json::Value>(line).expect("every line is valid JSON");
    }
    // The full run's timing file is beside its lines; the stopped run wrote none (its times
    // would not describe a finished file).
    assert_eq!(
        entries(&dir),
        ["cut.jsonl", "full.jsonl", "full.jsonl.timing.json"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
