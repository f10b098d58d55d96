//! The scene's goal on a world snapshot: whether each predicate holds, and which blocks still
//! have work to do. Pure functions of a [`World`].

use serde::Serialize;

use super::World;
use super::conditions::Tolerances;
use crate::scene::{GoalAtom, GoalPlace, ObjectKind, Shape};

/// Largest horizontal offset of a stacked block from the one under it beyond half its edge,
/// metres (ManiSkill StackCube's criterion).
pub const STACK_XY_SLACK: f64 = 0.005;
/// Largest error of a stacked block's height above the one under it, metres.
pub const STACK_Z_TOLERANCE: f64 = 0.005;

/// Block `i` rests inside container `c`, released and at rest (speed below `rest_speed`, m/s):
/// its centre is inside the walls (in the container's frame) and below the rim, and no pad
/// touches it.
pub fn rests_in(w: &World, i: usize, c: usize, rest_speed: f64) -> bool {
    w.inside(i, c) && w.released(i) && w.at_rest(i, rest_speed)
}

/// Block `i` rests on block `s`: its centre within half its edge + [`STACK_XY_SLACK`] of `s`'s
/// in x and in y, its centre higher than `s`'s by the two half edges ± [`STACK_Z_TOLERANCE`],
/// released, and at rest (speed below `rest_speed`, m/s). On an obstacle `s` (a shelf board, a
/// pedestal): its bottom on the obstacle's top over its footprint ([`World::resting_on`]),
/// released and at rest.
pub fn rests_on(w: &World, i: usize, s: usize, rest_speed: f64) -> bool {
    if w.spec(s).kind() == ObjectKind::Obstacle {
        return w.resting_on(i) == Some(s) && w.released(i) && w.at_rest(i, rest_speed);
    }
    let (a, b) = (&w.objects[i], &w.objects[s]);
    let d = a.pos - b.pos;
    let (ha, hb) = (w.half(i), w.half(s));
    d.x.abs() <= ha + STACK_XY_SLACK
        && d.y.abs() <= ha + STACK_XY_SLACK
        && (d.z - (ha + hb)).abs() <= STACK_Z_TOLERANCE
        && w.released(i)
        && w.at_rest(i, rest_speed)
}

/// Block `i` rests at `place` ([`super::conditions::at`] with the place's point, yaw and
/// tolerances): released, at rest, on the table, a container's floor, or the top of what it
/// rests on (a shelf board, a pedestal, a block).
pub fn rests_at(w: &World, i: usize, place: &GoalPlace, rest_speed: f64) -> bool {
    super::conditions::at(
        w,
        i,
        place.point,
        place.tolerance,
        place.yaw,
        place.yaw_tolerance,
        rest_speed,
    )
}

/// Whether one goal predicate holds.
pub fn atom_holds(w: &World, atom: &GoalAtom) -> bool {
    let Some(i) = w.index_of(atom.object()) else {
        return false;
    };
    if let GoalAtom::At { place, .. } = atom {
        return rests_at(w, i, place, Tolerances::REST_SPEED);
    }
    let Some(d) = atom.destination_object().and_then(|d| w.index_of(d)) else {
        return false;
    };
    match atom {
        GoalAtom::In { .. } => rests_in(w, i, d, Tolerances::REST_SPEED),
        GoalAtom::On { .. } => rests_on(w, i, d, Tolerances::REST_SPEED),
        GoalAtom::At { .. } => unreachable!("handled above"),
    }
}

/// Every predicate of the scene's goal holds (true for a scene without a goal).
pub fn goal_holds(w: &World) -> bool {
    w.scene.goal.atoms.iter().all(|a| atom_holds(w, a))
}

/// One predicate's value, as reports carry it.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct GoalValue {
    /// The predicate, e.g. `red in red_bin`.
    pub predicate: String,
    /// Whether it holds.
    pub holds: bool,
    /// An `at` goal with a yaw: the block's yaw taken at the quarter turn nearest the goal's
    /// (a block's side faces repeat every 90°, so a block at 0.3° matches a goal of 90° as
    /// 90.3°), degrees. Absent for other goals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matched_yaw_deg: Option<f64>,
}

