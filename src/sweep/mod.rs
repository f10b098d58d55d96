//! Sweeps: a tree run over many seeded, randomized layouts (optionally with a fault), in
//! parallel, with results in scenario order — the library behind `macrotree sweep`.
//!
//! Scenario `k` of sweep seed `S` ([`sample_scenario`]) depends only on `(S, k)`, so a sweep gives
//! the same results for any number of jobs, and the shards `K/M` of a sweep (the scenarios with
//! `k ≡ K mod M`) concatenate into the full sweep. One [`Cell`] (one `MjData` of the shared model)
//! per worker thread is reset before every scenario.
//!
//! ```no_run
//! use std::sync::Arc;
//! use macrotree::sweep::{SweepConfig, run_sweep};
//!
//! let scene = macrotree::sim::Scene::load().unwrap();
//! let app = macrotree::App::new();
//! let plan = Arc::new(app.load_tree("trees/cube_to_bowl.yaml".as_ref()).unwrap());
//! let config = SweepConfig { scenarios: 100, seed: 1, ..SweepConfig::default() };
//! let run = run_sweep(&scene, &plan, app.factory(), &config, |r| println!("{}", r.to_jsonl())).unwrap();
//! println!("{} of {} succeeded", run.results.iter().filter(|r| r.success).count(), run.results.len());
//! ```

pub mod digest;
mod indices;
pub mod layout;
pub mod report;
pub mod resume;
mod summary;
pub mod tally;

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

pub use indices::ScenarioIndices;
pub use layout::{Region, Scenario, ScenarioLayout, sample_scenario, sample_scenario_in};
pub use report::{MergeError, Merged, merge_results};
pub use summary::{Coverage, Failure, FailureGroup, NodeTotals, Summary, percentile, wilson_interval};

use crate::actions::{CONTROL_PERIOD, Cell, Checks};
use crate::episode::Collision;
use crate::episode::{EpisodeConfig, EpisodeReport, Goal, NoObserver, NodeReport, ObjectReport, run_in_cell};
use crate::factory::Factory;
use crate::failure::FailureKind;
use crate::faults::FaultKind;
use crate::plan::Plan;
use crate::runtime::substitute::Substitution;
use crate::scene::{Placement, PlacementError, sample_placement};
use crate::sim::{Layout, Scene};
use crate::world::goal::GoalValue;

/// `--shard K/M`: the scenarios whose index is ≡ K (mod M), `0 ≤ K < M`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Shard {
    /// K.
    pub index: u64,
    /// M.
    pub count: u64,
}

impl Shard {
    /// Scenario `i` belongs to this shard.
    pub fn contains(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let form = "expected K/M with 0 ≤ K < M, e.g. 0/4 (shard K of M, counted from 0)";
        let (k, m) = s.split_once('/').ok_or_else(|| format!("{s:?}: {form}"))?;
        let k: u64 = k.trim().parse().map_err(|_| format!("{s:?}: {form}"))?;
        let m: u64 = m.trim().parse().map_err(|_| format!("{s:?}: {form}"))?;
        if m == 0 || k >= m {
            return Err(format!("{s:?}: {form}"));
        }
        Ok(Self { index: k, count: m })
    }
}

/// `--shard`: a fixed `K/M`, or `auto` (from a Slurm array or a Kubernetes Indexed Job).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardSpec {
    /// `K/M`.
    Fixed(Shard),
    /// `auto`: see [`Shard::from_env`].
    Auto,
}

impl FromStr for ShardSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim() == "auto" {
            Ok(ShardSpec::Auto)
        } else {
            s.parse()
                .map(ShardSpec::Fixed)
                .map_err(|e| format!("{e}, or auto"))
        }
    }
}

/// Most shards `--shard auto` accepts from the environment.
pub const MAX_AUTO_SHARDS: u64 = 1_000_000;

