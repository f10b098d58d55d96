//! [`World`]: everything the tree may know about the cell at one instant.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::objects::{ObjectState, Touch};
use crate::scene::SceneSpec;

/// A snapshot of the simulated cell, refreshed after every control step.
///
/// Every object of the scene is in [`objects`](Self::objects) (same order as the scene). The
/// legacy names `cube` and `bowl` are resolved on demand ([`World::cube`], [`World::bowl`]).
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// Simulated time, seconds.
    pub time: f64,
    /// Measured arm joint angles, radians (shoulder pan … wrist 3).
    pub arm_q: [f64; 6],
    /// Measured arm joint velocities, rad/s.
    pub arm_qd: [f64; 6],
    /// Commanded arm joint angles (what the servos track), radians.
    pub arm_cmd: [f64; 6],
    /// Gripper opening: free distance between the two pad faces, metres.
    pub gripper_width: f64,
    /// Gripper closure speed (right driver joint velocity), rad/s.
    pub gripper_speed: f64,
    /// Pinch point (tool point between the fingertips) position, world frame, metres.
    pub pinch_pos: Vector3<f64>,
    /// Pinch frame orientation (its z axis points out of the fingers), world frame (a rotation
    /// matrix whose columns are the frame's axes).
    pub pinch_rot: Matrix3<f64>,
    /// Centre of the left pads, world frame, metres.
    pub left_pad_pos: Vector3<f64>,
    /// Centre of the right pads, world frame, metres.
    pub right_pad_pos: Vector3<f64>,
    /// The arm's home joint angles, radians.
    pub home_q: [f64; 6],
    /// The scene: object names, shapes, colours and the goal.
    pub scene: Arc<SceneSpec>,
    /// Every object's state, in scene order.
    pub objects: Vec<ObjectState>,
    /// The contacts between distinct parts of the cell right now (robot–object, object–object),
    /// table contacts excluded.
    pub touches: Vec<Touch>,
}

// Declared in `angles`; kept at these paths too.

#[cfg(test)]
mod tests {
    use nalgebra::UnitQuaternion;

    use crate::world::angles::fold_quarter_turn;

    #[test]
    fn a_blocks_yaw_is_read_from_the_side_faces_whatever_face_it_rests_on() {
        let mut w = crate::world::tests_support::resting();
        for yaw_deg in [-40.0f64, -10.0, 0.0, 20.6, 44.0] {
            let yaw = yaw_deg.to_radians();
            // Upright, then tipped onto a side face (90° about its own x or y axis) and turned.
            for tip in [
                UnitQuaternion::identity(),
                UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_2, 0.0, 0.0),
                UnitQuaternion::from_euler_angles(0.0, std::f64::consts::FRAC_PI_2, 0.0),
            ] {
                w.objects[0].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw) * tip;
                let got = w.yaw(0);
                assert!(
                    (fold_quarter_turn(got - yaw)).abs() < 1e-9,
                    "yaw {yaw_deg}°, tip {tip:?}: got {}°",
                    got.to_degrees()
                );
            }
        }
    }
}
