//! `macrotree test` and `macrotree report` end to end on real physics: scenario files with
//! substitutions and expectations, exit codes, JUnit XML, JSONL, located errors, the committed
//! JSON Schema, and shards run as separate processes whose merged report equals the unsharded one.

use crate::support::cli;

use std::path::{Path, PathBuf};

use cli::{BIN, macrotree, results_only, s, scratch, text_without_timings};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const SCHEMA: &str = "schema/scenario.schema.json";
const PASS: &str = "tests/fixtures/scenarios/pass";
const FAIL: &str = "tests/fixtures/scenarios/fail";
const TREE: &str = "trees/cube_to_bowl.yaml";

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn last_json(out: &std::process::Output) -> serde_json::Value {
    let text = stdout(out);
    serde_json::from_str(text.lines().last().unwrap()).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// A small well-formedness and shape check of JUnit XML: every tag closes in order, attribute
/// values are quoted, entities are the five XML ones, the root is `<testsuites>` holding
/// `<testsuite>`s holding `<testcase>`s (with `failure` / `system-out` children), and the
/// counts in the attributes match the elements. Returns (testcases, failures, failure texts).
fn check_junit(xml: &str) -> (usize, usize, Vec<String>) {
    assert!(
        xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"),
        "{xml}"
    );
    let body = &xml[xml.find("?>").unwrap() + 2..];
    let mut stack: Vec<String> = Vec::new();
    let (mut cases, mut failures) = (0, 0);
    let mut texts = Vec::new();
    let mut declared = None;
    let mut rest = body;
    let mut text_start = None::<usize>;
    let allowed_parent = |tag: &str| -> &[&str] {
        match tag {
            "testsuites" => &[""],
            "testsuite" => &["testsuites"],
            "testcase" => &["testsuite"],
            "failure" | "system-out" => &["testcase"],
            other => panic!("unexpected element <{other}>"),
        }
    };
    while let Some(open) = rest.find('<') {
        let text = &rest[..open];
        for (i, _) in text.match_indices('&') {
            let ent = &text[i..];
            assert!(
                ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                    .iter()
                    .any(|e| ent.starts_with(e)),
                "bad entity in {ent:.20}"
            );
        }
        if let Some(_start) = text_start.take() {
            texts.push(
                text.replace("&lt;", "<")
                    .replace("&gt;", ">")
                    .replace("&apos;", "'")
                    .replace("&quot;", "\"")
                    .replace("&amp;", "&"),
            );
        }
        let close = rest[open..].find('>').expect("tag closes") + open;
        let tag = &rest[open + 1..close];
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name), "mismatched </{name}>");
        } else {
            let self_closing = tag.ends_with('/');
            let tag = tag.trim_end_matches('/');
            let name = tag.split_whitespace().next().unwrap();
            let attrs = &tag[name.len()..];
            // Attributes: name="value" pairs, values without raw < or ".
            let mut a = attrs.trim();
            let mut map = std::collections::HashMap::new();
            while !a.is_empty() {
                let eq = a.find("=\"").expect("quoted attribute");
                let key = a[..eq].trim();
                let end = a[eq + 2..].find('"').unwrap() + eq + 2;
                let value = &a[eq + 2..end];
                assert!(!value.contains('<'), "raw < in attribute");
                map.insert(key.to_string(), value.to_string());
                a = a[end + 1..].trim_start();
            }
            let parent = stack.last().map_or("", String::as_str);
            assert!(
                allowed_parent(name).contains(&parent),
                "<{name}> inside <{parent}>"
            );
            match name {
                "testsuite" => {
                    declared = Some((
                        map["tests"].parse::<usize>().unwrap(),
                        map["failures"].parse::<usize>().unwrap(),
                    ));
                    assert!(map.contains_key("name") && map.contains_key("time"));
                }
                "testcase" => {
                    cases += 1;
                    assert!(
                        map.contains_key("name")
                            && map.contains_key("classname")
                            && map["time"].parse::<f64>().is_ok()
                    );
                }
                "failure" => {
                    failures += 1;
                    assert!(map.contains_key("message") && map.contains_key("type"));
                    text_start = Some(0);
                }
                _ => {}
            }
            if !self_closing {
                stack.push(name.to_string());
            }
        }
        rest = &rest[close + 1..];
    }
    assert!(stack.is_empty(), "unclosed {stack:?}");
    assert_eq!(rest.trim(), "");
    assert_eq!(
        declared,
        Some((cases, failures)),
        "counts in <testsuite> disagree with its elements"
    );
    (cases, failures, texts)
}