impl Shard {
    /// The shard of this process in a job array, read through `var` (the environment):
    ///
    /// - Slurm array (`sbatch --array=0-3`): K = `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN`
    ///   (0 when unset), M = `SLURM_ARRAY_TASK_COUNT`; `count`, if given, must equal M;
    /// - Kubernetes Indexed Job: K = `JOB_COMPLETION_INDEX`, M = `count` (the Job's
    ///   `completions`, which the pod cannot read), required.
    ///
    /// Errors say which variable is missing or inconsistent.
    pub fn from_env(var: impl Fn(&str) -> Option<String>, count: Option<u64>) -> Result<Shard, String> {
        let num = |name: &str| -> Result<Option<u64>, String> {
            match var(name) {
                None => Ok(None),
                Some(v) => v
                    .trim()
                    .parse::<u64>()
                    .map(Some)
                    .map_err(|_| format!("{name}={v:?} is not a whole number")),
            }
        };
        let check = |k: u64, m: u64, how: &str| -> Result<Shard, String> {
            if m == 0 || m > MAX_AUTO_SHARDS {
                return Err(format!(
                    "{how}: the shard count must be 1 to {MAX_AUTO_SHARDS}, got {m}"
                ));
            }
            if k >= m {
                return Err(format!("{how}: index {k} is not below the shard count {m}"));
            }
            Ok(Shard { index: k, count: m })
        };
        if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let m = num("SLURM_ARRAY_TASK_COUNT")?.ok_or(
                "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not (run as an array job: sbatch --array=0-M-1)",
            )?;
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let k = id
                .checked_sub(min)
                .ok_or_else(|| format!("SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"))?;
            if let Some(c) = count
                && c != m
            {
                return Err(format!(
                    "--shard-count {c} disagrees with SLURM_ARRAY_TASK_COUNT {m}"
                ));
            }
            if let Some(step) = num("SLURM_ARRAY_TASK_STEP")?
                && step != 1
            {
                return Err(format!(
                    "SLURM_ARRAY_TASK_STEP is {step}: use a contiguous array (--array=0-{})",
                    m.saturating_sub(1)
                ));
            }
            return check(k, m, "Slurm array");
        }
        if let Some(k) = num("JOB_COMPLETION_INDEX")? {
            let m =
                count.ok_or("JOB_COMPLETION_INDEX is set: give the Job's completions as --shard-count M")?;
            return check(k, m, "Kubernetes Indexed Job");
        }
        Err(
            "neither a Slurm array (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT) nor a Kubernetes \
             Indexed Job (JOB_COMPLETION_INDEX) is in the environment; give --shard K/M"
                .into(),
        )
    }
}

/// What to sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    /// Scenarios 0..N of the sweep (before sharding).
    pub scenarios: u64,
    /// Sweep seed S.
    pub seed: u64,
    /// Worker threads (0 = one per core).
    pub jobs: usize,
    /// A fault injected in every scenario.
    pub fault: Option<FaultKind>,
    /// What counts as success.
    pub goal: Goal,
    /// Only this shard's scenarios.
    pub shard: Option<Shard>,
    /// Per-episode simulated time limit, seconds.
    pub max_sim_time: f64,
    /// The `--scene` file the sweep was given, if any (printed in reproduction commands).
    pub scene_file: Option<String>,
    /// The tree file, as given (written to every result line, printed in reproduction
    /// commands).
    pub tree: String,
    /// Leaves replaced by scripted outcomes in every scenario (see
    /// [`crate::runtime::substitute`]).
    pub substitutions: Vec<Substitution>,
    /// The scenario file of `macrotree test` this sweep belongs to, if any.
    pub suite: Option<String>,
    /// The digest of the tree file, its includes and the scene file ([`digest::files_digest`]),
    /// written to every result line: `--resume` refuses lines of other contents.
    pub tree_digest: Option<String>,
    /// How reproduction commands name the program (`macrotree` when it is on `PATH`, else the
    /// path of the binary that ran, e.g. `target/release/macrotree`), shell-quoted.
    pub program: String,
}

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            scenarios: 100,
            seed: 0,
            jobs: 0,
            fault: None,
            goal: Goal::default(),
            shard: None,
            max_sim_time: EpisodeConfig::default().max_sim_time,
            scene_file: None,
            tree: String::new(),
            substitutions: Vec::new(),
            suite: None,
            tree_digest: None,
            program: "macrotree".to_string(),
        }
    }
}

impl SweepConfig {
    /// The scenario indices this sweep runs, ascending (computed, never listed).
    pub fn indices(&self) -> ScenarioIndices {
        ScenarioIndices::new(self.scenarios, self.shard)
    }

