//! `release`: open the gripper (fully or to a width), then retreat straight up.

use nalgebra::Vector3;

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use crate::failure::{Failure, FailureKind};
use crate::kinds::Release as ReleaseSpec;
use crate::motion::gripper::{OPEN_CTRL, ctrl_for_width, width_for_ctrl};
use crate::motion::{CartesianMove, MotionLimits, Trajectory};

/// How close the opening must come to its target, metres.
const WIDTH_TOLERANCE: f64 = 0.002;

/// Driver-joint speed below which the fingers count as stopped, rad/s.
const STALL_SPEED: f64 = 0.02;
/// Consecutive stopped ticks (after [`MIN_OPEN_TIME`]) before an opening counts as blocked.
const STALL_TICKS: u32 = 10;
/// Time the fingers get to start moving before a stop counts, seconds.
const MIN_OPEN_TIME: f64 = 0.2;

/// Executes a [`ReleaseSpec`].
pub struct Release {
    spec: ReleaseSpec,
    target_width: f64,
    t0: f64,
    stalled: u32,
    retreating: bool,
    /// The unit direction of the retreat, world frame (straight up unless told otherwise).
    retreat_along: Vector3<f64>,
    goal_q: [f64; 6],
    arrival: Arrival,
}

impl Release {
    /// A release controller for `spec`.
    pub fn new(spec: ReleaseSpec) -> Self {
        Self {
            spec,
            target_width: 0.0,
            t0: 0.0,
            stalled: 0,
            retreating: false,
            retreat_along: Vector3::z(),
            goal_q: [0.0; 6],
            arrival: Arrival::default(),
        }
    }

    /// A release that retreats along `along` (unit, world frame) instead of straight up: back
    /// out the way the hand came, from under something.
    pub fn retreating_along(spec: ReleaseSpec, along: Vector3<f64>) -> Self {
        Self {
            retreat_along: along,
            ..Self::new(spec)
        }
    }
}

impl MacroAction for Release {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        // The arm holds still — unless a sibling action (in a `parallel`) is moving it.
        if cell.arm_motion_finished() {
            cell.hold();
        }
        let (mut ctrl, mut width) = match self.spec.width {
            Some(w) => (ctrl_for_width(w), w.min(width_for_ctrl(OPEN_CTRL))),
            None => (OPEN_CTRL, width_for_ctrl(OPEN_CTRL)),
        };
        // Letting a block go beside a wall or a neighbour: open only as wide as the fingers
        // clear it.
        let room = super::release_room::room_to_open(cell.world(), width);
        if room < width {
            tracing::debug!(target: "macrotree::actions", "release: opening to {:.1} mm, not {:.1} mm: the fingers would touch what is beside the block", room * 1e3, width * 1e3);
            (ctrl, width) = (ctrl_for_width(room), room);
        }
        cell.set_gripper(ctrl);
        self.target_width = width;
        self.retreating = false;
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
        if self.retreating {
            return format!("retreat: {}", self.arrival.waiting_for(cell, &self.goal_q));
        }
        let w = cell.world();
        let touching: Vec<&str> = (0..w.objects.len())
            .filter(|&i| !w.released(i))
            .map(|i| w.name(i))
            .collect();
        let mut s = format!(
            "gripper still opening, width {:.3} m of {:.3} m",
            w.gripper_width, self.target_width
        );
        if !touching.is_empty() {
            s += &format!(", pads still touch {}", touching.join(", "));
        }
        s
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if !self.retreating {
            let w = cell.world();
            if (w.gripper_width - self.target_width).abs() > WIDTH_TOLERANCE {
                // Fingers stopped short of the opening (against a wall): once no pad touches a
                // block any more the release has done its job, so retreat anyway.
                let stopped = w.time - self.t0 >= MIN_OPEN_TIME && w.gripper_speed.abs() < STALL_SPEED;
                self.stalled = if stopped { self.stalled + 1 } else { 0 };
                // A pad still on a block (wedged against a neighbour) would lift it out again.
                let touching = (0..w.objects.len()).any(|i| !w.released(i));
                if self.stalled < STALL_TICKS || touching {
                    return Progress::Running;
                }
                tracing::debug!(target: "macrotree::actions", width = w.gripper_width, "release: the fingers stopped at {:.1} mm of {:.1} mm (blocked); retreating", w.gripper_width * 1e3, self.target_width * 1e3);
            }
            if self.spec.retreat == 0.0 {
                return Progress::Done;
            }
            let from = cell.arm_setpoint();
            let mut pose = crate::motion::fk(&from);
            pose.translation.vector += self.retreat_along * self.spec.retreat;
            match CartesianMove::new(from, pose, &MotionLimits::default()) {
                Ok(mv) => {
                    self.goal_q = mv.end();
                    cell.track(Box::new(mv));
                    self.retreating = true;
                }
                Err(e) => {
                    return Progress::Failed(Failure::new(
                        FailureKind::Unreachable,
                        format!(
                            "cannot retreat {:.3} m {}: {e}",
                            self.spec.retreat,
                            if self.retreat_along == Vector3::z() {
                                "up"
                            } else {
                                "back out"
                            }
                        ),
                    ));
                }
            }
        }
        self.arrival.progress(cell, &self.goal_q)
    }
}
