//! `carry`: lift the held cube, transfer it above the goal on a straight line at a safe height,
//! and lower it to the place height. Fails at once when the grasp is lost.

use nalgebra::{Isometry3, Translation3, Vector3};

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::targets::resolve;
use crate::motion::{CartesianMove, MotionLimits, Trajectory};
use crate::spec::Carry as CarrySpec;
use crate::world::CUBE_HALF;
use crate::world::conditions::{Tolerances, cube_grasped};

/// Consecutive ticks without a grasp before the carry fails (filters single-step contact flicker).
const LOST_TICKS: u32 = 3;

/// Executes a [`CarrySpec`].
pub struct Carry {
    spec: CarrySpec,
    /// Pinch poses at the end of each phase (lift, transfer, lower).
    waypoints: Vec<Isometry3<f64>>,
    phase: usize,
    goal_q: [f64; 6],
    lost: u32,
}

impl Carry {
    /// A carry controller for `spec`.
    pub fn new(spec: CarrySpec) -> Self {
        Self {
            spec,
            waypoints: Vec::new(),
            phase: 0,
            goal_q: [0.0; 6],
            lost: 0,
        }
    }

    fn limits(&self) -> MotionLimits {
        MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        }
    }

    fn start_phase(&mut self, cell: &mut Cell) -> Result<(), String> {
        let pose = self.waypoints[self.phase];
        let mv = CartesianMove::new(cell.arm_setpoint(), pose, &self.limits())
            .map_err(|e| format!("unreachable carry path ({}): {e}", PHASES[self.phase]))?;
        self.goal_q = mv.end();
        cell.track(Box::new(mv));
        Ok(())
    }
}

const PHASES: [&str; 3] = ["lift", "transfer", "lower"];

impl MacroAction for Carry {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        let w = cell.world();
        if !cube_grasped(w, Tolerances::GRASP_OFF_AXIS) {
            return Err("carry needs the cube in the gripper, but it is not grasped".into());
        }
        // Keep the pinch where it holds the cube: move the pinch by as much as the cube should move.
        let pinch_from_cube = w.pinch_pos - w.cube_pos;
        let rotation = nalgebra::UnitQuaternion::from_matrix(&w.pinch_rot);
        let goal = resolve(&self.spec.to, w);
        let carry_z = self.spec.lift + CUBE_HALF;
        let place_z = goal.z + self.spec.place_height + CUBE_HALF;
        let cube_path = [
            Vector3::new(w.cube_pos.x, w.cube_pos.y, carry_z.max(w.cube_pos.z)),
            Vector3::new(goal.x, goal.y, carry_z.max(place_z)),
            Vector3::new(goal.x, goal.y, place_z),
        ];
        self.waypoints = cube_path
            .iter()
            .map(|c| Isometry3::from_parts(Translation3::from(c + pinch_from_cube), rotation))
            .collect();
        self.phase = 0;
        self.lost = 0;
        self.start_phase(cell)
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        let w = cell.world();
        if cube_grasped(w, Tolerances::GRASP_OFF_AXIS) {
            self.lost = 0;
        } else {
            self.lost += 1;
            if self.lost >= LOST_TICKS {
                let c = w.cube_pos;
                return Progress::Failed(format!(
                    "grasp lost during {}: cube at ({:.3}, {:.3}, {:.3}) m",
                    PHASES[self.phase], c.x, c.y, c.z
                ));
            }
        }
        if self.phase + 1 < self.waypoints.len() {
            if cell.arm_motion_finished() {
                self.phase += 1;
                if let Err(e) = self.start_phase(cell) {
                    return Progress::Failed(e);
                }
            }
            return Progress::Running;
        }
        if Arrival::default().reached(cell, &self.goal_q) {
            Progress::Done
        } else {
            Progress::Running
        }
    }
}
