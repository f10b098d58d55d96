//! `macrotree run TREE`: one headless episode.

use std::path::PathBuf;
use std::sync::Arc;

use clap::Args;

use super::args::{CubeArg, XyArg};
use super::{CliError, load_task};
use crate::dataset::EpisodeRecorder;
use crate::episode::{EpisodeConfig, EpisodeObserver, Goal, NoObserver, run_episode};
use crate::sim::{Layout, Scene};
use crate::viewer::{LiveViewer, Recorder, ViewObserver, ViewerOptions};

/// Arguments of `run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// The tree file (YAML).
    pub tree: PathBuf,
    #[command(flatten)]
    pub episode: EpisodeArgs,
    /// Print the episode report as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
    /// Serve the live 3D view (MeshCat) and the tree's status on http://127.0.0.1:PORT; keeps
    /// serving after the episode until Ctrl-C.
    #[arg(long)]
    pub view: bool,
    /// Port of the live view (0 picks a free one).
    #[arg(long, default_value_t = crate::viewer::DEFAULT_PORT, requires = "view")]
    pub port: u16,
    /// Pause the live episode at every node whose path matches PATTERN (the glob of
    /// --substitute), when it starts, or when it finishes with `PATTERN@after`; resume or step
    /// from the page. Repeatable.
    #[arg(long = "break", value_name = "PATTERN[@after]", requires = "view")]
    pub breaks: Vec<crate::viewer::BreakSpec>,
    /// Pace the simulation to wall-clock time so a person can watch.
    #[arg(long, conflicts_with = "speed")]
    pub realtime: bool,
    /// Pace the simulation at X times real time.
    #[arg(long, value_name = "X", value_parser = super::limits::speed)]
    pub speed: Option<f64>,
    /// Write the episode as one self-contained HTML replay (plays offline); a regular file or a
    /// new path, never the tree itself (see docs/security.md).
    #[arg(long, value_name = "FILE.html")]
    pub record: Option<PathBuf>,
    /// Write an H.264 MP4 of the episode from one camera, with the simulated time and the
    /// running leaf drawn on it (needs EGL/OpenGL and the pinned ffmpeg; see README).
    #[arg(long, value_name = "FILE.mp4", conflicts_with = "view")]
    pub video: Option<PathBuf>,
    /// Camera of --video: `front`, `overview` or `wrist`.
    #[arg(long, value_name = "NAME", default_value = "front", requires = "video")]
    pub camera: String,
    /// Image size of --video, WxH pixels (even, at most 1280x960).
    #[arg(long, value_name = "WxH", default_value = "640x480", requires = "video")]
    pub size: crate::render::FrameSize,
    /// Frames per second of simulated time of --video and --frames (1…250).
    #[arg(long, value_name = "N", default_value_t = 30, value_parser = crate::video::parse_fps)]
    pub fps: u32,
    /// Write the episode sampled at --fps as JSON lines (state, action, object poses, running
    /// leaf), the same frames `sweep --dataset` writes (see docs/datasets.md).
    #[arg(long, value_name = "FILE.jsonl", conflicts_with = "view")]
    pub frames: Option<PathBuf>,
}

/// Calls two episode observers in turn.
struct Both<'a>(&'a mut dyn EpisodeObserver, &'a mut dyn EpisodeObserver);

impl EpisodeObserver for Both<'_> {
    fn on_period_start(
        &mut self,
        cell: &crate::actions::Cell,
        command: &crate::motion::CellCommand,
        runner: &mut crate::runtime::TreeRunner,
    ) {
        self.0.on_period_start(cell, command, runner);
        self.1.on_period_start(cell, command, runner);
    }
    fn on_event(&mut self, event: crate::episode::EpisodeEvent<'_>) {
        self.0.on_event(event);
        self.1.on_event(event);
    }
    fn on_tick(&mut self, cell: &crate::actions::Cell, runner: &mut crate::runtime::TreeRunner) {
        self.0.on_tick(cell, runner);
        self.1.on_tick(cell, runner);
    }
}

