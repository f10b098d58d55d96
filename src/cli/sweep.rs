//! `macrotree sweep TREE --scenarios N`: the tree over N seeded random layouts, in parallel.
//!
//! Exit codes: 0 when every scenario succeeded, 1 when any failed, 2 on bad input.

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::Arc;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::{CliError, load_task};
use crate::episode::Goal;
use crate::faults::FaultKind;
use crate::sweep::{RunTiming, SweepConfig, Timings, run_sweep_streaming};

/// Arguments of `sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// The tree file (YAML).
    pub tree: PathBuf,
    /// Sweep this scene file instead of the tree's own `scene:` (or the built-in cube_bowl).
    #[arg(long, value_name = "FILE.yaml")]
    pub scene: Option<PathBuf>,
    /// Number of scenarios (indices 0..N, N ≤ 10 000 000); with --shard, only this shard's share
    /// of them runs.
    #[arg(long, value_name = "N", value_parser = super::limits::scenarios)]
    pub scenarios: u64,
    /// Sweep seed: scenario k of seed S is the same layout and episode seed everywhere.
    #[arg(long, default_value_t = 0, value_name = "S")]
    pub seed: u64,
    /// Worker threads, 1…1024 (default: one per core).
    #[arg(long, short = 'j', value_name = "J", value_parser = super::limits::jobs)]
    pub jobs: Option<u64>,
    /// Inject this fault through physics in every scenario (see docs/faults.md).
    #[arg(long, value_parser = super::limits::fault())]
    pub fault: Option<FaultKind>,
    /// Success means: `scene` = the tree succeeded and the scene's goal holds; `bowl` = the tree
    /// succeeded and the cube rests in the bowl; `tree` = the tree succeeded.
    #[arg(long, value_parser = super::limits::goal(), default_value = "scene")]
    pub goal: Goal,
    /// Contacts that should not happen (the arm, the fingers or the held block on a container,
    /// an obstacle or another block): `count` them (default), or `fail` the episode at the first
    /// one (failure kind `collision`).
    #[arg(long, value_parser = super::limits::collisions(), default_value = "count")]
    pub collisions: crate::episode::CollisionPolicy,
    /// Write one JSON line per scenario here, in scenario order (a regular file or a new path);
    /// the run's times go beside it, to FILE.jsonl.timing.json, for `report`.
    #[arg(long, value_name = "FILE.jsonl")]
    pub out: Option<PathBuf>,
    /// Keep the complete results already in --out (from an interrupted run of this same sweep)
    /// and run only the missing scenarios.
    #[arg(long, requires = "out")]
    pub resume: bool,
    /// Print the summary as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
    /// Run only the scenarios with index ≡ K (mod M), 0 ≤ K < M; `auto` takes K and M from a
    /// Slurm array job (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT) or a Kubernetes Indexed Job
    /// (JOB_COMPLETION_INDEX and --shard-count M); see docs/scale_out.md.
    #[arg(long, value_name = "K/M|auto")]
    pub shard: Option<crate::sweep::ShardSpec>,
    /// M for `--shard auto` in a Kubernetes Indexed Job (its `completions`); with Slurm, a check.
    #[arg(long, value_name = "M", requires = "shard", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub shard_count: Option<u64>,
    /// Replace the leaves whose path matches PATTERN (`main/**/grasp`) with a scripted outcome:
    /// success, failure, running:N or fail_first:N (repeatable; see docs/testing_trees.md).
    #[arg(long = "substitute", value_name = "PATTERN=OUTCOME")]
    pub substitute: Vec<crate::runtime::substitute::Substitution>,
    /// Stop each episode (as a failure) after this much simulated time, seconds (at most 3600).
    #[arg(long, default_value_t = crate::episode::DEFAULT_MAX_SIM_TIME_S, value_name = "S", value_parser = super::limits::max_sim_time)]
    pub max_sim_time: f64,
    /// Write the episodes, in scenario order, as a LeRobot v3.0 dataset in this folder (new or
    /// empty; see docs/datasets.md).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub dataset: Option<PathBuf>,
    /// Cameras of --dataset, comma-separated (`front`, `wrist`, `overview`), or `none` for the
    /// episode data without videos.
    #[arg(
        long,
        value_name = "LIST",
        default_value = "front,wrist",
        requires = "dataset"
    )]
    pub cameras: String,
    /// Frames per second of simulated time of --dataset: a whole number of 4 ms control periods
    /// per frame (1, 2, 5, 10, 25, 50, 125 or 250), so a policy can act at the data's rate.
    #[arg(long, value_name = "N", default_value_t = crate::dataset::DEFAULT_FRAME_RATE, requires = "dataset", value_parser = crate::dataset::parse_frame_rate)]
    pub fps: u32,
    /// Image size of --dataset's cameras, WxH pixels (even, at most 1280x960).
    #[arg(long, value_name = "WxH", default_value = "320x240", requires = "dataset")]
    pub size: crate::render::FrameSize,
    /// Write only the episodes that met the goal into --dataset.
    #[arg(long, requires = "dataset")]
    pub only_success: bool,
    /// Replace the dataset macrotree wrote earlier at --dataset DIR.
    #[arg(long, requires = "dataset")]
    pub overwrite: bool,
    /// Noise added to what --dataset's episodes execute, the recorded actions staying the clean
    /// commands (DART): `JOINT_SIGMA[,GRIPPER_SIGMA]`, radians (at most 0.2) and gripper actuator
    /// units (at most 100), redrawn every 0.1 s from the episode seed (see docs/datasets.md).
    #[arg(long, value_name = "SIGMA[,G]", requires = "dataset", conflicts_with = "out", allow_hyphen_values = true, value_parser = crate::faults::ActionNoise::parse)]
    pub noise: Option<crate::faults::ActionNoise>,
}

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
            crate::sweep::run_scene_scenario(cell, &plan, app.factory(), &config, index),
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
        if !r.success {
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
