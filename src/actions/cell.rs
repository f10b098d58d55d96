//! [`Cell`]: the simulated work cell as the macro actions see it — the simulation, the arm's
//! trajectory tracker, the gripper command and the latest [`World`] snapshot.

use crate::kinds::ActionRole;
use crate::motion::{ArmCommand, CellCommand, Trajectory};
use crate::sim::collision::{DEFAULT_MARGIN, SceneChecker};
use crate::sim::{Layout, Scene, Sim, TIMESTEP};
use crate::world::World;

use super::planning_tally::PlanningTally;

/// Default control period: the tree is ticked every 4 ms of simulated time (2 physics steps).
pub const CONTROL_PERIOD: f64 = 0.004;

/// Longest control period accepted, seconds.
pub const MAX_CONTROL_PERIOD: f64 = 0.1;

/// Checks a control period: a whole number, at least one, of 2 ms physics steps
/// ([`TIMESTEP`]), at most [`MAX_CONTROL_PERIOD`] seconds.
///
/// # Errors
/// [`crate::Error::Config`] stating the rule and the value given.
pub fn check_control_period(period: f64) -> Result<(), crate::Error> {
    let steps = period / TIMESTEP;
    if period.is_finite()
        && period > 0.0
        && period <= MAX_CONTROL_PERIOD
        && steps.round() >= 1.0
        && (steps - steps.round()).abs() < 1e-9
    {
        return Ok(());
    }
    Err(crate::Error::Config {
        message: format!(
            "control_period must be a whole number (at least 1) of 2 ms physics steps, at most {MAX_CONTROL_PERIOD} s, got {}",
            crate::yaml::short_number(period)
        ),
    })
}

/// What the arm is doing between ticks.
enum ArmPlan {
    /// Hold these joint angles (radians).
    Hold([f64; 6]),
    /// One period of an explicit command given at `t0` (simulated seconds), as the step-wise
    /// environment's `ctrl` action gives it; afterwards the arm holds where the command ended.
    Command { command: ArmCommand, t0: f64 },
    /// Follow a trajectory that started at `t0` (simulated seconds).
    Track {
        trajectory: Box<dyn Trajectory>,
        t0: f64,
    },
}

/// Sees every physics step and every macro action that starts: fault injection acts on the
/// physics through it, benchmarks record the controls.
pub trait StepObserver: Send {
    /// A control period starts under `command` (what the cell holds over it).
    fn on_period(&mut self, _command: &CellCommand) {}
    /// Called after the controls for the coming physics step are set; may act on the physics
    /// (fault injection) or record the controls.
    fn before_step(&mut self, sim: &mut Sim);
    /// A macro action of `kind` (`"reach"`, `"grasp"`, `"carry"`, …) starts now; `role` is what
    /// its kind declares it does in the pick-and-place cycle (act on the role, not the name, so
    /// that a custom kind playing the part is treated alike).
    fn on_action_start(&mut self, _kind: &str, _role: ActionRole, _world: &World) {}
}

/// The simulated cell: simulation, arm tracker, gripper command and the latest world snapshot.
pub struct Cell {
    sim: Sim,
    world: World,
    arm: ArmPlan,
    gripper_ctrl: f64,
    /// The command of the period starting now, once computed ([`Cell::period_command`]);
    /// cleared when the arm or gripper is told something new and after the period.
    pending: Option<CellCommand>,
    /// The command of the last period the physics ran.
    last_command: Option<CellCommand>,
    steps_per_tick: u32,
    /// The motion planner's collision checker of this cell, built at its first use (it holds a
    /// private copy of the model, tens of megabytes: a cell driven by `ctrl` actions alone never
    /// pays for it) and synced from the simulation before each check.
    checker: Option<SceneChecker>,
    /// The checker could not be built (then motions run unchecked).
    checker_unavailable: bool,
    /// What motion checking and planning cost in this episode.
    tally: PlanningTally,
    /// Per-step hooks (fault injection, control recording), called in order.
    pub observers: Vec<Box<dyn StepObserver>>,
}

impl Cell {
    /// A cell of `scene` reset to `layout`, ticked every `control_period` seconds
    /// (rounded to a whole number of physics steps, at least one).
    pub fn new(scene: &Scene, layout: &Layout, control_period: f64) -> Self {
        let sim = Sim::new(scene);
        let world = sim.observe();
        let steps_per_tick = ((control_period / TIMESTEP).round() as u32).max(1);
        let mut cell = Self {
            sim,
            world,
            arm: ArmPlan::Hold(crate::sim::HOME_Q),
            gripper_ctrl: 0.0,
            pending: None,
            last_command: None,
            steps_per_tick,
            checker: None,
            checker_unavailable: false,
            tally: PlanningTally::default(),
            observers: Vec::new(),
        };
        cell.reset(layout);
        cell
    }

