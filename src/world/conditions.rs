//! Condition leaves: pure functions of a [`World`]. Each answers in the tick it is asked
//! (never Running). Tolerances are arguments so YAML can override them; the defaults live in
//! [`Tolerances`].

use super::World;

/// Default tolerances of the condition leaves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances;

impl Tolerances {
    /// Cube speed below which it counts as at rest, m/s.
    pub const REST_SPEED: f64 = 0.05;
    /// Cube bottom height above the table that counts as lifted, metres.
    pub const LIFT_HEIGHT: f64 = 0.03;
    /// Largest distance of the cube centre from the line between the pad centres, metres.
    pub const GRASP_OFF_AXIS: f64 = 0.03;
    /// Gripper opening that counts as open, metres.
    pub const OPEN_WIDTH: f64 = 0.07;
    /// Joint-space distance to home that counts as at home (Euclidean norm), radians.
    pub const HOME_TOLERANCE: f64 = 0.04;
    /// Cube bottom height above the table that still counts as resting on it, metres.
    pub const ON_TABLE_HEIGHT: f64 = 0.005;
}

/// Both pads touch the cube and its centre lies between them: projected onto the pad-to-pad
/// segment it falls inside the segment, and it is at most `off_axis` metres from that line.
pub fn cube_grasped(w: &World, off_axis: f64) -> bool {
    if !(w.left_pad_contact && w.right_pad_contact) {
        return false;
    }
    let axis = w.right_pad_pos - w.left_pad_pos;
    let len2 = axis.norm_squared();
    if len2 < 1e-12 {
        return false;
    }
    let rel = w.cube_pos - w.left_pad_pos;
    let t = rel.dot(&axis) / len2;
    let off = (rel - axis * t).norm();
    (0.0..=1.0).contains(&t) && off <= off_axis
}

/// The cube's lowest point is at least `min_height` metres above the table.
pub fn cube_lifted(w: &World, min_height: f64) -> bool {
    w.cube_bottom() >= min_height
}

/// The cube is at rest (speed below `rest_speed`, m/s) inside the bowl: its centre within the
/// inner footprint and below the rim.
pub fn cube_in_bowl(w: &World, rest_speed: f64) -> bool {
    let d = w.cube_pos - w.bowl_pos;
    let inside = d.x.abs() < w.bowl.inner_half_width && d.y.abs() < w.bowl.inner_half_width;
    let below_rim = w.cube_pos.z < w.bowl.rim_height;
    inside && below_rim && w.cube_linvel.norm() < rest_speed
}

/// The cube rests on the table (bottom within `max_height` metres of z = 0, at rest), outside the bowl.
pub fn cube_on_table(w: &World, max_height: f64, rest_speed: f64) -> bool {
    let d = w.cube_pos - w.bowl_pos;
    let over_bowl = d.x.abs() < w.bowl.inner_half_width + 0.01 && d.y.abs() < w.bowl.inner_half_width + 0.01;
    w.cube_bottom() <= max_height && !over_bowl && w.cube_linvel.norm() < rest_speed
}

/// The gripper is open at least `min_width` metres.
pub fn gripper_open(w: &World, min_width: f64) -> bool {
    w.gripper_width >= min_width
}

/// Euclidean joint-space distance between the measured arm joints and home, radians.
pub fn home_error(w: &World) -> f64 {
    w.arm_q
        .iter()
        .zip(&w.home_q)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The arm is within `tolerance` radians (joint-space norm) of home.
pub fn at_home(w: &World, tolerance: f64) -> bool {
    home_error(w) <= tolerance
}
