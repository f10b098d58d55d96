//! `macrotree test [PATH…]`: runs scenario files (default: `scenarios/`) and checks their
//! expectations; a summary per file, `--junit FILE.xml`, `--out FILE.jsonl`, `--json`.
//!
//! Exit codes: 0 when every expectation holds, 1 when one does not, 2 on bad input (any
//! scenario file, tree, scene or substitution invalid: nothing runs).

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::Arc;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;

use super::CliError;
use super::outputs::{check_output, output_error};
use super::scenario_check::{CheckedScenario, check_scenario};
use crate::suite::junit::{Case, to_xml};
use crate::suite::{ScenarioFile, SuiteOutcome, find_files, offending_commands};
use crate::sweep::run_sweep_from;

/// Most reproduce commands listed per failing scenario file (JUnit and text).
const MAX_LISTED: usize = 20;

/// Arguments of `test`.
#[derive(Debug, Args)]
pub struct TestArgs {
    /// Scenario files, or folders to search for `*.yaml` (default: scenarios/).
    pub paths: Vec<PathBuf>,
    /// Worker threads (default: one per core).
    #[arg(long, short = 'j', value_name = "J", value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub jobs: Option<u64>,
    /// Run only the scenarios with index ≡ K (mod M) of every file; `auto` as for `sweep`
    /// (Slurm array or Kubernetes Indexed Job). Merge the shards' --out with `macrotree report`.
    #[arg(long, value_name = "K/M|auto")]
    pub shard: Option<crate::sweep::ShardSpec>,
    /// M for `--shard auto` in a Kubernetes Indexed Job.
    #[arg(long, value_name = "M", requires = "shard", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub shard_count: Option<u64>,
    /// Write a JUnit XML report here (one test case per scenario file).
    #[arg(long, value_name = "FILE.xml")]
    pub junit: Option<PathBuf>,
    /// Write one JSON line per scenario here (the sweep's lines, each naming its `suite`).
    #[arg(long, value_name = "FILE.jsonl")]
    pub out: Option<PathBuf>,
    /// In every scenario file: contacts that should not happen (the arm, the fingers or the held block on a container,
    /// an obstacle or another block): `count` them (default), or `fail` the episode at the first
    /// one (failure kind `collision`).
    #[arg(long, value_parser = super::limits::collisions(), default_value = "count")]
    pub collisions: crate::episode::CollisionPolicy,
    /// Print the outcome as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
    /// Check every scenario file, its scene, its tree, its substitutions and its node patterns,
    /// and run nothing: exit 0 when all are valid, 2 with every error located otherwise.
    #[arg(long, conflicts_with_all = ["junit", "out", "json", "shard"])]
    pub check: bool,
}

/// The whole outcome, as `--json` prints it.
#[derive(Debug, Serialize)]
pub(super) struct TestReport {
    /// Every expectation of every file holds.
    pub passed: bool,
    /// Scenario files run.
    pub files: usize,
    /// Files whose expectations all hold.
    pub files_passed: usize,
    /// Each file's outcome.
    pub suites: Vec<SuiteOutcome>,
}

