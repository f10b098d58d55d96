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

/// The files a tree reads: the tree file, every file it includes and the scene file it names
/// (just the tree file when it cannot be loaded; the caller reports that).
pub(super) fn tree_inputs(tree: &Path) -> Vec<PathBuf> {
    let mut files = vec![tree.to_path_buf()];
    if let Ok(spec) = crate::spec::load_file(tree) {
        files.extend(spec.files);
        if let Some((rel, _)) = &spec.scene {
            files.push(tree.parent().unwrap_or(Path::new(".")).join(rel));
        }
    }
    files
}

/// An output error as bad input (exit 2).
pub(super) fn output_error(e: OutputError) -> CliError {
    CliError::Input(format!("error: {e}"))
}

/// The digest of the files a sweep reads (see [`crate::sweep::digest`]).
pub(super) fn inputs_digest(inputs: &[PathBuf]) -> String {
    let files: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    crate::sweep::digest::files_digest(&files)
}

/// The files a scenario file's sweep reads: its tree (with includes and `scene:`) and its
/// `scene:` override.
pub(super) fn suite_inputs(file: &crate::suite::ScenarioFile) -> Vec<PathBuf> {
    let mut inputs = tree_inputs(&file.tree);
    inputs.extend(file.scene.clone());
    inputs
}
