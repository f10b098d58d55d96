//! `macrotree validate TREE...`: parse and check trees without simulating.

use std::path::PathBuf;

use clap::Args;

use super::CliError;

/// Arguments of `validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Tree files (YAML).
    #[arg(required = true)]
    pub trees: Vec<PathBuf>,
}

/// Runs `macrotree validate`: every error of every file, exit 2 if any.
pub fn validate(args: ValidateArgs) -> Result<(), CliError> {
    let mut failed = 0;
    for tree in &args.trees {
        match crate::plan::load_plan(tree) {
            Ok(plan) => println!(
                "{}: ok ({} nodes, {} leaves)",
                tree.display(),
                plan.nodes.len(),
                plan.leaves.len()
            ),
            Err(diags) => {
                failed += 1;
                for d in &diags {
                    eprintln!("{d}");
                }
            }
        }
    }
    if failed > 0 {
        Err(CliError::Input(format!(
            "error: {failed} of {} file(s) invalid",
            args.trees.len()
        )))
    } else {
        Ok(())
    }
}
