//! `macrotree sweep TREE --scenarios N`: the tree over N seeded random layouts, in parallel.
//!
//! Exit codes: 0 when every scenario succeeded, 1 when any failed, 2 on bad input.

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::sync::Arc;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::sweep_args::SweepArgs;
use super::{CliError, load_task};
use crate::sweep::{RunTiming, SweepConfig, Timings, run_sweep_streaming};

/// Runs `macrotree sweep`.
pub fn sweep(app: &crate::App, args: SweepArgs) -> Result<(), CliError> {
    if !(args.max_sim_time.is_finite() && args.max_sim_time > 0.0) {
        return Err(CliError::Input(format!(
            "error: --max-sim-time must be a positive number of seconds, got {}",
            args.max_sim_time
        )));
    }
    let shard = super::resolve_shard(args.shard, args.shard_count)?;
    let (plan, scene) = load_task(app, &args.tree, args.scene.as_deref())?;
    let resolved = super::resolve_substitutions(&plan, &args.substitute)?;
    super::run::check_goal(args.goal, &scene)?;
    let plan = Arc::new(plan);
    // Every file the sweep reads: never an output, and digested into every result line.
    let mut inputs = super::outputs::tree_inputs(&args.tree, &plan);
    inputs.extend(args.scene.clone());
    let config = SweepConfig {
        scenarios: args.scenarios,
        seed: args.seed,
        jobs: args.jobs.map_or(0, |j| j as usize),
        fault: args.fault,
        noise: args.noise,
        goal: args.goal,
        shard,
        max_sim_time: args.max_sim_time,
        scene_file: args.scene.as_ref().map(|p| p.display().to_string()),
        tree: args.tree.display().to_string(),
        substitutions: args.substitute.clone(),
        resolved: Some(resolved),
        suite: None,
        tree_digest: Some(super::outputs::inputs_digest(&inputs)),
        collisions: args.collisions,
        program: super::program_name(),
    };
    let total = config.indices().len() as u64;
    if total == 0 {
        return Err(CliError::Input(format!(
            "error: shard {} of {} scenario(s) is empty (no index below {} is {} mod {}); \
             use more --scenarios or fewer shards",
            shard.map_or(String::new(), |s| s.to_string()),
            config.scenarios,
            config.scenarios,
            shard.map_or(0, |s| s.index),
            shard.map_or(1, |s| s.count),
        )));
    }
    // Every option is checked before any output is touched.
    if let (Some(out), Some(dir)) = (&args.out, &args.dataset) {
        super::output_set::refuse_output_inside("--out", out, "--dataset", dir)?;
    }
    let tree = args.tree.display().to_string();
    let mut tally = crate::sweep::tally::Tally::new(&tree, &config);
    let prepared = match &args.out {
        Some(path) => Some(super::sweep_out::prepare(
            path,
            args.resume,
            &inputs,
            &config,
            super::sweep_out::Task {
                scene: &scene,
                plan: &plan,
                factory: app.factory(),
            },
            &mut tally,
        )?),
        None => None,
    };
    let mut dataset = match &args.dataset {
        Some(dir) => Some(super::dataset::start(&args, dir, &scene, &plan, &config)?),
        None => None,
    };
    let mut out = prepared.as_ref().map(|p| p.start()).transpose()?;
    let (resumed, timing_out) = prepared.map_or_else(Default::default, |p| (p.resumed, p.timing));
    let done = resumed.count;
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {rate} eta {eta} {msg}")
            .expect("valid template")
            .with_key(
                "rate",
                |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{:.0}/min", s.per_sec() * 60.0);
                },
            )
            .progress_chars("=> "),
    );
    bar.set_position(done);
    let mut failures = 0u64;
    let mut write_error = None;
    let mut dataset_error = None;
    let recorder = dataset.as_ref().map(|d| d.recorder());
    let episode = |cell: &mut crate::actions::Cell, index: u64| match &recorder {
        Some(rec) => {
            let (r, recording) = rec.run(cell, &plan, app.factory(), &config, index);
            (r, Some(recording))
        }
        None => (
            crate::sweep::run_scenario(
                cell,
                &plan,
                app.factory(),
                &config,
                index,
                &mut crate::episode::NoObserver,
            ),
            None,
        ),
    };
    let run = run_sweep_streaming(&scene, &config, done, episode, |r, recording| {
        let r = &r;
        tally.add(r);
        if let Some(w) = out.as_mut()
            && let Err(e) = w.write_line(&r.to_jsonl())
        {
            write_error = Some(e);
            return ControlFlow::Break(());
        }
        if let Some(d) = dataset.as_mut()
            && let Err(e) = d.add(r, recording.flatten())
        {
            dataset_error = Some(e);
            return ControlFlow::Break(());
        }
        if !r.outcome.success {
            failures += 1;
            bar.set_message(format!("{failures} failed"));
        }
        bar.inc(1);
        ControlFlow::Continue(())
    })
    .map_err(|e| CliError::Input(format!("error: cannot start {} worker threads: {e}", config.jobs)))?;
    bar.finish_and_clear();
    if let (Some(e), Some(w)) = (write_error, &out) {
        return Err(CliError::Input(format!(
            "error: {e}\nthe sweep stopped: the file keeps its {} complete line(s) of {total}; fix \
             the problem and add --resume to run the rest",
            done + w.lines()
        )));
    }
    if let Some(w) = out {
        w.finish().map_err(super::outputs::output_error)?;
    }
    if let Some(e) = dataset_error {
        return Err(CliError::Input(format!(
            "error: {e}\nthe sweep stopped; the dataset was not written"
        )));
    }
    if let Some(d) = dataset {
        d.finish()?;
    }
    let summary = tally.finish(run.wall_time_s, run.jobs);
    let timing = RunTiming {
        lines: summary.scenarios.saturating_sub(done),
        jobs: run.jobs,
        wall_time_s: run.wall_time_s,
        process_wall_time_s: super::process_elapsed_s(),
        physics_time_s: run.physics_time_s,
        planning_time_s: summary.planning.wall_time_s,
    };
    if let Some(t) = timing_out {
        t.write(timing)?;
    }
    let total = Timings::default().then(timing).total().expect("one run");
    let summary = summary.with_timing(&total);
    super::human::say_text!(args.json, summary.to_text());
    if args.json {
        println!("{}", serde_json::to_string(&summary).expect("summary serializes"));
    }
    if summary.all_succeeded() {
        Ok(())
    } else {
        Err(CliError::TaskFailed)
    }
}
