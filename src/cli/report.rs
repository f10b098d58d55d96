//! `macrotree report FILE.jsonl…`: merges the `--out` files of sharded sweeps or `macrotree
//! test` runs into the summary (and, for tests, the JUnit report) of one unsharded run. A sweep's
//! wall time, jobs and physics and planning shares come from the timing files beside its
//! files (`FILE.timing.json`, written by `sweep --out`).
//!
//! Exit codes as for `sweep` / `test`: 0 when every scenario succeeded (every expectation held),
//! 1 when not, 2 on bad input (unreadable or mixed files, missing or duplicate scenarios).

use std::path::PathBuf;

use clap::Args;

use super::CliError;
use super::outputs::check_output;
use crate::suite::{SuiteOutcome, load_scenario_file};
use crate::sweep::{Source, Summary, Timings, Total, merge_results};

/// Arguments of `report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// JSONL files written by `sweep --out` or `test --out` (the shards of one run, any order).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print the summary as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
    /// For `macrotree test` results: write the JUnit XML report here.
    #[arg(long, value_name = "FILE.xml")]
    pub junit: Option<PathBuf>,
}

/// The timings of the files a sweep's lines came from, put together: `None` unless every file
/// has a timing file beside it that covers exactly its lines (a missing one, or one left by a
/// run that did not write all of them, cannot give the run's times).
fn timing_of(sources: &[Source]) -> Result<Option<Total>, CliError> {
    let mut total: Option<Total> = None;
    for source in sources {
        let timings = Timings::read(&Timings::path_beside(&source.path))
            .map_err(|e| CliError::Input(format!("error: {e}")))?;
        let Some(t) = timings
            .filter(|t| t.lines() == source.lines)
            .and_then(|t| t.total())
        else {
            return Ok(None);
        };
        total = Some(total.map_or(t, |sum| sum.beside(t)));
    }
    Ok(total)
}

/// Runs `macrotree report`.
pub fn report(app: &crate::App, args: ReportArgs) -> Result<(), CliError> {
    let mut merged = merge_results(&args.files).map_err(|e| CliError::Input(format!("error: {e}")))?;
    for m in &mut merged {
        m.config.program = super::program_name();
    }
    let is_test = merged.iter().any(|m| m.config.suite.is_some());
    if !is_test {
        if args.junit.is_some() {
            return Err(CliError::Input(
                "error: --junit needs `macrotree test` results (these are a sweep's)".into(),
            ));
        }
        let m = &merged[0];
        let mut summary = Summary::new(&m.config.tree, &m.config, &m.results, 0.0, 0);
        if let Some(total) = timing_of(&m.sources)? {
            summary = summary.with_timing(&total);
        }
        super::human::say_text!(args.json, summary.to_text());
        if args.json {
            println!("{}", serde_json::to_string(&summary).expect("summary serializes"));
        }
        return if summary.all_succeeded() {
            Ok(())
        } else {
            Err(CliError::TaskFailed)
        };
    }
    // Expectations live in the scenario files: read them again, and check that they still
    // describe the runs the lines came from.
    let mut files = Vec::new();
    for m in &merged {
        let path = PathBuf::from(m.config.suite.as_deref().unwrap_or_default());
        crate::spec::confine::check_path_from_results(&path, app.loader().allows_includes_anywhere())
            .map_err(|e| CliError::Input(format!("error: {e}")))?;
        let file = load_scenario_file(&path, &app.registry().failure_kinds())
            .map_err(|d| super::invalid(d, format!("{} (named by the results)", path.display())))?;
        let mut same = file.sweep.clone();
        same.jobs = 0;
        same.shard = None;
        same.program = super::program_name();
        same.tree_digest = Some(super::outputs::inputs_digest(
            &super::outputs::suite_inputs_read_again(app, &file),
        ));
        if same != m.config {
            return Err(CliError::Input(format!(
                "error: {} no longer describes the run in these results (tree, scene, count, seed, fault, goal, time limit or substitutions changed); run `macrotree test` again",
                path.display()
            )));
        }
        files.push(file);
    }
    let mut inputs = args.files.clone();
    inputs.extend(files.iter().map(|f| f.path.clone()));
    let junit = args
        .junit
        .as_deref()
        .map(|p| check_output(p, &inputs))
        .transpose()?;
    let outcomes: Vec<_> = files
        .iter()
        .zip(merged)
        .map(|(f, m)| {
            let o = SuiteOutcome::new(f, &m.results, 0.0, 0);
            (f, o, m.results)
        })
        .collect();
    let paths: Vec<PathBuf> = files.iter().map(|f| f.path.clone()).collect();
    let names = crate::suite::names::shared_folder_names(&paths);
    super::test::finish(&outcomes, &names, junit.as_ref(), args.json)
}
