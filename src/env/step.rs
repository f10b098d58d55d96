//! [`StepResult`] and the tick loop every action runs in: tick the action at the start of a
//! control period, advance the physics one period, repeat until the action finishes — the loop
//! of [`crate::episode::run_in_cell`], so a leaf stepped here runs exactly as in a tree.

use serde::Serialize;

use crate::actions::MacroAction;
use crate::episode::{Collision, MacroDriver};
use crate::failure::{Failure, FailureKind};
use crate::runtime::{TreeRunner, TreeStatus};
use crate::world::goal::GoalValue;

use super::config::time_limit_reached;
use super::observation::Observation;

/// How an action ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The action did what it should (a condition held, a motion arrived, a subtree succeeded).
    Success,
    /// It failed; [`StepResult::failure`] says how.
    Failure,
}

/// What one [`super::MacroEnv::step`] did.
///
/// Reward, `terminated` and `truncated` follow Gymnasium's meaning:
/// - `reward` is the reference tutorial's sparse reward: 1.0 when the scene's goal holds at the
///   end of the step (every predicate of its `goal:`, e.g. the cube at rest in the bowl,
///   released), else 0.0; always 0.0 for a scene without a goal.
/// - `terminated`: the episode reached a terminal state — the scene's goal holds (reward 1), or
///   the simulation became unstable (MuJoCo reset its state; the step then fails with kind
///   `unstable` and the environment must be reset).
/// - `truncated`: the episode's time limit (`EnvConfig::max_sim_time`) was reached during or
///   before this step; the running action was halted there (its failure has kind
///   `time_limit`). Not terminal: the state is still valid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepResult {
    /// The observation at the end of the step.
    pub observation: Observation,
    /// How the action ended.
    pub status: Status,
    /// Why it failed (stable kind, message, node path), when it did.
    pub failure: Option<Failure>,
    /// Simulated time the step took, seconds.
    pub sim_time: f64,
    /// Physics steps (2 ms each) the step took.
    pub physics_steps: u64,
    /// 1.0 when the scene's goal holds at the end of the step, else 0.0 (see above).
    pub reward: f64,
    /// Control periods of this step at whose end the scene's goal held (the count of the
    /// reference's per-step rewards that were 1).
    pub goal_ticks: u64,
    /// The reward at the end of every control period of the step, when
    /// `EnvConfig::rewards_per_tick` is set (empty otherwise).
    pub rewards: Vec<f32>,
    /// The goal holds or the simulation became unstable (see above).
    pub terminated: bool,
    /// The time limit was reached (see above).
    pub truncated: bool,
    /// Contacts that should not happen (the fingers on a container wall or an obstacle, the
    /// carried block on a wall), first seen during this step.
    pub collisions: Vec<Collision>,
    /// Every predicate of the scene's goal at the end of the step, in the scene's order.
    pub goal: Vec<GoalValue>,
    /// Faults that fired during this step, each as `kind: what it did`.
    pub faults_fired: Vec<String>,
    /// Values of a `ctrl` or `setpoint` action clamped to the limits ([`super::CTRL_LIMITS`]);
    /// 0 for other actions.
    pub ctrl_clamped: u32,
    /// For a residual step: the base tree's command and status; `None` for other actions.
    pub base: Option<BaseStep>,
}

/// The base tree's part of a residual step's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BaseStep {
    /// The command the base tree gave for this control period, before the residual
    /// ([`CellCommand::to_vector`](crate::motion::CellCommand::to_vector)'s layout: set points in
    /// radians, velocities in rad/s, accelerations in rad/s², the gripper command); after the tree
    /// has finished, its hold.
    pub command: [f64; crate::motion::COMMAND_LEN],
    /// The base tree's status after its tick (it stays at its end once finished).
    pub status: TreeStatus,
}

impl StepResult {
    /// The action succeeded.
    pub fn success(&self) -> bool {
        self.status == Status::Success
    }
}

/// The answer of one tick of an action.
pub(super) enum Tick {
    /// Still running: advance the physics one control period and tick again.
    Running,
    /// Finished (no physics after it).
    Done(Result<(), Failure>),
}

