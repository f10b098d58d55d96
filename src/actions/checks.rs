//! The checks the reference tutorial asserts on every pick-and-place
//! (TorchRL's CubeBowlEnv macro-action tutorial), measured the same way on our episodes, on the
//! scene's cube and bowl ([`World::cube`], [`World::bowl`]). A scene without a cube measures
//! nothing (no grasp distance, no motion or lift, not in the bowl); without a bowl, nothing is in
//! it.

use nalgebra::Vector3;
use serde::Serialize;

use crate::world::conditions::{Tolerances, home_error};
use crate::world::{World, goal};

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
    /// The cube rests inside the bowl at the end (the `in` condition on the scene's cube and
    /// bowl; false in a scene without them).
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
    /// reference for the closed-gripper motion checks (nothing without a cube).
    pub fn after_grasp(&mut self, w: &World) {
        let Some(cube) = w.cube() else { return };
        let d = pad_block_distance(w, cube);
        self.grasp_distance = Some(self.grasp_distance.map_or(d, |g| g.min(d)));
        self.grasp_ref = Some(w.objects[cube].pos);
    }

    /// The gripper opens: stop tracking cube motion.
    pub fn on_open(&mut self) {
        self.grasp_ref = None;
    }

    /// Called after every control period with whether the gripper is commanded closed.
    pub fn on_tick(&mut self, w: &World, gripper_closed: bool) {
        if let (Some(r), true, Some(cube)) = (self.grasp_ref, gripper_closed, w.cube()) {
            let p = w.objects[cube].pos;
            self.motion = self.motion.max((p - r).norm());
            self.lift = self.lift.max(p.z - r.z);
        }
    }

    /// The checks at the end of the episode, with the final world.
    pub fn finish(&self, w: &World) -> Checks {
        Checks {
            grasp_distance: self.grasp_distance,
            cube_motion_while_closed: self.motion,
            cube_lift_while_closed: self.lift,
            home_error: home_error(w),
            in_bowl: match (w.cube(), w.bowl()) {
                (Some(c), Some(b)) => goal::rests_in(w, c, b, Tolerances::REST_SPEED),
                _ => false,
            },
        }
    }
}

/// Distance from the nearer pad centre to block `i`'s surface (0 when inside), metres. Unlike
/// the reference, the block's rotation is taken into account.
pub fn pad_block_distance(w: &World, i: usize) -> f64 {
    let (o, half) = (&w.objects[i], w.half(i));
    let to_block = |p: &Vector3<f64>| {
        let local = o.quat.inverse() * (p - o.pos);
        let excess = local.map(|c| (c.abs() - half).max(0.0));
        excess.norm()
    };
    to_block(&w.left_pad_pos).min(to_block(&w.right_pad_pos))
}
