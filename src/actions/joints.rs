//! `home` and `move_joints`: joint-space moves to a named or given configuration.

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use crate::motion::{JointMove, MotionLimits};

/// Moves the arm in joint space to fixed joint angles (radians).
pub struct MoveJoints {
    goal_q: [f64; 6],
    arrival: Arrival,
}

impl MoveJoints {
    /// A joint move to `goal_q` (radians).
    pub fn new(goal_q: [f64; 6]) -> Self {
        Self {
            goal_q,
            arrival: Arrival::default(),
        }
    }

    /// A joint move to the UR5e home configuration.
    pub fn home() -> Self {
        Self::new(crate::sim::HOME_Q)
    }
}

impl MacroAction for MoveJoints {
    fn start(&mut self, cell: &mut Cell) -> Result<(), crate::failure::Failure> {
        let from = cell.arm_setpoint();
        cell.track(Box::new(JointMove::new(
            from,
            self.goal_q,
            &MotionLimits::default(),
        )));
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        self.arrival.progress(cell, &self.goal_q)
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        self.arrival.waiting_for(cell, &self.goal_q)
    }
}
