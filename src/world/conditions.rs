//! Condition leaves: pure functions of a [`World`]. Each answers in the tick it is asked
//! (never Running). Tolerances are arguments so YAML can override them; the defaults live in
//! [`Tolerances`].

use super::World;

/// Default tolerances of the condition leaves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances;

impl Tolerances {
    /// Block speed below which it counts as at rest, m/s.
    pub const REST_SPEED: f64 = 0.05;
    /// Cube bottom height above the table that counts as lifted, metres.
    pub const LIFT_HEIGHT: f64 = 0.03;
    /// Largest distance of the cube centre from the line between the pad centres, metres.
    pub const GRASP_OFF_AXIS: f64 = 0.03;
    /// Gripper opening that counts as open, metres.
    pub const OPEN_WIDTH: f64 = 0.08;
    /// Joint-space distance to home that counts as at home (Euclidean norm), radians.
    pub const HOME_TOLERANCE: f64 = 0.04;
    /// Cube bottom height above the table that still counts as resting on it, metres.
    pub const ON_TABLE_HEIGHT: f64 = 0.01;
}

/// Both pads touch block `i` and its centre lies between them, at most `off_axis` metres from
/// the line through the pad centres (the `grasped` condition).
pub fn grasped(w: &World, i: usize, off_axis: f64) -> bool {
    w.holds(i, off_axis)
}

/// Block `i`'s lowest point is at least `min_height` metres above the table (the `lifted`
/// condition).
pub fn lifted(w: &World, i: usize, min_height: f64) -> bool {
    w.bottom(i) >= min_height
}

/// Block `i` rests at `point` = (x, y), metres (the `at` condition and the scene goal's `at`):
/// released (no pad touches it), at rest (speed below `rest_speed`, m/s), its bottom within
/// [`Tolerances::ON_TABLE_HEIGHT`] of the surface under it — the table outside every container
/// ([`on_table`]), the floor of the container it is inside (a kitting tray), or the top of the
/// obstacle or block it rests on ([`World::resting_on`]: a shelf board, a pedestal) —, its centre within
/// `tolerance` metres of the point in the table plane and, when `yaw` is given, its side faces
/// within `yaw_tolerance` radians of `yaw` modulo a quarter turn (a cube looks the same every
/// quarter turn).
pub fn at(
    w: &World,
    i: usize,
    point: [f64; 2],
    tolerance: f64,
    yaw: Option<f64>,
    yaw_tolerance: f64,
    rest_speed: f64,
) -> bool {
    let pos = w.objects[i].pos;
    let near = (pos.x - point[0]).hypot(pos.y - point[1]) <= tolerance;
    let turned =
        yaw.is_none_or(|target| super::angles::fold_quarter_turn(w.yaw(i) - target).abs() <= yaw_tolerance);
    let resting = match w.container_of(i) {
        Some(c) => {
            w.bottom(i) - w.support_height(c) <= Tolerances::ON_TABLE_HEIGHT
                && w.released(i)
                && w.at_rest(i, rest_speed)
        }
        // On the table, or on the top of what it rests on: a shelf board, a pedestal, a block.
        None => {
            on_table(w, i, Tolerances::ON_TABLE_HEIGHT, rest_speed)
                || (w.resting_on(i).is_some() && w.released(i) && w.at_rest(i, rest_speed))
        }
    };
    resting && near && turned
}

