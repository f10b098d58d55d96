//! A scenario file checked without running anything, the same way for `test` (before it runs)
//! and `validate`: the file itself, its scene, its tree for that scene, its substitutions and
//! its node patterns — every error located.

use std::path::Path;
use std::sync::Arc;

use crate::plan::Plan;
use crate::runtime::substitute::Resolved;
use crate::spec::Diagnostic;
use crate::suite::{ScenarioFile, load_scenario_file};

/// A scenario file that passed every check, with what running it needs.
pub(super) struct CheckedScenario {
    /// The file as read.
    pub file: ScenarioFile,
    /// Its tree, compiled for its scene.
    pub plan: Plan,
    /// Its substitutions resolved against that plan.
    pub resolved: Resolved,
}

/// Checks the scenario file at `path` and everything it names.
pub(super) fn check_scenario(app: &crate::App, path: &Path) -> Result<CheckedScenario, Vec<Diagnostic>> {
    let file = load_scenario_file(path, &app.registry().failure_kinds())?;
    let scene = match &file.scene {
        Some(p) => Some(Arc::new(
            crate::scene::load_scene_file(p).map_err(|d| named_by(d, path))?,
        )),
        None => None,
    };
    let plan = app
        .loader()
        .load_for(&file.tree, scene)
        .map_err(|d| named_by(d, path))?;
    let resolved = file.check_against(&plan)?;
    Ok(CheckedScenario { file, plan, resolved })
}

/// Diagnostics of a file the scenario file names, each noting which scenario file named it.
fn named_by(mut diags: Vec<Diagnostic>, scenario: &Path) -> Vec<Diagnostic> {
    for d in &mut diags {
        d.note
            .get_or_insert_with(|| format!("named by the scenario file {}", scenario.display()));
    }
    diags
}