/// An action the tick loop runs.
pub(super) trait Stepper {
    /// Ticks the action at simulated time `now` (seconds), before the coming control period of
    /// `dt` seconds.
    fn tick(&mut self, d: &mut MacroDriver<'_>, now: f64, dt: f64) -> Tick;
    /// The action is stopped before it finished (time limit, unstable simulation).
    fn halt(&mut self, d: &mut MacroDriver<'_>);
}

/// A plan (a one-leaf plan or a subtree) on the tree runner, through the episode's leaf driver.
pub(super) struct PlanStepper(pub TreeRunner);

impl Stepper for PlanStepper {
    fn tick(&mut self, d: &mut MacroDriver<'_>, now: f64, dt: f64) -> Tick {
        match self.0.tick(now, dt, d) {
            TreeStatus::Running => Tick::Running,
            TreeStatus::Success => Tick::Done(Ok(())),
            TreeStatus::Failure => Tick::Done(Err(self
                .0
                .failure()
                .cloned()
                .or_else(|| d.last_failure.clone())
                .unwrap_or_else(|| Failure::other("the action failed")))),
        }
    }
    fn halt(&mut self, d: &mut MacroDriver<'_>) {
        self.0.halt_all(d);
    }
}

/// A controller ([`MacroAction`]) ticked as the leaf driver ticks an action leaf: started on
/// the first tick (which is Running), updated on every tick after.
pub(super) struct ControllerStepper {
    controller: Box<dyn MacroAction>,
    started: bool,
    /// The node path failures carry (`reach_pose`, `ctrl`).
    path: &'static str,
}

impl ControllerStepper {
    /// Ticks `controller`; its failures carry the node path `path`.
    pub fn new(controller: Box<dyn MacroAction>, path: &'static str) -> Self {
        Self {
            controller,
            started: false,
            path,
        }
    }
}

impl Stepper for ControllerStepper {
    fn tick(&mut self, d: &mut MacroDriver<'_>, _now: f64, _dt: f64) -> Tick {
        let cell = d.cell();
        if !self.started {
            self.started = true;
            return match self.controller.start(cell) {
                Ok(()) => Tick::Running,
                Err(f) => Tick::Done(Err(f.at(self.path))),
            };
        }
        match self.controller.update(cell) {
            crate::actions::Progress::Running => Tick::Running,
            crate::actions::Progress::Done => Tick::Done(Ok(())),
            crate::actions::Progress::Failed(f) => Tick::Done(Err(f.at(self.path))),
        }
    }
    fn halt(&mut self, d: &mut MacroDriver<'_>) {
        if self.started {
            self.controller.halt(d.cell());
        }
    }
}

/// What the tick loop measured.
pub(super) struct Ran {
    /// The action's outcome.
    pub outcome: Result<(), Failure>,
    /// The time limit stopped it.
    pub truncated: bool,
    /// MuJoCo reported an unstable simulation.
    pub unstable: bool,
    /// Control periods whose end saw the goal hold.
    pub goal_ticks: u64,
    /// Per-tick rewards (when asked for).
    pub rewards: Vec<f32>,
    /// Contacts that should not happen.
    pub collisions: Vec<Collision>,
    /// The caller's interrupt stopped it (at the start of a control period; halted there).
    pub interrupted: bool,
}

/// Runs `stepper` on the driver's cell until it finishes, the time limit `max_sim_time`
/// (seconds) is reached, the simulation becomes unstable, or `interrupt` (asked at the start
/// of every control period after the first) says to stop.
pub(super) fn run(
    d: &mut MacroDriver<'_>,
    stepper: &mut dyn Stepper,
    max_sim_time: f64,
    rewards_per_tick: bool,
    on_tick: &mut dyn FnMut(&crate::actions::Cell),
    interrupt: &mut dyn FnMut() -> bool,
) -> Ran {
    let dt = d.cell().control_period();
    let mut ran = Ran {
        outcome: Ok(()),
        truncated: false,
        unstable: false,
        goal_ticks: 0,
        rewards: Vec::new(),
        collisions: Vec::new(),
        interrupted: false,
    };
    let mut first = true;
    loop {
        if !std::mem::take(&mut first) && interrupt() {
            stepper.halt(d);
            ran.interrupted = true;
            break;
        }
        let now = d.cell().world().time;
        if time_limit_reached(now, max_sim_time) {
            stepper.halt(d);
            ran.truncated = true;
            ran.outcome = Err(Failure::new(
                FailureKind::TimeLimit,
                format!("time limit: the episode reached its {max_sim_time} s of simulated time"),
            ));
            break;
        }
        if let Tick::Done(outcome) = stepper.tick(d, now, dt) {
            ran.outcome = outcome;
            break;
        }
        d.advance();
        on_tick(d.cell());
        let holds = goal_holds(d.cell().world());
        ran.goal_ticks += u64::from(holds);
        if rewards_per_tick {
            ran.rewards.push(if holds { 1.0 } else { 0.0 });
        }
        if let Some(why) = d.cell().sim().instability() {
            tracing::error!(target: "macrotree::env", "{why}");
            stepper.halt(d);
            ran.unstable = true;
            ran.outcome = Err(Failure::new(FailureKind::Unstable, why));
            break;
        }
    }
    ran.collisions = std::mem::take(&mut d.collisions);
    ran
}

/// The scene has a goal and every predicate of it holds.
pub(super) fn goal_holds(w: &crate::world::World) -> bool {
    !w.scene.goal.atoms.is_empty() && crate::world::goal::goal_holds(w)
}
