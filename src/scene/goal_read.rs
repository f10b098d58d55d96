//! Reading a scene file's `goal:` into a [`Goal`]: every predicate checked against the scene's
//! objects and spots, located (file:line:column), with did-you-mean and range checks.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer};

use super::goal::{
    AT_MAX_TOLERANCE, AT_MAX_YAW_TOLERANCE, AT_TOLERANCE, AT_YAW_TOLERANCE, Goal, GoalAtom, GoalPlace,
};
use super::types::{ObjectKind, ObjectSpec, SceneSpec, reach_limits};
use crate::yaml::de::from_value;
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::units::{self, Angle};
use crate::yaml::value::{Value, ValueKind};

/// `in:` goal.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InRaw {
    /// A block.
    object: String,
    /// A container.
    container: String,
}

/// `on:` goal.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OnRaw {
    /// The block on top.
    object: String,
    /// The block under it.
    support: String,
}

fn d_at_tolerance() -> f64 {
    AT_TOLERANCE
}
fn d_at_yaw_tolerance() -> f64 {
    AT_YAW_TOLERANCE
}
fn opt_point<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    units::vec2(d).map(Some)
}

/// `at:` goal: a block resting at a point (or a named spot), at a yaw if given.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AtRaw {
    /// A block.
    object: String,
    /// Where its centre should rest, `[x, y]` on the table, world metres (or give `spot`).
    #[serde(default, deserialize_with = "opt_point")]
    point: Option<[f64; 2]>,
    /// A spot of the scene's `spots:` (or give `point`); its yaw is checked only when `yaw` is
    /// written.
    spot: Option<String>,
    /// The yaw its side faces should have (radians or `deg(..)`, compared modulo 90°). Absent:
    /// any.
    yaw: Option<Angle>,
    /// Largest horizontal distance of its centre from the point, metres (> 0, at most 0.10).
    /// Default 0.01.
    #[serde(default = "d_at_tolerance", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = 0.1))]
    tolerance: f64,
    /// Largest yaw error when `yaw` is given, radians or `deg(..)` (> 0, at most 45°). Default
    /// 5°.
    #[serde(default = "d_at_yaw_tolerance", deserialize_with = "units::angle_tolerance")]
    #[schemars(with = "Angle")]
    yaw_tolerance: f64,
}

/// `base_at:` of a stack: where the bottom block rests (an `at` goal without `object`).
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BaseAtRaw {
    /// Where the bottom block's centre should rest, `[x, y]`, world metres (or give `spot`).
    #[serde(default, deserialize_with = "opt_point")]
    point: Option<[f64; 2]>,
    /// A spot of the scene's `spots:` (or give `point`).
    spot: Option<String>,
    /// The yaw of the bottom block's side faces (radians or `deg(..)`, modulo 90°). Absent: any.
    yaw: Option<Angle>,
    /// Largest horizontal distance from the point, metres (> 0, at most 0.10). Default 0.01.
    #[serde(default = "d_at_tolerance", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = 0.1))]
    tolerance: f64,
    /// Largest yaw error when `yaw` is given, radians or `deg(..)` (> 0, at most 45°). Default
    /// 5°.
    #[serde(default = "d_at_yaw_tolerance", deserialize_with = "units::angle_tolerance")]
    #[schemars(with = "Angle")]
    yaw_tolerance: f64,
}

/// `stack: {blocks, base_at}`: the map form of a stack.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StackMapRaw {
    /// `[top, …, bottom]`: each block rests on the next.
    blocks: Vec<String>,
    /// Where the bottom block rests. Absent: anywhere on the table.
    base_at: Option<BaseAtRaw>,
}

/// `stack:` — `[top, …, bottom]`, or `{blocks: [top, …, bottom], base_at: {point: [x, y]}}`.
#[derive(JsonSchema)]
#[serde(untagged)]
pub enum StackRaw {
    /// `[top, …, bottom]`: each block rests on the next; the last stays on the table.
    List(Vec<String>),
    /// The blocks and where the bottom one rests.
    Map(StackMapRaw),
}

