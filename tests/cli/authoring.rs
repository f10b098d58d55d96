//! The authoring commands: `schema`, `graph`, `nodes`, and the editor hook in every tree file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::files;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn macrotree(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_macrotree"))
        .args(args)
        .current_dir(ROOT)
        .env_remove("RUST_LOG")
        .output()
        .expect("macrotree runs")
}

fn stdout(out: &Output) -> String {
    String::from_utf8(out.stdout.clone()).expect("stdout is UTF-8")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Every `.yaml` file under `trees/`, sorted.
fn tree_files() -> Vec<PathBuf> {
    files::yaml_files(&Path::new(ROOT).join("trees"))
}

#[test]
fn schema_command_prints_the_committed_schema() {
    let out = macrotree(&["schema"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let committed = std::fs::read_to_string(Path::new(ROOT).join("schema/tree.schema.json")).unwrap();
    assert!(
        stdout(&out) == committed,
        "`macrotree schema` differs from schema/tree.schema.json: run `UPDATE_SCHEMA=1 cargo test --release --test tree schema`"
    );
    let schema: serde_json::Value = serde_json::from_str(&committed).unwrap();
    assert_eq!(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
}

#[test]
fn every_tree_file_names_the_schema_on_its_first_line_and_is_valid() {
    let files = tree_files();
    assert!(files.len() >= 5, "trees/ holds the example trees: {files:?}");
    let schema = std::fs::canonicalize(Path::new(ROOT).join("schema/tree.schema.json")).unwrap();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let first = text.lines().next().unwrap_or_default();
        let rel = first
            .strip_prefix("# yaml-language-server: $schema=")
            .unwrap_or_else(|| panic!("{}: first line is {first:?}", file.display()));
        let target = std::fs::canonicalize(file.parent().unwrap().join(rel))
            .unwrap_or_else(|e| panic!("{}: $schema={rel} does not resolve: {e}", file.display()));
        assert_eq!(target, schema, "{}", file.display());
    }
    // Library files (only subtrees, no `main:`) are checked through the trees that include them.
    let mains: Vec<&str> = files
        .iter()
        .filter(|f| std::fs::read_to_string(f).unwrap().contains("\nmain:"))
        .map(|f| f.to_str().unwrap())
        .collect();
    let mut args = vec!["validate"];
    args.extend(&mains);
    let out = macrotree(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(stdout(&out).matches(": ok (").count(), mains.len());
}

#[test]
fn graph_dot_has_one_edge_per_non_root_node() {
    let out = macrotree(&["graph", "trees/cube_to_bowl.yaml"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let dot = stdout(&out);
    assert!(dot.starts_with("digraph tree {"), "{dot}");
    let plan = macrotree::plan::Loader::default()
        .load(&Path::new(ROOT).join("trees/cube_to_bowl.yaml"))
        .unwrap();
    assert_eq!(dot.matches(" -> ").count(), plan.nodes.len() - 1);
    assert!(dot.contains("retry ×3"), "{dot}");
    assert!(
        dot.contains("[label=\"while\""),
        "the guard's condition edge: {dot}"
    );
}

#[test]
fn readme_shows_the_flagship_as_the_current_mermaid_graph() {
    let out = macrotree(&["graph", "trees/cube_to_bowl.yaml", "--format", "mermaid"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let mermaid = stdout(&out);
    let readme = std::fs::read_to_string(Path::new(ROOT).join("README.md")).unwrap();
    let block = readme
        .split("```mermaid\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("README has a ```mermaid block");
    assert!(
        block == mermaid,
        "README's mermaid block is stale: replace it with `macrotree graph trees/cube_to_bowl.yaml --format mermaid`"
    );
}

#[test]
fn graph_of_an_invalid_tree_is_bad_input_with_a_location() {
    let out = macrotree(&[
        "graph",
        "tests/fixtures/cli/misspelled_param.yaml",
        "--format",
        "mermaid",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "no diagram for an invalid tree");
    let err = stderr(&out);
    assert!(err.contains("misspelled_param.yaml:4:31"), "{err}");
    assert!(err.contains("did you mean `offset`?"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn nodes_lists_every_kind_with_parameters_and_examples() {
    let out = macrotree(&["nodes"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    let catalog = macrotree::Registry::builtin().catalog();
    for doc in &catalog {
        assert!(
            text.contains(&format!("\n  {} — {}", doc.kind, doc.summary)),
            "{}",
            doc.kind
        );
        assert!(text.contains(doc.example.lines().next().unwrap()), "{}", doc.kind);
    }
    // Units and defaults of a leaf's parameters come through.
    assert!(text.contains("lift"), "{text}");
    assert!(text.contains("default 0.2"), "{text}");
}

#[test]
fn nodes_kind_json_is_one_entry() {
    let out = macrotree(&["nodes", "carry", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(stdout(&out).trim()).unwrap();
    let entries = v.as_array().unwrap();
    assert_eq!(entries.len(), 1);
    assert_eq!(entries[0]["kind"], "carry");
    assert_eq!(entries[0]["category"], "action");
    let params: Vec<&str> = entries[0]["params"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(
        params.contains(&"lift") && params.contains(&"place_height"),
        "{params:?}"
    );
}

#[test]
fn nodes_unknown_kind_suggests_the_nearest() {
    let out = macrotree(&["nodes", "reac"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("unknown node kind `reac`"), "{err}");
    assert!(err.contains("did you mean `reach`?"), "{err}");
}

#[test]
fn validate_json_gives_one_object_per_file_with_located_diagnostics() {
    let bad = "tests/fixtures/cli/misspelled_param.yaml";
    let out = macrotree(&["validate", "--format", "json", bad, "trees/cube_to_bowl.yaml"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let files: Vec<serde_json::Value> = stdout(&out)
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert_eq!(files.len(), 2);
    assert_eq!(files[0]["file"], bad);
    assert_eq!(files[0]["valid"], false);
    let d = &files[0]["diagnostics"][0];
    assert_eq!((d["line"].as_u64(), d["column"].as_u64()), (Some(4), Some(31)));
    assert_eq!(d["end_column"], 36, "`ofset` is 5 characters: {d}");
    assert_eq!(d["message"], "unknown parameter `ofset` in `reach`");
    assert_eq!(d["help"], "did you mean `offset`?");
    assert_eq!(files[1]["valid"], true);
    assert_eq!(files[1]["diagnostics"].as_array().map(Vec::len), Some(0));
    assert!(files[1]["nodes"].as_u64().unwrap_or(0) > 10);
}

#[test]
fn validate_github_prints_one_annotation_per_error() {
    let out = macrotree(&[
        "validate",
        "--format",
        "github",
        "tests/fixtures/cli/misspelled_param.yaml",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1, "{text}");
    assert!(
        lines[0].starts_with(
            "::error file=tests/fixtures/cli/misspelled_param.yaml,line=4,col=31,endColumn=35,title=macrotree::unknown parameter `ofset`"
        ),
        "{}",
        lines[0]
    );
    assert!(lines[0].ends_with("%0Adid you mean `offset`?"), "{}", lines[0]);
}
