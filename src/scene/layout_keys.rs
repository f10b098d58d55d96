//! The layout keys of a scene file beyond the objects themselves: top-level `spots:` and
//! `regions:`, what each block rests on (`on:`, `random: {in: ..}` / `{on: ..}`), and the
//! regions a `random:` names — each problem located, with what to change.

use std::collections::{BTreeMap, BTreeSet};

use schemars::JsonSchema;
use serde::Deserialize;

use super::object_name::is_object_name;
use super::types::{ObjectKind, ObjectSpec, Region, RegionRole, SceneSpec, Spot, reach_limits};
use crate::yaml::TablePose;
use crate::yaml::de::from_value;
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::value::Value;

/// Most spots, and most regions, in one scene.
pub const MAX_SPOTS: usize = 32;

/// `regions: {NAME: ...}` — a box on the table.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RegionRaw {
    /// Range of x `[lo, hi]`, metres (lo < hi, within ±1 m).
    x: [f64; 2],
    /// Range of y `[lo, hi]`, metres (lo < hi, within ±1 m).
    y: [f64; 2],
    /// `keep_out` (random placement never puts a footprint in it) or `allowed` (an object's
    /// `random: {region: NAME}` keeps its footprint within it).
    role: RegionRoleRaw,
}

/// `role:` values of a region.
#[derive(Deserialize, JsonSchema, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub enum RegionRoleRaw {
    /// No randomized object's footprint enters it.
    KeepOut,
    /// Objects whose `random:` names it keep their footprint within it.
    Allowed,
}

/// The scene's names so far (objects, then spots, then regions), for uniqueness.
fn taken(scene: &SceneSpec) -> BTreeSet<&str> {
    scene
        .objects
        .iter()
        .map(|o| o.name.as_str())
        .chain(scene.spots.iter().map(|s| s.name.as_str()))
        .chain(scene.regions.iter().map(|r| r.name.as_str()))
        .collect()
}

/// A name key of `spots:` or `regions:`: valid and not yet used.
fn name_of<'a>(k: &'a Value, what: &str, scene: &SceneSpec, issues: &mut Vec<Issue>) -> Option<&'a str> {
    let Some(name) = k.as_str().filter(|n| is_object_name(n)) else {
        issues.push(
            Issue::new(
                k.loc,
                format!("`{}` is not a valid {what} name", k.as_str().unwrap_or("?")),
            )
            .label("expected lower-case letters, digits and `_`, starting with a letter (at most 32)"),
        );
        return None;
    };
    if taken(scene).contains(name) {
        issues.push(
            Issue::new(k.loc, format!("the name `{name}` is already used in this scene"))
                .label("objects, spots and regions share one set of names")
                .help(format!("rename this {what}")),
        );
        return None;
    }
    Some(name)
}

/// A spot written as a mapping: where, and what a block set down there rests on.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpotOnRaw {
    /// The point `[x, y]` or `[x, y, yaw]` (metres; yaw in radians or `deg(..)`).
    pub at: TablePose,
    /// The obstacle or block under the point that a block set down there rests on (the lower
    /// board of a two-level shelf, where the upper board is also over the point).
    pub on: String,
}

/// One `spots:` value: a point, or a point on a named support.
#[derive(Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum SpotRaw {
    /// `[x, y]` or `[x, y, yaw]`: on whatever is under the point with the highest top.
    Point(TablePose),
    /// `{at: [x, y, yaw], on: NAME}`.
    On(SpotOnRaw),
}

