//! `examples/custom_leaf.rs`: a user's `push` action and `near` and `upright` conditions,
//! registered next to the built-in kinds. The example's demo pushes the cube on physics and checks
//! it stands (orientation and contacts); its command line knows the new kinds everywhere
//! (`nodes`, `schema`, `validate` with located errors and suggestions) and shows its own name.

use crate::support::cli;

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::OnceLock;

use cli::{s, scratch};

/// The example's binary, built once (`cargo build --release --example custom_leaf`; nothing to
/// do when `cargo test --release` already built it).
fn example() -> &'static PathBuf {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let status = Command::new(env!("CARGO"))
            .args(["build", "--release", "--example", "custom_leaf"])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .status()
            .expect("runs cargo");
        assert!(status.success(), "the example builds");
        // This test runs from target/release/deps; the example is in target/release/examples.
        let exe = std::env::current_exe().unwrap();
        let release = exe.parent().and_then(|d| d.parent()).unwrap();
        let bin = release.join("examples").join("custom_leaf");
        assert!(bin.is_file(), "{} exists", bin.display());
        bin
    })
}

fn run(args: &[&str]) -> Output {
    Command::new(example())
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env_remove("RUST_LOG")
        .output()
        .expect("runs the example")
}

#[test]
fn the_demo_pushes_the_cube_by_the_distance_on_physics() {
    let out = run(&[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("the report is JSON");
    assert_eq!(report["success"], true, "{report}");
    assert_eq!(report["tree_status"], "success");
    let cube = report["objects"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == "cube")
        .expect("the cube is reported");
    let at = |key: &str, k: usize| cube[key][k].as_f64().unwrap();
    let (dx, dy) = (
        at("final", 0) - at("initial", 0),
        at("final", 1) - at("initial", 1),
    );
    // The tree pushes 0.10 m along -y.
    eprintln!("cube moved dx = {:.4} m, dy = {:.4} m", dx, dy);
    assert!(
        (dy + 0.10).abs() <= 0.01,
        "moved {dy} m along y, expected -0.10 ± 0.01"
    );
    assert!(dx.abs() <= 0.01, "moved {dx} m sideways");
    // Pushed, not lifted: it is still on the table.
    assert!((at("final", 2) - at("initial", 2)).abs() < 0.002, "{cube}");
}

#[test]
fn the_cli_documents_the_new_kinds() {
    let out = run(&["nodes", "push"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Slide a block along the table"), "{text}");
    assert!(text.contains("distance"), "{text}");
    assert!(text.contains("metres (0.01 … 0.25)"), "{text}");

    let out = run(&["nodes", "--json"]);
    let all: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let kinds: Vec<&str> = all
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"push") && kinds.contains(&"near") && kinds.contains(&"reach"));
    let near = all
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["kind"] == "near")
        .unwrap();
    assert_eq!(near["category"], "condition");

    let out = run(&["schema"]);
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let variants = schema["$defs"]["Node"]["oneOf"].as_array().unwrap();
    assert!(variants.iter().any(|v| v["required"][0] == "push"));
    let conditions = schema["$defs"]["Condition"]["oneOf"].as_array().unwrap();
    assert!(conditions.iter().any(|v| v["required"][0] == "near"));
}

#[test]
fn trees_with_the_new_kinds_are_validated_with_located_errors() {
    let dir = scratch("custom-leaf");
    let good = dir.join("good.yaml");
    std::fs::write(
        &good,
        "main:\n  sequence:\n    children:\n      - push: {object: cube, direction: deg(90), distance: 0.05}\n      - guard: {condition: {near: {object: cube, point: [0.45, -0.13]}}, child: {home: {}}}\n",
    )
    .unwrap();
    let out = run(&["validate", s(&good)]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let bad = dir.join("bad.yaml");
    std::fs::write(
        &bad,
        "main:\n  sequence:\n    children:\n      - push: {object: cube, direction: 0, distance: 0.5}\n      - puhs: {object: cube, direction: 0, distance: 0.1}\n      - near: {object: cbe, point: [0.4, 0]}\n",
    )
    .unwrap();
    let out = run(&["validate", s(&bad)]);
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stderr);
    // The range check points at the value.
    assert!(text.contains("bad.yaml:4:54"), "{text}");
    assert!(text.contains("between 0.01 and 0.25 m"), "{text}");
    // A misspelled custom kind gets a suggestion.
    assert!(text.contains("bad.yaml:5:9"), "{text}");
    assert!(text.contains("did you mean `push`?"), "{text}");
    // Object names of custom leaves are checked against the scene.
    assert!(text.contains("bad.yaml:6:24"), "{text}");
    assert!(text.contains("`cbe`"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_params_type_error_is_located_at_the_value_not_the_node_kind() {
    let dir = scratch("custom-leaf-validate-fields");
    let bad = dir.join("tilt.yaml");
    std::fs::write(
        &bad,
        "main:\n  sequence:\n    children:\n      - home: {}\n      - upright: {object: cube, max_tilt: deg(60)}\n",
    )
    .unwrap();
    let out = run(&["validate", s(&bad)]);
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stderr);
    // At the value `deg(60)` (column 43), not at `upright` (column 9).
    assert!(text.contains("tilt.yaml:5:43"), "{text}");
    assert!(!text.contains("tilt.yaml:5:9"), "{text}");
    assert!(
        text.contains("`max_tilt` must be between 0 and 45°, found 60.0°"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn nodes_printed_an_angle_default_in_radians() {
    let out = run(&["nodes", "upright"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("max_tilt  Angle (default deg(10))"), "{text}");
    assert!(!text.contains("0.1745"), "{text}");
}

#[test]
fn run_cli_showed_macrotrees_own_name_and_description_in_help() {
    let out = run(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with(
            "The macrotree command line with a `push` action and the `near` and `upright` conditions"
        ),
        "{text}"
    );
    assert!(text.contains("Usage: custom_leaf [OPTIONS] <COMMAND>"), "{text}");
    assert!(!text.contains("Behavior trees in YAML driving"), "{text}");
    let out = run(&["--version"]);
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "custom_leaf 0.1.0");
    // A subcommand's usage names the program too.
    let out = run(&["validate", "--help"]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("Usage: custom_leaf validate"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}
