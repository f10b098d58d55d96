//! `macrotree graph TREE [--format dot|mermaid]`: the tree as a diagram with the node names
//! and key parameters (see [`crate::plan::to_dot`] and [`crate::plan::to_mermaid`]).

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::{CliError, load_plan_or_exit, write_output};

/// Diagram language.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GraphFormat {
    /// Graphviz DOT (`dot -Tsvg tree.dot > tree.svg`).
    #[default]
    Dot,
    /// Mermaid flowchart (renders in GitHub/GitLab Markdown and mermaid.live).
    Mermaid,
}

/// Arguments of `graph`.
#[derive(Debug, Args)]
pub struct GraphArgs {
    /// Tree file (YAML).
    pub tree: PathBuf,
    /// Diagram language.
    #[arg(long, value_enum, default_value_t = GraphFormat::Dot)]
    pub format: GraphFormat,
    /// Write to this file instead of stdout.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
}

/// Runs `macrotree graph`: validates the tree (exit 2 with located errors) and prints it.
pub fn graph(app: &crate::App, args: GraphArgs) -> Result<(), CliError> {
    let plan = load_plan_or_exit(app, &args.tree)?;
    let text = match args.format {
        GraphFormat::Dot => crate::plan::to_dot(&plan),
        GraphFormat::Mermaid => crate::plan::to_mermaid(&plan),
    };
    write_output(
        args.out.as_deref(),
        &super::outputs::tree_inputs(&args.tree, &plan),
        &text,
    )
}
