//! `home` and `move_joints`: joint-space moves to a named or given configuration.

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::planning::{check_motion, describe, plan_motion_within};
use crate::motion::plan::GoalSet;
use crate::motion::{JointMove, MotionLimits};

/// Moves the arm in joint space to fixed joint angles (radians).
pub struct MoveJoints {
    goal_q: [f64; 6],
    max_checks: Option<u64>,
    arrival: Arrival,
}

impl MoveJoints {
    /// A joint move to `goal_q` (radians).
    pub fn new(goal_q: [f64; 6]) -> Self {
        Self {
            goal_q,
            max_checks: None,
            arrival: Arrival::default(),
        }
    }

    /// The planner, when the direct move collides, may spend at most `max_checks` collision
    /// checks (`None`: its default budget); past them the move fails with `no_path`.
    pub fn with_max_checks(mut self, max_checks: Option<u64>) -> Self {
        self.max_checks = max_checks;
        self
    }

    /// A joint move to the UR5e home configuration.
    pub fn home() -> Self {
        Self::new(crate::sim::HOME_Q)
    }
}

impl MacroAction for MoveJoints {
    fn start(&mut self, cell: &mut Cell) -> Result<(), crate::failure::Failure> {
        let from = cell.arm_setpoint();
        let mv = JointMove::new(from, self.goal_q, &MotionLimits::default());
        if let Some((_, pairs)) = check_motion(cell, &[&mv], &[], false) {
            // The straight joint move would collide: plan around whatever is in the way to
            // exactly these joint angles.
            tracing::debug!(target: "macrotree::actions", "move_joints: the direct joint move would touch {}; planning", describe(&pairs));
            let goals = GoalSet::configs(vec![self.goal_q]);
            let motion = plan_motion_within(cell, "move_joints", &from, &goals, self.max_checks)?;
            cell.track(Box::new(motion.trajectory));
            return Ok(());
        }
        cell.track(Box::new(mv));
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        self.arrival.progress(cell, &self.goal_q)
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        self.arrival.waiting_for(cell, &self.goal_q)
    }
}