/// Why spot `name`'s `on:` cannot hold a block at `(x, y)`, if it cannot: it must name an
/// obstacle or a block of the scene whose fixed footprint (when it has one) covers the point.
fn check_spot_support(scene: &SceneSpec, name: &str, on: &str, x: f64, y: f64) -> Option<(String, String)> {
    let Some(o) = scene.object(on) else {
        let names: Vec<&str> = scene
            .objects
            .iter()
            .filter(|o| matches!(o.kind(), ObjectKind::Obstacle | ObjectKind::Block))
            .map(|o| o.name.as_str())
            .collect();
        return Some((
            format!("spot `{name}` is `on: {on}`, which is not an object of this scene"),
            format!("name one of its obstacles or blocks: {}", names.join(", ")),
        ));
    };
    if o.kind() == ObjectKind::Container {
        return Some((
            format!("spot `{name}` is `on: {on}`, a container"),
            "a spot in a container needs no `on:`: write the point alone (a block set down there rests on the floor)".into(),
        ));
    }
    if let Some(pose) = &o.pose
        && o.random.is_none()
        && o.shape.footprint(pose).distance_to_point([x, y]) > 0.0
    {
        return Some((
            format!("spot `{name}` at ({x}, {y}) is not over `{on}`"),
            format!("move the spot onto `{on}`'s top, or name the object under it"),
        ));
    }
    None
}

/// `spots: {NAME: [x, y] | [x, y, yaw] | {at: [x, y, yaw], on: SUPPORT}}`: each point on the
/// table within the arm's reach.
pub(super) fn read_spots(v: &Value, scene: &mut SceneSpec, issues: &mut Vec<Issue>) {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                v.loc,
                format!(
                    "`spots` must be a mapping of names to points, found {}",
                    v.describe()
                ),
            )
            .label("expected e.g. `spots: {buffer: [0.40, 0.25, deg(90)]}`"),
        );
        return;
    };
    if entries.len() > MAX_SPOTS {
        issues.push(Issue::new(
            v.loc,
            format!(
                "a scene has at most {MAX_SPOTS} spots, this one has {}",
                entries.len()
            ),
        ));
        return;
    }
    let [rmin, rmax] = reach_limits();
    for (k, body) in entries {
        let Some(name) = name_of(k, "spot", scene, issues) else {
            continue;
        };
        let (pose_v, on) = match body.as_map() {
            Some(_) => match from_value::<SpotOnRaw>(body) {
                Ok(raw) => {
                    let entry = |key: &str| {
                        body.as_map()
                            .and_then(|m| m.iter().find(|(k, _)| k.as_str() == Some(key)))
                            .map_or(body, |(_, v)| v)
                    };
                    (entry("at"), Some((raw.on, entry("on").loc)))
                }
                Err(e) => {
                    let mut issue = e
                        .into_issue(body.loc, |l| format!("{l:?}"))
                        .help_or("a spot on a support is `{at: [x, y, yaw], on: NAME}`");
                    issue.message = format!("{} in spot `{name}`", issue.message);
                    issues.push(issue);
                    continue;
                }
            },
            None => (body, None),
        };
        let p: TablePose = match from_value(pose_v) {
            Ok(p) => p,
            Err(e) => {
                let mut issue = e.into_issue(pose_v.loc, |l| format!("{l:?}")).help_or(
                    "a spot is `[x, y]` or `[x, y, yaw]` (metres; yaw in radians or `deg(..)`), or `{at: [x, y, yaw], on: NAME}`",
                );
                issue.message = format!("{} in spot `{name}`", issue.message);
                issues.push(issue);
                continue;
            }
        };
        let (x, y) = (p.x, p.y);
        let r = x.hypot(y);
        if !(rmin..=rmax).contains(&r) {
            let mut issue = Issue::new(
                body.loc,
                format!("spot `{name}` at ({x}, {y}) is {r:.3} m from the robot's base: spots must be {rmin} … {rmax} m away, where the arm can set a block down from above"),
            )
            .label(format!("expected a point {rmin} … {rmax} m from the origin"));
            if (rmin..=rmax).contains(&(r / 100.0)) {
                issue = issue.help(format!(
                    "coordinates are metres: for centimetres write [{}, {}]",
                    x / 100.0,
                    y / 100.0
                ));
            }
            issues.push(issue);
            continue;
        }
        if let Some((support, loc)) = &on
            && let Some((message, help)) = check_spot_support(scene, name, support, x, y)
        {
            issues.push(Issue::new(*loc, message).help(help));
            continue;
        }
        scene.spots.push(Spot {
            name: name.to_string(),
            x,
            y,
            yaw: p.yaw.unwrap_or(0.0),
            on: on.map(|(support, _)| support),
        });
    }
}

