//! `macrotree plan SCENE`: one motion-planning query in a cell, as a leaf would ask it.
//!
//! The scene is laid out as `run` lays it out (the scene's poses, or `--scenario K` of a sweep),
//! and the arm is planned from `--from` (home by default) to `--to-joints` or to the tool
//! pointing down at `--to-point` (every IK branch, at `--yaw` and the yaw half a turn away),
//! with the planner and margin the leaves use, but without their allowances: a start in contact
//! is `start_in_collision`. It prints the plan's statistics and waypoints, or the typed reason
//! there is none: the query a MoveIt user sends from RViz, without a tree.

use std::path::PathBuf;

use clap::Args;
use nalgebra::Vector3;
use serde::Serialize;

use super::CliError;
use super::args::{JointsArg, PointArg};
use super::run::EpisodeArgs;
use crate::actions::{CONTROL_PERIOD, Cell};
use crate::motion::plan::{GoalSet, PlannedMotion, PlannerConfig};

/// Largest `--max-checks`: fifty times the planner's default budget (20 000 checks).
pub const MAX_PLAN_CHECKS: u64 = 1_000_000;

/// Arguments of `plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The scene file (YAML).
    pub scene: PathBuf,
    /// Lay the scene out as scenario K of a sweep (see --sweep-seed); default: the scene's own
    /// poses (scenario 0 of seed 0 for a randomized scene).
    #[arg(long, value_name = "K")]
    pub scenario: Option<u64>,
    /// The sweep seed S of --scenario.
    #[arg(long, value_name = "S", default_value_t = 0, requires = "scenario")]
    pub sweep_seed: u64,
    /// Start: `home` or six joint angles J1,…,J6 (radians).
    #[arg(
        long,
        value_name = "home|J1,…,J6",
        default_value = "home",
        allow_hyphen_values = true
    )]
    pub from: JointsArg,
    /// Goal: six joint angles J1,…,J6 (radians).
    #[arg(
        long,
        value_name = "J1,…,J6",
        allow_hyphen_values = true,
        conflicts_with = "to_point",
        required_unless_present = "to_point"
    )]
    pub to_joints: Option<JointsArg>,
    /// Goal: the tool pointing down with its pinch point at X,Y,Z (metres, world frame).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub to_point: Option<PointArg>,
    /// The finger axis's yaw at --to-point, degrees (−360 … 360; or with its unit, `30deg`,
    /// `0.5236rad`); the yaw half a turn away is equivalent and also a goal.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, requires = "to_point", allow_hyphen_values = true, value_parser = super::args::yaw_degrees)]
    pub yaw: f64,
    /// Clearance margin, metres (0 … 0.1; the leaves use 0.005).
    #[arg(long, value_name = "M", value_parser = super::limits::margin)]
    pub margin: Option<f64>,
    /// The planner's seed (its random samples; the same query and seed give the same path).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The planner's collision-check budget (1 … 1 000 000; the leaves' default otherwise).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=MAX_PLAN_CHECKS))]
    pub max_checks: Option<u64>,
    /// Print the result as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// What `plan --json` prints. Angles in radians, lengths in metres, times in seconds.
#[derive(Debug, Serialize)]
pub struct PlanReport {
    /// The scene's name.
    pub scene: String,
    /// The start configuration.
    pub from: [f64; 6],
    /// The clearance margin the query used.
    pub margin_m: f64,
    /// Goal configurations offered (every IK branch of a point goal).
    pub goals: usize,
    /// The planner's seed.
    pub seed: u64,
    /// True when a motion was found.
    pub success: bool,
    /// The failure kind when there is none (`start_in_collision`, `goal_in_collision`,
    /// `unreachable`, `no_path`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure_kind: Option<String>,
    /// What the reason names.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Configurations given to the collision checker, found or not.
    pub collision_checks: u64,
    /// Wall-clock planning time, seconds (the only figure that depends on the machine).
    pub planning_time_s: f64,
    /// The plan, when found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plan: Option<PlanFound>,
}

/// A found motion.
#[derive(Debug, Serialize)]
pub struct PlanFound {
    /// The goal configuration reached.
    pub goal: [f64; 6],
    /// Goal configurations inside the joint limits and free.
    pub free_goals: usize,
    /// True when the straight joint-space segment was free (no search).
    pub direct: bool,
    /// Search iterations.
    pub iterations: usize,
    /// Nodes of both search trees.
    pub nodes: usize,
    /// Checks the conservative screen answered without MuJoCo.
    pub screened: u64,
    /// Joint-space length of the path, radians (after shortcutting; as found).
    pub length_rad: f64,
    /// Joint-space length of the path the search found, radians.
    pub raw_length_rad: f64,
    /// Corners blended.
    pub blends: usize,
    /// Duration of the timed trajectory within the UR5e's limits, seconds.
    pub duration_s: f64,
    /// The shortcut path's waypoints, start and goal included.
    pub waypoints: Vec<[f64; 6]>,
}

impl PlanFound {
    fn of(m: &PlannedMotion) -> Self {
        let s = &m.stats;
        let waypoints = m.trajectory.waypoints().to_vec();
        Self {
            goal: waypoints.last().copied().unwrap_or_default(),
            free_goals: s.free_goals,
            direct: s.direct,
            iterations: s.iterations,
            nodes: s.nodes,
            screened: s.screened,
            length_rad: s.length,
            raw_length_rad: s.raw_length,
            blends: s.blends,
            duration_s: s.duration,
            waypoints,
        }
    }
}