    /// Scenario `index` of this sweep on `scene`. A scene with `sampler: tutorial` (the built-in
    /// `cube_bowl`) draws its cube and bowl with the documented task-region sampler
    /// ([`sample_scenario`]), so its sweeps and reproduction commands (`--cube … --bowl …`) are
    /// those of earlier releases; every other scene draws its own randomization
    /// ([`crate::scene::sample_placement`]).
    pub fn scene_scenario(&self, scene: &Scene, index: u64) -> Result<SceneScenario, PlacementError> {
        if scene.spec.sampler == crate::scene::Sampler::Tutorial {
            let s = sample_scenario(self.seed, index);
            return Ok(SceneScenario {
                sweep_seed: s.sweep_seed,
                index,
                seed: s.seed,
                placement: scene.placement_from_layout(&s.layout.to_layout()),
                layout: Some(s.layout),
            });
        }
        let (seed, placement) = sample_placement(&scene.spec, self.seed, index)?;
        Ok(SceneScenario {
            sweep_seed: self.seed,
            index,
            seed,
            placement,
            layout: None,
        })
    }

    /// The episode configuration of a scenario of any scene (see [`Self::scene_scenario`]).
    pub fn scene_episode_config(&self, scenario: &SceneScenario) -> EpisodeConfig {
        EpisodeConfig {
            placement: Some(scenario.placement.clone()),
            seed: scenario.seed,
            max_sim_time: self.max_sim_time,
            control_period: CONTROL_PERIOD,
            fault: self.fault,
            goal: self.goal,
            substitutions: self.substitutions.clone(),
        }
    }

    /// The episode configuration of `scenario` of a `sampler: tutorial` scene (`scene`): exactly
    /// what `macrotree run` builds from the reproduction command [`ScenarioResult::reproduce`]
    /// prints.
    pub fn episode_config(&self, scene: &Scene, scenario: &Scenario) -> EpisodeConfig {
        EpisodeConfig {
            placement: Some(scene.placement_from_layout(&scenario.layout.to_layout())),
            seed: scenario.seed,
            max_sim_time: self.max_sim_time,
            control_period: CONTROL_PERIOD,
            fault: self.fault,
            goal: self.goal,
            substitutions: self.substitutions.clone(),
        }
    }
}

/// A scenario of a sweep on any scene: the episode seed and every object's starting pose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneScenario {
    /// The sweep seed `S`.
    pub sweep_seed: u64,
    /// The scenario index `k`.
    pub index: u64,
    /// The episode seed (fault timing and magnitude).
    pub seed: u64,
    /// Every object's starting pose, scene order.
    pub placement: Placement,
    /// The tutorial's cube/bowl layout, for a `sampler: tutorial` scene.
    pub layout: Option<ScenarioLayout>,
}