    /// Back to home, gripper open, cube and bowl where `layout` puts them, time zero.
    pub fn reset(&mut self, layout: &Layout) {
        let placement = self.sim.scene().placement_from_layout(layout);
        self.reset_placement(&placement);
    }

    /// Back to home, gripper open, every object where `placement` puts it, time zero.
    pub fn reset_placement(&mut self, placement: &crate::scene::Placement) {
        self.sim.reset_placement(placement);
        self.arm = ArmPlan::Hold(crate::sim::HOME_Q);
        self.gripper_ctrl = 0.0;
        self.pending = None;
        self.last_command = None;
        self.world = self.sim.observe();
        if let Some(c) = &mut self.checker {
            c.release();
        }
        self.tally = PlanningTally::default();
    }

    /// The cell's collision checker synced to the simulation as it is now (every object's pose,
    /// the gripper's opening), holding the block the gripper holds now (grasp and release are
    /// followed from the world: [`World::held_block`]), or `None` when the cell has none.
    pub fn checker(&mut self) -> Option<&mut SceneChecker> {
        if self.checker.is_none() && !self.checker_unavailable {
            match SceneChecker::from_sim(&self.sim, DEFAULT_MARGIN) {
                Ok(c) => self.checker = Some(c),
                Err(e) => {
                    tracing::warn!(target: "macrotree::plan", "no collision checker for this cell, motions run unchecked: {e}");
                    self.checker_unavailable = true;
                }
            }
        }
        let c = self.checker.as_mut()?;
        let held = self
            .world
            .held_block(crate::world::conditions::Tolerances::GRASP_OFF_AXIS);
        let synced = c.sync(self.sim.data()).and_then(|()| match held {
            Some(b) if c.held() != Some(b) => c.hold(b),
            None if c.held().is_some() => {
                c.release();
                Ok(())
            }
            _ => Ok(()),
        });
        if let Err(e) = synced {
            tracing::warn!(target: "macrotree::plan", "collision checker out of step with the simulation: {e}");
            return None;
        }
        Some(c)
    }

    /// What motion checking and planning cost so far in this episode.
    pub fn planning(&self) -> &PlanningTally {
        &self.tally
    }

    /// The tally, to add to.
    pub(crate) fn planning_mut(&mut self) -> &mut PlanningTally {
        &mut self.tally
    }

    /// Tells the observers that a macro action of `kind`, playing `role`, starts.
    pub fn notify_action_start(&mut self, kind: &str, role: ActionRole) {
        for obs in &mut self.observers {
            obs.on_action_start(kind, role, &self.world);
        }
    }

    /// The control period, seconds.
    pub fn control_period(&self) -> f64 {
        self.steps_per_tick as f64 * TIMESTEP
    }

    /// The latest world snapshot (refreshed after every control period).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The simulation.
    pub fn sim(&self) -> &Sim {
        &self.sim
    }

    /// The simulation, mutably (fault injection acts on physics through it).
    pub fn sim_mut(&mut self) -> &mut Sim {
        &mut self.sim
    }

    /// The joint angles the arm is commanded to right now (not the measured, possibly lagging ones), radians.
    pub fn arm_setpoint(&self) -> [f64; 6] {
        match &self.arm {
            ArmPlan::Hold(q) => *q,
            ArmPlan::Command { command, t0 } => command.at(self.sim.time() - t0).q,
            ArmPlan::Track { trajectory, t0 } => trajectory.sample(self.sim.time() - t0).0,
        }
    }

    /// Starts following `trajectory` now.
    pub fn track(&mut self, trajectory: Box<dyn Trajectory>) {
        if tracing::enabled!(target: "macrotree::motion", tracing::Level::DEBUG) {
            let q = trajectory.end();
            let pose = crate::motion::fk(&q);
            let p = pose.translation.vector;
            let tool_yaw = super::targets::tool_yaw(pose.rotation.to_rotation_matrix().matrix()).to_degrees();
            let sign = |x: f64| if x >= 0.0 { '+' } else { '−' };
            tracing::debug!(
                target: "macrotree::motion",
                sim_time = self.sim.time(),
                "plan: {} of {:.3} s to pinch ({:.3}, {:.3}, {:.3}) m, tool yaw {tool_yaw:.1}°, joints [{}] rad (IK branch: shoulder {}, elbow {}, wrist {})",
                trajectory.name(),
                trajectory.duration(),
                p.x,
                p.y,
                p.z,
                q.iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>().join(", "),
                sign(q[1]),
                sign(q[2]),
                sign(q[4]),
            );
        }
        self.arm = ArmPlan::Track {
            trajectory,
            t0: self.sim.time(),
        };
        self.pending = None;
    }

