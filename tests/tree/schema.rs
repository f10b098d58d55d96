//! The committed JSON Schema must match the one generated from the Rust types, and it must agree
//! with the loader: an editor using it shows no false errors on valid trees and flags mistakes.
//!
//! Regenerate after changing a node kind or parameter:
//! `UPDATE_SCHEMA=1 cargo test --release --test tree schema`

use macrotree::kinds::{NodeDoc, Registry};

fn catalog() -> Vec<NodeDoc> {
    Registry::builtin().catalog()
}

fn json_schema() -> serde_json::Value {
    Registry::builtin().json_schema()
}

use crate::support::files;

const PATH: &str = "schema/tree.schema.json";

/// The subtrees the node examples call (`pick`, `place`, `wiggle`), and the example as `main`.
fn example_tree(example: &str) -> String {
    format!(
        "subtrees:\n  pick: {{params: {{approach: 0.1}}, root: {{home: {{}}}}}}\n  place: {{root: {{home: {{}}}}}}\n  wiggle: {{root: {{home: {{}}}}}}\nmain:\n  {example}\n"
    )
}

/// A JSON Schema validator for the committed schema (what an editor's YAML plugin loads).
fn editor_validator() -> jsonschema::Validator {
    let schema: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(PATH).unwrap()).unwrap();
    jsonschema::validator_for(&schema).expect("the committed schema is a valid JSON Schema")
}

/// Schema errors of a YAML text, read as JSON data the way an editor plugin reads it.
fn schema_errors(validator: &jsonschema::Validator, yaml: &str) -> Vec<String> {
    let data: serde_json::Value = serde_saphyr::from_str(yaml).expect("YAML");
    validator
        .iter_errors(&data)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect()
}

#[test]
fn committed_schema_is_up_to_date() {
    let generated = serde_json::to_string_pretty(&json_schema()).unwrap() + "\n";
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        std::fs::create_dir_all("schema").unwrap();
        std::fs::write(PATH, &generated).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(PATH).unwrap_or_default();
    assert!(
        committed == generated,
        "{PATH} is out of date: run `UPDATE_SCHEMA=1 cargo test --release --test tree schema` and commit it"
    );
}

#[test]
fn schema_lists_every_catalog_kind() {
    let schema = json_schema();
    let variants = schema["$defs"]["Node"]["oneOf"].as_array().unwrap();
    let kinds: Vec<&str> = variants
        .iter()
        .map(|v| v["required"][0].as_str().unwrap())
        .collect();
    let cat: Vec<&str> = catalog().iter().map(|d| d.kind).collect();
    assert_eq!(kinds, cat);
    // Leaf parameters come from the Rust structs, with units and defaults.
    let reach = &variants.iter().find(|v| v["required"][0] == "reach").unwrap()["properties"]["reach"];
    assert_eq!(reach["required"][0], "target");
    assert_eq!(reach["properties"]["speed"]["default"], 0.5);
    assert!(
        reach["properties"]["speed"]["description"]
            .as_str()
            .unwrap()
            .contains("m/s")
    );
    assert_eq!(reach["additionalProperties"], false);
}

#[test]
fn catalog_documents_every_node() {
    let cat = catalog();
    assert_eq!(cat.len(), 39);
    for d in &cat {
        assert!(
            !d.summary.is_empty() && !d.example.is_empty() && !d.halt.is_empty(),
            "{}",
            d.kind
        );
        // Every example is a valid node.
        let yaml = example_tree(d.example);
        // Read as a tree of trees/ (a `policy` example names trees/policies/cube_pick.onnx).
        if let Err(e) = macrotree::plan::Loader::default().compile_str(&yaml, "trees/example.yaml") {
            panic!("example of `{}` does not compile: {}", d.kind, e[0]);
        }
    }
    let carry = cat.iter().find(|d| d.kind == "carry").unwrap();
    let lift = carry.params.iter().find(|p| p.name == "lift").unwrap();
    assert_eq!(lift.default.as_deref(), Some("0.2"));
    assert!(lift.doc.contains("metres"));
}

#[test]
fn docs_nodes_holds_one_file_per_kind_and_nothing_else() {
    let mut files: Vec<String> = std::fs::read_dir("docs/nodes")
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    let mut expected: Vec<String> = catalog().iter().map(|d| format!("{}.md", d.kind)).collect();
    expected.sort();
    assert_eq!(
        files, expected,
        "docs/nodes/ must hold exactly one file per node kind"
    );
}

#[test]
fn node_doc_parts_are_read_from_the_markdown() {
    let (summary, details, halt, example) = macrotree::kinds::catalog::parse_node_doc(
        "Do a thing\nin two lines.\n\nMore about it.\n\nHalt: it stops.\n\n```yaml\nthing: {}\n```\n",
    );
    assert_eq!(summary, "Do a thing in two lines.");
    assert_eq!(details, "More about it.");
    assert_eq!(halt, "it stops");
    assert_eq!(example, "thing: {}");
}

#[test]
fn the_schema_accepts_every_tree_and_node_example_the_loader_accepts() {
    let validator = editor_validator();
    let files = files::yaml_files(std::path::Path::new("trees"));
    assert!(files.len() >= 5);
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let errors = schema_errors(&validator, &text);
        assert!(errors.is_empty(), "{}: {errors:#?}", f.display());
    }
    for d in catalog() {
        let errors = schema_errors(&validator, &example_tree(d.example));
        assert!(errors.is_empty(), "example of `{}`: {errors:#?}", d.kind);
    }
}

#[test]
fn the_schema_flags_what_the_loader_rejects() {
    let validator = editor_validator();
    for (yaml, what) in [
        ("main: {sequnce: {children: [home: {}]}}", "misspelled kind"),
        (
            "main: {reach: {target: cube, ofset: [0, 0, 0.1]}}",
            "misspelled parameter",
        ),
        ("main: {reach: {offset: [0, 0, 0.1]}}", "missing parameter"),
        ("main: {reach: {target: cube, speed: fast}}", "wrong type"),
        (
            "main: {release: {width: 0.2}}",
            "opening beyond the 2F-85's 0.085 m",
        ),
        (
            "main: {retry: {attempts: 0, child: {home: {}}}}",
            "attempts below 1",
        ),
        ("main: {sequence: {children: []}}", "empty composite"),
        (
            "main: {guard: {condition: {cube_graspd: {}}, child: {home: {}}}}",
            "unknown condition",
        ),
        ("mian: {home: {}}", "unknown top-level key"),
    ] {
        assert!(
            macrotree::plan::Loader::default()
                .compile_str(yaml, "t.yaml")
                .is_err(),
            "the loader accepts {what}: {yaml}"
        );
        assert!(
            !schema_errors(&validator, yaml).is_empty(),
            "the schema accepts {what}: {yaml}"
        );
    }
}