/// `regions: {NAME: {x: [lo, hi], y: [lo, hi], role: keep_out | allowed}}`.
pub(super) fn read_regions(v: &Value, scene: &mut SceneSpec, issues: &mut Vec<Issue>) {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                v.loc,
                format!(
                    "`regions` must be a mapping of names to boxes, found {}",
                    v.describe()
                ),
            )
            .label("expected e.g. `regions: {no_go: {x: [0.3, 0.4], y: [-0.1, 0.1], role: keep_out}}`"),
        );
        return;
    };
    if entries.len() > MAX_SPOTS {
        issues.push(Issue::new(
            v.loc,
            format!(
                "a scene has at most {MAX_SPOTS} regions, this one has {}",
                entries.len()
            ),
        ));
        return;
    }
    for (k, body) in entries {
        let Some(name) = name_of(k, "region", scene, issues) else {
            continue;
        };
        let raw: RegionRaw = match from_value(body) {
            Ok(r) => r,
            Err(e) => {
                issues.push(e.into_issue(body.loc, |l| format!("{l:?}")).help_or(
                    "a region is `{x: [lo, hi], y: [lo, hi], role: keep_out}` (or `role: allowed`), metres",
                ));
                continue;
            }
        };
        let mut ok = true;
        for (key, range) in [("x", raw.x), ("y", raw.y)] {
            if !(range.iter().all(|x| x.is_finite() && x.abs() <= 1.0) && range[0] < range[1]) {
                issues.push(
                    Issue::new(
                        body.get(key).map_or(body.loc, |v| v.loc),
                        format!("region `{name}`'s `{key}` must be a range [lo, hi] with lo < hi, within ±1 m of the robot"),
                    )
                    .label("expected e.g. [0.30, 0.45] (metres)"),
                );
                ok = false;
            }
        }
        if ok {
            scene.regions.push(Region {
                name: name.to_string(),
                x: raw.x,
                y: raw.y,
                role: match raw.role {
                    RegionRoleRaw::KeepOut => RegionRole::KeepOut,
                    RegionRoleRaw::Allowed => RegionRole::Allowed,
                },
            });
        }
    }
}

/// The location of `objects.NAME.path…` (or of the object when absent).
fn at(objects_v: &Value, name: &str, path: &[&str]) -> Loc {
    objects_v.get(name).map_or(objects_v.loc, |v| v.loc_at(path))
}

