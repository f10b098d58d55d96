//! What a newcomer tripped on, round 2 (issue 22): pure JSON on stdout, JUnit names that do not
//! depend on the checkout, count expectations, what `failed_node` is, the grasp histogram with
//! substitutions, named subtree calls, and the stock `validate` on a custom node kind. Real
//! physics throughout (small runs).

use crate::support::cli;

use std::path::Path;

use cli::{macrotree, s, scratch};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const TREE: &str = "trees/cube_to_bowl.yaml";
const PICK_GRASP: &str = "main/**/subtree[pick]/**/grasp";

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The whole of stdout as one JSON document (fails on anything before or after it).
fn whole_stdout_json(what: &str, out: &std::process::Output) -> serde_json::Value {
    let text = stdout(out);
    serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{what} --json: stdout is not exactly one JSON document ({e}):\n{text}"))
}

#[test]
fn json_flag_leaves_stdout_to_the_json_alone() {
    let dir = scratch("round2-json");
    let out_file = dir.join("sweep.jsonl");

    let run = macrotree(&["run", TREE, "--json"]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let v = whole_stdout_json("run", &run);
    assert_eq!(v["success"], true);
    // The summary for people is still there, on stderr.
    assert!(stderr(&run).contains("SUCCESS: tree success"), "{}", stderr(&run));

    let sweep = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "2",
        "--seed",
        "1",
        "-j",
        "1",
        "--out",
        s(&out_file),
        "--json",
    ]);
    assert!(sweep.status.code().is_some_and(|c| c < 2), "{}", stderr(&sweep));
    let v = whole_stdout_json("sweep", &sweep);
    assert_eq!(v["scenarios"], 2);
    assert!(stderr(&sweep).contains("grasp attempts"), "{}", stderr(&sweep));

    let report = macrotree(&["report", s(&out_file), "--json"]);
    assert!(report.status.code().is_some_and(|c| c < 2), "{}", stderr(&report));
    assert_eq!(whole_stdout_json("report", &report)["scenarios"], 2);

    let test = macrotree(&[
        "test",
        "tests/fixtures/scenarios/pass/never_works.yaml",
        "-j",
        "1",
        "--json",
    ]);
    assert_eq!(test.status.code(), Some(0), "{}", stderr(&test));
    let v = whole_stdout_json("test", &test);
    assert_eq!(v["passed"], true);
    assert!(
        stderr(&test).contains("1 of 1 scenario file(s) passed"),
        "{}",
        stderr(&test)
    );

    let bench = macrotree(&["bench", TREE, "--repeat", "1", "--json"]);
    assert_eq!(bench.status.code(), Some(0), "{}", stderr(&bench));
    let v = whole_stdout_json("bench", &bench);
    assert!(v["ratio"].as_f64().is_some_and(|r| r > 0.0), "{v}");
    assert!(
        stderr(&bench).contains("replay (bare mj_step)"),
        "{}",
        stderr(&bench)
    );

    // Without --json the text stays on stdout.
    let plain = macrotree(&["run", TREE]);
    assert!(
        stdout(&plain).starts_with("SUCCESS: tree success"),
        "{}",
        stdout(&plain)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `name` attribute of every `<testcase>` of a JUnit file.
fn testcase_names(xml: &str) -> Vec<String> {
    xml.split("<testcase ")
        .skip(1)
        .map(|t| {
            let at = t.find(" name=\"").expect("a name attribute") + 7;
            t[at..at + t[at..].find('"').unwrap()].to_string()
        })
        .collect()
}

#[test]
fn junit_testcase_names_are_relative_to_the_suite_not_absolute_paths() {
    let dir = scratch("round2-junit");
    let (xml, jsonl, merged) = (dir.join("a.xml"), dir.join("a.jsonl"), dir.join("m.xml"));
    // The suite folder given by an absolute path, as a CI checkout in some build folder would.
    let suite = Path::new(ROOT).join("tests/fixtures/scenarios/pass");
    let out = macrotree(&[
        "test",
        s(&suite),
        "-j",
        "2",
        "--junit",
        s(&xml),
        "--out",
        s(&jsonl),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let names = testcase_names(&std::fs::read_to_string(&xml).unwrap());
    assert_eq!(names, ["grasp_fails_once.yaml", "never_works.yaml"]);
    // The merged report of the same results names them the same way.
    let out = macrotree(&["report", s(&jsonl), "--junit", s(&merged)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(testcase_names(&std::fs::read_to_string(&merged).unwrap()), names);
    // A file given by itself: its file name.
    let one = suite.join("never_works.yaml");
    let out = macrotree(&["test", s(&one), "-j", "2", "--junit", s(&xml)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(
        testcase_names(&std::fs::read_to_string(&xml).unwrap()),
        ["never_works.yaml"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes a scenario file over the flagship tree whose pick's grasp fails once in each of 3
/// scenarios, with `expect` (YAML lines under `expect:`).
fn grasp_fails_once_suite(dir: &Path, name: &str, expect: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    let tree = Path::new(ROOT).join(TREE);
    std::fs::write(
        &path,
        format!(
            "tree: {}\ncount: 3\nseed: 3\nsubstitute:\n  - {{pattern: \"{PICK_GRASP}\", outcome: \"fail_first:1\"}}\nexpect:\n{expect}",
            tree.display()
        ),
    )
    .unwrap();
    path
}

#[test]
fn count_expectations_on_node_failures_are_checked() {
    let dir = scratch("round2-counts");
    // Each scenario: the grasp runs twice (the substituted failure, then the real one) and fails
    // once; over the 3 scenarios it fails exactly 3 times.
    let good = grasp_fails_once_suite(
        &dir,
        "good.yaml",
        &format!(
            "  counts:\n    - {{node: \"{PICK_GRASP}\", ran: {{exactly: 2}}, per: scenario}}\n    - {{node: \"{PICK_GRASP}\", failed: {{exactly: 3}}}}\n    - {{node: \"main/**/carry\", ran: {{at_least: 1, at_most: 2}}, per: scenario}}\n"
        ),
    );
    let out = macrotree(&["test", s(&good), "-j", "2", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = whole_stdout_json("test", &out);
    let checks = v["suites"][0]["checks"].as_array().unwrap();
    let find = |text: &str| {
        checks
            .iter()
            .find(|c| c["expectation"].as_str().unwrap().contains(text))
            .unwrap_or_else(|| panic!("no check {text:?} in {checks:?}"))
    };
    let per_scenario = find("ran exactly 2 time(s) in every scenario");
    assert_eq!(per_scenario["ok"], true);
    assert_eq!(per_scenario["measured"], "2 in each of 3");
    let total = find("failed exactly 3 time(s) over the suite");
    assert_eq!(
        (total["ok"].as_bool(), total["measured"].as_str()),
        (Some(true), Some("3"))
    );

    // The same suite with counts that do not hold: exit 1, what was measured, and the offending
    // scenarios' reproduce commands.
    let bad = grasp_fails_once_suite(
        &dir,
        "bad.yaml",
        &format!(
            "  counts:\n    - {{node: \"{PICK_GRASP}\", ran: {{exactly: 1}}, per: scenario}}\n    - {{node: \"{PICK_GRASP}\", failed: {{at_most: 2}}}}\n"
        ),
    );
    let out = macrotree(&["test", s(&bad), "-j", "2"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("FAIL `main/**/subtree[pick]/**/grasp` ran exactly 1 time(s) in every scenario: 3 scenario(s) outside: #0: 2, #1: 2, #2: 2"),
        "{text}"
    );
    assert!(
        text.contains("FAIL `main/**/subtree[pick]/**/grasp` failed at most 2 time(s) over the suite: 3"),
        "{text}"
    );
    assert_eq!(
        text.matches(" run ").count(),
        3,
        "one reproduce command per scenario: {text}"
    );

    // One shard cannot judge a suite total; the merged report does.
    let (a, b) = (dir.join("a.jsonl"), dir.join("b.jsonl"));
    for (k, f) in [("0/2", &a), ("1/2", &b)] {
        let out = macrotree(&["test", s(&good), "-j", "1", "--shard", k, "--out", s(f)]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        assert!(stdout(&out).contains("in this shard (the merged report judges the total)"));
    }
    // The suite lies outside the current folder: `report` reads it back only when allowed.
    let out = macrotree(&["report", s(&a), s(&b), "--allow-include-outside"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out)
            .contains("ok   `main/**/subtree[pick]/**/grasp` failed exactly 3 time(s) over the suite: 3"),
        "{}",
        stdout(&out)
    );

    // Bad counts are located errors (exit 2), nothing runs.
    for (expect, at, what) in [
        (
            "  counts:\n    - {node: \"main/**/carry\", ran: {exactly: 1, at_least: 1}}\n",
            "bad_count.yaml:8:36",
            "`exactly` goes alone",
        ),
        (
            "  counts:\n    - {node: \"main/**/carry\", failed: {at_least: 3, at_most: 2}}\n",
            "bad_count.yaml:8:39",
            "`at_least` (3) is more than `at_most` (2)",
        ),
        (
            "  counts:\n    - {node: \"main/**/carry\"}\n",
            "bad_count.yaml:8:14",
            "give `ran: {…}` or `failed: {…}`",
        ),
        (
            "  counts:\n    - {node: \"main/**/carry\", ran: {exactly: -1}}\n",
            "bad_count.yaml:8",
            "-1",
        ),
        // A count glob that matches no node is located at its `node:`.
        (
            "  counts:\n    - {node: \"main/**/cary\", ran: {exactly: 1}}\n",
            "bad_count.yaml:8:14",
            "matches no node",
        ),
    ] {
        let f = grasp_fails_once_suite(&dir, "bad_count.yaml", expect);
        let out = macrotree(&["test", s(&f)]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{expect}: {err}");
        assert!(err.contains(at) && err.contains(what), "{expect}: {err}");
        assert!(!stdout(&out).contains("PASS") && !stdout(&out).contains("FAIL"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failed_node_is_the_leaf_where_the_failure_started() {
    // The grasp never works: the retry gives up after 3 attempts and the episode ends there, but
    // `failed_node` is the leaf where the failure started.
    let out = macrotree(&["run", TREE, "--substitute", "main/**/grasp=failure", "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v = whole_stdout_json("run", &out);
    let node = v["failed_node"].as_str().unwrap();
    assert!(node.ends_with("/subtree[pick]/sequence[pick]/grasp"), "{node}");
    assert!(
        v["failure_reason"]
            .as_str()
            .unwrap()
            .starts_with("all 3 attempts failed"),
        "{v}"
    );
    let doc = std::fs::read_to_string(Path::new(ROOT).join("docs/testing_trees.md")).unwrap();
    assert!(doc.contains("**leaf where the failure started**"));
    assert!(!doc.contains("the node whose failure ended it"));
}

#[test]
fn the_grasp_histogram_counts_only_physical_grasps_and_says_so() {
    let out = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "2",
        "--seed",
        "3",
        "-j",
        "1",
        "--substitute",
        &format!("{PICK_GRASP}=fail_first:1"),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = whole_stdout_json("sweep", &out);
    // One physical grasp per scenario; the grasp node ran twice (the substituted one counts there).
    assert_eq!(v["attempts_histogram"]["1"], 2, "{v}");
    let grasp = v["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| {
            n["path"]
                .as_str()
                .unwrap()
                .ends_with("/subtree[pick]/sequence[pick]/grasp")
        })
        .unwrap();
    assert_eq!(grasp["activations"], 4, "{grasp}");
    // The text says which grasps the histogram counts.
    assert!(
        stderr(&out).contains(
            "grasp attempts (physical only; grasps answered by a substitution are not counted): 1: 2"
        ),
        "{}",
        stderr(&out)
    );
    // Without substitutions the label is unchanged.
    let plain = macrotree(&["sweep", TREE, "--scenarios", "1", "-j", "1"]);
    assert!(
        stdout(&plain).contains("  grasp attempts: 1: 1"),
        "{}",
        stdout(&plain)
    );
}

#[test]
fn tree_format_read_as_if_a_subtree_call_could_not_be_named() {
    let dir = scratch("round2-subtree-names");
    let tree = dir.join("t.yaml");
    std::fs::write(
        &tree,
        "main:\n  sequence:\n    children:\n      - subtree: {ref: p, name: first pick}\n      - subtree: {ref: p}\n      - subtree: {ref: p}\nsubtrees:\n  p:\n    root: {sequence: {children: [{home: {}}]}}\n",
    )
    .unwrap();
    let out = macrotree(&["run", s(&tree), "--goal", "tree", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v = whole_stdout_json("run", &out);
    let paths: Vec<&str> = v["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["path"].as_str().unwrap())
        .filter(|p| p.matches('/').count() == 2)
        .collect();
    assert_eq!(
        paths,
        [
            "main/sequence/subtree[first pick]",
            "main/sequence/subtree[p]#1",
            "main/sequence/subtree[p]#2"
        ]
    );
    let doc = std::fs::read_to_string(Path::new(ROOT).join("docs/tree_format.md")).unwrap();
    assert!(doc.contains("`subtree: {ref: pick, name: first pick}` is `subtree[first pick]`"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn stock_validate_says_a_custom_kind_is_validated_by_its_program() {
    let dir = scratch("round2-custom-kind");
    let tree = dir.join("t.yaml");
    std::fs::write(
        &tree,
        "main:\n  sequence:\n    children:\n      - home: {}\n      - upright: {object: cube}\n",
    )
    .unwrap();
    let out = macrotree(&["validate", s(&tree)]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("t.yaml:5:9") && err.contains("unknown node kind `upright`"),
        "{err}"
    );
    assert!(
        err.contains(
            "a node kind registered by your own program (docs/custom_nodes.md) is validated with that program"
        ),
        "{err}"
    );
    // A near miss of a built-in kind gets the suggestion, not the note.
    std::fs::write(&tree, "main: {grasp_: {}}\n").unwrap();
    let err = stderr(&macrotree(&["validate", s(&tree)]));
    assert!(err.contains("did you mean"), "{err}");
    assert!(!err.contains("your own program"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