#[test]
fn the_committed_scenario_schema_is_what_the_binary_prints() {
    let out = macrotree(&["schema", "--scenario"]);
    assert_eq!(out.status.code(), Some(0));
    let printed = stdout(&out);
    let path = Path::new(ROOT).join(SCHEMA);
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        std::fs::write(&path, &printed).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        printed == committed,
        "`macrotree schema --scenario` differs from {SCHEMA}: run `UPDATE_SCHEMA=1 cargo test --release --test cli scenario_suites`"
    );
}

#[test]
fn every_shipped_scenario_file_loads_and_passes_the_schema() {
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(Path::new(ROOT).join(SCHEMA)).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).expect("a valid JSON Schema");
    let files = macrotree::suite::find_files(&[Path::new(ROOT).join("scenarios")]).unwrap();
    let trees: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join("trees"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    let mut covered = std::collections::HashSet::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            text.starts_with("# yaml-language-server: $schema=../schema/scenario.schema.json"),
            "{}",
            path.display()
        );
        let file = macrotree::suite::load_scenario_file(path, &[]).unwrap_or_else(|d| panic!("{}", d[0]));
        covered.insert(std::fs::canonicalize(Path::new(ROOT).join(&file.tree)).unwrap_or_default());
        let v: serde_json::Value = serde_saphyr::from_str(&text).unwrap();
        let errors: Vec<String> = validator.iter_errors(&v).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", path.display());
    }
    for t in trees {
        assert!(
            covered.contains(&std::fs::canonicalize(&t).unwrap()),
            "no scenario file runs {}",
            t.display()
        );
    }
}

