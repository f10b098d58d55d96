//! The JSONL file of `sweep --out`, and `--resume`: checked and locked before the sweep starts,
//! installed safely (see [`crate::output`]), then written one whole line per scenario; and its
//! timing file beside it ([`Timings`]), written when the sweep ends.

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use super::CliError;
use super::outputs::output_error;
use crate::output::{LineFile, OutputFile};
use crate::plan::Plan;
use crate::sim::Scene;
use crate::sweep::resume::{Resumed, read_existing, spot_check};
use crate::sweep::tally::Tally;
use crate::sweep::{RunTiming, SweepConfig, Timings};

/// The checked (and locked) output of a sweep, not yet touched: [`Prepared::start`] installs it.
pub(super) struct Prepared {
    out: OutputFile,
    /// The existing file, open and locked (kept lines are copied from it).
    held: Option<Arc<File>>,
    /// The results kept from the interrupted run (`--resume`).
    pub resumed: Resumed,
    /// The timing file beside it (`None` when the output is a stream).
    pub timing: Option<TimingOut>,
}

/// The timing file of a sweep's `--out` file, checked before the sweep starts.
pub(super) struct TimingOut {
    out: OutputFile,
    /// The runs that wrote the kept lines (`--resume`), when their timing file covers them all.
    before: Option<Timings>,
}

impl TimingOut {
    /// Writes the timing file: the earlier runs' (when they cover the kept lines) and `run`.
    pub(super) fn write(self, run: RunTiming) -> Result<(), CliError> {
        let timings = self.before.unwrap_or_default().then(run);
        self.out
            .write_all(timings.to_json().as_bytes())
            .map_err(output_error)
    }
}

impl Prepared {
    /// Installs the file (holding the kept results) and opens it for the new lines. A timing
    /// file left beside it by an earlier run is removed: it no longer describes the lines.
    pub(super) fn start(&self) -> Result<LineFile, CliError> {
        if let Some(t) = &self.timing {
            match std::fs::remove_file(t.out.path()) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(CliError::Input(format!(
                        "error: cannot remove the stale timing file {}: {e}",
                        t.out.path().display()
                    )));
                }
            }
        }
        match &self.held {
            Some(file) if self.resumed.kept_len > 0 => self
                .out
                .stream_from(file, self.resumed.kept_len)
                .map_err(output_error),
            _ => self.out.stream(&[]).map_err(output_error),
        }
    }
}

/// What the sweep runs, against which a resumed file's last line is checked by running it again.
#[derive(Clone, Copy)]
pub(super) struct Task<'a> {
    /// The scene, compiled with the robot.
    pub scene: &'a Scene,
    /// The tree.
    pub plan: &'a Arc<Plan>,
    /// How its leaves run.
    pub factory: &'a crate::factory::Factory,
}

/// Checks the output of a sweep at `path`, which must be none of `inputs` (the files the sweep
/// reads), and takes its lock (a second writer is refused): with `resume`, reads the complete
/// results already there (checked to belong to this sweep) into `tally`; otherwise the file will
/// start empty (saying so when it replaces an existing file). Nothing is written until
/// [`Prepared::start`].
pub(super) fn prepare(
    path: &Path,
    resume: bool,
    inputs: &[std::path::PathBuf],
    config: &SweepConfig,
    task: Task<'_>,
    tally: &mut Tally,
) -> Result<Prepared, CliError> {
    let Task { scene, plan, factory } = task;
    let inputs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let mut out = OutputFile::check(path, &inputs).map_err(output_error)?;
    if resume && out.is_stream() {
        return Err(CliError::Input(format!(
            "error: --resume needs the results of the interrupted run: give the file they were \
             written to as --out, not {}",
            path.display()
        )));
    }
    let held = out.lock_existing().map_err(output_error)?;
    let resumed = match (&held, resume) {
        (Some(file), true) => {
            let resumed = read_existing(file, path, scene, config, |r| tally.add(r))
                .map_err(|e| CliError::Input(format!("error: {e}")))?;
            spot_check(scene, plan, factory, config, resumed.last.as_ref()).map_err(|reason| {
                CliError::Input(format!(
                    "error: cannot resume from {}: {reason}; resume with the same options, or run \
                     without --resume to start over",
                    path.display()
                ))
            })?;
            eprintln!(
                "resuming {}: {} of {} scenario(s) already done{}",
                path.display(),
                resumed.count,
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
        }
        _ => {
            if out.replaces_existing() && !resume {
                eprintln!("overwriting existing {}", path.display());
            }
            Resumed::default()
        }
    };
    let timing = if out.is_stream() {
        None
    } else {
        let sidecar = Timings::path_beside(path);
        let timing_out = OutputFile::check(&sidecar, &inputs).map_err(output_error)?;
        // A timing file that does not cover exactly the kept lines is not carried on.
        let before = if resumed.count > 0 {
            Timings::read(&sidecar)
                .ok()
                .flatten()
                .filter(|t| t.lines() == resumed.count)
        } else {
            None
        };
        Some(TimingOut {
            out: timing_out,
            before,
        })
    };
    Ok(Prepared {
        out,
        held,
        resumed,
        timing,
    })
}
