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
    pub const OPEN_WIDTH: f64 = 0.08;
    /// Joint-space distance to home that counts as at home (Euclidean norm), radians.
    pub const HOME_TOLERANCE: f64 = 0.04;
    /// Cube bottom height above the table that still counts as resting on it, metres.
    pub const ON_TABLE_HEIGHT: f64 = 0.01;
    /// Horizontal distance of the cube's centre from a goal point that counts as there, metres.
    pub const AT_POINT: f64 = 0.01;
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

/// The cube is at rest (speed below `rest_speed`, m/s) inside the bowl, released: its centre
/// at most (inner half-width − the cube's half-size) from the bowl's centre along each axis — so
/// the whole cube fits between the walls — and below the rim, and no pad touching it (a cube
/// squeezed onto the rim by a closed gripper is not in the bowl).
pub fn cube_in_bowl(w: &World, rest_speed: f64) -> bool {
    let d = w.cube_pos - w.bowl_pos;
    let half = w
        .scene
        .legacy_cube()
        .map_or(super::CUBE_HALF, |c| w.spec(c).shape.footprint_half()[0]);
    let room = w.bowl.inner_half_width - half;
    let inside = d.x.abs() <= room && d.y.abs() <= room;
    let below_rim = w.cube_pos.z < w.bowl.rim_height;
    let released = !(w.left_pad_contact || w.right_pad_contact);
    inside && below_rim && released && w.cube_linvel.norm() < rest_speed
}

/// The cube rests on the table (bottom within `max_height` metres of z = 0, at rest), outside the bowl.
pub fn cube_on_table(w: &World, max_height: f64, rest_speed: f64) -> bool {
    let d = w.cube_pos - w.bowl_pos;
    let over_bowl = d.x.abs() < w.bowl.inner_half_width + 0.01 && d.y.abs() < w.bowl.inner_half_width + 0.01;
    w.cube_bottom() <= max_height && !over_bowl && w.cube_linvel.norm() < rest_speed
}

/// The cube rests on the table (as [`cube_on_table`] with `max_height`) with its centre within
/// `tolerance` metres of `point` = (x, y), measured in the table plane.
pub fn cube_at(w: &World, point: [f64; 2], tolerance: f64, max_height: f64, rest_speed: f64) -> bool {
    let (dx, dy) = (w.cube_pos.x - point[0], w.cube_pos.y - point[1]);
    cube_on_table(w, max_height, rest_speed) && dx.hypot(dy) <= tolerance
}