/// The yaw of block `i` at the quarter turn nearest `target` (radians), radians.
pub fn matched_yaw(w: &World, i: usize, target: f64) -> f64 {
    target + super::angles::fold_quarter_turn(w.yaw(i) - target)
}

/// Every predicate's value, in the scene's order.
pub fn evaluate(w: &World) -> Vec<GoalValue> {
    w.scene
        .goal
        .atoms
        .iter()
        .map(|a| GoalValue {
            predicate: a.to_string(),
            holds: atom_holds(w, a),
            matched_yaw_deg: match a {
                GoalAtom::At { place, .. } => place.yaw.zip(w.index_of(a.object())).map(|(target, i)| {
                    // Rounded to 0.1° like every yaw a report prints, so lines stay short.
                    (matched_yaw(w, i, target).to_degrees() * 10.0).round() / 10.0
                }),
                _ => None,
            },
        })
        .collect()
}

/// Block `i`'s goal predicate holds (false for a block without one).
pub fn done(w: &World, i: usize) -> bool {
    w.scene.goal.of(w.name(i)).is_some_and(|a| atom_holds(w, a))
}

/// Some block rests on top of object `i` (so it cannot be picked up, nor stacked on).
pub fn covered(w: &World, i: usize) -> bool {
    w.scene
        .of_kind(ObjectKind::Block)
        .any(|j| j != i && w.resting_on(j) == Some(i))
}

/// Another block occupies `place` for block `i`: some block other than `i` has its centre within
/// the two half edges of the place's point in the table plane, so the two would overlap there
/// whatever their yaws (the inscribed circles meet).
pub fn place_taken(w: &World, i: usize, place: &GoalPlace) -> bool {
    let p = nalgebra::Vector2::new(place.point[0], place.point[1]);
    w.scene
        .of_kind(ObjectKind::Block)
        .any(|j| j != i && (w.objects[j].pos.xy() - p).norm() < w.half(i) + w.half(j))
}

/// Block `i` has a goal that does not hold yet and that can be worked on now: it is not covered
/// by another block; when it goes on top of another block, that block is finished (its own goal
/// holds, or it has none and rests, released, on the table) and uncovered; when it goes to a
/// place (`at`), no other block occupies that place (a swap needs a buffer).
pub fn pending(w: &World, i: usize) -> bool {
    if !matches!(w.spec(i).shape, Shape::Block { .. }) || covered(w, i) {
        return false;
    }
    let Some(atom) = w.scene.goal.of(w.name(i)) else {
        return false;
    };
    if atom_holds(w, atom) {
        return false;
    }
    match atom {
        GoalAtom::In { .. } => true,
        GoalAtom::At { place, .. } => !place_taken(w, i, place),
        GoalAtom::On { support, .. } => w.index_of(support).is_some_and(|s| {
            let settled = match w.scene.goal.of(support) {
                Some(a) => atom_holds(w, a),
                // A fixed obstacle (a board, a pedestal) is always ready to take a block.
                None if w.spec(s).kind() == ObjectKind::Obstacle => true,
                None => {
                    w.bottom(s) < Tolerances::ON_TABLE_HEIGHT && w.container_of(s).is_none() && w.released(s)
                }
            };
            settled && !covered(w, s)
        }),
    }
}

/// The object block `i`'s goal sends it to (a container or the supporting block), if it has an
/// `in` or `on` goal.
pub fn destination(w: &World, i: usize) -> Option<usize> {
    w.scene
        .goal
        .of(w.name(i))
        .and_then(|a| a.destination_object())
        .and_then(|d| w.index_of(d))
}

