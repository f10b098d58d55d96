//! One episode: a compiled tree ticked on simulated time against the simulated cell, from a
//! layout to a report. This is where tree logic ([`crate::runtime`]) meets physics
//! ([`crate::actions`], [`crate::sim`]).

pub mod collision;
mod cube_bowl;
mod driver;
mod outcome;
pub mod replay;
mod report;
pub mod scenario;
pub use crate::world::vectors;

use std::sync::Arc;
use std::time::Instant;

pub use collision::{Collision, CollisionCounts, CollisionPolicy, HitKind, Hitter};
pub use cube_bowl::CubeBowlReport;
pub use driver::{DriverState, LeafCounters, MacroDriver};
pub use outcome::EpisodeOutcome;
pub use report::{EpisodeReport, LayoutJson, NodeReport, ObjectReport};

use crate::actions::Cell;
use crate::factory::Factory;
use crate::failure::{Failure, FailureKind};
use crate::motion::CellCommand;
use crate::plan::Plan;
use crate::runtime::substitute::Resolved;
use crate::runtime::{TreeRunner, TreeStatus};
use crate::scene::Placement;
use crate::sim::{Layout, Scene};

/// Longest episode accepted anywhere (API, command line, scenario files), simulated seconds.
pub const MAX_SIM_TIME_S: f64 = 3600.0;

/// Length of an episode when none is given, simulated seconds.
pub const DEFAULT_MAX_SIM_TIME_S: f64 = 60.0;

/// How to run an episode.
#[derive(Debug, Clone, PartialEq)]
pub struct EpisodeConfig {
    /// Where every object of the scene starts (one pose per object, scene order); `None`: the
    /// scene's default placement ([`Scene::default_placement`]). The legacy `--cube`/`--bowl`
    /// layouts become placements through [`Scene::placement_from_layout`].
    pub placement: Option<Placement>,
    /// Seed for everything random in the episode (fault timing and magnitude). The same tree,
    /// layout and seed give a bit-identical result.
    pub seed: u64,
    /// The episode stops (as a failure) after this much simulated time, seconds.
    pub max_sim_time: f64,
    /// Tree tick period, seconds (a whole number of 2 ms physics steps).
    pub control_period: f64,
    /// A fault to inject through physics, if any.
    pub fault: Option<crate::faults::FaultKind>,
    /// Noise added to what the arm and gripper execute, the recorded commands staying clean
    /// ([`crate::faults::ActionNoise`]); `None`: none.
    pub noise: Option<crate::faults::ActionNoise>,
    /// What counts as success.
    pub goal: Goal,
    /// Leaves replaced by scripted outcomes (test doubles, see
    /// [`crate::runtime::substitute`]).
    pub substitutions: Vec<crate::runtime::substitute::Substitution>,
    /// `substitutions` already resolved against the plan this configuration runs
    /// ([`crate::runtime::substitute::resolve`]): a command resolves its substitutions once and
    /// every episode reuses them. `None`, or a resolution of other rules or of a plan with other
    /// leaves ([`Resolved::is_for`](crate::runtime::substitute::Resolved::is_for)): the episode
    /// resolves `substitutions` itself.
    pub resolved: Option<Arc<crate::runtime::substitute::Resolved>>,
    /// What a contact that should not happen does: counted (default), or an episode failure of
    /// kind `collision` (`--collisions fail`).
    pub collisions: CollisionPolicy,
}

/// What counts as a successful episode (`run --goal`, `sweep --goal`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Goal {
    /// The tree succeeded and the scene's goal holds (for the `cube_bowl` scene: the cube rests
    /// in the bowl). A tree that succeeds without doing the job is caught.
    #[default]
    Scene,
    /// The tree succeeded and the legacy cube rests in the legacy bowl (the cube-to-bowl task).
    Bowl,
    /// The tree succeeded; the tree's own conditions define the task (e.g. `cube_at` for a
    /// placement on the table).
    Tree,
}

impl Goal {
    /// Every goal.
    pub const ALL: [Goal; 3] = [Goal::Scene, Goal::Bowl, Goal::Tree];