/// One line of the sweep's JSONL: the scenario and its episode's outcome (the fields of
/// `run --json`, except the wall time, so that a sweep's output is byte-identical for any number
/// of jobs and any machine).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScenarioResult {
    /// The scenario file of `macrotree test` this result belongs to (absent for sweeps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub suite: Option<String>,
    /// The tree file, as given to the sweep.
    pub tree: String,
    /// The `--scene` file, if one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene_file: Option<String>,
    /// Scenarios in the whole sweep (N, before sharding).
    pub scenarios: u64,
    /// What counted as success (`--goal`).
    pub sweep_goal: Goal,
    /// The per-episode simulated time limit, seconds.
    pub max_sim_time: f64,
    /// Substitutions applied in every scenario (`PATTERN=OUTCOME`).
    #[serde(skip_serializing_if = "Vec::is_empty", serialize_with = "as_rules")]
    pub substitutions: Vec<Substitution>,
    /// Scenario index k.
    pub index: u64,
    /// Sweep seed S.
    pub sweep_seed: u64,
    /// Episode seed (`run --seed`).
    pub seed: u64,
    /// The injected fault.
    pub fault: Option<FaultKind>,
    /// The layout of a `sampler: tutorial` scene (the built-in one), exactly as sampled (and as
    /// `run --cube X,Y,YAW --bowl X,Y` takes it); other scenes list every object in `objects`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layout: Option<ScenarioLayout>,
    /// The episode met the sweep's goal (by default: the tree succeeded and the cube rests in
    /// the bowl; see [`Goal`]).
    pub success: bool,
    /// Final status of the tree.
    pub tree_status: &'static str,
    /// Why it failed, if it did.
    pub failure_reason: Option<String>,
    /// Simulated time, seconds.
    pub sim_time_s: f64,
    /// Grasp leaves started on the arm (a grasp answered by a substitution is not counted).
    pub grasp_attempts: u32,
    /// Leaves preempted while running.
    pub halts: u32,
    /// MuJoCo steps taken.
    pub physics_steps: u64,
    /// Final centre [x, y, z] of the scene's cube, metres; absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cube_final: Option<[f64; 3]>,
    /// Bowl target [x, y, z] at the end, metres; absent without a bowl.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bowl_target: Option<[f64; 3]>,
    /// The reference tutorial's checks.
    pub checks: Checks,
    /// The scene's name.
    pub scene: String,
    /// Every object's initial and final pose, `[x, y, z, yaw°]`.
    pub objects: Vec<ObjectReport>,
    /// Every goal predicate's value at the end.
    pub goal: Vec<GoalValue>,
    /// Contacts that should not happen, by name.
    pub collisions: Vec<Collision>,
    /// The path of the node whose failure ended the episode, if one did.
    pub failed_node: Option<String>,
    /// The kind of failure (`timeout`, `grasp_lost`, …; serialized as its name), for grouping.
    pub failure_kind: Option<FailureKind>,
    /// How often every node ran, in plan order.
    pub nodes: Vec<NodeReport>,
    /// The digest of the tree, its includes and the scene the sweep ran
    /// ([`SweepConfig::tree_digest`]); a line that has it also ends with its checksum (`crc32`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tree_digest: Option<String>,
    /// Motions checked and planned in the episode.
    pub planning: crate::actions::PlanCounts,
    /// Wall-clock time of the episode, seconds (not written to the JSONL).
    #[serde(skip)]
    pub wall_time_s: f64,
    /// Wall-clock time the episode spent checking and planning motions, seconds (not written to
    /// the JSONL).
    #[serde(skip)]
    pub planning_wall_s: f64,
}

impl ScenarioResult {
    /// The result of `scenario` (of a `sampler: tutorial` scene) of the sweep `config` from its
    /// episode report.
    pub fn new(scenario: &Scenario, config: &SweepConfig, r: EpisodeReport) -> Self {
        Self::of(config, scenario.index, scenario.seed, Some(scenario.layout), r)
    }

    /// The result of a scenario of any scene of the sweep `config` from its episode report.
    pub fn of_scene(scenario: &SceneScenario, config: &SweepConfig, r: EpisodeReport) -> Self {
        Self::of(config, scenario.index, scenario.seed, scenario.layout, r)
    }

    fn of(
        config: &SweepConfig,
        index: u64,
        seed: u64,
        layout: Option<ScenarioLayout>,
        r: EpisodeReport,
    ) -> Self {
        Self {
            suite: config.suite.clone(),
            tree: config.tree.clone(),
            scene_file: config.scene_file.clone(),
            scenarios: config.scenarios,
            sweep_goal: config.goal,
            max_sim_time: config.max_sim_time,
            substitutions: config.substitutions.clone(),
            index,
            sweep_seed: config.seed,
            seed,
            fault: config.fault,
            layout,
            success: r.success,
            tree_status: r.tree_status,
            failure_reason: r.failure_reason,
            sim_time_s: r.sim_time_s,
            grasp_attempts: r.grasp_attempts,
            halts: r.halts,
            physics_steps: r.physics_steps,
            cube_final: r.cube_final,
            bowl_target: r.bowl_target,
            checks: r.checks,
            scene: r.scene,
            objects: r.objects,
            goal: r.goal,
            collisions: r.collisions,
            failure_kind: r.failure_kind,
            failed_node: r.failed_node,
            nodes: r.nodes,
            tree_digest: config.tree_digest.clone(),
            wall_time_s: r.wall_time_s,
            planning: r.planning.counts(),
            planning_wall_s: r.planning.planning_wall_s,
        }
    }

