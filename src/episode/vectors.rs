//! The flat vectors of the robot's state and the scene's objects, one definition for the
//! LeRobot dataset (`observation.state`, `action`, `observation.environment_state`) and the
//! step-wise environment's observation.

/// Names of the 7 values of a state vector ([`state_vector`]): the UR5e's joints, then the
/// gripper. A command vector's are [`crate::motion::COMMAND_NAMES`].
pub const STATE_NAMES: [&str; 7] = [
    "shoulder_pan",
    "shoulder_lift",
    "elbow",
    "wrist_1",
    "wrist_2",
    "wrist_3",
    "gripper",
];

/// Values per object in an environment-state vector ([`pose_vector`]).
pub const VALUES_PER_OBJECT: usize = 7;

/// `observation.state`: the six measured arm joint angles (radians), then the gripper closure
/// (the right driver joint's angle, radians: 0 open … about 0.8 closed), as `f32`.
pub fn state_vector(joint_pos: &[f64; 6], gripper_joint: f64) -> [f32; 7] {
    seven(joint_pos, gripper_joint)
}

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

fn seven(arm: &[f64; 6], gripper: f64) -> [f32; 7] {
    let mut s = [0f32; 7];
    for (v, q) in s.iter_mut().zip(arm) {
        *v = *q as f32;
    }
    s[6] = gripper as f32;
    s
}
