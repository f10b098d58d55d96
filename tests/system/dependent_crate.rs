//! A crate of a user's own that depends on macrotree (`macrotree = { path = … }`) builds and
//! runs with nothing beyond what docs/custom_nodes.md states: its `.cargo/config.toml` names
//! MuJoCo's library folder (mujoco-rs links from it) and its `build.rs` bakes that folder into
//! its programs' rpath (so they run without `LD_LIBRARY_PATH`).
//!
//! The crate is generated in a temporary folder and built with `CARGO_TARGET_DIR` set to this
//! package's target folder, the same compiler, `Cargo.lock`, dependency features and release
//! profile, so that every dependency of macrotree is reused. macrotree itself is compiled once
//! more as a dependency (cargo's hash of a path dependency includes its place relative to the
//! workspace root), unoptimised as a user's debug build compiles a path dependency: 35 s on 2
//! cores after macrotree's sources change (132 s at the release profile's opt-level 3), 2.6 s
//! when they have not. Nothing is downloaded (`--offline`).

use crate::support::cli;

use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The user's `.cargo/config.toml`, as docs/custom_nodes.md gives it (`MACROTREE` is the
/// checkout's path).
const CONFIG: &str = "[env]\nMUJOCO_DYNAMIC_LINK_DIR = \"MACROTREE/third_party/mujoco/lib\"\n";

/// The user's `build.rs`, as docs/custom_nodes.md gives it.
const BUILD_RS: &str = r#"fn main() {
    println!("cargo:rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
"#;

/// A program with a condition of its own, reading the world snapshot's orientation: runs a
/// tree on physics and prints the report, or (with arguments) is the command line.
const MAIN_RS: &str = r#"use macrotree::episode::{EpisodeConfig, Goal};
use macrotree::world::World;
use macrotree::{App, Failure, Params};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `flat: {}` parameters (none).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Flat {}

impl Params for Flat {}

const FLAT_DOC: &str = "Every block rests flat (tilted less than 5°).\n\nHalt: nothing to halt (instantaneous).\n\n```yaml\nflat: {}\n```\n";

fn flat(w: &World, _: &Flat) -> Result<bool, Failure> {
    Ok(w.objects.iter().zip(&w.scene.objects).all(|(o, spec)| {
        spec.kind() != macrotree::scene::ObjectKind::Block || {
            let r = o.quat.to_rotation_matrix();
            (0..3).map(|k| r[(2, k)].abs()).fold(0.0, f64::max) > 5f64.to_radians().cos()
        }
    }))
}

fn main() -> std::process::ExitCode {
    let mut app = App::new();
    app.register_condition("flat", FLAT_DOC, flat).expect("registers");
    if std::env::args_os().len() > 1 {
        app.cli_name("my_cell").cli_about("My cell's trees");
        return app.run_cli();
    }
    let plan = app
        .compile_str("main: {sequence: {children: [{home: {}}, {flat: {}}]}}", "t.yaml")
        .expect("compiles");
    let config = EpisodeConfig { goal: Goal::Tree, ..EpisodeConfig::default() };
    let report = app.run_episode(&plan, &config).expect("runs");
    println!("{}", serde_json::to_string(&report).expect("serializes"));
    std::process::ExitCode::SUCCESS
}
"#;

/// The folder `cargo test` builds into (the parent of `target/tmp`).
fn target_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("target/tmp has a parent")
        .to_path_buf()
}

/// A `cargo` command for the user's crate with the environment of a fresh shell: no
/// `MUJOCO_DYNAMIC_LINK_DIR` (macrotree's own `.cargo/config.toml` sets it for this test
/// process), no `LD_LIBRARY_PATH`, no `RUSTFLAGS`.
fn fresh_cargo(dir: &Path) -> Command {
    let cargo = PathBuf::from(env!("CARGO"));
    let mut c = Command::new(&cargo);
    c.current_dir(dir).env_clear();
    for key in [
        "PATH",
        "HOME",
        "CARGO_HOME",
        "RUSTUP_HOME",
        "RUSTUP_TOOLCHAIN",
        "TMPDIR",
    ] {
        if let Some(v) = std::env::var_os(key) {
            c.env(key, v);
        }
    }
    // The compiler next to this cargo (the one that built this test), so artifacts are shared.
    let rustc = cargo.with_file_name("rustc");
    if rustc.exists() {
        c.env("RUSTC", rustc);
    }
    c.env("CARGO_TARGET_DIR", target_dir());
    c
}