    /// A result of the sweep `config` for an episode that could not run (it panicked, or its
    /// layout could not be drawn).
    fn not_run(
        config: &SweepConfig,
        index: u64,
        seed: u64,
        layout: Option<ScenarioLayout>,
        reason: crate::failure::Failure,
    ) -> Self {
        Self {
            suite: config.suite.clone(),
            tree: config.tree.clone(),
            scene_file: config.scene_file.clone(),
            scenarios: config.scenarios,
            sweep_goal: config.goal,
            max_sim_time: config.max_sim_time,
            substitutions: config.substitutions.clone(),
            index,
            sweep_seed: config.seed,
            seed,
            fault: config.fault,
            layout,
            success: false,
            tree_status: "failure",
            failure_kind: Some(reason.kind),
            failure_reason: Some(reason.message),
            sim_time_s: 0.0,
            grasp_attempts: 0,
            halts: 0,
            physics_steps: 0,
            cube_final: None,
            bowl_target: None,
            checks: Checks {
                grasp_distance: None,
                cube_motion_while_closed: 0.0,
                cube_lift_while_closed: 0.0,
                home_error: f64::NAN,
                in_bowl: false,
            },
            scene: String::new(),
            objects: Vec::new(),
            goal: Vec::new(),
            collisions: Vec::new(),
            failed_node: None,
            nodes: Vec::new(),
            tree_digest: config.tree_digest.clone(),
            wall_time_s: 0.0,
            planning: Default::default(),
            planning_wall_s: 0.0,
        }
    }

    /// The result as one JSON line (without the newline).
    pub fn to_jsonl(&self) -> String {
        let json = serde_json::to_string(self).expect("a scenario result serializes");
        if self.tree_digest.is_some() {
            digest::with_checksum(&json)
        } else {
            json
        }
    }

    /// The `macrotree run …` command that reproduces this scenario bit for bit (the program
    /// named as [`SweepConfig::program`] says). Floats are
    /// printed with Rust's shortest round-trip formatting, so they parse back to the same bits.
    pub fn reproduce(&self, tree: &str, config: &SweepConfig) -> String {
        let mut cmd = match &self.layout {
            Some(l) => format!(
                "{} run {} --cube {},{},{} --bowl {},{} --seed {}",
                config.program,
                shell_quote(tree),
                l.cube[0],
                l.cube[1],
                l.cube[2],
                l.bowl[0],
                l.bowl[1],
                self.seed
            ),
            None => format!(
                "{} run {} --sweep-seed {} --scenario {}",
                config.program,
                shell_quote(tree),
                self.sweep_seed,
                self.index
            ),
        };
        if let Some(scene) = &config.scene_file {
            cmd += &format!(" --scene {}", shell_quote(scene));
        }
        if let Some(fault) = self.fault {
            cmd += &format!(" --fault {fault}");
        }
        if config.goal != Goal::default() {
            cmd += &format!(" --goal {}", config.goal.name());
        }
        if config.max_sim_time != EpisodeConfig::default().max_sim_time {
            cmd += &format!(" --max-sim-time {}", config.max_sim_time);
        }
        for sub in &config.substitutions {
            cmd += &format!(" --substitute {}", shell_quote(&sub.to_string()));
        }
        cmd
    }
}

/// Substitutions as their `PATTERN=OUTCOME` text.
fn as_rules<S: serde::Serializer>(subs: &[Substitution], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(subs.iter().map(|x| x.to_string()))
}

/// Quotes `s` for a POSIX shell when it holds anything but `[A-Za-z0-9_./+-]`.
pub(crate) fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./+-".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Runs scenario `scenario` (of a `sampler: tutorial` scene, such as the built-in one) of
/// `config` in `cell` (reset first).
pub fn run_scenario(
    cell: &mut Cell,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    scenario: &Scenario,
) -> ScenarioResult {
    let episode = config.episode_config(cell.sim().scene(), scenario);
    let report = run_in_cell(cell, plan.clone(), factory, &episode, &mut NoObserver);
    ScenarioResult::new(scenario, config, report)
}

/// Runs scenario `index` of `config` on the cell's scene (reset first).
pub fn run_scene_scenario(
    cell: &mut Cell,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    index: u64,
) -> ScenarioResult {
    run_scene_scenario_observed(cell, plan, factory, config, index, &mut NoObserver)
}

/// Most scenarios a sweep runs ahead of the first one not yet handed to its callback (at least
/// four per worker): bounds the results held while a slow scenario holds up the ones after it.
pub const REORDER_WINDOW: usize = 1024;