impl<'de> Deserialize<'de> for StackRaw {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = StackRaw;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a list of blocks `[top, …, bottom]` or `{blocks: [top, …, bottom], base_at: {point: [x, y]}}`")
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<StackRaw, A::Error> {
                Vec::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(StackRaw::List)
            }
            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<StackRaw, A::Error> {
                StackMapRaw::deserialize(de::value::MapAccessDeserializer::new(map)).map(StackRaw::Map)
            }
        }
        d.deserialize_any(V)
    }
}

/// `all_in:` goal.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AllInRaw {
    /// The container every block must end in.
    container: String,
}

/// `sorted_by_color:` goal (no parameters).
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

/// One goal predicate (see `docs/scenes.md`).
#[derive(Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GoalRaw {
    /// The block rests in the container.
    In(InRaw),
    /// The block rests on the other block.
    On(OnRaw),
    /// The block rests at a point or spot, at a yaw if given.
    At(AtRaw),
    /// Every block rests in the container.
    AllIn(AllInRaw),
    /// `[top, …, bottom]`: each block rests on the next; the last stays on the table (or at
    /// `base_at`).
    Stack(StackRaw),
    /// Every block rests in the container of its colour.
    SortedByColor(NoParams),
}

/// Names the scene file declares (objects and spots) whose declaration was refused, its error
/// reported where it is written: a goal that names one is not reported again as unknown.
pub(super) type Rejected<'a> = std::collections::BTreeSet<&'a str>;

