//! `carry`: lift the held cube, transfer it above the goal on a straight line at a safe height,
//! and lower it to the place height. Fails at once when the grasp is lost.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::targets::resolve;
use crate::motion::{CartesianMove, MotionLimits, Trajectory};
use crate::spec::Carry as CarrySpec;
use crate::world::CUBE_HALF;
use crate::world::conditions::{Tolerances, cube_grasped};

/// Consecutive ticks without a grasp before the carry fails (filters single-step contact flicker).
const LOST_TICKS: u32 = 3;

/// How far the goal may have moved during the transfer before the transfer is re-planned to its
/// new place (a bowl slid aside), metres.
const GOAL_MOVED: f64 = 0.005;

/// Re-plans of the transfer allowed in one carry.
const MAX_REPLANS: u32 = 3;

/// The carry's phases, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Lift,
    Transfer,
    Lower,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Phase::Lift => "lift",
            Phase::Transfer => "transfer",
            Phase::Lower => "lower",
        }
    }
}

/// Executes a [`CarrySpec`].
///
/// Each phase is planned when it starts, from the world as it is then: the transfer and the
/// lowering aim at where the goal is *now*, and a transfer whose goal moved meanwhile is re-planned.
pub struct Carry {
    spec: CarrySpec,
    /// Pinch position minus cube centre when the carry started (kept, so the cube goes where the
    /// pinch is sent), metres.
    pinch_from_cube: Vector3<f64>,
    /// Tool orientation kept during the carry.
    rotation: UnitQuaternion<f64>,
    phase: Phase,
    /// Cube centre the current phase ends at, metres.
    phase_end: Vector3<f64>,
    replans: u32,
    goal_q: [f64; 6],
    arrival: Arrival,
    lost: u32,
}

impl Carry {
    /// A carry controller for `spec`.
    pub fn new(spec: CarrySpec) -> Self {
        Self {
            spec,
            pinch_from_cube: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            phase: Phase::Lift,
            phase_end: Vector3::zeros(),
            replans: 0,
            goal_q: [0.0; 6],
            lost: 0,
            arrival: Arrival::default(),
        }
    }

    /// Height of the cube centre during the transfer, metres.
    fn carry_z(&self) -> f64 {
        self.spec.lift + CUBE_HALF
    }

    /// Where the cube centre ends up when placed at the goal as it is now, metres.
    fn place(&self, cell: &Cell) -> Vector3<f64> {
        let goal = resolve(&self.spec.to, cell.world());
        Vector3::new(goal.x, goal.y, goal.z + self.spec.place_height + CUBE_HALF)
    }

    /// Moves the cube centre to `cube_end` in a straight line: the phase `phase` starts.
    fn start_phase(&mut self, cell: &mut Cell, phase: Phase, cube_end: Vector3<f64>) -> Result<(), String> {
        let pose = Isometry3::from_parts(Translation3::from(cube_end + self.pinch_from_cube), self.rotation);
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        let mv = CartesianMove::new(cell.arm_setpoint(), pose, &limits)
            .map_err(|e| format!("unreachable carry path ({}): {e}", phase.name()))?;
        self.goal_q = mv.end();
        self.phase = phase;
        self.phase_end = cube_end;
        cell.track(Box::new(mv));
        Ok(())
    }

    /// The current phase's motion has ended: start the next one (or re-plan the transfer).
    fn next_phase(&mut self, cell: &mut Cell) -> Result<(), String> {
        let place = self.place(cell);
        let above = Vector3::new(place.x, place.y, self.carry_z().max(place.z));
        match self.phase {
            Phase::Lift => self.start_phase(cell, Phase::Transfer, above),
            Phase::Transfer if (above.xy() - self.phase_end.xy()).norm() > GOAL_MOVED => {
                self.replans += 1;
                if self.replans > MAX_REPLANS {
                    return Err(format!(
                        "the goal kept moving: re-planned the transfer {MAX_REPLANS} times"
                    ));
                }
                tracing::debug!(target: "macrotree::actions", replans = self.replans, "carry: goal moved, re-planning the transfer");
                self.start_phase(cell, Phase::Transfer, above)
            }
            Phase::Transfer => self.start_phase(cell, Phase::Lower, place),
            Phase::Lower => Ok(()),
        }
    }
}

impl MacroAction for Carry {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        let w = cell.world();
        if !cube_grasped(w, Tolerances::GRASP_OFF_AXIS) {
            return Err("carry needs the cube in the gripper, but it is not grasped".into());
        }
        // Keep the pinch where it holds the cube: move the pinch by as much as the cube should move.
        self.pinch_from_cube = w.pinch_pos - w.cube_pos;
        self.rotation = UnitQuaternion::from_matrix(&w.pinch_rot);
        let lift = Vector3::new(w.cube_pos.x, w.cube_pos.y, self.carry_z().max(w.cube_pos.z));
        self.replans = 0;
        self.lost = 0;
        self.start_phase(cell, Phase::Lift, lift)
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
                    self.phase.name(),
                    c.x,
                    c.y,
                    c.z
                ));
            }
        }
        if self.phase != Phase::Lower {
            if cell.arm_motion_finished()
                && let Err(e) = self.next_phase(cell)
            {
                return Progress::Failed(e);
            }
            return Progress::Running;
        }
        self.arrival.progress(cell, &self.goal_q)
    }
}
