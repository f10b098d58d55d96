//! `release`: open the gripper (fully or to a width), then retreat straight up.

use nalgebra::Vector3;

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use crate::motion::gripper::{OPEN_CTRL, ctrl_for_width, width_for_ctrl};
use crate::motion::{CartesianMove, MotionLimits, Trajectory};
use crate::spec::Release as ReleaseSpec;

/// How close the opening must come to its target, metres.
const WIDTH_TOLERANCE: f64 = 0.002;

/// Executes a [`ReleaseSpec`].
pub struct Release {
    spec: ReleaseSpec,
    target_width: f64,
    retreating: bool,
    goal_q: [f64; 6],
    arrival: Arrival,
}

impl Release {
    /// A release controller for `spec`.
    pub fn new(spec: ReleaseSpec) -> Self {
        Self {
            spec,
            target_width: 0.0,
            retreating: false,
            goal_q: [0.0; 6],
            arrival: Arrival::default(),
        }
    }
}

impl MacroAction for Release {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        cell.hold();
        let (ctrl, width) = match self.spec.width {
            Some(w) => (ctrl_for_width(w), w.min(width_for_ctrl(OPEN_CTRL))),
            None => (OPEN_CTRL, width_for_ctrl(OPEN_CTRL)),
        };
        cell.set_gripper(ctrl);
        self.target_width = width;
        self.retreating = false;
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if !self.retreating {
            if (cell.world().gripper_width - self.target_width).abs() > WIDTH_TOLERANCE {
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
        self.arrival.progress(cell, &self.goal_q)
    }
}