/// The goal `v` (a list of predicates) of `scene`, every problem added to `issues`.
pub(super) fn read_goal(
    v: &Value,
    scene: &SceneSpec,
    rejected: &Rejected<'_>,
    issues: &mut Vec<Issue>,
) -> Goal {
    let Some(items) = v.as_seq() else {
        issues.push(
            Issue::new(
                v.loc,
                format!("`goal` must be a list of predicates, found {}", v.describe()),
            )
            .label("expected e.g. `- in: {object: red, container: red_bin}`"),
        );
        return Goal::default();
    };
    let mut atoms: Vec<(GoalAtom, Loc)> = Vec::new();
    for item in items {
        let raw: GoalRaw = match from_value(item) {
            Ok(r) => r,
            Err(e) => {
                issues.push(e.into_issue(item.loc, |l| format!("{l:?}")).help_or(
                    "a goal predicate is one of `in`, `on`, `at`, `all_in`, `stack`, `sorted_by_color`",
                ));
                continue;
            }
        };
        let body = match &item.kind {
            ValueKind::Map(e) if e.len() == 1 => &e[0].1,
            _ => item,
        };
        let mut want = |name: &str, key: &str, kinds: &[ObjectKind]| -> bool {
            let at = if key.is_empty() {
                body.loc
            } else {
                body.loc_at(&[key])
            };
            want_at(scene, rejected, name, at, kinds, issues)
        };
        match raw {
            GoalRaw::In(r) => {
                if want(&r.object, "object", &[ObjectKind::Block])
                    & want(&r.container, "container", &[ObjectKind::Container])
                {
                    atoms.push((
                        GoalAtom::In {
                            object: r.object,
                            container: r.container,
                        },
                        item.loc,
                    ));
                }
            }
            GoalRaw::On(r) => {
                if want(&r.object, "object", &[ObjectKind::Block])
                    & want(&r.support, "support", &[ObjectKind::Block, ObjectKind::Obstacle])
                {
                    atoms.push((
                        GoalAtom::On {
                            object: r.object,
                            support: r.support,
                        },
                        item.loc,
                    ));
                }
            }
            GoalRaw::AllIn(r) => {
                if want(&r.container, "container", &[ObjectKind::Container]) {
                    for b in scene.of_kind(ObjectKind::Block) {
                        let object = scene.objects[b].name.clone();
                        atoms.push((
                            GoalAtom::In {
                                object,
                                container: r.container.clone(),
                            },
                            item.loc,
                        ));
                    }
                }
            }
            GoalRaw::At(r) => {
                let ok = want(&r.object, "object", &[ObjectKind::Block]);
                let raw = PlaceFields {
                    point: r.point,
                    spot: r.spot,
                    yaw: r.yaw,
                    tolerance: r.tolerance,
                    yaw_tolerance: r.yaw_tolerance,
                };
                if let Some(place) = read_place(raw, body, scene, rejected, issues)
                    && ok
                {
                    atoms.push((
                        GoalAtom::At {
                            object: r.object,
                            place,
                        },
                        item.loc,
                    ));
                }
            }
            GoalRaw::Stack(form) => {
                let (names, base_at, names_v) = match form {
                    StackRaw::List(names) => (names, None, body),
                    StackRaw::Map(m) => (m.blocks, m.base_at, body.get("blocks").unwrap_or(body)),
                };
                if names.len() < 2 {
                    issues.push(
                        Issue::new(names_v.loc, "a stack names at least two blocks, top first")
                            .label("expected e.g. `[red, green, blue]` (red on green on blue)"),
                    );
                    continue;
                }
                // Every name is checked (and reported), not only up to the first bad one.
                let checked: Vec<bool> = names
                    .iter()
                    .enumerate()
                    .map(|(k, n)| {
                        let at = names_v
                            .as_seq()
                            .and_then(|s| s.get(k))
                            .map_or(names_v.loc, |e| e.loc);
                        want_at(scene, rejected, n, at, &[ObjectKind::Block], issues)
                    })
                    .collect();
                let base = base_at.and_then(|b| {
                    let raw = PlaceFields {
                        point: b.point,
                        spot: b.spot,
                        yaw: b.yaw,
                        tolerance: b.tolerance,
                        yaw_tolerance: b.yaw_tolerance,
                    };
                    read_place(raw, body.get("base_at").unwrap_or(body), scene, rejected, issues)
                });
                if checked.iter().all(|&b| b) {
                    for pair in names.windows(2) {
                        atoms.push((
                            GoalAtom::On {
                                object: pair[0].clone(),
                                support: pair[1].clone(),
                            },
                            item.loc,
                        ));
                    }
                    if let Some(place) = base {
                        let object = names.last().expect("two or more").clone();
                        atoms.push((GoalAtom::At { object, place }, item.loc));
                    }
                }
            }
            GoalRaw::SortedByColor(NoParams {}) => {
                for b in scene.of_kind(ObjectKind::Block) {
                    let block = &scene.objects[b];
                    let matching: Vec<&ObjectSpec> = scene
                        .objects
                        .iter()
                        .filter(|o| {
                            o.kind() == ObjectKind::Container
                                && o.color.name.is_some()
                                && o.color.name == block.color.name
                        })
                        .collect();
                    if matching.len() == 1 {
                        atoms.push((
                            GoalAtom::In {
                                object: block.name.clone(),
                                container: matching[0].name.clone(),
                            },
                            item.loc,
                        ));
                    } else {
                        issues.push(Issue::new(
                            item.loc,
                            format!(
                                "`sorted_by_color` needs exactly one container of block `{}`'s colour ({}), found {}",
                                block.name,
                                block.color,
                                matching.len()
                            ),
                        ));
                    }
                }
            }
        }
    }
    // At most one predicate per block, and no block stacked on itself.
    let mut seen: BTreeMap<String, Loc> = BTreeMap::new();
    for (a, loc) in &atoms {
        if Some(a.object()) == a.destination_object() {
            issues.push(Issue::new(
                *loc,
                format!("`{}` cannot rest on itself", a.object()),
            ));
        }
        if let Some(first) = seen.insert(a.object().to_string(), *loc) {
            issues.push(
                Issue::new(*loc, format!("block `{}` has two goals", a.object()))
                    .note(format!("the first is at line {}", first.line))
                    .help("give each block one destination"),
            );
        }
    }
    super::feasible::check_goal_feasible(scene, &atoms, issues);
    Goal {
        atoms: atoms.into_iter().map(|(a, _)| a).collect(),
    }
}

