//! `macrotree schema`: the JSON Schema of tree files, generated from the Rust spec types.
//!
//! The output is byte-identical to the committed `schema/tree.schema.json` (a test checks it),
//! so `macrotree schema > my.schema.json` gives an editor the schema of the installed version.

use std::path::PathBuf;

use clap::Args;

use super::{CliError, write_output};

/// Arguments of `schema`.
#[derive(Debug, Args)]
pub struct SchemaArgs {
    /// Write to this file instead of stdout.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
}

/// The schema as pretty JSON with a final newline (the committed file's exact bytes).
pub fn schema_text() -> String {
    let schema = crate::spec::json_schema();
    serde_json::to_string_pretty(&schema).expect("a serde_json::Value always serializes") + "\n"
}

/// Runs `macrotree schema`.
pub fn schema(args: SchemaArgs) -> Result<(), CliError> {
    write_output(args.out.as_deref(), &[], &schema_text())
}