/// The name `select … goal_as` writes for block `i`: its goal's container, supporting block or
/// spot ([`GoalAtom::destination`]); `None` without a goal or for an `at` goal at a bare point.
pub fn destination_name(w: &World, i: usize) -> Option<String> {
    w.scene
        .goal
        .of(w.name(i))
        .and_then(|a| a.destination())
        .map(str::to_string)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::scene::{AT_TOLERANCE, AT_YAW_TOLERANCE};
    use crate::world::conditions::on_table;
    use crate::world::tests_support::{HALF, held, resting, two_blocks};

    #[test]
    fn in_means_inside_the_walls_below_the_rim_released_and_at_rest() {
        let mut w = resting();
        w.objects[0].pos = Vector3::new(0.47, 0.06, 0.01 + HALF);
        let v = Tolerances::REST_SPEED;
        assert!(rests_in(&w, 0, 1, v));
        assert!(!on_table(&w, 0, 0.01, v));
        let mut moving = w.clone();
        moving.objects[0].linvel = Vector3::new(0.0, 0.0, -0.3);
        assert!(!rests_in(&moving, 0, 1, v));
        let mut above = w.clone();
        above.objects[0].pos.z = 0.2;
        assert!(!rests_in(&above, 0, 1, v));
        let mut squeezed = w.clone();
        squeezed.objects[0].left_pad_contact = true;
        squeezed.objects[0].right_pad_contact = true;
        assert!(!rests_in(&squeezed, 0, 1, v), "a held cube is not in the bowl");
        let mut on_rim = w.clone();
        on_rim.objects[0].pos.x = 0.45 + 0.08;
        assert!(!rests_in(&on_rim, 0, 1, v));
        // The whole cube must fit between the walls: its centre at most 0.075 − 0.022 m from the
        // bowl's centre (issue 13, item 15: the centre alone within 0.075 m was accepted).
        let bowl_x = w.objects[1].pos.x;
        let mut flush = w.clone();
        flush.objects[0].pos.x = bowl_x + 0.075 - HALF - 1e-9;
        assert!(rests_in(&flush, 0, 1, v));
        let mut in_wall = w.clone();
        in_wall.objects[0].pos.x = bowl_x + 0.075 - HALF + 0.001;
        assert!(!rests_in(&in_wall, 0, 1, v));
        in_wall.objects[0].pos.x = bowl_x + 0.074;
        assert!(!rests_in(&in_wall, 0, 1, v));
        assert!(!rests_in(&resting(), 0, 1, v));
    }

    #[test]
    fn a_swap_is_pending_only_once_the_other_block_left_the_place() {
        let mut w = two_blocks(
            "  - at: {object: a, point: [0.40, 0.10]}\n  - at: {object: b, point: [0.40, -0.10]}\n",
        );
        assert!(
            !pending(&w, 0) && !pending(&w, 1),
            "each place is taken by the other block"
        );
        assert!(!done(&w, 0) && !goal_holds(&w));
        // b moved to a buffer: a can go to b's place, b cannot yet go to a's.
        w.objects[1].pos = Vector3::new(0.30, 0.25, HALF);
        assert!(pending(&w, 0) && !pending(&w, 1));
        w.objects[0].pos = Vector3::new(0.40, 0.10, HALF);
        assert!(done(&w, 0) && !pending(&w, 0) && pending(&w, 1));
        w.objects[1].pos = Vector3::new(0.40, -0.10, HALF);
        assert!(goal_holds(&w));
        assert_eq!(evaluate(&w).iter().filter(|g| g.holds).count(), 2);
        // Placed but still in the gripper: not done.
        w.objects[1].left_pad_contact = true;
        w.objects[1].right_pad_contact = true;
        assert!(!done(&w, 1) && !goal_holds(&w));
    }

    #[test]
    fn a_stack_on_a_base_at_a_point_waits_for_the_base() {
        let mut w = two_blocks("  - stack: {blocks: [a, b], base_at: {point: [0.50, 0.0]}}\n");
        assert!(pending(&w, 1), "the base goes first");
        assert!(!pending(&w, 0), "the top waits for its base");
        w.objects[1].pos = Vector3::new(0.50, 0.0, HALF);
        assert!(done(&w, 1) && pending(&w, 0));
        assert_eq!(destination(&w, 0), Some(1));
        assert_eq!(destination(&w, 1), None, "a place is not an object");
        assert_eq!(destination_name(&w, 0).as_deref(), Some("b"));
    }

    #[test]
    fn rests_at_is_the_at_condition_on_the_goal_place() {
        let w = resting();
        let p = w.objects[0].pos;
        let place = GoalPlace {
            spot: None,
            point: [p.x + 0.005, p.y],
            yaw: Some(0.0),
            tolerance: AT_TOLERANCE,
            yaw_tolerance: AT_YAW_TOLERANCE,
        };
        assert!(rests_at(&w, 0, &place, Tolerances::REST_SPEED));
        assert!(!rests_at(&held(), 0, &place, Tolerances::REST_SPEED));
    }
}
