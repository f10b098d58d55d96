//! `macrotree schema [--scene]`: the JSON Schema of tree files (or scene files), generated from
//! the Rust types.
//!
//! The output is byte-identical to the committed `schema/tree.schema.json` and
//! `schema/scene.schema.json` (tests check both), so `macrotree schema > my.schema.json` gives an
//! editor the schema of the installed version.

use std::path::PathBuf;

use clap::Args;

use super::{CliError, write_output};

/// Arguments of `schema`.
#[derive(Debug, Args)]
pub struct SchemaArgs {
    /// Write to this file instead of stdout.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// The schema of scene files instead of tree files.
    #[arg(long, conflicts_with = "scenario")]
    pub scene: bool,
    /// The schema of scenario files (`macrotree test`) instead of tree files.
    #[arg(long)]
    pub scenario: bool,
}

/// The scene-file schema as pretty JSON with a final newline (the committed file's exact bytes).
pub fn scene_schema_text() -> String {
    let schema = schemars::generate::SchemaSettings::draft2020_12()
        .for_deserialize()
        .into_generator()
        .into_root_schema_for::<crate::scene::SceneFileSchema>();
    let mut v = serde_json::to_value(&schema).expect("a schema serializes");
    v["$id"] = "https://macrotree.invalid/schema/scene.schema.json".into();
    v["title"] = "macrotree scene file".into();
    v["description"] = "A cell's objects by name (blocks, containers, obstacles), their poses or randomization, and the task's goal. See docs/scenes.md. Units: m, kg, rad (or deg(..)).".into();
    serde_json::to_string_pretty(&v).expect("a serde_json::Value always serializes") + "\n"
}

/// The schema as pretty JSON with a final newline (the committed file's exact bytes).
pub fn schema_text(registry: &crate::kinds::Registry) -> String {
    let schema = registry.json_schema();
    serde_json::to_string_pretty(&schema).expect("a serde_json::Value always serializes") + "\n"
}

/// Runs `macrotree schema`.
pub fn schema(app: &crate::App, args: SchemaArgs) -> Result<(), CliError> {
    let text = if args.scenario {
        crate::suite::schema_text()
    } else if args.scene {
        scene_schema_text()
    } else {
        schema_text(app.registry())
    };
    write_output(args.out.as_deref(), &[], &text)
}