/// The outcome of a sweep.
#[derive(Debug, Clone)]
pub struct SweepRun {
    /// One result per scenario run, in index order.
    pub results: Vec<ScenarioResult>,
    /// Wall-clock time of the whole sweep, seconds.
    pub wall_time_s: f64,
    /// Worker threads used.
    pub jobs: usize,
    /// Wall-clock time the workers spent inside `mj_step`, summed over workers, seconds.
    pub physics_time_s: f64,
}

/// Runs the sweep on `config.jobs` worker threads (one [`Cell`] each) and calls `on_result` on
/// the calling thread for every scenario, in index order, as soon as it and all before it are
/// done. An episode that panics is recorded as a failure (its worker gets a fresh cell).
pub fn run_sweep(
    scene: &Scene,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    mut on_result: impl FnMut(&ScenarioResult),
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    run_sweep_from(scene, plan, factory, config, 0, |r| {
        on_result(r);
        ControlFlow::Continue(())
    })
}

/// [`run_sweep`] without the first `skip` scenarios of the sweep (those already done, see
/// [`resume`]), stopping as soon as `on_result` breaks: no scenario starts after that, the ones
/// already running are finished and dropped, and `results` ends with the one that broke.
pub fn run_sweep_from(
    scene: &Scene,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    skip: u64,
    mut on_result: impl FnMut(&ScenarioResult) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    run_sweep_with(
        scene,
        config,
        skip,
        |cell, index| (run_scene_scenario(cell, plan, factory, config, index), ()),
        |r, _| on_result(r),
    )
}

/// Runs scenario `index` of `config` on the cell's scene (reset first), with `observer` seeing
/// every control tick (e.g. a dataset recorder).
pub fn run_scene_scenario_observed(
    cell: &mut Cell,
    plan: &Arc<Plan>,
    factory: &Factory,
    config: &SweepConfig,
    index: u64,
    observer: &mut dyn crate::episode::EpisodeObserver,
) -> ScenarioResult {
    match config.scene_scenario(cell.sim().scene(), index) {
        Ok(scenario) => {
            let episode = config.scene_episode_config(&scenario);
            let report = run_in_cell(cell, plan.clone(), factory, &episode, observer);
            ScenarioResult::of_scene(&scenario, config, report)
        }
        Err(e) => ScenarioResult::not_run(
            config,
            index,
            0,
            None,
            crate::failure::Failure::new(FailureKind::Layout, format!("layout: {e}")),
        ),
    }
}

/// [`run_sweep_from`] with a per-episode payload: `episode` runs scenario `index` in a worker's
/// cell and returns its result with a payload of any kind (a dataset recording), and
/// `on_result` receives both in scenario order (the payload is `None` for an episode that
/// panicked).
pub fn run_sweep_with<T: Send>(
    scene: &Scene,
    config: &SweepConfig,
    skip: u64,
    episode: impl Fn(&mut Cell, u64) -> (ScenarioResult, T) + Sync,
    mut on_result: impl FnMut(&ScenarioResult, Option<T>) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    // Memory grows with the results, not with the size of the sweep.
    let mut results = Vec::with_capacity(config.indices().skip_first(skip).len().min(4096));
    let mut run = run_sweep_streaming(scene, config, skip, episode, |r, payload| {
        let flow = on_result(&r, payload);
        results.push(r);
        flow
    })?;
    run.results = results;
    Ok(run)
}