/// True when `name` is an object of `scene` of one of `kinds`; else an issue at `at` (none for
/// a `rejected` name, whose declaration has its own).
fn want_at(
    scene: &SceneSpec,
    rejected: &Rejected<'_>,
    name: &str,
    at: Loc,
    kinds: &[ObjectKind],
    issues: &mut Vec<Issue>,
) -> bool {
    match scene.object(name) {
        None if rejected.contains(name) => false,
        Some(o) if kinds.contains(&o.kind()) => true,
        Some(o) => {
            let expect: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
            issues.push(
                Issue::new(
                    at,
                    format!("`{name}` is a {}, not a {}", o.kind(), expect.join(" or ")),
                )
                .label(format!("expected a {}", expect.join(" or "))),
            );
            false
        }
        None => {
            let mut issue = Issue::new(at, format!("unknown object `{name}`"))
                .label("expected one of the scene's objects")
                .maybe_help(did_you_mean(name, scene.objects.iter().map(|o| o.name.as_str())));
            if scene.spot(name).is_some() {
                issue = issue.help(format!(
                    "`{name}` is a spot: say where a block goes with `at: {{object: BLOCK, spot: {name}}}`"
                ));
            }
            issues.push(issue);
            false
        }
    }
}

/// The fields an `at` goal and a stack's `base_at` share.
struct PlaceFields {
    point: Option<[f64; 2]>,
    spot: Option<String>,
    yaw: Option<Angle>,
    tolerance: f64,
    yaw_tolerance: f64,
}

