//! The contract every macro-action controller follows.

use super::cell::Cell;

/// How a running macro action is doing after a tick.
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    /// Still executing.
    Running,
    /// Finished successfully.
    Done,
    /// Finished unsuccessfully, with a reason a person can act on.
    Failed(String),
}

/// A macro action: planned on its first tick, updated every tick after, halted when preempted.
pub trait MacroAction: Send {
    /// Plans the action from the current world (first tick). An error fails the leaf at once.
    fn start(&mut self, cell: &mut Cell) -> Result<(), String>;
    /// Checks progress after the last control period.
    fn update(&mut self, cell: &mut Cell) -> Progress;
    /// The action was preempted: by default the arm holds where it is commanded to be now and the
    /// gripper keeps its command.
    fn halt(&mut self, cell: &mut Cell) {
        cell.hold();
    }
}

/// Tolerances that decide when an arm motion has arrived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrival {
    /// Largest pinch position error, metres.
    pub position: f64,
    /// Largest joint speed, rad/s.
    pub joint_speed: f64,
}

impl Default for Arrival {
    fn default() -> Self {
        Self {
            position: 0.002,
            joint_speed: 0.05,
        }
    }
}

impl Arrival {
    /// The trajectory has ended, the pinch is within `position` of where `goal_q` puts it and every
    /// joint moves slower than `joint_speed`.
    pub fn reached(&self, cell: &Cell, goal_q: &[f64; 6]) -> bool {
        let w = cell.world();
        cell.arm_motion_finished()
            && (crate::motion::fk(goal_q).translation.vector - w.pinch_pos).norm() <= self.position
            && w.arm_qd.iter().all(|v| v.abs() <= self.joint_speed)
    }

    /// Pinch position error to the pose `goal_q` gives, metres (for failure reasons).
    pub fn error(cell: &Cell, goal_q: &[f64; 6]) -> f64 {
        (crate::motion::fk(goal_q).translation.vector - cell.world().pinch_pos).norm()
    }
}
