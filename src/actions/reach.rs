//! `reach`: move the pinch to a pose above/at a target, tool pointing down.

use nalgebra::Vector3;

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::targets::{resolve, tool_yaw};
use crate::motion::{CartesianMove, JointMove, MotionLimits, down_pose, ik_down};
use crate::spec::{PathKind, Reach as ReachSpec, Target, Yaw};

/// Executes a [`ReachSpec`].
pub struct Reach {
    spec: ReachSpec,
    goal_q: [f64; 6],
}

impl Reach {
    /// A reach controller for `spec`.
    pub fn new(spec: ReachSpec) -> Self {
        Self {
            spec,
            goal_q: [0.0; 6],
        }
    }
}

impl MacroAction for Reach {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        let w = cell.world();
        let offset = Vector3::from(self.spec.offset);
        let position = resolve(&self.spec.target, w) + offset;
        let current_yaw = tool_yaw(&w.pinch_rot);
        let (yaw, quarter) = match (&self.spec.yaw, &self.spec.target) {
            (Yaw::Object, Target::Cube) => (w.cube_yaw(), true),
            (Yaw::Object, _) | (Yaw::Keep, _) => (current_yaw, false),
            (Yaw::Angle(a), _) => (*a, false),
        };
        let from = cell.arm_setpoint();
        let goal_q = ik_down(&position, yaw, quarter, &from).map_err(|e| format!("unreachable: {e}"))?;
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        match self.spec.path {
            PathKind::Joint => cell.track(Box::new(JointMove::new(from, goal_q, &limits))),
            PathKind::Cartesian => {
                let pose = down_pose(&position, yaw_of_solution(&goal_q));
                let mv =
                    CartesianMove::new(from, pose, &limits).map_err(|e| format!("unreachable path: {e}"))?;
                cell.track(Box::new(mv));
            }
        }
        self.goal_q = goal_q;
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if Arrival::default().reached(cell, &self.goal_q) {
            Progress::Done
        } else {
            Progress::Running
        }
    }
}

/// The tool yaw that joint solution `q` gives, radians.
fn yaw_of_solution(q: &[f64; 6]) -> f64 {
    tool_yaw(crate::motion::fk(q).rotation.to_rotation_matrix().matrix())
}