/// What each block rests on and which regions its `random:` names: names known and of the
/// right kind, no support cycles, a block drawn over its support fits there, a block with a
/// fixed pose does not rest on a randomized support; `random:` x and y default to the box
/// around its allowed regions.
pub(super) fn resolve_layout(scene: &mut SceneSpec, objects_v: &Value, issues: &mut Vec<Issue>) {
    let names: Vec<String> = scene.objects.iter().map(|o| o.name.clone()).collect();
    let kinds: BTreeMap<String, ObjectKind> =
        scene.objects.iter().map(|o| (o.name.clone(), o.kind())).collect();
    let regions = scene.regions.clone();
    for o in scene.objects.iter_mut() {
        resolve_regions(o, &regions, objects_v, issues);
        let Some(s) = o.on.clone() else {
            continue;
        };
        let key: &[&str] = if o.random.as_ref().is_some_and(|r| r.support.is_some()) {
            &["random"]
        } else {
            &["on"]
        };
        let loc = at(objects_v, &o.name, key);
        match kinds.get(&s) {
            None => {
                issues.push(
                    Issue::new(loc, format!("`{}` rests on unknown object `{s}`", o.name))
                        .label("expected one of the scene's containers, obstacles or blocks")
                        .maybe_help(crate::yaml::suggest::did_you_mean(
                            &s,
                            names.iter().map(String::as_str),
                        )),
                );
                o.on = None;
            }
            Some(_) if s == o.name => {
                issues.push(Issue::new(loc, format!("`{s}` cannot rest on itself")));
                o.on = None;
            }
            Some(_) => {}
        }
    }
    if !issues.is_empty() {
        return;
    }
    // Cycles: follow `on` from each block.
    for (i, o) in scene.objects.iter().enumerate() {
        let mut cur = i;
        for _ in 0..=scene.objects.len() {
            match super::support_of(scene, cur) {
                Some(next) if next == i => {
                    issues.push(
                        Issue::new(
                            at(objects_v, &o.name, &["on"]),
                            format!("`{}` rests, through others, on itself", o.name),
                        )
                        .help("make the bottom of each pile rest on the table, a container or an obstacle"),
                    );
                    return;
                }
                Some(next) => cur = next,
                None => break,
            }
        }
    }
    for (i, o) in scene.objects.iter().enumerate() {
        let Some(s) = super::support_of(scene, i) else {
            continue;
        };
        let sup = &scene.objects[s];
        if o.random.is_none() && sup.random.is_some() {
            issues.push(
                Issue::new(
                    at(objects_v, &o.name, &["on"]),
                    format!(
                        "`{}` has a fixed pose on `{}`, which sweeps place at random",
                        o.name, sup.name
                    ),
                )
                .label(format!(
                    "this block would be left where `{}` no longer is",
                    sup.name
                ))
                .help(format!(
                    "give `{}` a `random: {{{}: {}}}` too, or give `{}` only a fixed pose",
                    o.name,
                    if sup.kind() == ObjectKind::Container {
                        "in"
                    } else {
                        "on"
                    },
                    sup.name,
                    sup.name
                )),
            );
        }
        if let Some(r) = &o.random
            && r.support.is_some()
        {
            let [hx, _] = o.shape.footprint_half();
            let wall = if sup.kind() == ObjectKind::Container {
                r.clearance
            } else {
                0.0
            };
            let [sx, sy] = sup.shape.support_half();
            if hx + wall > sx.min(sy) + 1e-9 {
                issues.push(
                    Issue::new(
                        at(objects_v, &o.name, &["random"]),
                        format!(
                            "block `{}` ({:.3} m) does not fit on `{}` ({:.3} × {:.3} m{}) with {:.3} m clearance",
                            o.name,
                            2.0 * hx,
                            sup.name,
                            2.0 * sx,
                            2.0 * sy,
                            if sup.kind() == ObjectKind::Container { " inside the walls" } else { " top" },
                            wall
                        ),
                    )
                    .help(format!(
                        "make `{}` larger, the block smaller, or lower its `clearance`",
                        sup.name
                    )),
                );
            }
        }
    }
}

/// `random: {region: NAME | [NAMES]}`: names known and `allowed`; absent x and y ranges become
/// the box around the regions.
fn resolve_regions(o: &mut ObjectSpec, regions: &[Region], objects_v: &Value, issues: &mut Vec<Issue>) {
    let Some(r) = o.random.as_mut() else {
        return;
    };
    let mut bx = [f64::INFINITY, f64::NEG_INFINITY];
    let mut by = [f64::INFINITY, f64::NEG_INFINITY];
    for n in &r.regions {
        match regions.iter().find(|g| &g.name == n) {
            Some(g) if g.role == RegionRole::Allowed => {
                bx = [bx[0].min(g.x[0]), bx[1].max(g.x[1])];
                by = [by[0].min(g.y[0]), by[1].max(g.y[1])];
            }
            Some(_) => issues.push(
                Issue::new(
                    at(objects_v, &o.name, &["random", "region"]),
                    format!("region `{n}` is a keep-out region, not an allowed one"),
                )
                .label("expected a region with `role: allowed`")
                .help("keep-out regions apply to every randomized object without being named"),
            ),
            None => issues.push(
                Issue::new(
                    at(objects_v, &o.name, &["random", "region"]),
                    format!("unknown region `{n}`"),
                )
                .label("expected one of the scene's `regions:`")
                .maybe_help(crate::yaml::suggest::did_you_mean(
                    n,
                    regions.iter().map(|g| g.name.as_str()),
                )),
            ),
        }
    }
    if r.x[0].is_nan() && bx[0].is_finite() {
        r.x = bx;
    }
    if r.y[0].is_nan() && by[0].is_finite() {
        r.y = by;
    }
}
