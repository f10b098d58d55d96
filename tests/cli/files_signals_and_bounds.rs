//! Hardening, round 3 (issue 21): no file read or written outside the rules, sweeps of any
//! length in bounded memory, clean stops on signals, one writer per output. One test (or more)
//! per item of the issue, named after the defect it pins.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::support::cli;
use cli::*;

const TREE: &str = "trees/cube_to_bowl.yaml";
/// Every leaf of the tree succeeds at once: episodes cost next to nothing.
const FREE: &str = "main/**=success";
/// Every leaf fails at once.
const FAILING: &str = "main/**=failure";

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Exit 2, `needle` on stderr, no panic.
fn assert_refused(out: &Output, needle: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    assert!(!err.contains("panicked at"), "{err}");
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `macrotree ARGS…` run from `dir`.
fn macrotree_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .env_remove("RUST_LOG")
        .output()
        .expect("runs the binary")
}

/// `macrotree ARGS…` started in the background from the repository.
fn spawn(args: &[&str]) -> Child {
    Command::new(BIN)
        .args(args)
        .current_dir(repo())
        .env_remove("RUST_LOG")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts the binary")
}

fn wait_for(what: &str, mut cond: impl FnMut() -> bool) {
    let start = Instant::now();
    while !cond() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "waited too long for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sets the modification time of `p` (a file or a folder) `secs` seconds back.
fn age(p: &Path, secs: u64) {
    let f = std::fs::File::open(p).unwrap();
    f.set_modified(std::time::SystemTime::now() - Duration::from_secs(secs))
        .unwrap();
}

fn lines_of(path: &Path) -> usize {
    std::fs::read(path)
        .map(|b| b.iter().filter(|&&c| c == b'\n').count())
        .unwrap_or(0)
}

fn hidden_entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    v.sort();
    v
}

fn kill(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(ok.success());
}

/// A copy of the flagship tree in `dir`.
fn tree_copy(dir: &Path) -> PathBuf {
    let tree = dir.join("tree.yaml");
    std::fs::copy(repo().join(TREE), &tree).unwrap();
    tree
}

const SECRET: &str = "AWS_SECRET_ACCESS_KEY=line2-very-secret\nDB_PASSWORD=line3-hunter2\n";

// ---------------------------------------------------------------------------------------------
// 1. Files read