    /// The name used on the command line (`bowl`, `tree`).
    pub fn name(self) -> &'static str {
        match self {
            Goal::Scene => "scene",
            Goal::Bowl => "bowl",
            Goal::Tree => "tree",
        }
    }
}

impl Goal {
    /// What this goal checks on a scene with `scene_goal`, for reports: `the tree's result and
    /// the scene's goal (2 predicates)`, or `the tree's result only (the scene declares no goal)`
    /// when `--goal scene` meets a scene without one.
    pub fn checked(self, scene_goal: &crate::scene::Goal) -> String {
        match self {
            Goal::Scene if scene_goal.is_empty() => {
                "the tree's result only (the scene declares no goal)".into()
            }
            Goal::Scene => format!(
                "the tree's result and the scene's goal ({} predicate{})",
                scene_goal.atoms.len(),
                if scene_goal.atoms.len() == 1 { "" } else { "s" }
            ),
            Goal::Bowl => "the tree's result and the cube at rest in the bowl".into(),
            Goal::Tree => "the tree's result".into(),
        }
    }
}

impl std::str::FromStr for Goal {
    type Err = String;

    /// Reads a goal's command-line name (`scene`, `bowl`, `tree`).
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|g| g.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|g| g.name()).collect();
            format!("unknown goal `{s}`: expected one of {}", names.join(", "))
        })
    }
}

impl Default for EpisodeConfig {
    fn default() -> Self {
        Self {
            placement: None,
            seed: 0,
            max_sim_time: DEFAULT_MAX_SIM_TIME_S,
            control_period: crate::actions::CONTROL_PERIOD,
            fault: None,
            noise: None,
            goal: Goal::Scene,
            substitutions: Vec::new(),
            resolved: None,
            collisions: CollisionPolicy::Count,
        }
    }
}

