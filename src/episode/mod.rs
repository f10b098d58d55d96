//! One episode: a compiled tree ticked on simulated time against the simulated cell, from a
//! layout to a report. This is where tree logic ([`crate::runtime`]) meets physics
//! ([`crate::actions`], [`crate::sim`]).

mod report;

use std::sync::Arc;
use std::time::Instant;

pub use report::EpisodeReport;

use crate::actions::{Cell, MacroDriver};
use crate::plan::Plan;
use crate::runtime::{TreeRunner, TreeStatus};
use crate::sim::{Layout, Scene};

/// How to run an episode.
#[derive(Debug, Clone, PartialEq)]
pub struct EpisodeConfig {
    /// Where the cube and the bowl start.
    pub layout: Layout,
    /// Seed for everything random in the episode (fault timing and magnitude). The same tree,
    /// layout and seed give a bit-identical result.
    pub seed: u64,
    /// The episode stops (as a failure) after this much simulated time, seconds.
    pub max_sim_time: f64,
    /// Tree tick period, seconds (a whole number of 2 ms physics steps).
    pub control_period: f64,
    /// A fault to inject through physics, if any.
    pub fault: Option<crate::faults::FaultKind>,
    /// What counts as success.
    pub goal: Goal,
}

/// What counts as a successful episode (`run --goal`, `sweep --goal`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Goal {
    /// The tree succeeded and the cube rests in the bowl (the cube-to-bowl task).
    #[default]
    Bowl,
    /// The tree succeeded; the tree's own conditions define the task (e.g. `cube_at` for a
    /// placement on the table).
    Tree,
}

impl Goal {
    /// The name used on the command line (`bowl`, `tree`).
    pub fn name(self) -> &'static str {
        match self {
            Goal::Bowl => "bowl",
            Goal::Tree => "tree",
        }
    }
}

impl Default for EpisodeConfig {
    fn default() -> Self {
        Self {
            layout: Layout::default(),
            seed: 0,
            max_sim_time: 60.0,
            control_period: crate::actions::CONTROL_PERIOD,
            fault: None,
            goal: Goal::Bowl,
        }
    }
}

/// Called after every control period (viewer, recorder, progress).
pub trait EpisodeObserver {
    /// The tree was ticked and the physics advanced by one control period.
    fn on_tick(&mut self, _cell: &Cell, _runner: &mut TreeRunner) {}
}

/// An observer that does nothing.
pub struct NoObserver;
impl EpisodeObserver for NoObserver {}

/// Runs one episode of `plan` in a fresh cell of `scene`.
pub fn run_episode(
    scene: &Scene,
    plan: Arc<Plan>,
    config: &EpisodeConfig,
    observer: &mut dyn EpisodeObserver,
) -> EpisodeReport {
    let mut cell = Cell::new(scene, &config.layout, config.control_period);
    run_in_cell(&mut cell, plan, config, observer)
}

/// Runs one episode of `plan` in `cell`, which is reset to the configured layout first.
pub fn run_in_cell(
    cell: &mut Cell,
    plan: Arc<Plan>,
    config: &EpisodeConfig,
    observer: &mut dyn EpisodeObserver,
) -> EpisodeReport {
    let wall = Instant::now();
    cell.reset(&config.layout);
    let observers_before = cell.observers.len();
    if let Some(kind) = config.fault {
        cell.observers.push(crate::faults::injector(kind, config.seed));
    }
    let dt = cell.control_period();
    let mut runner = TreeRunner::new(plan);
    let mut driver = MacroDriver::new(cell);
    let mut status = TreeStatus::Running;
    let mut timed_out = false;
    while status == TreeStatus::Running {
        let now = driver.cell().world().time;
        if now >= config.max_sim_time {
            timed_out = true;
            break;
        }
        status = runner.tick(now, dt, &mut driver);
        driver.advance();
        observer.on_tick(driver.cell(), &mut runner);
    }
    if timed_out {
        runner.halt_all(&mut driver);
    }
    let checks = driver.checks.clone();
    let counters = driver.counters;
    // The root's reason tells the whole story ("all 3 attempts failed; last: …"); an action's
    // own reason is the fallback.
    let root_reason = runner.node_reasons().first().cloned().flatten();
    let last_failure = root_reason.or_else(|| driver.last_failure.clone());
    cell.observers.truncate(observers_before);
    let world = cell.world().clone();
    EpisodeReport::new(
        status,
        timed_out,
        config,
        &world,
        checks.finish(&world),
        counters,
        cell.sim().steps(),
        wall.elapsed().as_secs_f64(),
        last_failure,
    )
}