/// Layout and limits shared by `run` and `bench`.
#[derive(Debug, Args)]
pub struct EpisodeArgs {
    /// Run on this scene file instead of the tree's own `scene:` (or the built-in cube_bowl).
    #[arg(long, value_name = "FILE.yaml")]
    pub scene: Option<PathBuf>,
    /// Start from scenario K of a sweep (the same layout and episode seed as `sweep --seed S`
    /// gives scenario K); see --sweep-seed.
    #[arg(long, value_name = "K", conflicts_with_all = ["cube", "bowl", "seed"])]
    pub scenario: Option<u64>,
    /// The sweep seed S of --scenario.
    #[arg(long, value_name = "S", default_value_t = 0, requires = "scenario")]
    pub sweep_seed: u64,
    /// Cube centre and yaw: X,Y[,YAW] (metres; the yaw in degrees, or with its unit: `30deg`,
    /// `0.5236rad`). Default 0.45,-0.18,0.
    #[arg(long, value_name = "X,Y[,YAW]", allow_hyphen_values = true)]
    pub cube: Option<CubeArg>,
    /// Bowl centre: X,Y (metres). Default 0.45,0.08.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true)]
    pub bowl: Option<XyArg>,
    /// Seed for fault timing and magnitude.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Stop the episode (as a failure) after this much simulated time, seconds (at most 3600).
    #[arg(long, default_value_t = crate::episode::DEFAULT_MAX_SIM_TIME_S, value_name = "S", value_parser = super::limits::max_sim_time)]
    pub max_sim_time: f64,
    /// Inject a fault through physics (see docs/faults.md).
    #[arg(long, value_parser = super::limits::fault())]
    pub fault: Option<crate::faults::FaultKind>,
    /// Success means: `scene` = the tree succeeded and the scene's goal holds; `bowl` = the tree
    /// succeeded and the cube rests in the bowl; `tree` = the tree succeeded (its own
    /// conditions check the task).
    #[arg(long, value_parser = super::limits::goal(), default_value = "scene")]
    pub goal: Goal,
    /// Contacts that should not happen (the arm, the fingers or the held block on a container,
    /// an obstacle or another block): `count` them (default), or `fail` the episode at the first
    /// one (failure kind `collision`).
    #[arg(long, value_parser = super::limits::collisions(), default_value = "count")]
    pub collisions: crate::episode::CollisionPolicy,
    /// Replace the leaves whose path matches PATTERN (`main/**/grasp`) with a scripted outcome:
    /// success, failure, running:N or fail_first:N (repeatable; see docs/testing_trees.md).
    #[arg(long = "substitute", value_name = "PATTERN=OUTCOME")]
    pub substitute: Vec<crate::runtime::substitute::Substitution>,
}

impl EpisodeArgs {
    /// The episode configuration these arguments describe, with the scene's default placement
    /// (see [`config_on`](Self::config_on) for `--cube`, `--bowl` and `--scenario`).
    pub fn config(&self) -> Result<EpisodeConfig, CliError> {
        if !(self.max_sim_time.is_finite() && self.max_sim_time > 0.0) {
            return Err(CliError::Input(format!(
                "error: --max-sim-time must be a positive number of seconds, got {}",
                self.max_sim_time
            )));
        }
        Ok(EpisodeConfig {
            placement: None,
            seed: self.seed,
            max_sim_time: self.max_sim_time,
            fault: self.fault,
            goal: self.goal,
            substitutions: self.substitute.clone(),
            collisions: self.collisions,
            ..EpisodeConfig::default()
        })
    }
}

impl EpisodeArgs {
    /// The legacy layout `--cube` and `--bowl` describe (the tutorial's default for what they
    /// leave out).
    pub fn layout(&self) -> Layout {
        let mut layout = Layout::default();
        if let Some(c) = self.cube {
            layout.cube_xy = [c.x, c.y];
            layout.cube_yaw = c.yaw_deg.to_radians();
        }
        if let Some(b) = self.bowl {
            layout.bowl_xy = [b.x, b.y];
        }
        layout
    }

    /// The episode configuration on `scene`: [`config`](Self::config) with every object placed —
    /// `--scenario K` draws the sweep's scenario K, `--cube`/`--bowl` move the scene's cube and
    /// bowl, otherwise the scene's poses (or, for a randomized scene without them, scenario 0 of
    /// seed 0). The placement is checked (on the table, clear of the robot's base and of each
    /// other, blocks within reach) before anything is simulated.
    pub fn config_on(&self, scene: &Scene) -> Result<EpisodeConfig, CliError> {
        let mut config = self.config()?;
        check_goal(config.goal, scene)?;
        let placement = if let Some(k) = self.scenario {
            let sweep = crate::sweep::SweepConfig {
                seed: self.sweep_seed,
                ..crate::sweep::SweepConfig::default()
            };
            let s = sweep.scenario(scene, k).map_err(|e| {
                CliError::Input(format!("error: scenario {k} of seed {}: {e}", self.sweep_seed))
            })?;
            config.seed = s.seed;
            s.placement
        } else {
            if (self.cube.is_some() && scene.spec.legacy_cube().is_none())
                || (self.bowl.is_some() && scene.spec.legacy_bowl().is_none())
            {
                return Err(CliError::Input(format!(
                    "error: --cube/--bowl place the scene's only block and container, but scene `{}` has {} blocks and {} containers; use --scenario K to draw a layout",
                    scene.spec.name,
                    scene.spec.of_kind(crate::scene::ObjectKind::Block).count(),
                    scene.spec.of_kind(crate::scene::ObjectKind::Container).count()
                )));
            }
            scene.placement_from_layout(&self.layout())
        };
        placement.check(&scene.spec).map_err(|e| {
            CliError::Input(format!(
                "error: the layout is not allowed: {e}\n  help: objects stand on the table (|x|, |y| ≤ 1 m), clear of the robot's base (within {} m of the origin) and of each other; blocks {:.2} … {:.2} m from the base",
                crate::scene::ROBOT_BASE_RADIUS,
                crate::scene::reach_limits()[0],
                crate::scene::reach_limits()[1]
            ))
        })?;
        config.placement = Some(placement);
        Ok(config)
    }
}