/// [`run_sweep_with`] that keeps no result: each is handed to `on_result` (in scenario order)
/// and dropped, so memory does not grow with the number of scenarios. The returned
/// [`SweepRun`] has no `results`.
pub fn run_sweep_streaming<T: Send>(
    scene: &Scene,
    config: &SweepConfig,
    skip: u64,
    episode: impl Fn(&mut Cell, u64) -> (ScenarioResult, T) + Sync,
    mut on_result: impl FnMut(ScenarioResult, Option<T>) -> ControlFlow<()>,
) -> Result<SweepRun, rayon::ThreadPoolBuildError> {
    let wall = Instant::now();
    let episode = &episode;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.jobs)
        .thread_name(|i| format!("sweep-{i}"))
        .build()?;
    let jobs = pool.current_num_threads();
    let indices = config.indices().skip_first(skip);
    let mut next = 0usize;
    let (tx, rx) = mpsc::channel::<(usize, ScenarioResult, Option<T>)>();
    let stop = AtomicBool::new(false);
    let physics_ns = AtomicU64::new(0);
    // Results handed to `on_result` so far: a worker does not start a scenario more than
    // `window` places ahead, so results waiting for a slow earlier one stay bounded.
    let delivered = AtomicUsize::new(0);
    let window = REORDER_WINDOW.max(4 * jobs);
    std::thread::scope(|s| {
        let stop = &stop;
        let physics_ns = &physics_ns;
        let delivered = &delivered;
        s.spawn(move || {
            let new_cell = || Cell::new(scene, &Layout::default(), CONTROL_PERIOD);
            pool.install(|| {
                // par_bridge hands out scenarios in index order, so results arrive nearly in order.
                let todo = indices.take_while(|_| !stop.load(Ordering::Relaxed)).enumerate();
                todo.par_bridge().for_each_init(new_cell, |cell, (pos, index)| {
                    // Every scenario before `pos` is done or running on another worker, so the
                    // one the consumer waits for always progresses.
                    while pos >= delivered.load(Ordering::Acquire) + window && !stop.load(Ordering::Relaxed) {
                        std::thread::sleep(std::time::Duration::from_millis(1));
                    }
                    if stop.load(Ordering::Relaxed) {
                        return; // the consumer stopped: its result would be dropped
                    }
                    let before = cell.sim().physics_time();
                    let outcome = catch_unwind(AssertUnwindSafe(|| episode(cell, index)));
                    let spent = cell.sim().physics_time().saturating_sub(before);
                    physics_ns.fetch_add(
                        u64::try_from(spent.as_nanos()).unwrap_or(u64::MAX),
                        Ordering::Relaxed,
                    );
                    let (result, payload) = match outcome {
                        Ok((r, t)) => (r, Some(t)),
                        Err(payload) => {
                            *cell = new_cell();
                            let s = config.scene_scenario(scene, index).ok();
                            let r = ScenarioResult::not_run(
                                config,
                                index,
                                s.as_ref().map_or(0, |s| s.seed),
                                s.and_then(|s| s.layout),
                                crate::failure::Failure::new(
                                    FailureKind::Panicked,
                                    format!("panicked: {}", panic_message(&*payload)),
                                ),
                            );
                            (r, None)
                        }
                    };
                    // The receiver lives until every result is in.
                    let _ = tx.send((pos, result, payload));
                });
            });
        });
        let mut pending = BTreeMap::new();
        for (pos, result, payload) in rx {
            if stop.load(Ordering::Relaxed) {
                continue; // draining the scenarios that were running
            }
            pending.insert(pos, (result, payload));
            while let Some((result, payload)) = pending.remove(&next) {
                next += 1;
                delivered.store(next, Ordering::Release);
                if on_result(result, payload).is_break() {
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
            }
        }
    });
    Ok(SweepRun {
        results: Vec::new(),
        wall_time_s: wall.elapsed().as_secs_f64(),
        jobs,
        physics_time_s: physics_ns.load(Ordering::Relaxed) as f64 * 1e-9,
    })
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_reject_bad_input() {
        assert_eq!("1/4".parse::<Shard>(), Ok(Shard { index: 1, count: 4 }));
        for bad in ["3/2", "2/2", "0/0", "1", "a/2", "-1/2", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_partition_the_indices() {
        let all = SweepConfig {
            scenarios: 10,
            ..SweepConfig::default()
        };
        let mut union: Vec<u64> = (0..3)
            .flat_map(|k| {
                SweepConfig {
                    shard: Some(Shard { index: k, count: 3 }),
                    ..all.clone()
                }
                .indices()
            })
            .collect();
        union.sort();
        assert_eq!(union, all.indices().collect::<Vec<_>>());
    }

    #[test]
    fn shell_quoting() {
        assert_eq!(shell_quote("trees/a_b-1.yaml"), "trees/a_b-1.yaml");
        assert_eq!(shell_quote("my tree.yaml"), "'my tree.yaml'");
        assert_eq!(shell_quote("it's.yaml"), r"'it'\''s.yaml'");
    }
}