/// Runs `macrotree test`.
pub fn test(app: &crate::App, args: TestArgs) -> Result<(), CliError> {
    let shard = super::resolve_shard(args.shard, args.shard_count)?;
    let paths = if args.paths.is_empty() {
        vec![PathBuf::from("scenarios")]
    } else {
        args.paths.clone()
    };
    let files = find_files(&paths).map_err(|e| CliError::Input(format!("error: {e}")))?;
    if files.is_empty() {
        return Err(CliError::Input(format!(
            "error: no scenario files (*.yaml) in {}",
            paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    // Everything is checked before anything runs, and every file's errors are reported.
    let mut diags = Vec::new();
    let mut checked = Vec::new();
    for f in &files {
        match check_scenario(app, f) {
            Ok(c) => checked.push(c),
            Err(d) => diags.extend(d),
        }
    }
    if !diags.is_empty() {
        return Err(super::invalid(diags, format!("{} scenario file(s)", files.len())));
    }
    if args.check {
        for c in &checked {
            super::print_warnings(&c.plan);
            println!(
                "{}: ok ({} scenarios of {})",
                c.file.path.display(),
                c.file.sweep.scenarios,
                c.file.tree.display()
            );
        }
        println!(
            "{} scenario file(s) checked; nothing was run (--check)",
            checked.len()
        );
        return Ok(());
    }
    let mut inputs: Vec<PathBuf> = files.clone();
    let mut suites = Vec::new();
    let mut tasks = Vec::new();
    for CheckedScenario {
        file: mut s,
        plan,
        resolved,
    } in checked
    {
        super::print_warnings(&plan);
        let scene =
            crate::sim::Scene::load_spec(&plan.scene).map_err(|e| CliError::Input(format!("error: {e}")))?;
        s.sweep.resolved = Some(Arc::new(resolved));
        s.sweep.shard = shard;
        s.sweep.jobs = args.jobs.map_or(0, |j| j as usize);
        s.sweep.program = super::program_name();
        s.sweep.collisions = args.collisions;
        let read = super::outputs::suite_inputs(&s, &plan);
        s.sweep.tree_digest = Some(super::outputs::inputs_digest(&read));
        inputs.extend(read);
        tasks.push((Arc::new(plan), scene));
        suites.push(s);
    }
    super::output_set::refuse_same_outputs(&[
        ("--junit", args.junit.as_deref()),
        ("--out", args.out.as_deref()),
    ])?;
    let junit_out = args
        .junit
        .as_deref()
        .map(|p| check_output(p, &inputs))
        .transpose()?;
    let mut out = match &args.out {
        Some(p) => Some(check_output(p, &inputs)?.stream(&[]).map_err(output_error)?),
        None => None,
    };
    let total: u64 = suites.iter().map(|s| s.sweep.indices().len() as u64).sum();
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let mut outcomes = Vec::new();
    for (s, (plan, scene)) in suites.iter().zip(&tasks) {
        bar.set_message(s.path.display().to_string());
        let mut write_error = None;
        let run = run_sweep_from(scene, plan, app.factory(), &s.sweep, 0, |r| {
            if let Some(w) = out.as_mut()
                && let Err(e) = w.write_line(&r.to_jsonl())
            {
                write_error = Some(e);
                return ControlFlow::Break(());
            }
            bar.inc(1);
            ControlFlow::Continue(())
        })
        .map_err(|e| CliError::Input(format!("error: cannot start worker threads: {e}")))?;
        if let Some(e) = write_error {
            bar.finish_and_clear();
            return Err(output_error(e));
        }
        outcomes.push((
            s,
            SuiteOutcome::new(s, &run.results, run.wall_time_s, run.jobs),
            run.results,
        ));
    }
    bar.finish_and_clear();
    if let Some(w) = out {
        w.finish().map_err(output_error)?;
    }
    let names = crate::suite::names::case_names(&paths, &files);
    finish(&outcomes, &names, junit_out.as_ref(), args.json)
}

/// Prints the outcome of every file and the totals, writes the JUnit file (test case `names`,
/// one per outcome: see [`crate::suite::names`]), and maps the verdict to the exit code (shared
/// with `macrotree report`).
pub(super) fn finish(
    outcomes: &[(&ScenarioFile, SuiteOutcome, Vec<crate::sweep::ScenarioResult>)],
    names: &[String],
    junit: Option<&crate::output::OutputFile>,
    json: bool,
) -> Result<(), CliError> {
    use super::human::say;
    let mut cases = Vec::new();
    for ((file, o, results), name) in outcomes.iter().zip(names) {
        let sm = &o.summary;
        say!(
            json,
            "{} {}: {} of {} succeeded, sim time median {:.2} s, p95 {:.2} s{}",
            if o.passed { "PASS" } else { "FAIL" },
            o.file,
            sm.successes,
            sm.scenarios,
            sm.median_sim_time_s,
            sm.p95_sim_time_s,
            sm.shard
                .as_ref()
                .map_or(String::new(), |k| format!(" (shard {k})"))
        );
        let mut details = String::new();
        for c in &o.checks {
            say!(
                json,
                "  {} {}: {}",
                if c.ok { "ok  " } else { "FAIL" },
                c.expectation,
                c.measured
            );
            if !c.ok {
                details += &format!("expected {}: {}\n", c.expectation, c.measured);
            }
        }
        for g in &sm.failure_groups {
            say!(json, "  failures: {} × {} at {}", g.count, g.kind, g.node);
        }
        say!(json, "  collisions: {}", sm.collisions.line());
        let cmds = offending_commands(&file.expect, results, &file.sweep);
        if !o.passed && !cmds.is_empty() {
            details += "reproduce:\n";
            say!(json, "  reproduce:");
            for c in cmds.iter().take(MAX_LISTED) {
                say!(json, "    {c}");
                details += &format!("  {c}\n");
            }
            if cmds.len() > MAX_LISTED {
                say!(json, "    … and {} more (see --out)", cmds.len() - MAX_LISTED);
                details += &format!("  … and {} more\n", cmds.len() - MAX_LISTED);
            }
        }
        let failed = o.checks.iter().filter(|c| !c.ok).count();
        cases.push(Case {
            name: name.clone(),
            time_s: sm.wall_time_s,
            failure: (!o.passed).then(|| (format!("{failed} expectation(s) failed"), details)),
            out: sm.to_text(),
        });
    }
    let passed = outcomes.iter().filter(|(_, o, _)| o.passed).count();
    say!(json, "{} of {} scenario file(s) passed", passed, outcomes.len());
    if let Some(j) = junit {
        j.write_all(to_xml(&cases).as_bytes()).map_err(output_error)?;
    }
    if json {
        let report = TestReport {
            passed: passed == outcomes.len(),
            files: outcomes.len(),
            files_passed: passed,
            suites: outcomes.iter().map(|(_, o, _)| o.clone()).collect(),
        };
        println!(
            "{}",
            serde_json::to_string(&report).expect("the report serializes")
        );
    }
    if passed == outcomes.len() {
        Ok(())
    } else {
        Err(CliError::TaskFailed)
    }
}