/// The place `raw` (read from `body`) names: exactly one of `point` and `spot` (a spot of
/// `scene`), within the arm's reach, the tolerances in range. `None` after adding an issue (or
/// for a `rejected` spot, whose declaration has its own).
fn read_place(
    raw: PlaceFields,
    body: &Value,
    scene: &SceneSpec,
    rejected: &Rejected<'_>,
    issues: &mut Vec<Issue>,
) -> Option<GoalPlace> {
    let before = issues.len();
    let point = match (&raw.point, &raw.spot) {
        (Some(p), None) => Some((*p, body.loc_at(&["point"]))),
        (None, Some(name)) => {
            let at = body.loc_at(&["spot"]);
            match scene.spot(name) {
                Some(s) => Some(([s.x, s.y], at)),
                None if rejected.contains(name.as_str()) => None,
                None => {
                    let mut issue = Issue::new(at, format!("unknown spot `{name}`"))
                        .label("expected one of the scene's `spots:`");
                    issue = match did_you_mean(name, scene.spots.iter().map(|s| s.name.as_str())) {
                        Some(h) => issue.help(h),
                        None if scene.object(name).is_some() => issue.help(format!(
                            "`{name}` is an object, not a spot: for a block on a block use `on:`, in a container `in:`"
                        )),
                        None if scene.spots.is_empty() => issue.help(
                            "the scene declares no spots: add `spots: {NAME: [x, y]}` (metres; `[x, y, yaw]` with a yaw, see docs/scenes.md) or give `point: [x, y]`",
                        ),
                        None => issue,
                    };
                    issues.push(issue);
                    None
                }
            }
        }
        (Some(_), Some(_)) => {
            issues.push(
                Issue::new(body.loc_at(&["spot"]), "give `point` or `spot`, not both")
                    .label("a spot already has a point")
                    .help("remove `point:` to use the spot, or `spot:` to use the point"),
            );
            None
        }
        (None, None) => {
            issues.push(
                Issue::new(body.loc, "where? give `point: [x, y]` or `spot: NAME`")
                    .label("expected `point` or `spot`")
                    .help("e.g. `at: {object: red, point: [0.40, -0.20], yaw: deg(90)}`"),
            );
            None
        }
    };
    if let Some((p, at)) = point {
        let r = p[0].hypot(p[1]);
        let [lo, hi] = reach_limits();
        if !(lo..=hi).contains(&r) {
            issues.push(
                Issue::new(
                    at,
                    format!(
                        "({:.3}, {:.3}) is {r:.3} m from the robot's base, outside the reach of {lo:.2} … {hi:.2} m",
                        p[0], p[1]
                    ),
                )
                .label("no block can be put down here")
                .help(format!("put the point {lo:.2} … {hi:.2} m from the base (the origin); lengths are in metres")),
            );
        }
    }
    if !(raw.tolerance > 0.0 && raw.tolerance <= AT_MAX_TOLERANCE) {
        issues.push(
            Issue::new(
                body.loc_at(&["tolerance"]),
                format!(
                    "`tolerance` must be > 0 and at most {AT_MAX_TOLERANCE} m, found {}",
                    raw.tolerance
                ),
            )
            .label("metres from the point")
            .help(format!("the default is {AT_TOLERANCE} m (1 cm)")),
        );
    }
    if !(raw.yaw_tolerance > 0.0 && raw.yaw_tolerance <= AT_MAX_YAW_TOLERANCE + 1e-12) {
        issues.push(
            Issue::new(
                body.loc_at(&["yaw_tolerance"]),
                format!(
                    "`yaw_tolerance` must be > 0 and at most 45° (a cube's yaw is compared modulo 90°), found {:.1}°",
                    raw.yaw_tolerance.to_degrees()
                ),
            )
            .label("radians, or deg(..)")
            .help("the default is deg(5)"),
        );
    }
    if issues.len() > before {
        return None;
    }
    let (point, _) = point?;
    Some(GoalPlace {
        spot: raw.spot,
        point,
        yaw: raw.yaw.map(|a| a.0),
        tolerance: raw.tolerance,
        yaw_tolerance: raw.yaw_tolerance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Spot;
    use crate::yaml::diag::Sources;
    use crate::yaml::value::parse_yaml;

    /// The goal `yaml` of the built-in scene with spots `slot_a` (0.40, −0.10, 90°) and
    /// `slot_b`: the atoms, or the issues' messages and helps.
    fn read(yaml: &str) -> Result<Goal, Vec<(String, Option<String>)>> {
        let mut scene = SceneSpec::builtin();
        scene.spots = vec![
            Spot {
                name: "slot_a".into(),
                x: 0.40,
                y: -0.10,
                yaw: std::f64::consts::FRAC_PI_2,
                on: None,
            },
            Spot {
                name: "slot_b".into(),
                x: 0.40,
                y: 0.10,
                yaw: 0.0,
                on: None,
            },
        ];
        let mut sources = Sources::new();
        let id = sources.add("t.yaml", yaml);
        let v = parse_yaml(yaml, id).unwrap();
        let mut issues = Vec::new();
        let goal = read_goal(&v, &scene, &Rejected::new(), &mut issues);
        if issues.is_empty() {
            Ok(goal)
        } else {
            Err(issues.into_iter().map(|i| (i.message, i.help)).collect())
        }
    }

    #[test]
    fn a_spot_gives_the_point_and_names_the_destination() {
        let g = read("- at: {object: cube, spot: slot_a}\n").unwrap();
        let place = g.atoms[0].place().unwrap();
        assert_eq!(place.point, [0.40, -0.10]);
        assert_eq!(
            place.yaw, None,
            "the spot's yaw is checked only when `yaw` is written"
        );
        assert_eq!(g.atoms[0].destination(), Some("slot_a"));
        assert_eq!(g.atoms[0].to_string(), "cube at slot_a (0.400, -0.100)");
        let g = read("- at: {object: cube, spot: slot_b, yaw: deg(30)}\n").unwrap();
        assert!((g.atoms[0].place().unwrap().yaw.unwrap() - 30f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn an_unknown_spot_suggests_the_nearest_name() {
        let e = read("- at: {object: cube, spot: slot_c}\n").unwrap_err();
        assert_eq!(e[0].0, "unknown spot `slot_c`");
        assert!(
            e[0].1.as_deref().unwrap().contains("slot_a") || e[0].1.as_deref().unwrap().contains("slot_b"),
            "{e:?}"
        );
        let e = read("- at: {object: cube, spot: bowl}\n").unwrap_err();
        assert!(
            e[0].1.as_deref().unwrap().contains("is an object, not a spot"),
            "{e:?}"
        );
        let e = read("- in: {object: slot_a, container: bowl}\n").unwrap_err();
        assert!(e[0].1.as_deref().unwrap().contains("is a spot"), "{e:?}");
    }
}