/// Something that happened to the cell during a control period, as observers see it (the
/// viewer marks it on its timeline).
#[derive(Clone, Copy, Debug)]
pub enum EpisodeEvent<'a> {
    /// The episode's fault fired.
    Fault(&'a crate::faults::FaultEvent),
    /// A contact that should not happen was first seen.
    Collision(&'a Collision),
}

/// Called after every control period (viewer, recorder, progress).
pub trait EpisodeObserver {
    /// A control period starts: the tree was ticked, the physics has not advanced yet, and
    /// `command` is what the cell will hold over the period (the state is the period's first).
    fn on_period_start(&mut self, _cell: &Cell, _command: &CellCommand, _runner: &mut TreeRunner) {}
    /// The tree was ticked and the physics advanced by one control period.
    fn on_tick(&mut self, _cell: &Cell, _runner: &mut TreeRunner) {}
    /// A fault fired or a collision was first seen during the period just advanced (called
    /// after [`on_tick`](Self::on_tick)).
    fn on_event(&mut self, _event: EpisodeEvent<'_>) {}
}

/// An observer that does nothing.
pub struct NoObserver;
impl EpisodeObserver for NoObserver {}

/// Runs one episode of `plan` in a fresh cell of `scene`, each leaf running as `factory` binds
/// its kind.
pub fn run_episode(
    scene: &Scene,
    plan: Arc<Plan>,
    factory: &Factory,
    config: &EpisodeConfig,
    observer: &mut dyn EpisodeObserver,
) -> EpisodeReport {
    let mut cell = Cell::new(scene, &Layout::default(), config.control_period);
    run_in_cell(&mut cell, plan, factory, config, observer)
}

/// Runs one episode of `plan` in `cell`, which is reset to the configured placement first; each
/// leaf runs as `factory` binds its kind.
pub fn run_in_cell(
    cell: &mut Cell,
    plan: Arc<Plan>,
    factory: &Factory,
    config: &EpisodeConfig,
    observer: &mut dyn EpisodeObserver,
) -> EpisodeReport {
    let wall = Instant::now();
    let placement = match &config.placement {
        Some(p) => p.clone(),
        None => cell.sim().scene().default_placement(),
    };
    cell.reset_placement(&placement);
    let initial = cell.world().clone();
    let observers_before = cell.observers.len();
    let mut fault_log = None;
    if let Some(kind) = config.fault {
        let (injector, log) = crate::faults::injector_with_log(kind, config.seed);
        cell.observers.push(injector);
        fault_log = Some(log);
    }
    if let Some(noise) = config.noise {
        cell.observers.push(noise.injector(config.seed));
    }
    let dt = cell.control_period();
    let resolved = match &config.resolved {
        Some(r) if r.is_for(&plan, &config.substitutions) => Ok(Resolved::clone(r)),
        _ => crate::runtime::substitute::resolve(&plan, &config.substitutions),
    };
    let (subs, bad_subs) = match resolved {
        Ok(subs) => (subs, None),
        Err(e) => (
            Default::default(),
            Some(Failure::new(FailureKind::Substitution, e.to_string())),
        ),
    };
    let mut runner = TreeRunner::with_substitutions(plan, subs);
    let mut driver = MacroDriver::new(cell, factory);
    driver.collision_policy = config.collisions;
    driver.set_leaf_paths(runner.plan().leaves.iter().map(|l| l.path.clone()).collect());
    let mut status = if bad_subs.is_some() {
        TreeStatus::Failure
    } else {
        TreeStatus::Running
    };
    let mut timed_out = false;
    let mut unstable = None;
    let mut collided = None;
    let mut collisions_seen = 0;
    while status == TreeStatus::Running {
        let now = driver.cell().world().time;
        if now >= config.max_sim_time {
            timed_out = true;
            break;
        }
        status = runner.tick(now, dt, &mut driver);
        let command = driver.cell().period_command();
        observer.on_period_start(driver.cell(), &command, &mut runner);
        driver.advance();
        observer.on_tick(driver.cell(), &mut runner);
        if let Some(log) = &fault_log {
            let fired = log.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(event) = fired.as_ref() {
                observer.on_event(EpisodeEvent::Fault(event));
                drop(fired);
                fault_log = None;
            }
        }
        while collisions_seen < driver.collisions.len() {
            observer.on_event(EpisodeEvent::Collision(&driver.collisions[collisions_seen]));
            collisions_seen += 1;
        }
        // MuJoCo resets an unstable simulation and carries on: the episode is no longer physics.
        if let Some(why) = driver.cell().sim().instability() {
            tracing::error!(target: "macrotree::episode", "{why}");
            unstable = Some(Failure::new(FailureKind::Unstable, why));
            break;
        }
        // `--collisions fail`: the first contact that should not happen ends the episode.
        if let Some(f) = driver.collision_failure.take() {
            tracing::info!(target: "macrotree::episode", "{}", f.message);
            collided = Some(f);
            break;
        }
    }
    if timed_out || unstable.is_some() || collided.is_some() {
        runner.halt_all(&mut driver);
    }
    let checks = driver.checks.clone();
    let counters = driver.counters;
    let collisions = std::mem::take(&mut driver.collisions);
    // The root's reason tells the whole story ("all 3 attempts failed; last: …"); an action's
    // own reason is the fallback.
    let root_reason = runner.failure().cloned();
    let last_failure = unstable
        .clone()
        .or(bad_subs)
        .or(root_reason)
        .or_else(|| driver.last_failure.clone());
    cell.observers.truncate(observers_before);
    let world = cell.world().clone();
    let mut report = EpisodeReport::new(
        status,
        timed_out,
        config,
        &world,
        checks.finish(&world),
        counters,
        cell.sim().steps(),
        wall.elapsed().as_secs_f64(),
        last_failure,
    );
    report.layout = LayoutJson::of(&placement, &world.scene);
    report.add_scene(&initial, &world, collisions, unstable);
    report.outcome.nodes = NodeReport::of(&runner);
    report.planning = cell.planning().clone();
    if !report.outcome.success {
        report.outcome.failed_node = runner.last_failed_path();
    }
    if let Some(f) = collided {
        report.outcome.success = false;
        report.outcome.failed_node = f.node.clone();
        report.set_failure(f);
    }
    report
}
