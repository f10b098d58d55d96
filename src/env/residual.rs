//! `Action::Residual`: residual control (Silver et al. 2018, Johannink et al. 2019) — the
//! environment's tree runs as the base controller, ticked once per control period across
//! steps exactly as [`crate::episode::run_in_cell`] ticks it, and each step adds the agent's
//! correction to the command the tree gave for that period. A zero residual leaves the base
//! command untouched, so the episode is the scripted one bit for bit.

use std::sync::Arc;

use super::config::time_limit_reached;
use super::step::{BaseStep, Status, StepResult};
use crate::episode::{DriverState, MacroDriver};
use crate::error::Error;
use crate::failure::{Failure, FailureKind};
use crate::motion::{CTRL_LIMITS, CellCommand, ClampedCommand, JOINT_LIMITS};
use crate::plan::Plan;
use crate::runtime::{TreeRunner, TreeStatus};

/// Values of a residual action: six joint set-point offsets, then a gripper-command offset.
pub const RESIDUAL_LEN: usize = 7;

/// The bounds of a residual action's values; values beyond them are clamped (and counted in
/// [`super::StepResult::ctrl_clamped`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualLimits {
    /// Largest offset of a joint set point from the base command's, radians.
    pub max_joint_offset: f64,
    /// Largest offset of the gripper command from the base command's (0 open … 255 closed).
    pub max_gripper_offset: f64,
}

impl ResidualLimits {
    /// The upper bound of each residual value (the lower is its negative): the joint offset
    /// for each of the six set points (rad), then the gripper offset.
    pub const fn high(&self) -> [f64; RESIDUAL_LEN] {
        let mut high = [self.max_joint_offset; RESIDUAL_LEN];
        high[RESIDUAL_LEN - 1] = self.max_gripper_offset;
        high
    }
}

/// The limits of every residual action: ±0.1 rad per joint (about 8 cm at the pinch for the
/// shoulder, 1 cm for a wrist), and the gripper's whole range, so a residual can open or close
/// it.
pub const RESIDUAL_LIMITS: ResidualLimits = ResidualLimits {
    max_joint_offset: 0.1,
    max_gripper_offset: crate::motion::CLOSED_CTRL - crate::motion::OPEN_CTRL,
};

/// Refuses a residual with a value that is not finite, naming it (`residual[3]`).
pub(super) fn check(residual: &[f64; RESIDUAL_LEN]) -> Result<(), Error> {
    match residual.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(Error::Action {
            message: format!("residual[{i}] is {}; every value must be finite", residual[i]),
        }),
        None => Ok(()),
    }
}

/// The command of a residual step: `base` with `residual` (checked finite) added to its set
/// points and gripper command, the residual first clamped to [`RESIDUAL_LIMITS`], the sum then
/// clamped like every `ctrl` command ([`CTRL_LIMITS`], from the set point `from` the last
/// period ended at, radians, over `period` seconds). The base's velocities and accelerations
/// stay. An all-zero residual gives `base` itself, unclamped.
pub(super) fn compose(
    base: &CellCommand,
    residual: &[f64; RESIDUAL_LEN],
    from: &[f64; 6],
    period: f64,
) -> ClampedCommand {
    if residual.iter().all(|&r| r == 0.0) {
        return ClampedCommand {
            command: *base,
            clamped: 0,
        };
    }
    let mut clamped = 0;
    let mut bounded = |r: f64, max: f64| {
        let b = r.clamp(-max, max);
        clamped += u32::from(b != r);
        b
    };
    let mut command = *base;
    for (i, q) in command.arm.q.iter_mut().enumerate() {
        let (lo, hi) = JOINT_LIMITS[i];
        *q = (*q + bounded(residual[i], RESIDUAL_LIMITS.max_joint_offset)).clamp(lo, hi);
    }
    command.gripper += bounded(residual[6], RESIDUAL_LIMITS.max_gripper_offset);
    let mut checked = CTRL_LIMITS.clamp(command, from, period);
    checked.clamped += clamped;
    checked
}

/// The base tree's run across residual steps.
pub(super) struct BaseRun {
    /// The tree, ticked once per step.
    pub runner: TreeRunner,
    /// The leaf driver's state between steps (`None` only while a step uses it).
    pub driver: Option<DriverState>,
    /// The tree's status after its last tick.
    pub status: TreeStatus,
}

impl BaseRun {
    /// A run of `tree` from its root, with `driver` fresh.
    pub fn new(tree: Arc<Plan>, driver: DriverState) -> Self {
        Self {
            runner: TreeRunner::new(tree),
            driver: Some(driver),
            status: TreeStatus::Running,
        }
    }
}

