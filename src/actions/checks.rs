//! The checks the reference tutorial asserts on every pick-and-place
//! (../shared/notes/torchrl_anchor.md §5.1), measured the same way on our episodes.

use nalgebra::Vector3;
use serde::Serialize;

use crate::world::conditions::{Tolerances, cube_in_bowl, home_error};
use crate::world::{CUBE_HALF, World};

/// The tutorial's checks for one episode. Distances in metres, joint error in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Checks {
    /// Smallest distance from a pad centre to the cube's surface measured right after a grasp
    /// (0 when a pad centre is at or inside the surface); `null` in JSON when nothing was grasped.
    pub grasp_distance: Option<f64>,
    /// Largest displacement of the cube from where it was grasped, while the gripper was closed.
    pub cube_motion_while_closed: f64,
    /// Largest rise of the cube above where it was grasped, while the gripper was closed.
    pub cube_lift_while_closed: f64,
    /// Joint-space distance of the arm from home at the end (Euclidean norm).
    pub home_error: f64,
    /// The cube rests inside the bowl at the end.
    pub in_bowl: bool,
}

impl Checks {
    /// Thresholds of the reference tutorial: grasp ≤ 0.025 m, motion ≥ 0.05 m, lift ≥ 0.08 m,
    /// home error ≤ 0.04 rad, cube in the bowl.
    pub fn pass_reference(&self) -> bool {
        self.grasp_distance.is_some_and(|d| d <= 0.025)
            && self.cube_motion_while_closed >= 0.05
            && self.cube_lift_while_closed >= 0.08
            && self.home_error <= 0.04
            && self.in_bowl
    }
}

/// Accumulates [`Checks`] over an episode.
#[derive(Debug, Clone, Default)]
pub struct ChecksRecorder {
    grasp_distance: Option<f64>,
    grasp_ref: Option<Vector3<f64>>,
    motion: f64,
    lift: f64,
}

impl ChecksRecorder {
    /// A grasp just finished: measure the pad–cube distance and take the cube's position as the
    /// reference for the closed-gripper motion checks.
    pub fn after_grasp(&mut self, w: &World) {
        let d = pad_cube_distance(w);
        self.grasp_distance = Some(self.grasp_distance.map_or(d, |g| g.min(d)));
        self.grasp_ref = Some(w.cube_pos);
    }

    /// The gripper opens: stop tracking cube motion.
    pub fn on_open(&mut self) {
        self.grasp_ref = None;
    }

    /// Called after every control period with whether the gripper is commanded closed.
    pub fn on_tick(&mut self, w: &World, gripper_closed: bool) {
        if let (Some(r), true) = (self.grasp_ref, gripper_closed) {
            self.motion = self.motion.max((w.cube_pos - r).norm());
            self.lift = self.lift.max(w.cube_pos.z - r.z);
        }
    }

    /// The checks at the end of the episode, with the final world.
    pub fn finish(&self, w: &World) -> Checks {
        Checks {
            grasp_distance: self.grasp_distance,
            cube_motion_while_closed: self.motion,
            cube_lift_while_closed: self.lift,
            home_error: home_error(w),
            in_bowl: cube_in_bowl(w, Tolerances::REST_SPEED),
        }
    }
}

/// Distance from the nearer pad centre to the cube's surface (0 when inside), metres. Unlike the
/// reference, the cube's rotation is taken into account.
pub fn pad_cube_distance(w: &World) -> f64 {
    let to_cube = |p: &Vector3<f64>| {
        let local = w.cube_quat.inverse() * (p - w.cube_pos);
        let excess = local.map(|c| (c.abs() - CUBE_HALF).max(0.0));
        excess.norm()
    };
    to_cube(&w.left_pad_pos).min(to_cube(&w.right_pad_pos))
}