/// `--goal bowl` judges the scene's cube in its bowl: refused (bad input) for a scene without
/// them, where it could never succeed.
pub(super) fn check_goal(goal: Goal, scene: &Scene) -> Result<(), CliError> {
    let spec = &scene.spec;
    if goal == Goal::Bowl && (spec.legacy_cube().is_none() || spec.legacy_bowl().is_none()) {
        return Err(CliError::Input(format!(
            "error: --goal bowl checks that the scene's cube rests in its bowl, but scene `{}` has {} blocks and {} containers (the cube and the bowl are the ones called `cube` and `bowl`, else the only block and the only container)\n  help: use --goal scene (the scene's own goal) or --goal tree",
            spec.name,
            spec.of_kind(crate::scene::ObjectKind::Block).count(),
            spec.of_kind(crate::scene::ObjectKind::Container).count()
        )));
    }
    if goal == Goal::Scene && spec.goal.is_empty() {
        tracing::warn!(target: "macrotree::cli", scene = %spec.name, "--goal scene on a scene without a goal");
        eprintln!(
            "warning: --goal scene, but scene `{}` declares no goal: success means only that the tree succeeded\n  help: add a `goal:` to the scene (see docs/scenes.md), or pass --goal tree to say so",
            spec.name
        );
    }
    Ok(())
}