/// Runs `plan`: exit 0 with a motion, 1 with the typed reason there is none, 2 on bad input.
pub fn plan(args: PlanArgs) -> Result<(), CliError> {
    let spec = crate::scene::load_scene_file(&args.scene)
        .map_err(|diags| super::invalid(diags, args.scene.display().to_string()))?;
    let scene = crate::sim::Scene::load_spec(&spec).map_err(|e| CliError::Input(format!("error: {e}")))?;
    let placement = layout(&args, &scene)?;
    let bounds = PlannerConfig::default().bounds;
    let from = args.from.resolve("--from", &bounds)?;
    let goals = match (&args.to_joints, &args.to_point) {
        (Some(j), _) => GoalSet::configs(vec![j.resolve("--to-joints", &bounds)?]),
        (None, Some(p)) => GoalSet::down(&Vector3::new(p.x, p.y, p.z), args.yaw.to_radians(), false, &from),
        (None, None) => return Err(CliError::Input("error: give --to-joints or --to-point".into())),
    };
    let mut cell = Cell::new(&scene, &crate::sim::Layout::default(), CONTROL_PERIOD);
    cell.reset_placement(&placement);
    let Some(checker) = cell.checker() else {
        return Err(CliError::Input(format!(
            "error: scene `{}` has no collision checker to plan with (see the warning above)",
            scene.spec.name
        )));
    };
    if let Some(m) = args.margin {
        checker
            .set_margin(m)
            .map_err(|e| CliError::Input(format!("error: --margin: {e}")))?;
    }
    let defaults = PlannerConfig::default();
    let config = PlannerConfig {
        seed: args.seed,
        max_checks: args.max_checks.unwrap_or(defaults.max_checks),
        ..defaults
    };
    let result = crate::motion::plan::plan(checker, &from, &goals, &config);
    let stats = match &result {
        Ok(m) => &m.stats,
        Err(e) => &e.stats,
    };
    tracing::debug!(target: "macrotree::plan", goals = goals.len(), stats = %stats.summary(), "plan query");
    let failure = result.as_ref().err().map(crate::sim::planning::plan_failure);
    let report = PlanReport {
        scene: scene.spec.name.clone(),
        from,
        margin_m: checker.margin(),
        goals: goals.len(),
        seed: args.seed,
        success: result.is_ok(),
        failure_kind: failure.as_ref().map(|f| f.kind.as_str().to_string()),
        message: failure.as_ref().map(|f| f.message.clone()),
        collision_checks: stats.collision_checks,
        planning_time_s: stats.planning_time.as_secs_f64(),
        plan: result.as_ref().ok().map(PlanFound::of),
    };
    print(&report, args.json);
    if report.success {
        Ok(())
    } else {
        Err(CliError::TaskFailed)
    }
}

/// The placement `run --scene SCENE [--scenario K --sweep-seed S]` would start from.
fn layout(args: &PlanArgs, scene: &crate::sim::Scene) -> Result<crate::scene::Placement, CliError> {
    let episode = EpisodeArgs {
        scene: None,
        scenario: args.scenario,
        sweep_seed: args.sweep_seed,
        cube: None,
        bowl: None,
        seed: 0,
        max_sim_time: crate::episode::DEFAULT_MAX_SIM_TIME_S,
        fault: None,
        goal: crate::episode::Goal::Tree,
        collisions: crate::episode::CollisionPolicy::default(),
        substitute: Vec::new(),
    };
    let config = episode.config_on(scene)?;
    Ok(config.placement.unwrap_or_else(|| scene.default_placement()))
}

fn joints(q: &[f64; 6]) -> String {
    let v: Vec<String> = q.iter().map(|x| format!("{x:.4}")).collect();
    v.join(", ")
}

fn print(r: &PlanReport, json: bool) {
    if json {
        println!(
            "{}",
            serde_json::to_string(r).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
        );
        return;
    }
    let mut out = String::new();
    match &r.plan {
        Some(p) => {
            out.push_str(&format!(
                "planned in `{}` (margin {:.1} mm): {} of {} goal configurations free, {}\n",
                r.scene,
                r.margin_m * 1e3,
                p.free_goals,
                r.goals,
                if p.direct { "direct" } else { "searched" }
            ));
            out.push_str(&format!(
                "  {:.2} ms, {} iterations, {} nodes, {} checks ({} screened)\n",
                r.planning_time_s * 1e3,
                p.iterations,
                p.nodes,
                r.collision_checks,
                p.screened
            ));
            out.push_str(&format!(
                "  path {:.3} rad ({:.3} found), {} waypoints, {} blends, {:.3} s\n  waypoints (rad):\n",
                p.length_rad,
                p.raw_length_rad,
                p.waypoints.len(),
                p.blends,
                p.duration_s
            ));
            for w in &p.waypoints {
                out.push_str(&format!("    [{}]\n", joints(w)));
            }
        }
        None => out.push_str(&format!(
            "no motion in `{}` (margin {:.1} mm, {} goal configurations): {}: {}\n",
            r.scene,
            r.margin_m * 1e3,
            r.goals,
            r.failure_kind.as_deref().unwrap_or("other"),
            r.message.as_deref().unwrap_or("")
        )),
    }
    print!("{out}");
}
