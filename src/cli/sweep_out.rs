//! The JSONL file of `sweep --out`, and `--resume`: checked before the sweep starts, installed
//! safely (see [`crate::output`]), then written one whole line per scenario.

use std::path::Path;
use std::sync::Arc;

use super::CliError;
use super::outputs::output_error;
use crate::output::{LineFile, OutputFile};
use crate::plan::Plan;
use crate::sim::Scene;
use crate::sweep::SweepConfig;
use crate::sweep::resume::{Resumed, read_existing, spot_check};

/// The checked output of a sweep, not yet touched: [`Prepared::start`] installs it.
pub(super) struct Prepared {
    out: OutputFile,
    /// The results kept from the interrupted run (`--resume`).
    pub resumed: Resumed,
}

impl Prepared {
    /// Installs the file (holding the kept results) and opens it for the new lines.
    pub(super) fn start(&self) -> Result<LineFile, CliError> {
        self.out.stream(&self.resumed.kept).map_err(output_error)
    }
}

/// Checks the output of a sweep of `tree` at `path`, which must be none of `inputs` (the files
/// the sweep reads): with `resume`, reads the complete results already there (checked to belong
/// to this sweep); otherwise the file will start empty (saying so when it replaces an existing
/// file). Nothing is written until [`Prepared::start`].
pub(super) fn prepare(
    path: &Path,
    resume: bool,
    inputs: &[std::path::PathBuf],
    config: &SweepConfig,
    scene: &Scene,
    plan: &Arc<Plan>,
) -> Result<Prepared, CliError> {
    let inputs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let out = OutputFile::check(path, &inputs).map_err(output_error)?;
    let resumed = if resume && out.is_stream() {
        return Err(CliError::Input(format!(
            "error: --resume needs the results of the interrupted run: give the file they were \
             written to as --out, not {}",
            path.display()
        )));
    } else if resume {
        let resumed =
            read_existing(path, scene, config).map_err(|e| CliError::Input(format!("error: {e}")))?;
        spot_check(scene, plan, config, &resumed).map_err(|reason| {
            CliError::Input(format!(
                "error: cannot resume from {}: {reason}; resume with the same options, or run \
                 without --resume to start over",
                path.display()
            ))
        })?;
        eprintln!(
            "resuming {}: {} of {} scenario(s) already done{}",
            path.display(),
            resumed.results.len(),
            config.indices().len(),
            if resumed.dropped_bytes > 0 {
                format!(
                    " (dropped a truncated last line of {} bytes)",
                    resumed.dropped_bytes
                )
            } else {
                String::new()
            }
        );
        resumed
    } else {
        if out.replaces_existing() {
            eprintln!("overwriting existing {}", path.display());
        }
        Resumed::default()
    };
    Ok(Prepared { out, resumed })
}