#[test]
fn a_dependent_crate_builds_and_runs_with_only_the_documented_setup() {
    // The snippets are the ones the guide gives.
    let guide = std::fs::read_to_string(Path::new(ROOT).join("docs/custom_nodes.md")).unwrap();
    assert!(
        guide.contains(BUILD_RS),
        "docs/custom_nodes.md gives another build.rs"
    );
    assert!(
        guide.contains("MUJOCO_DYNAMIC_LINK_DIR = \"/path/to/macrotree/third_party/mujoco/lib\""),
        "docs/custom_nodes.md gives another .cargo/config.toml"
    );

    let dir = cli::scratch("dependent-crate");
    std::fs::create_dir_all(dir.join("src")).unwrap();
    std::fs::create_dir_all(dir.join(".cargo")).unwrap();
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"my_cell\"\nversion = \"0.1.0\"\nedition = \"2024\"\n\n\
             [dependencies]\nmacrotree = {{ path = {ROOT:?} }}\nserde = {{ version = \"1\", features = [\"derive\"] }}\n\
             schemars = \"1\"\nserde_json = \"1\"\n\n\
             # Only so that this test shares the artifacts of macrotree's own test build (not\n\
             # needed by users): the workspace's dev-dependencies and the crates whose features\n\
             # the Python extension's dependencies add, for the same features of the shared\n\
             # dependencies; its feature resolver and release profile. macrotree itself\n\
             # unoptimised, as in a debug build (it is compiled again either way).\n\
             jsonschema = {{ version = \"=0.61.2\", default-features = false }}\npng = \"=0.18.1\"\n\
             matrixmultiply = {{ version = \"=0.3.11\", features = [\"cgemm\"] }}\n\
             num-complex = \"=0.4.6\"\nnum-integer = \"=0.1.47\"\n\
             portable-atomic = {{ version = \"=1.15.0\", features = [\"require-cas\"] }}\n\n\
             [profile.release]\ndebug = \"line-tables-only\"\n\n[profile.release.package.macrotree]\nopt-level = 0\ndebug = false\n\n[workspace]\nresolver = \"1\"\n"
        ),
    )
    .unwrap();
    std::fs::write(dir.join(".cargo/config.toml"), CONFIG.replace("MACROTREE", ROOT)).unwrap();
    std::fs::write(dir.join("build.rs"), BUILD_RS).unwrap();
    std::fs::write(dir.join("src/main.rs"), MAIN_RS).unwrap();
    // The same dependency versions as macrotree's own build (so they are reused, offline).
    std::fs::copy(Path::new(ROOT).join("Cargo.lock"), dir.join("Cargo.lock")).unwrap();

    let t = std::time::Instant::now();
    let out = fresh_cargo(&dir)
        .args(["build", "--release", "--offline"])
        .output()
        .expect("runs cargo");
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the dependent crate does not build:\n{log}");
    eprintln!(
        "built the dependent crate in {:.1} s; compiled: {:?}",
        t.elapsed().as_secs_f64(),
        log.lines()
            .filter(|l| l.trim_start().starts_with("Compiling"))
            .collect::<Vec<_>>()
    );

    // Run the program itself (not through cargo), without LD_LIBRARY_PATH: the rpath finds
    // libmujoco.so.
    let bin = target_dir().join("release/my_cell");
    let run = Command::new(&bin)
        .env_remove("LD_LIBRARY_PATH")
        .env_remove("MUJOCO_DYNAMIC_LINK_DIR")
        .output()
        .expect("runs the dependent crate's program");
    assert!(
        run.status.success(),
        "{}: {}",
        bin.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).expect("a JSON report");
    assert_eq!(report["success"], true, "{report}");
    let flat = report["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["path"].as_str().unwrap().ends_with("/flat"))
        .expect("the custom condition ran");
    assert_eq!(flat["successes"], 1, "{flat}");

    // Its command line knows the custom kind and shows the program's own name.
    let help = Command::new(&bin)
        .arg("--help")
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.starts_with("My cell's trees"), "{text}");
    assert!(text.contains("Usage: my_cell"), "{text}");
    let nodes = Command::new(&bin).args(["nodes", "flat"]).output().unwrap();
    assert!(
        String::from_utf8_lossy(&nodes.stdout).contains("Every block rests flat"),
        "{}",
        String::from_utf8_lossy(&nodes.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