#[test]
fn a_passing_suite_exits_0_with_junit_and_jsonl() {
    let dir = scratch("suite-pass");
    let (xml, jsonl) = (dir.join("report.xml"), dir.join("out.jsonl"));
    let out = macrotree(&[
        "test",
        PASS,
        "-j",
        "2",
        "--junit",
        s(&xml),
        "--out",
        s(&jsonl),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}{}", stdout(&out), stderr(&out));
    // With --json the text for people is on stderr.
    let text = stderr(&out);
    assert!(
        text.contains("PASS tests/fixtures/scenarios/pass/grasp_fails_once.yaml: 3 of 3 succeeded"),
        "{text}"
    );
    assert!(text.contains("2 of 2 scenario file(s) passed"), "{text}");
    let report = last_json(&out);
    assert_eq!(report["passed"], true);
    let (cases, failures, _) = check_junit(&std::fs::read_to_string(&xml).unwrap());
    assert_eq!((cases, failures), (2, 0));
    // The JSONL: one line per scenario, each naming its suite, with the forced failure and the
    // retry visible in the per-node counts.
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 5);
    let once: Vec<_> = lines
        .iter()
        .filter(|l| l["suite"].as_str().unwrap().ends_with("grasp_fails_once.yaml"))
        .collect();
    assert_eq!(once.len(), 3);
    for l in once {
        assert_eq!(l["success"], true);
        let pick = l["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|n| n["path"].as_str().unwrap().ends_with("/subtree[pick]"))
            .unwrap();
        assert_eq!(
            (
                pick["activations"].as_u64(),
                pick["failures"].as_u64(),
                pick["successes"].as_u64()
            ),
            (Some(2), Some(1), Some(1)),
            "{pick}"
        );
        assert_eq!(
            l["substitutions"][0],
            "main/**/subtree[pick]/**/grasp=fail_first:1"
        );
    }
    let never: Vec<_> = lines
        .iter()
        .filter(|l| l["suite"].as_str().unwrap().ends_with("never_works.yaml"))
        .collect();
    assert!(
        never
            .iter()
            .all(|l| l["success"] == false && l["failure_kind"] == "substituted")
    );
}

#[test]
fn a_failing_expectation_exits_1_and_its_junit_failure_reproduces() {
    let dir = scratch("suite-fail");
    let xml = dir.join("report.xml");
    let out = macrotree(&["test", FAIL, PASS, "-j", "2", "--junit", s(&xml)]);
    assert_eq!(out.status.code(), Some(1), "{}{}", stdout(&out), stderr(&out));
    assert!(stdout(&out).contains("FAIL tests/fixtures/scenarios/fail/expects_failure.yaml"));
    let (cases, failures, texts) = check_junit(&std::fs::read_to_string(&xml).unwrap());
    assert_eq!((cases, failures), (3, 1));
    let text = &texts[0];
    assert!(
        text.contains("expected every scenario fails: 2 of 2 succeeded"),
        "{text}"
    );
    // The scenarios that broke the expectation (they succeeded) are listed with commands that
    // reproduce them.
    let cmds: Vec<&str> = text
        .lines()
        .map(str::trim)
        // The program as it ran (`target/release/macrotree` here, `macrotree` when on PATH).
        .filter(|l| {
            l.split_whitespace()
                .next()
                .is_some_and(|p| p.ends_with("macrotree"))
                && l.contains(" run ")
        })
        .collect();
    assert_eq!(cmds.len(), 2, "{text}");
    let args: Vec<&str> = cmds[0].split_whitespace().skip(1).collect();
    let again = macrotree(&args);
    assert_eq!(again.status.code(), Some(0), "{}: {}", cmds[0], stderr(&again));
}

#[test]
fn bad_scenario_files_exit_2_with_located_errors_and_nothing_runs() {
    let cases = [
        ("typo.yaml", "typo.yaml:4:3", "min_success_rate"),
        ("range.yaml", "range.yaml:2:8", "`count` must be 1 to"),
        ("kind.yaml", "kind.yaml:5:17", "did you mean `grasp_lost`"),
        // A substitution that matches no leaf is located at its rule, with close paths.
        (
            "nomatch.yaml",
            "nomatch.yaml:4:5",
            "subtree[pick]/sequence[pick]/grasp",
        ),
        // An `expect:` glob that matches no node is located at the pattern.
        (
            "expect_nomatch.yaml",
            "expect_nomatch.yaml:6:14",
            "matches no node",
        ),
    ];
    for (file, where_, what) in cases {
        let path = format!("tests/fixtures/scenarios/bad/{file}");
        let out = macrotree(&["test", &path]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        assert!(err.contains(where_) && err.contains(what), "{file}: {err}");
        assert!(!stdout(&out).contains("PASS") && !stdout(&out).contains("FAIL"));
    }
    let out = macrotree(&["test", "tests/fixtures/scenarios/none"]);
    assert_eq!(out.status.code(), Some(2));
    let out = macrotree(&["run", TREE, "--substitute", "main/**/grasp=fail_first:0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("1 to 100000"), "{}", stderr(&out));
}

/// `validate` knows scenario files: it checks each as `test` would before running (its tree,
/// its substitutions, its node patterns) instead of asking for a `main:` tree, and `test
/// --check` does the same for a whole suite without running a scenario.
#[test]
fn validate_and_test_check_judge_scenario_files_without_running_them() {
    let pass_file = "tests/fixtures/scenarios/pass/grasp_fails_once.yaml";
    let out = macrotree(&["validate", pass_file, "scenarios/clear_table.yaml", TREE]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("scenarios/clear_table.yaml: ok (scenario: ")
            && text.contains("of trees/clear_table.yaml"),
        "{text}"
    );
    assert!(!stderr(&out).contains("main:"), "{}", stderr(&out));

    let bad = "tests/fixtures/scenarios/bad";
    let (nomatch, expect_nomatch) = (
        format!("{bad}/nomatch.yaml"),
        format!("{bad}/expect_nomatch.yaml"),
    );
    let out = macrotree(&[
        "validate",
        "--format",
        "json",
        &nomatch,
        &expect_nomatch,
        pass_file,
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let lines: Vec<serde_json::Value> = stdout(&out)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    assert!(lines.iter().all(|l| l["kind"] == "scenario"), "{lines:?}");
    assert_eq!(
        lines.iter().map(|l| l["valid"] == true).collect::<Vec<_>>(),
        [false, false, true]
    );
    let at = |l: &serde_json::Value| {
        (
            l["diagnostics"][0]["line"].as_u64(),
            l["diagnostics"][0]["column"].as_u64(),
        )
    };
    assert_eq!(at(&lines[0]), (Some(4), Some(5)), "{}", lines[0]);
    assert_eq!(at(&lines[1]), (Some(6), Some(14)), "{}", lines[1]);

    // `test --check`: every file's errors at once, exit 2, and no scenario runs.
    let out = macrotree(&["test", "--check", &nomatch, &expect_nomatch]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("nomatch.yaml:4:5") && err.contains("expect_nomatch.yaml:6:14"),
        "{err}"
    );
    let out = macrotree(&["test", "--check", PASS, FAIL]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("nothing was run (--check)"), "{text}");
    assert!(!text.contains("PASS") && !text.contains("FAIL"), "{text}");
}

/// Runs `args` with shard K of M through `--shard auto` and a Slurm array environment.
fn slurm_shard(args: &[&str], k: u64, m: u64) -> std::process::Child {
    std::process::Command::new(BIN)
        .args(args)
        .args(["--shard", "auto"])
        .current_dir(ROOT)
        .env_remove("RUST_LOG")
        .env("SLURM_ARRAY_TASK_ID", (k + 1).to_string())
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", m.to_string())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn four_sweep_shards_as_processes_merge_into_the_unsharded_report() {
    let dir = scratch("shards-sweep");
    let all = dir.join("all.jsonl");
    let base = [
        "sweep",
        TREE,
        "--scenarios",
        "10",
        "--seed",
        "7",
        "-j",
        "1",
        "--fault",
        "slip",
        "--substitute",
        "main/**/subtree[pick]/**/grasp=fail_first:1",
    ];
    let whole = macrotree(&[&base[..], &["--out", s(&all), "--json"]].concat());
    assert!(whole.status.code().is_some_and(|c| c < 2), "{}", stderr(&whole));
    let shard_files: Vec<PathBuf> = (0..4).map(|k| dir.join(format!("shard{k}.jsonl"))).collect();
    let children: Vec<_> = (0..4u64)
        .map(|k| {
            slurm_shard(
                &[&base[..], &["--out", s(&shard_files[k as usize])]].concat(),
                k,
                4,
            )
        })
        .collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(
            o.status.code().is_some_and(|c| c < 2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(String::from_utf8_lossy(&o.stderr).contains("(from the environment)"));
    }
    let mut args = vec!["report", "--json"];
    // Any order.
    for f in shard_files.iter().rev() {
        args.push(s(f));
    }
    let merged = macrotree(&args);
    let unsharded = macrotree(&["report", "--json", s(&all)]);
    assert_eq!(merged.status.code(), unsharded.status.code());
    assert!(merged.status.code().is_some_and(|c| c < 2), "{}", stderr(&merged));
    // The same results, text and JSON; the times are the shards' own.
    assert_eq!(
        results_only(last_json(&merged)),
        results_only(last_json(&unsharded))
    );
    assert_eq!(
        text_without_timings(&stderr(&merged)),
        text_without_timings(&stderr(&unsharded))
    );
    // `report` on the unsharded file gives its sweep's summary, times included: they come from
    // the timing file beside it.
    assert_eq!(last_json(&unsharded), last_json(&whole));
    // Merged, the shards' times add up as one run's would: four one-job runs side by side.
    let timings: Vec<serde_json::Value> = shard_files
        .iter()
        .map(|f| {
            let t = std::fs::read_to_string(format!("{}.timing.json", s(f)))
                .expect("a timing file beside each shard");
            serde_json::from_str(&t).unwrap()
        })
        .collect();
    let sum = |key: &str| -> f64 { timings.iter().map(|t| t["runs"][0][key].as_f64().unwrap()).sum() };
    let longest = timings
        .iter()
        .map(|t| t["runs"][0]["wall_time_s"].as_f64().unwrap())
        .fold(0.0, f64::max);
    let summary = last_json(&merged);
    assert_eq!(summary["jobs"], 4);
    assert_eq!(summary["wall_time_s"].as_f64(), Some(longest));
    for key in ["physics_time_s", "planning_time_s"] {
        let merged_value = summary[key].as_f64().unwrap();
        assert!(
            (merged_value - sum(key)).abs() < 1e-9,
            "{key}: {merged_value} against {}",
            sum(key)
        );
    }
    let share = summary["physics_share"].as_f64().unwrap();
    assert!(share > 0.0 && share <= 1.0, "physics share {share}");
    let text = stderr(&merged);
    assert!(
        text.contains("on 4 job(s)") && text.contains("physics share"),
        "{text}"
    );
    // Without a timing file beside every file, the text says the times are unknown rather than
    // passing off a zero.
    std::fs::remove_file(format!("{}.timing.json", s(&shard_files[2]))).unwrap();
    let partial = macrotree(&args);
    let text = stderr(&partial);
    assert!(
        text.contains("wall time, physics and planning shares: unknown"),
        "{text}"
    );
    assert!(!text.contains("0 job(s)"), "{text}");
    assert_eq!(
        results_only(last_json(&partial)),
        results_only(last_json(&unsharded))
    );
    assert_eq!(summary["scenarios"], 10);
    assert_eq!(
        summary["substitutions"][0],
        "main/**/subtree[pick]/**/grasp=fail_first:1"
    );
    assert!(summary["coverage"]["ran"].as_u64().unwrap() > 0);

    // Missing, duplicate and foreign shards are refused, naming what is wrong.
    let out = macrotree(&[
        "report",
        s(&shard_files[0]),
        s(&shard_files[1]),
        s(&shard_files[2]),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("2 of 10 scenarios are missing: 3, 7"),
        "{}",
        stderr(&out)
    );
    let out = macrotree(&["report", s(&all), s(&shard_files[1])]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("duplicate scenarios: scenario 1"),
        "{}",
        stderr(&out)
    );
    let other = dir.join("other.jsonl");
    let o = macrotree(&[
        "sweep",
        TREE,
        "--scenarios",
        "10",
        "--seed",
        "8",
        "-j",
        "1",
        "--shard",
        "3/4",
        "--out",
        s(&other),
        "--fault",
        "slip",
        "--substitute",
        "main/**/subtree[pick]/**/grasp=fail_first:1",
    ]);
    assert!(o.status.code().is_some_and(|c| c < 2));
    let out = macrotree(&[
        "report",
        s(&shard_files[0]),
        s(&shard_files[1]),
        s(&shard_files[2]),
        s(&other),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("its seed is 8") && stderr(&out).contains("has 7"),
        "{}",
        stderr(&out)
    );
    // The collision policy is part of a run's identity, as for `--resume`.
    let failing = dir.join("collisions_fail.jsonl");
    let o = macrotree(
        &[
            &base[..],
            &["--shard", "3/4", "--collisions", "fail", "--out", s(&failing)],
        ]
        .concat(),
    );
    assert!(o.status.code().is_some_and(|c| c < 2), "{}", stderr(&o));
    let out = macrotree(&[
        "report",
        s(&shard_files[0]),
        s(&shard_files[1]),
        s(&shard_files[2]),
        s(&failing),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("its collision policy is fail"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn test_shards_merge_into_the_unsharded_junit_and_outcome() {
    let dir = scratch("shards-test");
    let all = dir.join("all.jsonl");
    let whole = macrotree(&["test", PASS, "-j", "1", "--out", s(&all)]);
    assert_eq!(whole.status.code(), Some(0), "{}", stderr(&whole));
    let files: Vec<PathBuf> = (0..4).map(|k| dir.join(format!("s{k}.jsonl"))).collect();
    let children: Vec<_> = (0..4usize)
        .map(|k| {
            std::process::Command::new(BIN)
                .args([
                    "test",
                    PASS,
                    "-j",
                    "1",
                    "--shard",
                    "auto",
                    "--shard-count",
                    "4",
                    "--out",
                    s(&files[k]),
                ])
                .current_dir(ROOT)
                .env_remove("RUST_LOG")
                .env("JOB_COMPLETION_INDEX", k.to_string())
                .output()
                .unwrap()
        })
        .collect();
    for o in &children {
        // A shard's verdict covers only its scenarios (a shard with one scenario of
        // `grasp_fails_once` still passes; an empty one does not).
        assert!(
            o.status.code().is_some_and(|c| c < 2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let (xa, xb) = (dir.join("a.xml"), dir.join("b.xml"));
    let mut args = vec!["report", "--json", "--junit", s(&xa)];
    args.extend(files.iter().map(|f| s(f)));
    let merged = macrotree(&args);
    let unsharded = macrotree(&["report", "--json", "--junit", s(&xb), s(&all)]);
    assert_eq!(merged.status.code(), Some(0), "{}", stderr(&merged));
    assert_eq!(stdout(&merged), stdout(&unsharded));
    assert_eq!(std::fs::read(&xa).unwrap(), std::fs::read(&xb).unwrap());
    assert_eq!(check_junit(&std::fs::read_to_string(&xa).unwrap()).0, 2);
}

#[test]
fn shard_auto_needs_a_job_array_environment() {
    let run = |env: &[(&str, &str)], extra: &[&str]| {
        let mut c = std::process::Command::new(BIN);
        c.args(["sweep", TREE, "--scenarios", "4", "--shard", "auto"])
            .args(extra)
            .current_dir(ROOT);
        for k in [
            "SLURM_ARRAY_TASK_ID",
            "SLURM_ARRAY_TASK_COUNT",
            "SLURM_ARRAY_TASK_MIN",
            "SLURM_ARRAY_TASK_STEP",
            "JOB_COMPLETION_INDEX",
        ] {
            c.env_remove(k);
        }
        for (k, v) in env {
            c.env(k, v);
        }
        let o = c.output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (code, err) = run(&[], &[]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("neither a Slurm array") && err.contains("--shard K/M"),
        "{err}"
    );
    let (code, err) = run(&[("JOB_COMPLETION_INDEX", "1")], &[]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--shard-count"), "{err}");
    let (code, err) = run(&[("JOB_COMPLETION_INDEX", "4")], &["--shard-count", "4"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("index 4 is not below the shard count 4"), "{err}");
    let (code, err) = run(&[("SLURM_ARRAY_TASK_ID", "2")], &[]);
    assert_eq!(code, Some(2));
    assert!(err.contains("SLURM_ARRAY_TASK_COUNT"), "{err}");
    let (code, err) = run(
        &[("SLURM_ARRAY_TASK_ID", "1"), ("SLURM_ARRAY_TASK_COUNT", "4")],
        &["--shard-count", "3"],
    );
    assert_eq!(code, Some(2));
    assert!(err.contains("disagrees"), "{err}");
    let (code, err) = run(
        &[("SLURM_ARRAY_TASK_ID", "x"), ("SLURM_ARRAY_TASK_COUNT", "4")],
        &[],
    );
    assert_eq!(code, Some(2));
    assert!(err.contains("not a whole number"), "{err}");
}
