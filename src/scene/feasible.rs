//! Scenes whose task can never be done are refused at load, located: a scene without a block
//! (nothing to pick), goals that stack blocks in a cycle (`a on b`, `b on a`), and a block
//! wider than the inside of the container it must end in, two blocks whose `at` goals overlap,
//! and an `at` goal (judged on the table or a container's floor) inside the footprint of a
//! fixed obstacle too low to put the block under — a spot there is a set-down place on the
//! obstacle's top, never an `at` place.

use std::collections::BTreeMap;

use super::goal::GoalAtom;
use super::types::{ObjectSpec, SceneSpec, Shape};
use crate::yaml::diag::{Issue, Loc};

/// The first obstacle with a fixed pose (and no `random:`) whose footprint contains the point
/// `p` (metres) and whose underside is less than `height` metres above the table: a block that
/// tall cannot rest on the table at `p`.
pub(super) fn obstacle_over(scene: &SceneSpec, p: [f64; 2], height: f64) -> Option<&ObjectSpec> {
    scene.objects.iter().find(|o| {
        matches!(o.shape, Shape::Obstacle { .. })
            && o.random.is_none()
            && o.pose
                .is_some_and(|pose| o.z < height && o.shape.footprint(&pose).distance_to_point(p) == 0.0)
    })
}

/// A scene without a block: the issue at `objects:` (`at`).
pub(super) fn check_has_block(scene: &SceneSpec, at: Loc, issues: &mut Vec<Issue>) {
    if scene.of_kind(super::ObjectKind::Block).next().is_none() {
        issues.push(
            Issue::new(at, format!("scene `{}` has no block", scene.name))
                .label("expected at least one `NAME: {block: {...}, ...}` here")
                .help("a tree picks and places blocks: add one (see docs/scenes.md)"),
        );
    }
}

/// Goals that can never hold together: an `on` cycle, or a block that does not fit inside its
/// container.
pub(super) fn check_goal_feasible(scene: &SceneSpec, atoms: &[(GoalAtom, Loc)], issues: &mut Vec<Issue>) {
    // Each block has at most one goal (checked before), so following `on` from a block either
    // ends or comes back: a cycle.
    let on: BTreeMap<&str, (&str, Loc)> = atoms
        .iter()
        .filter_map(|(a, loc)| match a {
            GoalAtom::On { object, support } if object != support => {
                Some((object.as_str(), (support.as_str(), *loc)))
            }
            _ => None,
        })
        .collect();
    let mut reported = std::collections::BTreeSet::new();
    for (&start, &(_, loc)) in &on {
        let mut path = vec![start];
        let mut cur = start;
        while let Some(&(next, _)) = on.get(cur) {
            if next == start {
                let mut members = path.clone();
                members.sort_unstable();
                if reported.insert(members) {
                    path.push(start);
                    issues.push(
                        Issue::new(loc, format!("the `on` goals form a cycle: {}", path.join(" on ")))
                            .label("a block cannot rest, through others, on itself")
                            .help("make the bottom block of each stack rest on the table or in a container"),
                    );
                }
                break;
            }
            if path.contains(&next) {
                break; // a cycle that does not pass through `start`: reported from its own members
            }
            path.push(next);
            cur = next;
        }
    }
    for (a, loc) in atoms {
        let GoalAtom::In { object, container } = a else {
            continue;
        };
        let (Some(block), Some(bin)) = (scene.object(object.as_str()), scene.object(container.as_str()))
        else {
            continue;
        };
        if let (Shape::Block { half, .. }, Shape::Container { inner_half, .. }) = (&block.shape, &bin.shape) {
            let inside = inner_half[0].min(inner_half[1]);
            if *half >= inside {
                issues.push(
                    Issue::new(
                        *loc,
                        format!(
                            "block `{object}` ({:.3} m wide) does not fit inside container `{container}` ({:.3} × {:.3} m inside)",
                            2.0 * half,
                            2.0 * inner_half[0],
                            2.0 * inner_half[1]
                        ),
                    )
                    .label("this goal can never hold")
                    .help("make the block smaller or the container wider (see docs/scenes.md)"),
                );
            }
        }
    }
    // An `at` goal inside a fixed obstacle that stands on the table (or too low to go under):
    // `at` is judged on the table, and a block set down there rests on the obstacle's top.
    for (a, loc) in atoms {
        let (Some(place), Some(block)) = (a.place(), scene.object(a.object())) else {
            continue;
        };
        if let Some(o) = obstacle_over(scene, place.point, block.shape.height()) {
            issues.push(
                Issue::new(
                    *loc,
                    format!(
                        "block `{}` can never be `at` ({}, {}): the point is inside obstacle `{}`'s footprint, whose underside is {:.3} m above the table ({:.3} m needed), and `at` is judged on the table or a container's floor",
                        a.object(),
                        place.point[0],
                        place.point[1],
                        o.name,
                        o.z,
                        block.shape.height()
                    ),
                )
                .label("this goal can never hold")
                .help(format!(
                    "move the point or spot out of `{}`'s footprint; a block set down on an obstacle's top is placed there by `place`, not graded by `at`",
                    o.name
                )),
            );
        }
    }
    // Two `at` goals whose places overlap whatever the blocks' yaws, even at the tolerances'
    // ends: the blocks' inscribed circles would meet.
    let places: Vec<(&str, &super::GoalPlace, Loc)> = atoms
        .iter()
        .filter_map(|(a, loc)| a.place().map(|p| (a.object(), p, *loc)))
        .collect();
    let half = |name: &str| match scene.object(name).map(|o| &o.shape) {
        Some(Shape::Block { half, .. }) => *half,
        _ => 0.0,
    };
    for (k, (a, pa, _)) in places.iter().enumerate() {
        for (b, pb, loc) in &places[k + 1..] {
            let d = (pa.point[0] - pb.point[0]).hypot(pa.point[1] - pb.point[1]);
            if d + pa.tolerance + pb.tolerance < half(a) + half(b) {
                issues.push(
                    Issue::new(
                        *loc,
                        format!(
                            "blocks `{a}` and `{b}` cannot both be there: their places are {:.0} mm apart and the blocks {:.0} mm and {:.0} mm wide",
                            d * 1e3,
                            2e3 * half(a),
                            2e3 * half(b)
                        ),
                    )
                    .label("these `at` goals can never hold together")
                    .help("move the points apart by at least the blocks' half widths added"),
                );
            }
        }
    }
}