#[test]
fn a_tree_scene_outside_its_folder_is_refused_without_reading_it() {
    let dir = scratch("h3-scene-outside");
    let secrets = dir.join("secrets.env");
    std::fs::write(&secrets, format!("API_TOKEN=line1-token\n{SECRET}")).unwrap();
    let trees = dir.join("trees");
    std::fs::create_dir(&trees).unwrap();
    let tree = trees.join("t.yaml");
    let text = std::fs::read_to_string(repo().join(TREE)).unwrap();
    std::fs::write(&tree, format!("scene: ../secrets.env\n{text}")).unwrap();
    for format in [None, Some("github")] {
        let mut args = vec!["validate", s(&tree)];
        if let Some(f) = format {
            args.extend(["--format", f]);
        }
        let out = macrotree(&args);
        let all = stderr(&out) + &stdout(&out);
        assert_eq!(out.status.code(), Some(2), "{all}");
        assert!(all.contains("outside the tree's folder"), "{all}");
        assert!(
            all.contains("t.yaml:1:") || all.contains("t.yaml,line=1,"),
            "located at the tree's `scene:`: {all}"
        );
        for secret in ["line1-token", "line2-very-secret", "line3-hunter2"] {
            assert!(!all.contains(secret), "leaked {secret}: {all}");
        }
    }
    // `run` refuses it the same way, and a YAML file outside the tree's folder and the current
    // folder too.
    let out = macrotree(&["run", s(&tree)]);
    assert_refused(&out, "outside the tree's folder");
    std::fs::write(dir.join("secrets.yaml"), format!("token: line1-token\n{SECRET}")).unwrap();
    std::fs::write(&tree, format!("scene: ../secrets.yaml\n{text}")).unwrap();
    let out = macrotree(&["validate", s(&tree)]);
    assert_refused(&out, "outside the tree's folder");
    assert!(!stderr(&out).contains("line1-token"), "{}", stderr(&out));
    // The shipped trees name scenes of the repository's `scenes/` (run from the repository).
    let out = macrotree(&["validate", "trees/sort_by_color.yaml", "trees/stack_three.yaml"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_scene_rule_does_not_depend_on_the_working_folder() {
    let dir = scratch("h4-scene-any-folder");
    let from_root = |args: &[&str]| {
        Command::new(BIN)
            .args(args)
            .current_dir("/")
            .env_remove("RUST_LOG")
            .output()
            .unwrap()
    };
    // The shipped trees name `../scenes/…`: allowed from any folder.
    let shipped = repo().join("trees/sort_by_color.yaml");
    let out = from_root(&["validate", s(&shipped)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // A project of one's own: trees/ and scenes/ side by side.
    for sub in ["trees", "scenes", "elsewhere"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    std::fs::copy(repo().join("scenes/sort_three.yaml"), dir.join("scenes/s.yaml")).unwrap();
    let body = "main: {home: {}}\n";
    let ok = dir.join("trees/ok.yaml");
    std::fs::write(&ok, format!("scene: ../scenes/s.yaml\n{body}")).unwrap();
    let out = from_root(&["validate", s(&ok)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // A YAML file elsewhere is refused, though it is under the working folder `/`; nothing of it
    // is read or shown.
    std::fs::write(
        dir.join("elsewhere/leak.yaml"),
        format!("description: x\ntoken: line1-token\n{SECRET}"),
    )
    .unwrap();
    let bad = dir.join("trees/bad.yaml");
    std::fs::write(&bad, format!("scene: ../elsewhere/leak.yaml\n{body}")).unwrap();
    let out = from_root(&["validate", s(&bad)]);
    let all = stderr(&out) + &stdout(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("outside the tree's folder"), "{all}");
    for secret in ["line1-token", "line2-very-secret", "line3-hunter2"] {
        assert!(!all.contains(secret), "leaked {secret}: {all}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_that_is_not_a_scene_file_gives_one_diagnostic_quoting_nothing() {
    let dir = scratch("h3-scene-not-scene");
    std::fs::write(
        dir.join("creds.env"),
        "API_TOKEN: line1-token\nAWS_SECRET_ACCESS_KEY: line2-very-secret\nDB_PASSWORD: line3-hunter2\n",
    )
    .unwrap();
    let text = std::fs::read_to_string(repo().join(TREE)).unwrap();
    let tree = dir.join("t.yaml");
    std::fs::write(&tree, format!("scene: creds.env\n{text}")).unwrap();
    // Read as a tree, it shows nothing of it either.
    let out = macrotree(&["validate", s(&dir.join("creds.env"))]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        !stderr(&out).contains("line1") && !stderr(&out).contains("line2") && !stderr(&out).contains("line3"),
        "{}",
        stderr(&out)
    );
    for args in [
        vec!["validate", s(&tree)],
        vec!["validate", s(&tree), "--format", "github"],
        vec!["run", TREE, "--scene", s(&dir.join("creds.env"))],
    ] {
        let out = macrotree(&args);
        let all = stderr(&out) + &stdout(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {all}");
        assert!(all.contains("not a scene file"), "{args:?}: {all}");
        for secret in ["API_TOKEN", "line1-token", "line2-very-secret", "line3-hunter2"] {
            assert!(!all.contains(secret), "{args:?} leaked {secret}: {all}");
        }
        assert_eq!(
            all.matches("not a scene file").count(),
            1,
            "one diagnostic: {all}"
        );
    }
    // A file that is not even YAML, and not named `.yaml`: located, none of its lines shown.
    let env = dir.join("dot.env");
    std::fs::write(&env, format!("API_TOKEN=line1-token\n{SECRET}  - x: [\n")).unwrap();
    let out = macrotree(&["run", TREE, "--scene", s(&env)]);
    let all = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(all.contains("dot.env:"), "{all}");
    for secret in ["line1-token", "line2-very-secret", "line3-hunter2"] {
        assert!(!all.contains(secret), "leaked {secret}: {all}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn report_refuses_a_suite_path_from_the_results_outside_the_current_folder() {
    let dir = scratch("h3-report-suite");
    let results = dir.join("r.jsonl");
    let out = macrotree(&[
        "test",
        "scenarios/cube_to_bowl_grasp_never_works.yaml",
        "--out",
        s(&results),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // The same results, naming a file outside the repository as their scenario file.
    let secrets = dir.join("secrets.yaml");
    std::fs::write(&secrets, format!("tree: x\n{SECRET}")).unwrap();
    let moved: String = std::fs::read_to_string(&results)
        .unwrap()
        .lines()
        .map(|l| {
            let mut r = macrotree::sweep::resume::parse_line(l).unwrap();
            r.suite = Some(s(&secrets).to_string());
            r.to_jsonl() + "\n"
        })
        .collect();
    std::fs::write(&results, moved).unwrap();
    let out = macrotree(&["report", s(&results)]);
    assert_refused(&out, "outside the current folder");
    assert!(!stderr(&out).contains("hunter2"));
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 2.–5. Files written

#[test]
fn sweep_out_naming_the_scene_file_is_refused() {
    let dir = scratch("h3-out-scene");
    let scene = dir.join("s.yaml");
    std::fs::copy(repo().join("scenes/cube_bowl.yaml"), &scene).unwrap();
    let before = std::fs::read(&scene).unwrap();
    let out = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "2",
        "--scene",
        s(&scene),
        "--out",
        s(&scene),
        "--substitute",
        FREE,
    ]);
    assert_refused(&out, "it is an input of this command");
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    // A scenario file given to `test` is an input too.
    let suite = dir.join("suite.yaml");
    std::fs::write(
        &suite,
        format!(
            "tree: {}\ncount: 1\nsubstitute:\n  - {{pattern: \"main/**\", outcome: success}}\nexpect: {{outcome: success}}\n",
            repo().join(TREE).display()
        ),
    )
    .unwrap();
    let before = std::fs::read(&suite).unwrap();
    let out = macrotree(&["test", s(&suite), "--out", s(&suite)]);
    assert_refused(&out, "it is an input of this command");
    assert_eq!(std::fs::read(&suite).unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sweep_refused_for_a_bad_option_leaves_the_existing_out_untouched() {
    let dir = scratch("h3-out-untouched");
    let results = dir.join("r.jsonl");
    std::fs::write(&results, "earlier results\n").unwrap();
    let full = dir.join("full");
    std::fs::create_dir(&full).unwrap();
    std::fs::write(full.join("x"), "someone's file").unwrap();
    let ds = dir.join("ds");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--dataset", s(&full), "--cameras", "none"], "not empty"),
        (vec!["--dataset", s(&ds), "--cameras", "nosuch"], "--cameras"),
    ];
    for (extra, needle) in cases {
        let mut args = vec![
            "sweep",
            TREE,
            "--scenarios",
            "2",
            "--substitute",
            FREE,
            "--out",
            s(&results),
        ];
        args.extend(extra);
        let out = macrotree(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert_eq!(
            std::fs::read_to_string(&results).unwrap(),
            "earlier results\n",
            "{args:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_out_inside_the_overwritten_dataset_folder_is_refused() {
    let dir = scratch("h3-out-in-dataset");
    let ds = dir.join("ds");
    let args = |out: &Path| {
        vec![
            "sweep".to_string(),
            TREE.into(),
            "--scenarios".into(),
            "2".into(),
            "--substitute".into(),
            FREE.into(),
            "--goal".into(),
            "tree".into(),
            "--dataset".into(),
            s(&ds).into(),
            "--cameras".into(),
            "none".into(),
            "--overwrite".into(),
            "--out".into(),
            s(out).into(),
        ]
    };
    let a = args(&dir.join("first.jsonl"));
    let out = macrotree(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    for inside in [ds.join("results.jsonl"), dir.join("./ds/../ds/meta/r.jsonl")] {
        let a = args(&inside);
        let out = macrotree(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert_refused(&out, "is inside --dataset");
        assert!(ds.join("meta").is_dir(), "the dataset stays");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_outputs_of_one_command_naming_one_file_are_refused() {
    let dir = scratch("h3-same-outputs");
    let x = dir.join("x");
    std::fs::write(&x, "keep").unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&x, &link).unwrap();
    let same_spelled_twice = s(&dir.join("sub/../x")).to_string();
    std::fs::create_dir(dir.join("sub")).unwrap();
    for (a, b) in [
        ("--record", "--frames"),
        ("--video", "--frames"),
        ("--record", "--video"),
    ] {
        let out = macrotree(&[
            "run",
            TREE,
            "--substitute",
            FREE,
            a,
            s(&x),
            b,
            &same_spelled_twice,
        ]);
        assert_refused(&out, "name the same file");
    }
    let out = macrotree(&[
        "run",
        TREE,
        "--substitute",
        FREE,
        "--record",
        "-",
        "--frames",
        "/dev/stdout",
    ]);
    assert_refused(&out, "name the same file");
    let out = macrotree(&[
        "test",
        "scenarios/cube_to_bowl_grasp_never_works.yaml",
        "--junit",
        s(&x),
        "--out",
        s(&x),
    ]);
    assert_refused(&out, "name the same file");
    assert_eq!(std::fs::read_to_string(&x).unwrap(), "keep");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 6. One writer per output

#[test]
fn a_second_writer_of_one_sweep_out_is_refused() {
    let dir = scratch("h3-second-writer");
    let results = dir.join("r.jsonl");
    let long = [
        "sweep",
        TREE,
        "--scenarios",
        "400",
        "--jobs",
        "1",
        "--out",
        s(&results),
    ];
    let mut first = spawn(&long);
    wait_for("the first result line", || lines_of(&results) >= 1);
    let second = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "400",
        "--jobs",
        "1",
        "--out",
        s(&results),
    ]);
    assert_refused(&second, "being written by another process");
    let resumed = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "400",
        "--jobs",
        "1",
        "--out",
        s(&results),
        "--resume",
    ]);
    assert_refused(&resumed, "being written by another process");
    // Another process replaces the file under the first: it does not report success.
    std::fs::write(dir.join("other"), "x\n").unwrap();
    std::fs::rename(dir.join("other"), &results).unwrap();
    kill(&first, "-INT");
    let status = first.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sweep_whose_out_is_replaced_while_it_runs_exits_2() {
    let dir = scratch("h3-replaced");
    let results = dir.join("r.jsonl");
    let first = spawn(&[
        "sweep",
        TREE,
        "--scenarios",
        "40",
        "--jobs",
        "1",
        "--out",
        s(&results),
    ]);
    wait_for("the first result line", || lines_of(&results) >= 1);
    std::fs::write(dir.join("other"), "x\n").unwrap();
    std::fs::rename(dir.join("other"), &results).unwrap();
    let out = first.wait_with_output().unwrap();
    assert_refused(&out, "was replaced or removed by another process");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 7. Resume identity

fn small_sweep(tree: &Path, out: &Path, resume: bool) -> Output {
    let mut args = vec![
        "sweep",
        s(tree),
        "--scenarios",
        "6",
        "--substitute",
        "main/**/grasp=fail_first:1",
        "--out",
        s(out),
    ];
    if resume {
        args.push("--resume");
    }
    macrotree(&args)
}

#[test]
fn resume_after_the_tree_is_edited_is_refused() {
    let dir = scratch("h3-resume-edited-tree");
    let tree = tree_copy(&dir);
    let results = dir.join("r.jsonl");
    let out = small_sweep(&tree, &results, false);
    assert!(
        out.status.code() == Some(0) || out.status.code() == Some(1),
        "{}",
        stderr(&out)
    );
    let text = std::fs::read_to_string(&results).unwrap();
    let first_two: String = text.lines().take(2).map(|l| format!("{l}\n")).collect();
    std::fs::write(&results, &first_two).unwrap();
    // The interrupted file resumes with the tree unchanged …
    let out = small_sweep(&tree, &results, true);
    assert_ne!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&results).unwrap(), text);
    // … and is refused once the tree changed (attempts: 3 → 2).
    std::fs::write(&results, &first_two).unwrap();
    let edited = std::fs::read_to_string(&tree)
        .unwrap()
        .replace("attempts: 3", "attempts: 2");
    std::fs::write(&tree, edited).unwrap();
    let out = small_sweep(&tree, &results, true);
    assert_refused(&out, "the tree, a file it includes or the scene changed");
    assert_eq!(std::fs::read_to_string(&results).unwrap(), first_two);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn resume_of_a_file_with_an_edited_middle_line_is_refused() {
    let dir = scratch("h3-resume-edited-line");
    let tree = tree_copy(&dir);
    let results = dir.join("r.jsonl");
    small_sweep(&tree, &results, false);
    let text = std::fs::read_to_string(&results).unwrap();
    let mut lines: Vec<String> = text.lines().take(4).map(str::to_string).collect();
    assert!(lines[1].contains("\"success\":true") || lines[1].contains("\"success\":false"));
    lines[1] = if lines[1].contains("\"success\":true") {
        lines[1].replacen("\"success\":true", "\"success\":false", 1)
    } else {
        lines[1].replacen("\"success\":false", "\"success\":true", 1)
    };
    std::fs::write(&results, lines.join("\n") + "\n").unwrap();
    let out = small_sweep(&tree, &results, true);
    assert_refused(&out, "line 2 is not a result of this sweep");
    assert!(stderr(&out).contains("checksum"), "{}", stderr(&out));
    // Lines of an earlier version (no digest, no checksum) are refused with what to do.
    let old: String = text
        .lines()
        .take(3)
        .map(|l| {
            let cut = l.find(",\"tree_digest\"").unwrap();
            format!("{}}}\n", &l[..cut])
        })
        .collect();
    std::fs::write(&results, old).unwrap();
    let out = small_sweep(&tree, &results, true);
    assert_refused(&out, "earlier version of macrotree");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 8.–9. Clips and ffmpeg

#[test]
fn a_link_planted_at_a_clip_path_is_never_written_through() {
    let dir = scratch("h3-clip-link");
    let target = dir.join("victim.txt");
    std::fs::write(&target, "precious").unwrap();
    let clip = dir.join("scenario-0-camera-0.mp4");
    std::os::unix::fs::symlink(&target, &clip).unwrap();
    let size: macrotree::render::FrameSize = "64x48".parse().unwrap();
    let started = macrotree::video::VideoEncoder::start(&clip, size, 10);
    assert!(started.is_err(), "a link at the clip path is refused");
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    // A hard link to another file, or a file already there, is refused too.
    let hard = dir.join("hard.mp4");
    std::fs::hard_link(&target, &hard).unwrap();
    assert!(macrotree::video::VideoEncoder::start(&hard, size, 10).is_err());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    // A new path is written.
    let fresh = dir.join("fresh.mp4");
    let mut enc = macrotree::video::VideoEncoder::start(&fresh, size, 10).unwrap();
    for _ in 0..3 {
        enc.push(&vec![128u8; size.rgb_bytes()]).unwrap();
    }
    assert_eq!(enc.finish().unwrap(), 3);
    assert!(std::fs::metadata(&fresh).unwrap().len() > 100);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_video_path_like_an_ffmpeg_option_or_a_url_is_written_as_a_file() {
    let dir = scratch("h3-video-names");
    std::fs::create_dir_all(dir.join("-d")).unwrap();
    std::fs::create_dir_all(dir.join("http:/127.0.0.1:9")).unwrap();
    let tree = repo().join(TREE);
    for path in ["-d/v.mp4", "http://127.0.0.1:9/v.mp4"] {
        let out = macrotree_in(
            &dir,
            &[
                "run",
                s(&tree),
                "--substitute",
                FREE,
                "--goal",
                "tree",
                "--size",
                "64x48",
                &format!("--video={path}"),
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{path}: {}", stderr(&out));
        let written = dir.join(path.replace("//", "/"));
        assert!(
            std::fs::metadata(&written).is_ok_and(|m| m.is_file() && m.len() > 100),
            "{path}: {}",
            written.display()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 10.–11. Bounded memory, capped failure lists

#[test]
fn a_sweep_tally_stays_bounded_however_many_scenarios_it_sums() {
    use macrotree::sweep::tally::{MAX_FAILURES_KEPT, MAX_GROUP_INDICES, Tally};
    let config = macrotree::sweep::SweepConfig {
        scenarios: 200_000,
        ..Default::default()
    };
    let dir = scratch("h3-tally");
    let tree = tree_copy(&dir);
    let out = dir.join("r.jsonl");
    // Real lines: one failing and one succeeding scenario, summed many times over.
    let made = macrotree(&[
        "sweep",
        s(&tree),
        "--scenarios",
        "2",
        "--substitute",
        "main/**/home#1=fail_first:1",
        "--out",
        s(&out),
    ]);
    assert_ne!(made.status.code(), Some(2), "{}", stderr(&made));
    let text = std::fs::read_to_string(&out).unwrap();
    let line = text.lines().next().unwrap();
    let template = macrotree::sweep::resume::parse_line(line).unwrap();
    let mut tally = Tally::new("t.yaml", &config);
    let mut failures = 0u64;
    for i in 0..200_000u64 {
        let mut r = template.clone();
        r.index = i;
        r.outcome.success = i % 3 != 0;
        failures += u64::from(!r.outcome.success);
        r.outcome.sim_time_s = (i % 500) as f64 * 0.004;
        tally.add(&r);
    }
    let summary = tally.finish(1.0, 1);
    assert_eq!(summary.scenarios, 200_000);
    assert_eq!(summary.failures.len(), MAX_FAILURES_KEPT);
    assert_eq!(summary.failures_not_listed, failures - MAX_FAILURES_KEPT as u64);
    assert!(
        summary
            .failure_groups
            .iter()
            .all(|g| g.indices.len() <= MAX_GROUP_INDICES)
    );
    assert_eq!(
        summary.failure_groups.iter().map(|g| g.count).sum::<u64>(),
        failures
    );
    // Exact nearest-rank order statistics.
    let mut times: Vec<f64> = (0..200_000u64).map(|i| (i % 500) as f64 * 0.004).collect();
    times.sort_by(f64::total_cmp);
    assert_eq!(
        summary.median_sim_time_s,
        macrotree::sweep::percentile(&times, 0.5)
    );
    assert_eq!(summary.p95_sim_time_s, macrotree::sweep::percentile(&times, 0.95));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_slow_scenario_does_not_let_results_pile_up_behind_it() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let scene = macrotree::sim::Scene::load().unwrap();
    let plan = std::sync::Arc::new(
        macrotree::plan::Loader::default()
            .load(&repo().join(TREE))
            .unwrap(),
    );
    let config = macrotree::sweep::SweepConfig {
        scenarios: 5000,
        jobs: 2,
        goal: macrotree::episode::Goal::Tree,
        substitutions: vec![FREE.parse().unwrap()],
        ..Default::default()
    };
    let first_done = AtomicBool::new(false);
    let started_meanwhile = AtomicUsize::new(0);
    let mut delivered = 0u64;
    let run = macrotree::sweep::run_sweep_streaming(
        &scene,
        &config,
        0,
        |cell, index| {
            if index == 0 {
                // Scenario 0 is slow: it waits until the others would have run far ahead.
                std::thread::sleep(Duration::from_millis(1500));
                first_done.store(true, Ordering::SeqCst);
            } else if !first_done.load(Ordering::SeqCst) {
                started_meanwhile.fetch_add(1, Ordering::SeqCst);
            }
            (
                macrotree::sweep::run_scenario(
                    cell,
                    &plan,
                    &macrotree::factory::Factory::builtin(),
                    &config,
                    index,
                    &mut macrotree::episode::NoObserver,
                ),
                (),
            )
        },
        |r, _| {
            assert_eq!(r.index, delivered, "in scenario order");
            delivered += 1;
            std::ops::ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert_eq!(delivered, 5000);
    assert!(run.results.is_empty(), "a streaming sweep keeps no result");
    let ahead = started_meanwhile.load(Ordering::SeqCst);
    assert!(
        ahead <= macrotree::sweep::REORDER_WINDOW,
        "{ahead} scenarios started while scenario 0 ran"
    );
    assert!(ahead > 10, "the other worker did run ahead ({ahead})");
}

/// Peak resident memory of `macrotree ARGS…`, KiB, through `/usr/bin/time -f %M`.
fn peak_rss_kib(args: &[&str]) -> u64 {
    let out = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("PEAK %M")
        .arg(BIN)
        .args(args)
        .current_dir(repo())
        .stdout(Stdio::null())
        .output()
        .expect("/usr/bin/time (GNU time) runs: it measures the peak memory");
    let err = stderr(&out);
    assert!(
        out.status.code() == Some(0) || out.status.code() == Some(1),
        "{err}"
    );
    err.lines()
        .find_map(|l| l.strip_prefix("PEAK "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("no peak in {err}"))
}

#[test]
fn sweep_memory_does_not_grow_with_the_scenario_count() {
    let dir = scratch("h3-rss");
    let out = dir.join("r.jsonl");
    let run = |n: &str, resume: bool| {
        let mut args = vec![
            "sweep",
            TREE,
            "--scenarios",
            n,
            "--substitute",
            FAILING,
            "--out",
            s(&out),
        ];
        if resume {
            args.push("--resume");
        }
        peak_rss_kib(&args)
    };
    let small = run("2000", false);
    let big = run("40000", false);
    // The earlier version needed about 4.4 KB per scenario: 170 MB more here.
    assert!(
        big < small + 40_000,
        "peak RSS {small} KiB at 2000 scenarios, {big} KiB at 40000"
    );
    // Resuming the big file reads it one line at a time.
    let len = std::fs::metadata(&out).unwrap().len();
    let f = std::fs::OpenOptions::new().write(true).open(&out).unwrap();
    f.set_len(len / 2).unwrap();
    let resumed = run("40000", true);
    assert!(resumed < small + 40_000, "peak RSS {resumed} KiB resuming 40000");
    assert_eq!(lines_of(&out), 40_000);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_summaries_list_at_most_20_failures_and_say_how_many_more() {
    let dir = scratch("h3-failure-cap");
    let out_file = dir.join("r.jsonl");
    let out = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "60",
        "--substitute",
        FAILING,
        "--out",
        s(&out_file),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    // With --json the text summary is on stderr and stdout holds only the JSON.
    let text = stderr(&out);
    assert!(text.contains("failures (60):"), "{text}");
    assert!(text.contains("… and 40 more"), "{text}");
    assert_eq!(text.matches("\n    #").count(), 20, "{text}");
    let json: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(json["failures"].as_array().unwrap().len(), 60);
    assert_eq!(lines_of(&out_file), 60, "the JSONL keeps every one");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 12. Range checks

#[test]
fn sweep_jobs_and_bench_repeat_are_range_checked() {
    let out = macrotree(&["sweep", TREE, "--scenarios", "1", "--jobs", "100000"]);
    assert_refused(&out, "between 1 and 1024");
    let out = macrotree(&["test", "--jobs", "5000"]);
    assert_eq!(out.status.code(), Some(2));
    let out = macrotree(&["bench", TREE, "--repeat", "1000000000000"]);
    assert_refused(&out, "between 1 and 1000");
    let out = macrotree(&["bench", TREE, "--repeat", "0"]);
    assert_refused(&out, "between 1 and 1000");
}

// ---------------------------------------------------------------------------------------------
// 13. Model cache bound

#[test]
fn the_model_cache_evicts_the_least_recently_used_and_removes_stale_temporaries() {
    use macrotree::sim::{MAX_MODELS, evict};
    let dir = scratch("h3-cache");
    let t0 = std::time::SystemTime::now() - Duration::from_secs(10_000);
    let mut paths = Vec::new();
    for i in 0..MAX_MODELS + 4 {
        let p = dir.join(format!("model-{i:040x}.mjb"));
        std::fs::write(&p, vec![0u8; 1000]).unwrap();
        let f = std::fs::File::options().write(true).open(&p).unwrap();
        f.set_modified(t0 + Duration::from_secs(i as u64 * 10)).unwrap();
        paths.push(p);
    }
    // The oldest model was used a moment ago: it stays.
    let f = std::fs::File::options().write(true).open(&paths[0]).unwrap();
    f.set_modified(std::time::SystemTime::now()).unwrap();
    let stale = dir.join(".model-abc.mjb.0123456789abcdef.tmp");
    std::fs::write(&stale, "half a model").unwrap();
    age(&stale, 60);
    let live = dir.join(".model-def.mjb.fedcba9876543210.tmp");
    std::fs::write(&live, "being written").unwrap();
    age(&live, 60);
    // One just created (its writer may not have locked it yet) is kept too.
    let fresh = dir.join(".model-fed.mjb.0000000000000001.tmp");
    std::fs::write(&fresh, "just created").unwrap();
    let held = std::fs::File::open(&live).unwrap();
    held.try_lock().unwrap();
    let keep = paths.last().unwrap().clone();
    let removed = evict(&dir, &keep);
    assert_eq!(removed.len(), 4, "{removed:?}");
    for p in &paths[1..5] {
        assert!(!p.exists(), "{} (least recently used) is evicted", p.display());
    }
    assert!(paths[0].exists() && keep.exists());
    assert!(
        !stale.exists(),
        "a temporary file of a writer that is gone is removed"
    );
    assert!(live.exists(), "a temporary file being written is kept");
    assert!(
        fresh.exists(),
        "a temporary file younger than the minimum age is kept"
    );
    drop(held);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// 14. Signals

#[test]
fn sigint_and_sigterm_remove_temporaries_and_staging_and_leave_out_resumable() {
    for (sig, code) in [("-INT", 130), ("-TERM", 143)] {
        let dir = scratch(&format!("h3-signal{sig}"));
        let results = dir.join("r.jsonl");
        let ds = dir.join("ds");
        // Leftovers of an earlier run killed with -9 (nobody holds their locks), a minute old.
        let stale_file = dir.join(".r.jsonl.00000000deadbeef.tmp");
        std::fs::write(&stale_file, "stale").unwrap();
        let stale_dir = dir.join(".ds.00000000deadbeef.partial");
        std::fs::create_dir(&stale_dir).unwrap();
        for p in [&stale_file, &stale_dir] {
            age(p, 60);
        }
        let mut child = spawn(&[
            "sweep",
            TREE,
            "--scenarios",
            "400",
            "--jobs",
            "1",
            "--out",
            s(&results),
            "--dataset",
            s(&ds),
            "--cameras",
            "none",
        ]);
        wait_for("two result lines", || lines_of(&results) >= 2);
        let staged = hidden_entries(&dir);
        assert_eq!(staged.len(), 1, "only this run's staging folder: {staged:?}");
        assert!(staged[0].starts_with(".ds.") && staged[0].ends_with(".partial"));
        kill(&child, sig);
        let status = child.wait().unwrap();
        let mut err = String::new();
        std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
        assert_eq!(status.code(), Some(code), "{err}");
        assert!(err.contains("stopped by SIG"), "{err}");
        assert_eq!(
            hidden_entries(&dir),
            Vec::<String>::new(),
            "no temporary file or staging left"
        );
        assert!(!ds.exists(), "no half dataset");
        // The results resume.
        let kept = lines_of(&results);
        assert!(kept >= 2);
        let resumed = spawn(&[
            "sweep",
            TREE,
            "--scenarios",
            "400",
            "--jobs",
            "1",
            "--out",
            s(&results),
            "--resume",
        ]);
        wait_for("a resumed line", || lines_of(&results) > kept);
        kill(&resumed, "-TERM");
        let out = resumed.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(143), "{}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!("resuming {}: {kept} of 400", results.display())),
            "{}",
            stderr(&out)
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

// ---------------------------------------------------------------------------------------------
// 15.–17. Diagnostics

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_scene_without_a_block_is_refused_by_validate_and_run_alike_located() {
    let dir = scratch("h3-no-block");
    let scene = write(
        &dir,
        "empty.yaml",
        "description: a bowl alone\nobjects:\n  bowl:\n    container: {inner: [0.15, 0.15], wall_height: 0.06}\n    pose: [0.45, 0.08]\n",
    );
    let validate = macrotree(&["validate", s(&scene)]);
    assert_refused(&validate, "has no block");
    assert!(
        stderr(&validate).contains("empty.yaml:2:"),
        "{}",
        stderr(&validate)
    );
    let run = macrotree(&["run", "trees/place_on_table.yaml", "--scene", s(&scene)]);
    assert_refused(&run, "has no block");
    assert!(stderr(&run).contains("empty.yaml:2:"), "{}", stderr(&run));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn goals_that_can_never_hold_are_refused_at_load_located() {
    let dir = scratch("h3-impossible-goals");
    let blocks = "objects:\n  a:\n    block: {size: 0.04}\n    pose: [0.45, -0.2]\n  b:\n    block: {size: 0.04}\n    pose: [0.45, 0.0]\n  c:\n    block: {size: 0.04}\n    pose: [0.45, 0.2]\n";
    let cycle = write(
        &dir,
        "cycle.yaml",
        &format!("{blocks}goal:\n  - on: {{object: a, support: b}}\n  - on: {{object: b, support: a}}\n"),
    );
    let out = macrotree(&["validate", s(&cycle)]);
    assert_refused(&out, "the `on` goals form a cycle");
    assert!(stderr(&out).contains("cycle.yaml:12:"), "{}", stderr(&out));
    let three = write(
        &dir,
        "cycle3.yaml",
        &format!("{blocks}goal:\n  - stack: [a, b, c]\n  - on: {{object: c, support: a}}\n"),
    );
    assert_refused(&macrotree(&["validate", s(&three)]), "a on b on c on a");
    let wide = write(
        &dir,
        "wide.yaml",
        "objects:\n  big:\n    block: {size: 0.07}\n    pose: [0.45, -0.2]\n  bin:\n    container: {inner: [0.06, 0.1], wall_height: 0.06}\n    pose: [0.45, 0.1]\ngoal:\n  - in: {object: big, container: bin}\n",
    );
    let out = macrotree(&["validate", s(&wide)]);
    assert_refused(&out, "does not fit inside container `bin`");
    assert!(stderr(&out).contains("wide.yaml:9:"), "{}", stderr(&out));
    // The shipped scenes all pass.
    for scene in [
        "scenes/cube_bowl.yaml",
        "scenes/clear_table.yaml",
        "scenes/sort_three.yaml",
        "scenes/stack_three.yaml",
    ] {
        let out = macrotree(&["validate", scene]);
        assert_eq!(out.status.code(), Some(0), "{scene}: {}", stderr(&out));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_misspelled_expect_failure_kind_is_refused_with_a_suggestion() {
    let dir = scratch("h3-failure-kind");
    let suite = write(
        &dir,
        "s.yaml",
        &format!(
            "tree: {}\ncount: 2\nsubstitute:\n  - {{pattern: \"main/**/grasp\", outcome: \"failure\"}}\nexpect:\n  outcome: failure\n  failure_kind: substitued\n",
            repo().join(TREE).display()
        ),
    );
    let out = macrotree(&["test", s(&suite)]);
    assert_refused(&out, "unknown failure kind `substitued`");
    assert!(stderr(&out).contains("s.yaml:7:"), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("substituted"),
        "did you mean: {}",
        stderr(&out)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