/// Block `i` rests on the table: its bottom within `max_height` metres of the table top, not over
/// any container's footprint (1 cm margin), released (no pad touches it) and at rest (speed below
/// `rest_speed`, m/s). A block still in the gripper, even one pressed onto the table, is not on
/// the table.
pub fn on_table(w: &World, i: usize, max_height: f64, rest_speed: f64) -> bool {
    let p = w.objects[i].pos;
    let over_container = w
        .scene
        .of_kind(crate::scene::ObjectKind::Container)
        .any(|c| w.from_footprint(c, &p).norm() < 0.01);
    w.bottom(i) <= max_height && !over_container && w.released(i) && w.at_rest(i, rest_speed)
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

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;
    use crate::world::tests_support::{HALF, held, resting};

    #[test]
    fn grasped_needs_both_pads_and_the_block_between_them() {
        assert!(grasped(&held(), 0, Tolerances::GRASP_OFF_AXIS));
        let mut one_pad = held();
        one_pad.objects[0].right_pad_contact = false;
        assert!(!grasped(&one_pad, 0, Tolerances::GRASP_OFF_AXIS));
        // Both pads touch, but the centre is outside the segment between them (pinched on an edge).
        let mut beside = held();
        beside.objects[0].pos.x += 0.05;
        assert!(!grasped(&beside, 0, Tolerances::GRASP_OFF_AXIS));
        // Between the pads along the axis, but 4 cm below their line.
        let mut low = held();
        low.objects[0].pos.z -= 0.04;
        assert!(!grasped(&low, 0, Tolerances::GRASP_OFF_AXIS));
        assert!(!grasped(&resting(), 0, Tolerances::GRASP_OFF_AXIS));
    }

    #[test]
    fn lifted_uses_the_lowest_point_even_when_the_block_is_tilted() {
        assert!(!lifted(&resting(), 0, 0.03));
        assert!(lifted(&held(), 0, 0.03));
        assert!(!lifted(&held(), 0, 0.11));
        // Tilted 45° about x: the lowest edge is √2·half below the centre.
        let mut tilted = resting();
        tilted.objects[0].pos.z = 0.03 + HALF * std::f64::consts::SQRT_2;
        tilted.objects[0].quat = UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_4, 0.0, 0.0);
        assert!((tilted.bottom(0) - 0.03).abs() < 1e-12);
        assert!(lifted(&tilted, 0, 0.029) && !lifted(&tilted, 0, 0.031));
    }

    #[test]
    fn on_table_is_resting_outside_every_container() {
        assert!(on_table(&resting(), 0, 0.005, Tolerances::REST_SPEED));
        assert!(!on_table(&held(), 0, 0.005, Tolerances::REST_SPEED));
        let mut sliding = resting();
        sliding.objects[0].linvel = Vector3::new(0.2, 0.0, 0.0);
        assert!(!on_table(&sliding, 0, 0.005, Tolerances::REST_SPEED));
    }

    #[test]
    fn at_is_resting_within_tolerance_of_the_point() {
        let w = resting();
        let p = w.objects[0].pos;
        let v = Tolerances::REST_SPEED;
        assert!(
            at(&w, 0, [p.x + 0.006, p.y - 0.0079], 0.01, None, 0.05, v),
            "9.9 mm away, 10 mm allowed"
        );
        assert!(
            !at(&w, 0, [p.x + 0.006, p.y - 0.009], 0.01, None, 0.05, v),
            "10.8 mm away"
        );
        assert!(
            !at(&held(), 0, [p.x, p.y], 0.01, None, 0.05, v),
            "a lifted cube is not placed"
        );
        let turned = 20f64.to_radians();
        let mut w = resting();
        w.objects[0].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, turned);
        assert!(at(&w, 0, [p.x, p.y], 0.01, Some(turned + 0.01), 0.02, v));
        assert!(!at(&w, 0, [p.x, p.y], 0.01, Some(turned + 0.03), 0.02, v));
    }

    /// The held cube pressed onto the table: on the table by height and at rest, but the pads
    /// touch it.
    fn held_on_the_table() -> World {
        let mut w = held();
        w.objects[0].pos.z = HALF;
        w
    }

    #[test]
    fn on_table_and_at_need_the_block_released() {
        let w = held_on_the_table();
        let p = w.objects[0].pos;
        let v = Tolerances::REST_SPEED;
        assert!(w.bottom(0) < 1e-9 && w.at_rest(0, v), "pressed flat and still");
        assert!(!on_table(&w, 0, 0.01, v), "held, not on the table");
        assert!(!at(&w, 0, [p.x, p.y], 0.01, None, 0.05, v), "held, not placed");
        let mut one_pad = w.clone();
        one_pad.objects[0].right_pad_contact = false;
        assert!(!on_table(&one_pad, 0, 0.01, v), "one pad still touching");
        let mut let_go = w.clone();
        let_go.objects[0].left_pad_contact = false;
        let_go.objects[0].right_pad_contact = false;
        assert!(on_table(&let_go, 0, 0.01, v) && at(&let_go, 0, [p.x, p.y], 0.01, None, 0.05, v));
    }

    #[test]
    fn at_accepts_a_block_resting_on_a_container_floor_at_the_point() {
        // The bowl's floor top is at z = 0.01: a cube on it, 2 cm from the bowl's centre.
        let mut w = resting();
        w.objects[0].pos = Vector3::new(0.47, 0.08, 0.01 + HALF);
        let v = Tolerances::REST_SPEED;
        assert!(
            at(&w, 0, [0.47, 0.08], 0.01, None, 0.05, v),
            "on the tray's floor at the point"
        );
        assert!(!on_table(&w, 0, 0.01, v), "but not on the table");
        let mut floating = w.clone();
        floating.objects[0].pos.z += 0.02;
        assert!(
            !at(&floating, 0, [0.47, 0.08], 0.01, None, 0.05, v),
            "2 cm above the floor"
        );
        let mut gripped = w.clone();
        gripped.objects[0].left_pad_contact = true;
        assert!(
            !at(&gripped, 0, [0.47, 0.08], 0.01, None, 0.05, v),
            "a pad touches it"
        );
    }

    #[test]
    fn at_compares_the_yaw_modulo_a_quarter_turn() {
        let mut w = resting();
        let p = w.objects[0].pos;
        w.objects[0].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, 88f64.to_radians());
        let v = Tolerances::REST_SPEED;
        let tol = 3f64.to_radians();
        assert!(
            at(&w, 0, [p.x, p.y], 0.01, Some(-2f64.to_radians()), tol, v),
            "88° is −2°"
        );
        assert!(at(
            &w,
            0,
            [p.x, p.y],
            0.01,
            Some(std::f64::consts::FRAC_PI_2),
            tol,
            v
        ));
        assert!(
            !at(&w, 0, [p.x, p.y], 0.01, Some(5f64.to_radians()), tol, v),
            "7° off"
        );
    }

    #[test]
    fn gripper_open_and_at_home_compare_against_their_tolerances() {
        assert!(gripper_open(&resting(), 0.08));
        assert!(!gripper_open(&held(), 0.08));
        let mut w = resting();
        w.arm_q = [0.03, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((home_error(&w) - 0.03).abs() < 1e-12);
        assert!(at_home(&w, 0.04));
        w.arm_q = [0.03, 0.03, 0.0, 0.0, 0.0, 0.0];
        assert!(!at_home(&w, 0.04), "the norm, not the largest joint, is compared");
    }
}
