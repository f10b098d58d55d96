//! `release`: open the gripper, then retreat straight up.

use nalgebra::Vector3;

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use crate::motion::gripper::{OPEN_CTRL, width_for_ctrl};
use crate::motion::{CartesianMove, MotionLimits, Trajectory};
use crate::spec::Release as ReleaseSpec;

/// Fraction of the fully open width at which the gripper counts as open.
const OPEN_FRACTION: f64 = 0.95;

/// Executes a [`ReleaseSpec`].
pub struct Release {
    spec: ReleaseSpec,
    retreating: bool,
    goal_q: [f64; 6],
}

impl Release {
    /// A release controller for `spec`.
    pub fn new(spec: ReleaseSpec) -> Self {
        Self {
            spec,
            retreating: false,
            goal_q: [0.0; 6],
        }
    }
}

impl MacroAction for Release {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        cell.hold();
        cell.set_gripper(OPEN_CTRL);
        self.retreating = false;
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if !self.retreating {
            if cell.world().gripper_width < OPEN_FRACTION * width_for_ctrl(OPEN_CTRL) {
                return Progress::Running;
            }
            if self.spec.retreat == 0.0 {
                return Progress::Done;
            }
            let from = cell.arm_setpoint();
            let mut pose = crate::motion::fk(&from);
            pose.translation.vector += Vector3::new(0.0, 0.0, self.spec.retreat);
            match CartesianMove::new(from, pose, &MotionLimits::default()) {
                Ok(mv) => {
                    self.goal_q = mv.end();
                    cell.track(Box::new(mv));
                    self.retreating = true;
                }
                Err(e) => {
                    return Progress::Failed(format!("cannot retreat {:.3} m up: {e}", self.spec.retreat));
                }
            }
        }
        if Arrival::default().reached(cell, &self.goal_q) {
            Progress::Done
        } else {
            Progress::Running
        }
    }
}
