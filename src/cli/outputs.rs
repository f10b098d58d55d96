//! The commands' side of [`crate::output`]: an output path is checked against the command's
//! input files before any work starts, and overwriting an existing file is said on stderr.

use std::path::{Path, PathBuf};

use super::CliError;
use crate::output::{OutputError, OutputFile};

/// Checks `path` as an output of a command that reads `inputs`; says on stderr when it will
/// replace an existing file. Bad paths are bad input (exit 2).
pub(super) fn check_output(path: &Path, inputs: &[PathBuf]) -> Result<OutputFile, CliError> {
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let out = OutputFile::check(path, &inputs).map_err(output_error)?;
    if out.replaces_existing() {
        eprintln!("overwriting existing {}", path.display());
    }
    Ok(out)
}

/// The files a loaded tree read: the tree file as given, every file it includes and the scene
/// file it names.
pub(super) fn tree_inputs(tree: &Path, plan: &crate::plan::Plan) -> Vec<PathBuf> {
    let mut files = vec![tree.to_path_buf()];
    files.extend(plan.inputs.iter().cloned());
    files
}

/// An output error as bad input (exit 2).
pub(super) fn output_error(e: OutputError) -> CliError {
    CliError::Input(format!("error: {e}"))
}
