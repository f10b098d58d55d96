//! [`World`]: everything the tree may know about the cell at one instant.

use std::sync::Arc;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use super::objects::{ObjectState, Touch};
use crate::scene::SceneSpec;

/// Half of the cube's edge (the cube is 44 mm), metres.
pub const CUBE_HALF: f64 = 0.022;

/// The bowl's shape, in its own frame (origin at the centre of its footprint on the table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlGeometry {
    /// Half-width of the free space inside the walls, metres.
    pub inner_half_width: f64,
    /// Half-width of the footprint, walls included, metres.
    pub outer_half_width: f64,
    /// Height of the rim above the table, metres.
    pub rim_height: f64,
    /// Height of the bowl's floor (top surface) above the table, metres.
    pub floor_height: f64,
}

impl BowlGeometry {
    /// No bowl (a scene without a container): nothing fits in it.
    pub const NONE: Self = Self {
        inner_half_width: 0.0,
        outer_half_width: 0.0,
        rim_height: 0.0,
        floor_height: 0.0,
    };

    /// The tray of the `cube_bowl` scene.
    pub const TRAY: Self = Self {
        inner_half_width: 0.075,
        outer_half_width: 0.085,
        rim_height: 0.06,
        floor_height: 0.01,
    };
}

/// A snapshot of the simulated cell, refreshed after every control step.
///
/// Every object of the scene is in [`objects`](Self::objects) (same order as the scene); the
/// `cube_*` and `bowl_*` fields repeat the state of the objects the legacy names `cube` and `bowl`
/// stand for ([`SceneSpec::legacy_cube`], [`SceneSpec::legacy_bowl`]), which the `cube_*`
/// conditions and the reference tutorial's checks read.
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
    /// The left pads touch the cube.
    pub left_pad_contact: bool,
    /// The right pads touch the cube.
    pub right_pad_contact: bool,
    /// Centre of the left pads, world frame, metres.
    pub left_pad_pos: Vector3<f64>,
    /// Centre of the right pads, world frame, metres.
    pub right_pad_pos: Vector3<f64>,
    /// Cube centre, world frame, metres.
    pub cube_pos: Vector3<f64>,
    /// Cube orientation, world frame (unit quaternion).
    pub cube_quat: UnitQuaternion<f64>,
    /// Cube linear velocity, m/s.
    pub cube_linvel: Vector3<f64>,
    /// Cube angular velocity, rad/s.
    pub cube_angvel: Vector3<f64>,
    /// Centre of the bowl's footprint on the table, metres.
    pub bowl_pos: Vector3<f64>,
    /// The bowl target (centre of its floor's top surface), metres.
    pub bowl_target: Vector3<f64>,
    /// The bowl's shape.
    pub bowl: BowlGeometry,
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

impl World {
    /// Yaw of the cube's side faces about world z, folded into [-45°, 45°) (a cube looks the
    /// same every 90°), radians. Taken from whichever cube axis lies most horizontal, so it is
    /// right for a cube resting on any of its faces, not only the one it started on.
    pub fn cube_yaw(&self) -> f64 {
        let r = self.cube_quat.to_rotation_matrix();
        let axis = (0..3)
            .map(|i| r.matrix().column(i).into_owned())
            .min_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))
            .expect("three axes");
        fold_quarter_turn(axis.y.atan2(axis.x))
    }

    /// Horizontal vector from the nearest point of the bowl's footprint to `p` (zero inside it), metres.
    pub fn from_bowl(&self, p: &Vector3<f64>) -> nalgebra::Vector2<f64> {
        let h = self.bowl.outer_half_width;
        let d = nalgebra::Vector2::new(p.x - self.bowl_pos.x, p.y - self.bowl_pos.y);
        d - d.map(|c| c.clamp(-h, h))
    }

    /// Lowest point of the cube above the table, metres (exact for any orientation).
    pub fn cube_bottom(&self) -> f64 {
        let r = self.cube_quat.to_rotation_matrix();
        let extent: f64 = (0..3).map(|i| r[(2, i)].abs() * CUBE_HALF).sum();
        self.cube_pos.z - extent
    }
}

/// Rotation about world z of a quaternion (the yaw of its x axis), radians in (-π, π].
pub fn yaw_of(q: &UnitQuaternion<f64>) -> f64 {
    let x = q * Vector3::x();
    x.y.atan2(x.x)
}

/// Folds an angle into [-π/4, π/4): the yaw of a square seen from above.
pub fn fold_quarter_turn(a: f64) -> f64 {
    let q = std::f64::consts::FRAC_PI_2;
    (a + q / 2.0).rem_euclid(q) - q / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_yaw_is_read_from_the_side_faces_whatever_face_it_rests_on() {
        let mut w = crate::world::conditions::tests_support::resting();
        for yaw_deg in [-40.0f64, -10.0, 0.0, 20.6, 44.0] {
            let yaw = yaw_deg.to_radians();
            // Upright, then tipped onto a side face (90° about its own x or y axis) and turned.
            for tip in [
                UnitQuaternion::identity(),
                UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_2, 0.0, 0.0),
                UnitQuaternion::from_euler_angles(0.0, std::f64::consts::FRAC_PI_2, 0.0),
            ] {
                w.cube_quat = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw) * tip;
                let got = w.cube_yaw();
                assert!(
                    (fold_quarter_turn(got - yaw)).abs() < 1e-9,
                    "yaw {yaw_deg}°, tip {tip:?}: got {}°",
                    got.to_degrees()
                );
            }
        }
    }

    #[test]
    fn quarter_turn_folding_stays_in_range() {
        for i in -100..100 {
            let a = i as f64 * 0.07;
            let f = fold_quarter_turn(a);
            assert!(
                (-std::f64::consts::FRAC_PI_4..std::f64::consts::FRAC_PI_4).contains(&f),
                "{a} -> {f}"
            );
            let k = ((a - f) / std::f64::consts::FRAC_PI_2).round();
            assert!((a - f - k * std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        }
    }
}
