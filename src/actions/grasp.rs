//! `grasp`: close the gripper to a width or until the fingers stall, then verify the cube is held.

use super::cell::Cell;
use super::macro_action::{MacroAction, Progress};
use super::targets::object_index;
use crate::failure::{Failure, FailureKind};
use crate::kinds::Grasp as GraspSpec;
use crate::motion::gripper::{CLOSED_CTRL, ctrl_for_width};
use crate::world::conditions::Tolerances;

/// Driver-joint speed below which the fingers count as stalled, rad/s.
const STALL_SPEED: f64 = 0.02;
/// Consecutive stalled ticks needed before the grasp is judged.
const STALL_TICKS: u32 = 5;
/// Time the fingers get to start moving before a stall counts, seconds.
const MIN_CLOSE_TIME: f64 = 0.1;

/// Executes a [`GraspSpec`].
pub struct Grasp {
    spec: GraspSpec,
    t0: f64,
    stalled: u32,
}

impl Grasp {
    /// A grasp controller for `spec`.
    pub fn new(spec: GraspSpec) -> Self {
        Self {
            spec,
            t0: 0.0,
            stalled: 0,
        }
    }
}

impl MacroAction for Grasp {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        // The arm holds still — unless a sibling action (in a `parallel`) is moving it.
        if cell.arm_motion_finished() {
            cell.hold();
        }
        let ctrl = self.spec.width.map_or(CLOSED_CTRL, ctrl_for_width);
        cell.set_gripper(ctrl);
        self.t0 = cell.world().time;
        self.stalled = 0;
        Ok(())
    }

    /// Preempted: the arm holds, and the fingers stop at the opening they have now (a finger on
    /// a block keeps its command, so a grip is not loosened).
    fn halt(&mut self, cell: &mut Cell) {
        super::macro_action::freeze_gripper(cell);
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        let w = cell.world();
        format!(
            "gripper still closing, width {:.3} m (fingers at {:.2} rad/s)",
            w.gripper_width,
            w.gripper_speed.abs()
        )
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        let w = cell.world();
        if w.time - self.t0 < MIN_CLOSE_TIME {
            return Progress::Running;
        }
        if w.gripper_speed.abs() < STALL_SPEED {
            self.stalled += 1;
        } else {
            self.stalled = 0;
        }
        if self.stalled < STALL_TICKS {
            return Progress::Running;
        }
        let (held, what) = match &self.spec.object {
            Some(o) => match object_index(o, w) {
                Ok(i) => (w.holds(i, Tolerances::GRASP_OFF_AXIS), w.name(i).to_string()),
                Err(e) => return Progress::Failed(e),
            },
            None => (
                w.held_block(Tolerances::GRASP_OFF_AXIS).is_some(),
                "a block".to_string(),
            ),
        };
        if held {
            Progress::Done
        } else {
            let touched: Vec<&str> = (0..w.objects.len())
                .filter(|&i| !w.released(i))
                .map(|i| w.name(i))
                .collect();
            Progress::Failed(Failure::new(
                FailureKind::GraspFailed,
                format!(
                    "grasp failed: fingers stopped at {:.1} mm without holding {what} (pads touch: {})",
                    w.gripper_width * 1e3,
                    if touched.is_empty() {
                        "nothing".to_string()
                    } else {
                        touched.join(", ")
                    }
                ),
            ))
        }
    }
}
