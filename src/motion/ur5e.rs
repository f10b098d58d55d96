//! The UR5e's facts, in one place: its joints, their limits and rated speed, the chain's
//! dimensions, the home keyframe, and the lever arms the planner bounds motion with. Every other
//! module reads them from here.
//!
//! The chain is read off `universal_robots_ur5e/ur5e.xml` (Menagerie, unmodified):
//!
//! | body | position in parent (m) | rotation in parent | joint axis |
//! |---|---|---|---|
//! | `base` | (0, 0, 0) in world | 180° about z (quat 0 0 0 −1) | — |
//! | `shoulder_link` | (0, 0, 0.163) | — | z (`shoulder_pan`) |
//! | `upper_arm_link` | (0, 0.138, 0) | +90° about y | y (`shoulder_lift`) |
//! | `forearm_link` | (0, −0.131, 0.425) | — | y (`elbow`) |
//! | `wrist_1_link` | (0, 0, 0.392) | +90° about y | y (`wrist_1`) |
//! | `wrist_2_link` | (0, 0.127, 0) | — | z (`wrist_2`) |
//! | `wrist_3_link` | (0, 0, 0.1) | — | y (`wrist_3`) |
//! | `attachment_site` | (0, 0.1, 0) | −90° about x (quat −1 1 0 0) | — |
//!
//! The gripper's part of the chain (attachment to pinch) is in
//! [`kinematics`](super::kinematics) ([`TOOL_LENGTH`](super::kinematics::TOOL_LENGTH)), its
//! calibration in [`gripper`](super::gripper).

/// The UR5e arm joints' names, base to wrist, each followed by `$suffix` (a string literal):
/// `arm_joint_names!("")` is [`ARM_JOINTS`], `arm_joint_names!(".vel")` names six velocities.
/// Every list of per-joint names is made with it, so the names are written once.
macro_rules! arm_joint_names {
    ($suffix:literal) => {
        [
            concat!("shoulder_pan", $suffix),
            concat!("shoulder_lift", $suffix),
            concat!("elbow", $suffix),
            concat!("wrist_1", $suffix),
            concat!("wrist_2", $suffix),
            concat!("wrist_3", $suffix),
        ]
    };
}
pub(crate) use arm_joint_names;

/// Names of the UR5e arm joints, base to wrist (Menagerie names without the `_joint` suffix;
/// the position actuators carry the same names).
pub const ARM_JOINTS: [&str; 6] = arm_joint_names!("");

/// The name lists `parts` one after the other, as one list of `N` names; a sum of lengths
/// other than `N` fails the build (the function runs in `const` items).
pub(crate) const fn joined_names<const N: usize>(parts: &[&[&'static str]]) -> [&'static str; N] {
    let mut out = [""; N];
    let (mut k, mut i) = (0, 0);
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[k] = parts[i][j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    assert!(k == N, "the parts' lengths do not add up to the list's");
    out
}

/// Joint limits used by IK and trajectories, radians: the position servos' `ctrlrange` in the
/// Menagerie UR5e (±6.2831 for every joint, ±3.1415 for the elbow), which is a hair inside the
/// joint `range` (±6.28319, elbow ±3.1415) — so every solution is a command the servos accept
/// without clamping. These are the Menagerie's literal values, not 2π / π.
#[allow(clippy::approx_constant)]
pub const JOINT_LIMITS: [(f64, f64); 6] = [
    (-6.2831, 6.2831),
    (-6.2831, 6.2831),
    (-3.1415, 3.1415),
    (-6.2831, 6.2831),
    (-6.2831, 6.2831),
    (-6.2831, 6.2831),
];

/// The UR5e's rated joint speed, rad/s: 180 °/s for every joint (base, shoulder, elbow and the
/// three wrists), from Universal Robots' UR5e technical specifications / user manual. UR
/// publishes no joint acceleration rating.
pub const RATED_JOINT_SPEED: f64 = std::f64::consts::PI;

/// Home joint angles (Menagerie keyframe `home`), radians. At home the pinch is at
/// (−0.134, 0.492, 0.3322) m pointing straight down, its x axis along world +y.
pub const HOME_Q: [f64; 6] = [
    -std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
    0.0,
];

/// Height of the shoulder-pan joint above the robot base (world origin), metres.
pub const SHOULDER_HEIGHT: f64 = 0.163;
/// Upper-arm length (shoulder-lift axis to elbow axis), metres.
pub const UPPER_ARM: f64 = 0.425;
/// Forearm length (elbow axis to wrist-1 axis), metres.
pub const FOREARM: f64 = 0.392;
/// Net lateral offset along the shoulder-lift axis from the shoulder-pan axis to the wrist-2
/// axis (0.138 − 0.131 + 0.127), metres.
pub const LATERAL_OFFSET: f64 = 0.134;
/// Wrist-2 origin to wrist-3 origin along the wrist-2 axis, metres.
pub const WRIST_2_TO_3: f64 = 0.1;
/// Wrist-2 origin to wrist-1 origin offset along the shoulder-lift axis, metres.
pub const WRIST_1_TO_2: f64 = 0.127;

/// Lever arms of the UR5e with the 2F-85 and a held block of up to 7 cm, metres: an upper bound
/// on the distance of any point of the moving robot from each joint's axis, base to wrist 3.
/// Measured on the Menagerie models (`tests/physics/motion_collision.rs`: the largest distance of
/// a collision geom's bounding sphere from each axis, over the stretched arm and random joints,
/// is 1.08, 1.11, 0.70, 0.31, 0.27, 0.10 m), plus a held block's 6.1 cm half diagonal
/// ([`HELD_BLOCK_REACH`](super::plan::HELD_BLOCK_REACH)).
pub const LEVER_ARMS: [f64; 6] = [1.16, 1.19, 0.77, 0.38, 0.34, 0.12];
