//! Scenes whose task can never be done are refused at load, located: a scene without a block
//! (nothing to pick), goals that stack blocks in a cycle (`a on b`, `b on a`), and a block
//! wider than the inside of the container it must end in, two blocks whose `at` goals overlap,
//! and an `at` goal where the block can rest on nothing: inside the footprint of fixed
//! obstacles that leave no room on the table under them and whose tops are too small for the
//! block or too close under another board.

use std::collections::BTreeMap;

use super::goal::GoalAtom;
use super::types::{ObjectSpec, SceneSpec, Shape};
use crate::yaml::diag::{Issue, Loc};

/// The fixed obstacles (a `pose:`, no `random:`) whose footprint contains the point `p`
/// (metres), lowest first.
fn fixed_obstacles_at(scene: &SceneSpec, p: [f64; 2]) -> Vec<&ObjectSpec> {
    let mut over: Vec<&ObjectSpec> = scene
        .objects
        .iter()
        .filter(|o| {
            matches!(o.shape, Shape::Obstacle { .. })
                && o.random.is_none()
                && o.pose
                    .is_some_and(|pose| o.shape.footprint(&pose).distance_to_point(p) == 0.0)
        })
        .collect();
    over.sort_by(|a, b| a.z.total_cmp(&b.z));
    over
}

/// Why a block cannot rest at a point.
struct NoRest<'a> {
    /// The lowest obstacle over the point (it leaves no room on the table).
    lowest: &'a ObjectSpec,
    /// What stops each obstacle top there from holding the block, for the message.
    tops: Vec<String>,
}

/// Whether a block `half` metres in half-width can rest at `p` on the table or on the top of a
/// fixed obstacle over `p` (a board, a pedestal): the level needs room for the block up to the
/// next obstacle's underside, and a top must hold the block's inscribed circle around `p`.
/// `Ok` when it can (or nothing stands there), else why not.
fn rest_at<'a>(scene: &'a SceneSpec, p: [f64; 2], half: f64) -> Result<(), NoRest<'a>> {
    let over = fixed_obstacles_at(scene, p);
    let Some(&lowest) = over.first() else {
        return Ok(());
    };
    let height = 2.0 * half;
    // Room above `level` up to the underside of the next obstacle over the point.
    let room = |level: f64| {
        over.iter()
            .map(|o| o.z)
            .filter(|&z| z >= level - 1e-9)
            .fold(f64::INFINITY, f64::min)
            - level
    };
    if room(0.0) >= height {
        return Ok(());
    }
    let mut tops = Vec::new();
    for o in &over {
        let (Some(pose), Shape::Obstacle { half: oh }) = (o.pose, &o.shape) else {
            continue;
        };
        let top = o.z + 2.0 * oh[2];
        let footprint = o.shape.footprint(&pose);
        let [u, v] = footprint.local(p);
        let inside = (footprint.half[0] - u.abs()).min(footprint.half[1] - v.abs());
        let above = over
            .iter()
            .map(|x| x.z)
            .filter(|&z| z >= top - 1e-9)
            .fold(f64::INFINITY, f64::min)
            - top;
        if inside + 1e-9 < half {
            tops.push(format!(
                "`{}`'s top holds {:.3} m around the point ({half:.3} m needed)",
                o.name,
                inside.max(0.0)
            ));
        } else if above < height {
            tops.push(format!(
                "`{}`'s top has {above:.3} m of room under the next board ({height:.3} m needed)",
                o.name
            ));
        } else {
            return Ok(());
        }
    }
    Err(NoRest { lowest, tops })
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
    // An `at` goal where the block can rest on nothing: neither on the table (obstacles over
    // the point leave no room under them) nor on an obstacle's top (too small, or too close
    // under the next board). `at` is judged on whatever the block rests on.
    for (a, loc) in atoms {
        let (Some(place), Some(Shape::Block { half, .. })) =
            (a.place(), scene.object(a.object()).map(|b| &b.shape))
        else {
            continue;
        };
        if let Err(no) = rest_at(scene, place.point, *half) {
            issues.push(
                Issue::new(
                    *loc,
                    format!(
                        "block `{}` can never be `at` ({}, {}): obstacle `{}` stands there ({:.3} m of room under it, {:.3} m needed), and {}",
                        a.object(),
                        place.point[0],
                        place.point[1],
                        no.lowest.name,
                        no.lowest.z,
                        2.0 * half,
                        no.tops.join("; ")
                    ),
                )
                .label("the block can rest on nothing here")
                .help(format!(
                    "move the point or spot off `{}`, onto a top wide enough for the block, or give the shelf's boards more room between them",
                    no.lowest.name
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
