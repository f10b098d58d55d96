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
/// released, and at rest (speed below `rest_speed`, m/s).
pub fn rests_on(w: &World, i: usize, s: usize, rest_speed: f64) -> bool {
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
/// tolerances): released, at rest, on the table or a container's floor.
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
#[derive(Debug, Clone, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct GoalValue {
    /// The predicate, e.g. `red in red_bin`.
    pub predicate: String,
    /// Whether it holds.
    pub holds: bool,
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