/// Block `i` rests on the table: its bottom within `max_height` metres of the table top, not over
/// any container's footprint (1 cm margin), at rest (speed below `rest_speed`, m/s).
pub fn on_table(w: &World, i: usize, max_height: f64, rest_speed: f64) -> bool {
    let p = w.objects[i].pos;
    let over_container = w
        .scene
        .of_kind(crate::scene::ObjectKind::Container)
        .any(|c| w.from_footprint(c, &p).norm() < 0.01);
    w.bottom(i) <= max_height && !over_container && w.at_rest(i, rest_speed)
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

/// Hand-built worlds for unit tests.
#[cfg(test)]
pub(crate) mod tests_support {
    use std::sync::Arc;

    use nalgebra::{Matrix3, UnitQuaternion, Vector3};

    use crate::scene::SceneSpec;
    use crate::world::{BowlGeometry, CUBE_HALF, ObjectState, World};

    /// A still object at `pos`.
    pub fn still(pos: Vector3<f64>) -> ObjectState {
        ObjectState {
            pos,
            quat: UnitQuaternion::identity(),
            linvel: Vector3::zeros(),
            angvel: Vector3::zeros(),
            left_pad_contact: false,
            right_pad_contact: false,
        }
    }

    /// A cube resting on the table at (0.45, −0.18), open gripper far above it, bowl at (0.45, 0.08)
    /// (the built-in `cube_bowl` scene: `objects[0]` is the cube, `objects[1]` the bowl).
    pub fn resting() -> World {
        World {
            time: 0.0,
            arm_q: [0.0; 6],
            arm_qd: [0.0; 6],
            arm_cmd: [0.0; 6],
            gripper_width: 0.085,
            gripper_speed: 0.0,
            pinch_pos: Vector3::new(0.45, -0.18, 0.3),
            pinch_rot: Matrix3::identity(),
            left_pad_contact: false,
            right_pad_contact: false,
            left_pad_pos: Vector3::new(0.40, -0.18, 0.3),
            right_pad_pos: Vector3::new(0.50, -0.18, 0.3),
            cube_pos: Vector3::new(0.45, -0.18, CUBE_HALF),
            cube_quat: UnitQuaternion::identity(),
            cube_linvel: Vector3::zeros(),
            cube_angvel: Vector3::zeros(),
            bowl_pos: Vector3::new(0.45, 0.08, 0.0),
            bowl_target: Vector3::new(0.45, 0.08, 0.01),
            bowl: BowlGeometry::TRAY,
            home_q: [0.0; 6],
            scene: Arc::new(SceneSpec::builtin()),
            objects: vec![
                still(Vector3::new(0.45, -0.18, CUBE_HALF)),
                still(Vector3::new(0.45, 0.08, 0.0)),
            ],
            touches: Vec::new(),
        }
    }

    /// The same cube held between the pads 10 cm above the table.
    pub fn held() -> World {
        let mut w = resting();
        w.cube_pos = Vector3::new(0.45, -0.18, 0.10 + CUBE_HALF);
        w.left_pad_pos = Vector3::new(0.45 - CUBE_HALF - 0.004, -0.18, 0.125);
        w.right_pad_pos = Vector3::new(0.45 + CUBE_HALF + 0.004, -0.18, 0.125);
        w.left_pad_contact = true;
        w.right_pad_contact = true;
        w.gripper_width = 2.0 * CUBE_HALF;
        w.objects[0].pos = w.cube_pos;
        w.objects[0].left_pad_contact = true;
        w.objects[0].right_pad_contact = true;
        w
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::tests_support::{held, resting};
    use super::*;
    use crate::world::CUBE_HALF;

    #[test]
    fn grasped_needs_both_pads_and_the_cube_between_them() {
        assert!(cube_grasped(&held(), Tolerances::GRASP_OFF_AXIS));
        let mut one_pad = held();
        one_pad.right_pad_contact = false;
        assert!(!cube_grasped(&one_pad, Tolerances::GRASP_OFF_AXIS));
        // Both pads touch, but the cube centre is outside the segment between them (pinched on an edge).
        let mut beside = held();
        beside.cube_pos.x += 0.05;
        assert!(!cube_grasped(&beside, Tolerances::GRASP_OFF_AXIS));
        // Between the pads along the axis, but 4 cm below their line.
        let mut low = held();
        low.cube_pos.z -= 0.04;
        assert!(!cube_grasped(&low, Tolerances::GRASP_OFF_AXIS));
        assert!(!cube_grasped(&resting(), Tolerances::GRASP_OFF_AXIS));
    }

    #[test]
    fn lifted_uses_the_lowest_point_even_when_the_cube_is_tilted() {
        assert!(!cube_lifted(&resting(), 0.03));
        assert!(cube_lifted(&held(), 0.03));
        assert!(!cube_lifted(&held(), 0.11));
        // Tilted 45° about x: the lowest edge is √2·half below the centre.
        let mut tilted = resting();
        tilted.cube_pos.z = 0.03 + CUBE_HALF * std::f64::consts::SQRT_2;
        tilted.cube_quat = UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_4, 0.0, 0.0);
        assert!((tilted.cube_bottom() - 0.03).abs() < 1e-12);
        assert!(cube_lifted(&tilted, 0.029) && !cube_lifted(&tilted, 0.031));
    }

    #[test]
    fn in_bowl_means_inside_the_walls_below_the_rim_and_at_rest() {
        let mut w = resting();
        w.cube_pos = Vector3::new(0.47, 0.06, 0.01 + CUBE_HALF);
        assert!(cube_in_bowl(&w, Tolerances::REST_SPEED));
        assert!(!cube_on_table(&w, 0.01, Tolerances::REST_SPEED));
        let mut moving = w.clone();
        moving.cube_linvel = Vector3::new(0.0, 0.0, -0.3);
        assert!(!cube_in_bowl(&moving, Tolerances::REST_SPEED));
        let mut above = w.clone();
        above.cube_pos.z = 0.2;
        assert!(!cube_in_bowl(&above, Tolerances::REST_SPEED));
        let mut squeezed = w.clone();
        squeezed.left_pad_contact = true;
        squeezed.right_pad_contact = true;
        assert!(
            !cube_in_bowl(&squeezed, Tolerances::REST_SPEED),
            "a held cube is not in the bowl"
        );
        let mut on_rim = w.clone();
        on_rim.cube_pos.x = 0.45 + 0.08;
        assert!(!cube_in_bowl(&on_rim, Tolerances::REST_SPEED));
        // The whole cube must fit between the walls: its centre at most 0.075 − 0.022 m from the
        // bowl's centre (issue 13, item 15: the centre alone within 0.075 m was accepted).
        let mut flush = w.clone();
        flush.cube_pos.x = w.bowl_pos.x + 0.075 - CUBE_HALF - 1e-9;
        assert!(cube_in_bowl(&flush, Tolerances::REST_SPEED));
        let mut in_wall = w.clone();
        in_wall.cube_pos.x = w.bowl_pos.x + 0.075 - CUBE_HALF + 0.001;
        assert!(!cube_in_bowl(&in_wall, Tolerances::REST_SPEED));
        in_wall.cube_pos.x = w.bowl_pos.x + 0.074;
        assert!(!cube_in_bowl(&in_wall, Tolerances::REST_SPEED));
        assert!(!cube_in_bowl(&resting(), Tolerances::REST_SPEED));
    }

    #[test]
    fn on_table_is_resting_outside_the_bowl() {
        assert!(cube_on_table(&resting(), 0.005, Tolerances::REST_SPEED));
        assert!(!cube_on_table(&held(), 0.005, Tolerances::REST_SPEED));
        let mut sliding = resting();
        sliding.cube_linvel = Vector3::new(0.2, 0.0, 0.0);
        assert!(!cube_on_table(&sliding, 0.005, Tolerances::REST_SPEED));
    }

    #[test]
    fn cube_at_is_resting_within_tolerance_of_the_point() {
        let w = resting();
        let (x, y) = (w.cube_pos.x, w.cube_pos.y);
        let h = Tolerances::ON_TABLE_HEIGHT;
        let v = Tolerances::REST_SPEED;
        assert!(
            cube_at(&w, [x + 0.006, y - 0.0079], 0.01, h, v),
            "9.9 mm away, 10 mm allowed"
        );
        assert!(!cube_at(&w, [x + 0.006, y - 0.009], 0.01, h, v), "10.8 mm away");
        assert!(
            !cube_at(&held(), [x, y], 0.01, h, v),
            "a lifted cube is not placed"
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

    #[test]
    fn distance_from_the_bowl_footprint() {
        let w = resting();
        let inside = w.from_bowl(&Vector3::new(0.45, 0.08, 0.0));
        assert_eq!(inside.norm(), 0.0);
        let d = w.from_bowl(&Vector3::new(0.45, -0.18, 0.0));
        assert!((d.y - (-0.26 + 0.085)).abs() < 1e-12 && d.x == 0.0);
    }
}