impl super::MacroEnv {
    /// One residual step (see [`super::Action::Residual`]).
    pub(super) fn step_residual(&mut self, residual: &[f64; RESIDUAL_LEN]) -> Result<StepResult, Error> {
        let tree = self.tree.clone().ok_or_else(|| Error::Action {
            message: "a residual step needs a base tree: give the environment a tree (MacroEnv::new)"
                .to_string(),
        })?;
        check(residual)?;
        let dt = self.cell.control_period();
        let (t0, s0) = (self.cell.world().time, self.cell.sim().steps());
        let base = match &mut self.base {
            Some(b) => b,
            None => {
                let mut fresh = MacroDriver::new(&mut self.cell, &self.factory);
                fresh.set_leaf_paths(tree.leaves.iter().map(|l| l.path.clone()).collect());
                self.base.insert(BaseRun::new(tree, fresh.suspend()))
            }
        };
        let state = base
            .driver
            .take()
            .expect("a base run keeps its driver between steps");
        let mut driver = MacroDriver::resume(&mut self.cell, &self.factory, state);
        let seen = driver.collisions.len();
        let now = driver.cell().world().time;
        let mut failure = None;
        let mut truncated = false;
        let mut clamped = 0;
        let mut base_command = driver.cell().period_command();
        if time_limit_reached(now, self.config.max_sim_time) {
            truncated = true;
            failure = Some(Failure::new(
                FailureKind::TimeLimit,
                format!(
                    "time limit: the episode reached its {} s of simulated time",
                    self.config.max_sim_time
                ),
            ));
        } else {
            if base.status == TreeStatus::Running {
                base.status = base.runner.tick(now, dt, &mut driver);
            }
            base_command = driver.cell().period_command();
            let from = match driver.cell().last_command() {
                Some(last) => last.arm.at(dt).q,
                None => driver.cell().arm_setpoint(),
            };
            let checked = compose(&base_command, residual, &from, dt);
            clamped = checked.clamped;
            if checked.command != base_command {
                driver.cell().override_period_command(checked.command);
            }
            driver.advance();
        }
        let collisions = driver.collisions[seen..].to_vec();
        if base.status == TreeStatus::Failure && failure.is_none() {
            failure = Some(
                base.runner
                    .failure()
                    .cloned()
                    .or_else(|| driver.last_failure.clone())
                    .unwrap_or_else(|| Failure::other("the base tree failed")),
            );
        }
        base.driver = Some(driver.suspend());
        #[cfg(feature = "render")]
        if let Some(f) = &mut self.film
            && !truncated
        {
            f.tick(&self.cell)?;
        }
        if let Some(why) = self.cell.sim().instability() {
            tracing::error!(target: "macrotree::env", "{why}");
            self.unstable = true;
            failure = Some(Failure::new(FailureKind::Unstable, why));
        }
        let world = self.cell.world();
        let holds = super::step::goal_holds(world);
        let base_step = BaseStep {
            command: base_command.to_vector(),
            status: base.status,
        };
        Ok(StepResult {
            observation: self.observe(),
            status: if failure.is_none() {
                Status::Success
            } else {
                Status::Failure
            },
            failure,
            sim_time: world.time - t0,
            physics_steps: self.cell.sim().steps() - s0,
            reward: if holds { 1.0 } else { 0.0 },
            goal_ticks: u64::from(holds && !truncated),
            rewards: if self.config.rewards_per_tick && !truncated {
                vec![if holds { 1.0 } else { 0.0 }]
            } else {
                Vec::new()
            },
            terminated: holds || self.unstable,
            truncated: truncated
                || (!self.unstable && time_limit_reached(world.time, self.config.max_sim_time)),
            collisions,
            goal: crate::world::goal::evaluate(world),
            faults_fired: self.faults_fired(),
            ctrl_clamped: clamped,
            base: Some(base_step),
        })
    }

    /// Ends the base tree's run, if one is under way: its running leaves are halted (another
    /// kind of action is about to command the cell); the next residual step starts the tree
    /// again from its root.
    pub(super) fn end_base_run(&mut self) {
        if let Some(mut base) = self.base.take()
            && let Some(state) = base.driver.take()
        {
            let mut driver = MacroDriver::resume(&mut self.cell, &self.factory, state);
            base.runner.halt_all(&mut driver);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{ArmCommand, HOME_Q};

    fn base() -> CellCommand {
        CellCommand {
            arm: ArmCommand {
                q: HOME_Q,
                qd: [0.1; 6],
                qdd: [0.2; 6],
            },
            gripper: 100.0,
        }
    }

    #[test]
    fn a_zero_residual_gives_the_base_command_itself() {
        let c = compose(&base(), &[0.0; RESIDUAL_LEN], &HOME_Q, 0.004);
        assert_eq!(c.command, base());
        assert_eq!(c.clamped, 0);
        // Even a base command beyond the ctrl limits stays as the tree gave it.
        let mut fast = base();
        fast.arm.qd = [100.0; 6];
        assert_eq!(
            compose(&fast, &[-0.0; RESIDUAL_LEN], &HOME_Q, 0.004).command,
            fast
        );
    }

    #[test]
    fn a_residual_adds_to_the_set_points_and_the_gripper_within_its_bounds() {
        let mut r = [0.0; RESIDUAL_LEN];
        r[0] = 0.01;
        r[6] = -30.0;
        let c = compose(&base(), &r, &HOME_Q, 0.004);
        assert_eq!(c.command.arm.q[0], HOME_Q[0] + 0.01);
        assert_eq!(c.command.arm.qd, base().arm.qd, "the base's feedforward stays");
        assert_eq!(c.command.gripper, 70.0);
        assert_eq!(c.clamped, 0);
        // Beyond the bounds: clamped to ±0.1 rad, then to one period's step from `from`.
        r[1] = 5.0;
        r[6] = 1000.0;
        let c = compose(&base(), &r, &HOME_Q, 0.1);
        assert_eq!(c.command.arm.q[1], HOME_Q[1] + RESIDUAL_LIMITS.max_joint_offset);
        assert_eq!(c.command.gripper, 255.0);
        assert_eq!(
            c.clamped, 3,
            "the joint offset, the gripper offset, the gripper range"
        );
        let c = compose(&base(), &r, &HOME_Q, 0.004);
        let step = super::super::CTRL_LIMITS.max_joint_speed * 0.004;
        assert!((c.command.arm.q[1] - (HOME_Q[1] + step)).abs() < 1e-9);
    }

    #[test]
    fn a_residual_that_is_not_finite_is_refused_by_index() {
        let mut r = [0.0; RESIDUAL_LEN];
        assert!(check(&r).is_ok());
        r[3] = f64::NAN;
        let e = check(&r).unwrap_err();
        assert_eq!(e.kind(), "invalid_action");
        assert!(e.to_string().contains("residual[3]"), "{e}");
    }
}