    /// Commands the arm with `command` for the coming control period (the environment's `ctrl`
    /// action); after it the arm holds where the command ended.
    pub fn command_arm(&mut self, command: ArmCommand) {
        self.arm = ArmPlan::Command {
            command,
            t0: self.sim.time(),
        };
        self.pending = None;
    }

    /// Stops where the arm is commanded to be now and holds there (a halt).
    pub fn hold(&mut self) {
        self.arm = ArmPlan::Hold(self.arm_setpoint());
        self.pending = None;
    }

    /// The current trajectory has reached its end (or the arm is holding).
    pub fn arm_motion_finished(&self) -> bool {
        match &self.arm {
            ArmPlan::Hold(_) | ArmPlan::Command { .. } => true,
            ArmPlan::Track { trajectory, t0 } => self.sim.time() - t0 >= trajectory.duration(),
        }
    }

    /// Commands the gripper actuator (0 = open … 255 = closed).
    pub fn set_gripper(&mut self, ctrl: f64) {
        self.gripper_ctrl = ctrl.clamp(0.0, 255.0);
        self.pending = None;
    }

    /// The gripper actuator command.
    pub fn gripper_command(&self) -> f64 {
        self.gripper_ctrl
    }

    /// The command of the control period starting now: the arm's trajectory sampled now (set
    /// point, velocity, acceleration) or its hold, and the gripper command. What the physics
    /// runs in [`Cell::advance`] and what a dataset records as the frame's `action`.
    pub fn period_command(&mut self) -> CellCommand {
        if let Some(c) = self.pending {
            return c;
        }
        let t = self.sim.time();
        let arm = match &self.arm {
            ArmPlan::Hold(q) => ArmCommand::hold(*q),
            ArmPlan::Command { command, t0 } if t == *t0 => *command,
            ArmPlan::Command { command, t0 } => {
                let q = command.at(t - t0).q;
                self.arm = ArmPlan::Hold(q);
                ArmCommand::hold(q)
            }
            ArmPlan::Track { trajectory, t0 } if t - t0 >= trajectory.duration() => {
                let end = trajectory.end();
                self.arm = ArmPlan::Hold(end);
                ArmCommand::hold(end)
            }
            ArmPlan::Track { trajectory, t0 } => {
                let (q, qd) = trajectory.sample(t - t0);
                ArmCommand {
                    q,
                    qd,
                    qdd: trajectory.acceleration(t - t0),
                }
            }
        };
        let command = CellCommand {
            arm,
            gripper: self.gripper_ctrl,
        };
        self.pending = Some(command);
        command
    }

    /// Replaces the command of the control period starting now (call it after the tick that
    /// set the period's command, before [`Cell::advance`]): the physics runs `command` for
    /// this one period, while the arm's trajectory or hold and the gripper command stay as the
    /// leaves set them — the next period's command is theirs again. The environment's residual
    /// mode adds its correction this way.
    pub fn override_period_command(&mut self, command: CellCommand) {
        self.pending = Some(command);
    }

    /// The command of the last control period the physics ran, `None` before the first.
    pub fn last_command(&self) -> Option<CellCommand> {
        self.last_command
    }

    /// Advances the physics by one control period under [`Cell::period_command`] (held over
    /// the period as [`ArmCommand::at`] says, applied at every physics step), then refreshes the
    /// world snapshot.
    pub fn advance(&mut self) {
        let command = self.period_command();
        for obs in &mut self.observers {
            obs.on_period(&command);
        }
        for step in 0..self.steps_per_tick {
            let arm = command.arm.at(step as f64 * TIMESTEP);
            self.sim.command_arm(&arm.q, &arm.qd, &arm.qdd);
            self.sim.set_gripper_ctrl(command.gripper);
            for obs in &mut self.observers {
                obs.before_step(&mut self.sim);
            }
            self.sim.step();
        }
        self.pending = None;
        self.last_command = Some(command);
        self.world = self.sim.observe();
    }
}
