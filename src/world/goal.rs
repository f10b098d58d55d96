//! The scene's goal on a world snapshot: whether each predicate holds, and which blocks still
//! have work to do. Pure functions of a [`World`].

use serde::Serialize;

use super::World;
use super::conditions::Tolerances;
use crate::scene::{GoalAtom, ObjectKind, Shape};

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

/// Whether one goal predicate holds.
pub fn atom_holds(w: &World, atom: &GoalAtom) -> bool {
    let (Some(i), Some(d)) = (w.index_of(atom.object()), w.index_of(atom.destination())) else {
        return false;
    };
    match atom {
        GoalAtom::In { .. } => rests_in(w, i, d, Tolerances::REST_SPEED),
        GoalAtom::On { .. } => rests_on(w, i, d, Tolerances::REST_SPEED),
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

/// Block `i` has a goal that does not hold yet and that can be worked on now: it is not covered
/// by another block, and when it goes on top of another block, that block is finished (its own
/// goal holds, or it has none and rests on the table) and uncovered.
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
        GoalAtom::On { support, .. } => w.index_of(support).is_some_and(|s| {
            let settled = match w.scene.goal.of(support) {
                Some(a) => atom_holds(w, a),
                None => w.bottom(s) < Tolerances::ON_TABLE_HEIGHT && w.container_of(s).is_none(),
            };
            settled && !covered(w, s)
        }),
    }
}

/// Where block `i`'s goal sends it (a container or the supporting block), if it has a goal.
pub fn destination(w: &World, i: usize) -> Option<usize> {
    w.scene
        .goal
        .of(w.name(i))
        .and_then(|a| w.index_of(a.destination()))
}
