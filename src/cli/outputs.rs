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

/// The digest of the files a sweep reads (see [`crate::sweep::digest`]).
pub(super) fn inputs_digest(inputs: &[PathBuf]) -> String {
    let files: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    crate::sweep::digest::files_digest(&files)
}

/// The files a scenario file's sweep reads: its tree (with includes and `scene:`, as `plan`
/// read them) and its `scene:` override.
pub(super) fn suite_inputs(file: &crate::suite::ScenarioFile, plan: &crate::plan::Plan) -> Vec<PathBuf> {
    let mut inputs = tree_inputs(&file.tree, plan);
    inputs.extend(file.scene.clone());
    inputs
}

/// [`suite_inputs`] of a scenario file whose tree is read again now (`report`); a tree that no
/// longer loads counts as its file and the scene override alone (its digest then differs).
pub(super) fn suite_inputs_read_again(app: &crate::App, file: &crate::suite::ScenarioFile) -> Vec<PathBuf> {
    let scene = file
        .scene
        .as_deref()
        .and_then(|p| crate::scene::load_scene_file(p).ok())
        .map(std::sync::Arc::new);
    match app.loader().load_for(&file.tree, scene) {
        Ok(plan) => suite_inputs(file, &plan),
        Err(_) => [file.tree.clone()]
            .into_iter()
            .chain(file.scene.clone())
            .collect(),
    }
}