/// Runs `macrotree run`.
pub fn run(app: &crate::App, args: RunArgs) -> Result<(), CliError> {
    args.episode.config()?;
    let (plan, scene) = load_task(app, &args.tree, args.episode.scene.as_deref())?;
    let plan = Arc::new(plan);
    let mut config = args.episode.config_on(&scene)?;
    config.resolved = Some(super::resolve_substitutions(&plan, &config.substitutions)?);
    let mut inputs = super::outputs::tree_inputs(&args.tree, &plan);
    inputs.extend(args.episode.scene.clone());
    super::output_set::refuse_same_outputs(&[
        ("--record", args.record.as_deref()),
        ("--video", args.video.as_deref()),
        ("--frames", args.frames.as_deref()),
    ])?;
    let record_out = (args.record.as_deref())
        .map(|p| super::outputs::check_output(p, &inputs))
        .transpose()?;
    let video_out = (args.video.as_deref())
        .map(|p| super::outputs::check_output(p, &inputs))
        .transpose()?;
    let frames_out = (args.frames.as_deref())
        .map(|p| super::outputs::check_output(p, &inputs))
        .transpose()?;
    let pending_video = video_out
        .as_ref()
        .map(|o| o.pending())
        .transpose()
        .map_err(super::outputs::output_error)?;
    let mut recorder_for_frames = if video_out.is_some() || frames_out.is_some() {
        let rec = EpisodeRecorder::new(plan.clone(), args.fps);
        Some(match &pending_video {
            Some(tmp) => {
                let camera = crate::render::camera_ids(&scene, std::slice::from_ref(&args.camera))
                    .map_err(|e| CliError::Input(format!("error: --camera: {e}")))?[0];
                crate::video::find_ffmpeg().map_err(|e| CliError::Input(format!("error: {e}")))?;
                // Fail before simulating when there is no OpenGL.
                crate::render::with_thread_renderer(&scene.model, args.size, |_| ())
                    .map_err(|e| CliError::Input(format!("error: {e}")))?;
                rec.with_camera(camera, args.size, tmp.path().to_path_buf())
                    .map_err(|e| CliError::Input(format!("error: {e}")))?
                    .with_overlay(true)
            }
            None => rec,
        })
    } else {
        None
    };
    tracing::info!(tree = %args.tree.display(), scene = %scene.spec.name, seed = config.seed, "episode start");
    let speed = match (args.realtime, args.speed) {
        (true, _) => Some(1.0),
        (false, Some(x)) if x.is_finite() && x > 0.0 => Some(x),
        (false, Some(x)) => {
            return Err(CliError::Input(format!(
                "error: --speed must be a positive number, got {x}"
            )));
        }
        (false, None) => None,
    };
    // A --break pattern that matches no node is refused before the viewer starts; a live view
    // also pauses at the tree file's own `breakpoints:` (checked the same way, located).
    let mut breaks = args.breaks.clone();
    if args.view {
        breaks.extend(super::breakpoints::declared(&plan).map_err(|d| super::invalid(d, plan.file.clone()))?);
    }
    crate::viewer::Monitor::new(&plan, &breaks).map_err(|e| CliError::Input(format!("error: {e}")))?;
    let live = if args.view {
        let opts = ViewerOptions {
            port: args.port,
            ..ViewerOptions::default()
        };
        let live =
            LiveViewer::start(&scene.model, &opts).map_err(|e| CliError::Input(format!("error: {e}")))?;
        eprintln!("live view: {} (Ctrl-C to stop)", live.url());
        Some(live)
    } else {
        None
    };
    if args.record.is_some() {
        // Fail before simulating if the bundle the replay inlines is missing.
        crate::viewer::load_bundle().map_err(|path| {
            CliError::Input(format!(
                "error: {}",
                crate::viewer::ViewerError::BundleMissing { path }
            ))
        })?;
    }
    let recorder = args.record.as_ref().map(|_| Recorder::new(&scene.model));
    let mut frame_recorder = recorder_for_frames.take();
    let report = if live.is_some() || recorder.is_some() || speed.is_some() {
        let mut view = ViewObserver::new(&plan, live, recorder, speed);
        view.set_breakpoints(&plan, &breaks)
            .map_err(|e| CliError::Input(format!("error: {e}")))?;
        let report = match frame_recorder.as_mut() {
            Some(frames) => run_episode(
                &scene,
                plan.clone(),
                app.factory(),
                &config,
                &mut Both(&mut view, frames),
            ),
            None => run_episode(&scene, plan.clone(), app.factory(), &config, &mut view),
        };
        let (live, recorder) = view.finish();
        if let (Some(rec), Some(out)) = (recorder, &record_out) {
            rec.write_to(out)
                .map_err(|e| CliError::Input(format!("error: {e}")))?;
            eprintln!("replay written to {}", out.path().display());
        }
        finish_report(&report, args.episode.goal, args.json);
        if let Some(live) = live {
            eprintln!("episode over; still serving {} (Ctrl-C to stop)", live.url());
            live.serve_forever();
        }
        report
    } else {
        let report = match frame_recorder.as_mut() {
            Some(frames) => run_episode(&scene, plan, app.factory(), &config, frames),
            None => run_episode(&scene, plan, app.factory(), &config, &mut NoObserver),
        };
        finish_report(&report, args.episode.goal, args.json);
        report
    };
    if let Some(rec) = frame_recorder {
        let recording = rec.finish().map_err(|e| CliError::Input(format!("error: {e}")))?;
        if let (Some(tmp), Some(out)) = (pending_video, &video_out) {
            tmp.install().map_err(super::outputs::output_error)?;
            let per = |s: f64| s * 1e3 / recording.renders.max(1) as f64;
            let (wall, cpu) = (
                per(recording.render_time.as_secs_f64()),
                per(recording.render_cpu_s),
            );
            eprintln!(
                "video written to {} ({} frames, {} at {} fps; rendering {wall:.1} ms wall, {cpu:.1} ms CPU per frame)",
                out.path().display(),
                recording.clips.first().map_or(0, |c| c.frames),
                args.size,
                args.fps
            );
        }
        if let Some(out) = &frames_out {
            let mut text = String::new();
            for f in &recording.frames {
                text += &serde_json::to_string(f).expect("a frame serializes");
                text.push('\n');
            }
            out.write_all(text.as_bytes())
                .map_err(super::outputs::output_error)?;
            eprintln!(
                "{} frames written to {}",
                recording.frames.len(),
                out.path().display()
            );
        }
    }
    if report.outcome.success {
        Ok(())
    } else {
        Err(CliError::TaskFailed)
    }
}

