//! The flat vectors of the robot's state and the scene's objects, one definition for the
//! LeRobot dataset (`observation.state`, `action`, `observation.environment_state`) and the
//! step-wise environment's observation.

use crate::motion::ur5e::{arm_joint_names, joined_names};

/// Values in a state vector ([`state_vector`]).
pub const STATE_LEN: usize = 20;

/// Names of the [`STATE_LEN`] values of a state vector ([`state_vector`]): the UR5e's joint
/// angles, the gripper closure, the joint velocities, then the pinch frame's position and
/// orientation. A command vector's are [`crate::motion::COMMAND_NAMES`].
pub const STATE_NAMES: [&str; STATE_LEN] = joined_names(&[
    &arm_joint_names!(""),
    &["gripper"],
    &arm_joint_names!("_vel"),
    &[
        "pinch_x", "pinch_y", "pinch_z", "pinch_qw", "pinch_qx", "pinch_qy", "pinch_qz",
    ],
]);

/// What a state vector is made of. Units: radians, rad/s, metres; quaternion `[w, x, y, z]`
/// in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotState {
    /// Measured arm joint angles (shoulder pan … wrist 3), radians.
    pub joint_pos: [f64; 6],
    /// Gripper closure: the right driver joint's angle, radians (0 open … about 0.8 closed).
    pub gripper_joint: f64,
    /// Measured arm joint velocities, rad/s.
    pub joint_vel: [f64; 6],
    /// Pinch point (between the fingertips), metres.
    pub pinch_pos: [f64; 3],
    /// Pinch frame orientation `[w, x, y, z]` (its z axis points out of the fingers).
    pub pinch_quat: [f64; 4],
}

impl RobotState {
    /// The robot's state in `world`, with the gripper closure `gripper_joint` (radians; the
    /// simulation's right driver joint, which the world snapshot does not keep).
    pub fn of(world: &crate::world::World, gripper_joint: f64) -> Self {
        let v = |v: &nalgebra::Vector3<f64>| [v.x, v.y, v.z];
        Self {
            joint_pos: world.arm_q,
            gripper_joint,
            joint_vel: world.arm_qd,
            pinch_pos: v(&world.pinch_pos),
            pinch_quat: pinch_quat(&world.pinch_rot),
        }
    }
}

/// The pinch frame's rotation matrix as a unit quaternion `[w, x, y, z]`.
pub fn pinch_quat(rot: &nalgebra::Matrix3<f64>) -> [f64; 4] {
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(*rot));
    [q.w, q.i, q.j, q.k]
}

/// `observation.state` (the Python env's `agent_pos`): the six measured arm joint angles
/// (radians), the gripper closure (radians: 0 open … about 0.8 closed), the six joint
/// velocities (rad/s), the pinch point (metres) and the pinch frame's orientation (qw, qx, qy,
/// qz), as `f32` — what a policy acting on state alone needs to see. Names: [`STATE_NAMES`].
pub fn state_vector(s: &RobotState) -> [f32; STATE_LEN] {
    let mut out = [0f32; STATE_LEN];
    let values = s
        .joint_pos
        .iter()
        .chain(std::iter::once(&s.gripper_joint))
        .chain(&s.joint_vel)
        .chain(&s.pinch_pos)
        .chain(&s.pinch_quat);
    for (o, v) in out.iter_mut().zip(values) {
        *o = *v as f32;
    }
    out
}

/// Values per object in an environment-state vector ([`pose_vector`]).
pub const VALUES_PER_OBJECT: usize = 7;

/// `action`: one control period's command ([`crate::motion::CellCommand::to_vector`]: six
/// joint set points in radians, six velocities in rad/s, six accelerations in rad/s², the
/// gripper command 0 open … 255 closed), as `f32`.
pub fn command_vector(command: &[f64; crate::motion::COMMAND_LEN]) -> [f32; crate::motion::COMMAND_LEN] {
    command.map(|v| v as f32)
}

/// One object's part of `observation.environment_state`: x, y, z (metres), then the
/// orientation qw, qx, qy, qz, as `f32`. The vector is every object's, in scene order.
pub fn pose_vector(pos: &[f64; 3], quat_wxyz: &[f64; 4]) -> [f32; VALUES_PER_OBJECT] {
    [
        pos[0],
        pos[1],
        pos[2],
        quat_wxyz[0],
        quat_wxyz[1],
        quat_wxyz[2],
        quat_wxyz[3],
    ]
    .map(|v| v as f32)
}

/// `observation.environment_state`: every object's [`pose_vector`], in scene order.
pub fn environment_vector(world: &crate::world::World) -> Vec<f32> {
    let mut out = Vec::with_capacity(world.objects.len() * VALUES_PER_OBJECT);
    for o in &world.objects {
        let p = [o.pos.x, o.pos.y, o.pos.z];
        let q = o.quat.quaternion();
        out.extend(pose_vector(&p, &[q.w, q.i, q.j, q.k]));
    }
    out
}

/// Values in an object vector ([`object_vector`]).
pub const OBJECT_LEN: usize = 5;

/// Names of the [`OBJECT_LEN`] values of an object vector ([`object_vector`]).
pub const OBJECT_NAMES: [&str; OBJECT_LEN] = [
    "object_dx",
    "object_dy",
    "object_dz",
    "object_sin4yaw",
    "object_cos4yaw",
];

/// `observation.object`: where object `i` is relative to the gripper — its centre minus the
/// pinch point (metres, world frame), then sin and cos of four times its yaw (the rotation of
/// its x axis about world z) minus the tool's yaw ([`crate::world::angles::tool_yaw`]; a square
/// block looks the same every quarter turn), as `f32`.
/// Names: [`OBJECT_NAMES`].
pub fn object_vector(world: &crate::world::World, i: usize) -> [f32; OBJECT_LEN] {
    let o = &world.objects[i];
    let d = o.pos - world.pinch_pos;
    let tool_yaw = crate::world::angles::tool_yaw(&world.pinch_rot);
    let rel = 4.0 * (crate::world::angles::yaw_of(&o.quat) - tool_yaw);
    [d.x, d.y, d.z, rel.sin(), rel.cos()].map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_state_vector_has_one_value_per_name_in_order() {
        let s = RobotState {
            joint_pos: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            gripper_joint: 7.0,
            joint_vel: [8.0, 9.0, 10.0, 11.0, 12.0, 13.0],
            pinch_pos: [14.0, 15.0, 16.0],
            pinch_quat: [17.0, 18.0, 19.0, 20.0],
        };
        let v = state_vector(&s);
        assert_eq!(v.len(), STATE_NAMES.len());
        for (i, x) in v.iter().enumerate() {
            assert_eq!(*x, (i + 1) as f32, "{}", STATE_NAMES[i]);
        }
    }
}