/// What a successful episode achieved, in the words of the goal that was checked: the scene's
/// goal predicates, the cube in the bowl, or only the tree's own success.
fn success_message(report: &crate::episode::EpisodeReport, goal: Goal) -> String {
    match goal {
        Goal::Tree => "the tree succeeded (goal checked: the tree's own conditions)".to_string(),
        Goal::Bowl => "the tree succeeded and the cube rests in the bowl".to_string(),
        Goal::Scene if report.outcome.goal.is_empty() => "the tree succeeded".to_string(),
        Goal::Scene => {
            let holds: Vec<String> = report.outcome.goal.iter().map(|g| g.predicate.clone()).collect();
            format!(
                "the tree succeeded and the scene's goal holds: {}",
                holds.join(", ")
            )
        }
    }
}

/// `x` seconds rounded to the millisecond (the logs' resolution; the control period is 4 ms).
fn ms(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

fn finish_report(report: &crate::episode::EpisodeReport, goal: Goal, json: bool) {
    if report.outcome.success {
        tracing::info!(
            sim_time_s = ms(report.outcome.sim_time_s),
            grasp_attempts = report.outcome.grasp_attempts,
            "episode succeeded: {}",
            success_message(report, goal)
        );
    } else {
        tracing::warn!(
            reason = report.outcome.failure_reason.as_deref().unwrap_or(""),
            node = report.outcome.failed_node.as_deref().unwrap_or("-"),
            sim_time_s = ms(report.outcome.sim_time_s),
            "episode failed"
        );
    }
    print_summary(report, goal, json);
    if json {
        println!("{}", serde_json::to_string(report).expect("report serializes"));
    }
}

fn print_summary(r: &crate::episode::EpisodeReport, goal: Goal, json: bool) {
    use super::human::say;
    say!(
        json,
        "{}: tree {}, {:.2} s simulated in {:.3} s wall ({} physics steps), {} grasp attempt(s)",
        if r.outcome.success { "SUCCESS" } else { "FAILURE" },
        r.outcome.tree_status,
        r.outcome.sim_time_s,
        r.wall_time_s,
        r.outcome.physics_steps,
        r.outcome.grasp_attempts
    );
    if let Some(reason) = &r.outcome.failure_reason {
        say!(json, "  reason: {reason}");
    }
    if let Some(node) = &r.outcome.failed_node {
        say!(json, "  failed node: {node}");
    }
    for n in r.outcome.nodes.iter().filter(|n| n.counts.overridden > 0) {
        say!(
            json,
            "  result forced from the monitor: {} ({}×; its successes and failures count them)",
            n.path,
            n.counts.overridden
        );
    }
    if goal != Goal::Scene {
        say!(
            json,
            "  success judged by --goal {}{}",
            goal.name(),
            if goal == Goal::Tree {
                " (the tree's own conditions); the scene's goal below is shown, not checked"
            } else {
                ""
            }
        );
    }
    for o in &r.outcome.objects {
        let [x, y, z, yaw] = o.end;
        say!(
            json,
            "  {} {}: final ({x:.3}, {y:.3}, {z:.3}) m, yaw {yaw:.1}°",
            o.kind,
            o.name
        );
    }
    for g in &r.outcome.goal {
        let matched = g
            .matched_yaw_deg
            .map(|y| format!(" (the block's yaw, at the quarter turn nearest the goal's: {y:.1}°)"))
            .unwrap_or_default();
        say!(
            json,
            "  goal: {} {}{matched}",
            g.predicate,
            if g.holds { "holds" } else { "does NOT hold" }
        );
    }
    say!(json, "  success judged by {}", r.goal_checked);
    for c in &r.outcome.collisions {
        say!(json, "  collision at {:.2} s ({}): {}", c.time, c.label(), c.what);
    }
    // The cube and bowl lines only for a scene that has a cube (see `World::cube`).
    let Some(legacy) = &r.outcome.cube_bowl else {
        return;
    };
    let xyz = |p: [f64; 3]| format!("({:.3}, {:.3}, {:.3}) m", p[0], p[1], p[2]);
    match legacy.bowl_target {
        Some(bowl) => say!(
            json,
            "  cube final {}, bowl target {}",
            xyz(legacy.cube_final),
            xyz(bowl)
        ),
        None => say!(json, "  cube final {}", xyz(legacy.cube_final)),
    }
    let c = &legacy.checks;
    say!(
        json,
        "  checks: grasp distance {} m, motion while closed {:.3} m, lift while closed {:.3} m, home error {:.4} rad{}",
        c.grasp_distance.map_or("-".into(), |d| format!("{d:.4}")),
        c.cube_motion_while_closed,
        c.cube_lift_while_closed,
        c.home_error,
        if legacy.bowl_target.is_some() {
            format!(", in bowl {}", c.in_bowl)
        } else {
            String::new()
        }
    );
}
