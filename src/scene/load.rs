//! Reading scene files: YAML → [`SceneSpec`], every problem located (file:line:column) with what
//! was expected and what to do, exactly like tree files.

use std::collections::BTreeMap;
use std::path::Path;

use schemars::JsonSchema;
use serde::Deserialize;

use super::color::Color;
use super::goal::Goal;
use super::goal_read::{GoalRaw, Rejected, read_goal};
use super::limits::{
    BASE_HEIGHT, BLOCK_EDGE, BLOCK_FRICTION, BLOCK_MASS, CLEARANCE, CONTAINER_INNER, OBSTACLE_HEIGHT,
    OBSTACLE_SIDE, WALL_HEIGHT,
};
use super::object_name::is_object_name;
use super::sample::{Placement, sample_placement};
use super::types::{ObjectKind, ObjectSpec, Pose, RandomPlacement, Sampler, SceneSpec, Shape};
use crate::yaml::de::from_value;
use crate::yaml::diag::{Diagnostic, Issue, Loc, Sources};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::units::Angle;
use crate::yaml::value::{Value, decode_utf8, parse_yaml};
use crate::yaml::{Bounds, TablePose};

/// The built-in scene `cube_bowl` (the reference tutorial's cell), used when a tree names no
/// scene. The same text as `scenes/cube_bowl.yaml`.
pub const BUILTIN_CUBE_BOWL: &str = include_str!("../../scenes/cube_bowl.yaml");

/// Most objects in one scene.
pub const MAX_OBJECTS: usize = 16;

/// Keys allowed at the top level of a scene file: the fields of [`SceneFileSchema`].
fn top_level_keys() -> &'static [&'static str] {
    crate::yaml::field_names::<SceneFileSchema>()
}

fn d_mass() -> f64 {
    0.05
}
fn d_friction() -> f64 {
    1.0
}
fn d_wall_height() -> f64 {
    0.06
}
fn d_gray() -> Color {
    Color::named("gray").expect("gray is in the palette")
}
fn d_orange() -> Color {
    Color::named("orange").expect("orange is in the palette")
}

/// `block:` — a movable cube on a free joint.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlockRaw {
    /// Edge length, metres (0.02 … 0.07: the 2F-85 opens 0.085 m).
    #[schemars(range(min = BLOCK_EDGE.lo, max = BLOCK_EDGE.hi))]
    size: f64,
    /// Mass, kg (0.005 … 0.5). Default 0.05.
    #[serde(default = "d_mass")]
    #[schemars(range(min = BLOCK_MASS.lo, max = BLOCK_MASS.hi))]
    mass: f64,
    /// Sliding friction coefficient (0.5 … 2: below 0.5 the 2F-85's pads cannot hold a block
    /// through a fast carry). Default 1.0.
    #[serde(default = "d_friction")]
    #[schemars(range(min = BLOCK_FRICTION.lo, max = BLOCK_FRICTION.hi))]
    friction: f64,
    /// Colour name or `[r, g, b, a]`. Default orange.
    #[serde(default = "d_orange")]
    color: Color,
}

/// `container:` — an open box (tray or bin) fixed on the table.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContainerRaw {
    /// Free space inside the walls `[x, y]`, metres (each 0.06 … 0.4).
    inner: [f64; 2],
    /// Height of the rim above the table, metres (0.02 … 0.12). Default 0.06.
    #[serde(default = "d_wall_height")]
    #[schemars(range(min = WALL_HEIGHT.lo, max = WALL_HEIGHT.hi))]
    wall_height: f64,
    /// Colour name or `[r, g, b, a]`. Default gray.
    #[serde(default = "d_gray")]
    color: Color,
}

/// `obstacle:` — a fixed box on the table.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObstacleRaw {
    /// Size `[x, y, z]`, metres (x, y: 0.01 … 0.5; z: 0.01 … 1, a post or a fixture).
    size: [f64; 3],
    /// Colour name or `[r, g, b, a]`. Default gray.
    #[serde(default = "d_gray")]
    color: Color,
}

/// `random:` — where a sweep may place the object.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RandomRaw {
    /// Range of the centre x `[lo, hi]`, metres. Required unless `in`, `on` or `region` is given.
    x: Option<[f64; 2]>,
    /// Range of the centre y `[lo, hi]`, metres. Required unless `in`, `on` or `region` is given.
    y: Option<[f64; 2]>,
    /// Range of the yaw `[lo, hi]` (radians, or `deg(..)`). Absent: no yaw is drawn.
    yaw: Option<[Angle; 2]>,
    /// Smallest gap to every other object's footprint (and to the walls of the container a
    /// block is drawn in), metres (0 … 0.5). Default 0.01.
    #[serde(default = "d_clearance")]
    #[schemars(range(min = CLEARANCE.lo, max = CLEARANCE.hi))]
    clearance: f64,
    /// A block only: draw it on the floor of this container, inside the walls (no `x`/`y`).
    #[serde(rename = "in")]
    in_: Option<String>,
    /// A block only: draw it on the top of this obstacle or block (no `x`/`y`).
    on: Option<String>,
    /// The `allowed` region(s) the footprint must lie within (one of them); `x`/`y` default to
    /// the box around them.
    region: Option<OneOrMany>,
}

/// One name or a list of names.
#[derive(Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum OneOrMany {
    /// One name.
    One(String),
    /// Several names.
    Many(Vec<String>),
}

fn d_clearance() -> f64 {
    0.01
}

/// One object of a scene file (`objects: {NAME: ...}`): exactly one of `block`, `container`,
/// `obstacle`, and a `pose`, a `random` placement, or both.
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectRaw {
    /// A movable cube.
    block: Option<BlockRaw>,
    /// A tray or bin.
    container: Option<ContainerRaw>,
    /// A fixed box.
    obstacle: Option<ObstacleRaw>,
    /// Fixed pose `[x, y]` or `[x, y, yaw]` (metres; yaw in radians or `deg(..)`), used by
    /// `macrotree run`.
    pose: Option<TablePose>,
    /// Randomization, used by sweeps.
    random: Option<RandomRaw>,
    /// A container or obstacle only: height of its base above the table, metres (0 … 0.6).
    /// Default 0 (standing on the table).
    #[schemars(range(min = BASE_HEIGHT.lo, max = BASE_HEIGHT.hi))]
    z: Option<f64>,
    /// A block only: what it rests on — a container (on its floor), an obstacle or another
    /// block (on its top). Its height follows; its `pose:` stays in world coordinates.
    on: Option<String>,
}

/// The whole scene file, for the JSON Schema (`macrotree schema --scene`).
#[derive(Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneFileSchema {
    /// One line on what the cell is.
    pub description: Option<String>,
    /// The objects by name (`[a-z][a-z0-9_]*`), in the order they are built.
    pub objects: BTreeMap<String, ObjectRaw>,
    /// Predicates that must hold when the episode ends.
    #[serde(default)]
    pub goal: Vec<GoalRaw>,
    /// How sweeps draw layouts: `objects` (default: each object from its `random:`) or
    /// `tutorial` (the reference tutorial's cube-and-bowl sampler; needs one block and one
    /// container).
    #[serde(default)]
    pub sampler: SamplerRaw,
    /// Named points on the table: `NAME: [x, y]` or `[x, y, yaw]` (metres; yaw in radians or
    /// `deg(..)`), each 0.22 … 0.72 m from the robot's base; or `{at: [x, y, yaw], on: NAME}`
    /// for a point on a named obstacle or block (a shelf's lower board).
    #[serde(default)]
    pub spots: BTreeMap<String, super::layout_keys::SpotRaw>,
    /// Named boxes on the table: `NAME: {x: [lo, hi], y: [lo, hi], role: keep_out | allowed}`.
    #[serde(default)]
    pub regions: BTreeMap<String, super::layout_keys::RegionRaw>,
}

/// `sampler:` values.
#[derive(Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum SamplerRaw {
    /// Every randomized object from its own `random:` region.
    #[default]
    Objects,
    /// The reference tutorial's sampler: the cube and the bowl drawn together from its task
    /// region (x 0.30…0.60 m, y −0.30…0.30 m, cube yaw −45°…45°, at least 0.16 m apart).
    Tutorial,
}

impl SceneSpec {
    /// Read a scene from text. `file_name` names it in diagnostics; its stem is the scene's name.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, file_name: &str) -> Result<SceneSpec, Vec<Diagnostic>> {
        Self::read_text(text, file_name, None)
    }

    /// [`from_str`](Self::from_str) for text read from the file at `disk`, if any: a file
    /// that is not a scene, or not named `.yaml`, is never quoted ([`Sources::add_file`]).
    fn read_text(text: &str, file_name: &str, disk: Option<&Path>) -> Result<SceneSpec, Vec<Diagnostic>> {
        let mut sources = Sources::new();
        let id = match disk {
            Some(path) => sources.add_file(path, text),
            None => sources.add(file_name, text),
        };
        let mut issues = Vec::new();
        let spec = match parse_yaml(text, id) {
            Ok(v) => {
                if !is_scene_document(&v) {
                    sources.withhold(id);
                }
                read_scene(&v, stem(file_name), &mut issues)
            }
            Err(issue) => {
                issues.push(issue);
                None
            }
        };
        match spec {
            Some(s) if issues.is_empty() => Ok(s),
            _ => Err(sources.diagnostics(&issues)),
        }
    }

    /// The built-in `cube_bowl` scene.
    pub fn builtin() -> SceneSpec {
        SceneSpec::from_str(BUILTIN_CUBE_BOWL, "cube_bowl.yaml").expect("the built-in scene is valid")
    }
}

/// Read a scene file from disk (a regular file of at most 1 MiB).
pub fn load_scene_file(path: &Path) -> Result<SceneSpec, Vec<Diagnostic>> {
    let name = path.display().to_string();
    let fail = |msg: String, help: String| {
        let mut sources = Sources::new();
        let id = sources.add(name.clone(), "");
        Err(sources.diagnostics(&[Issue::new(Loc::file_start(id), msg).help(help)]))
    };
    let bytes = match crate::yaml::read_limited(path) {
        Ok(b) => b,
        Err((msg, help)) => return fail(msg, help),
    };
    match std::str::from_utf8(&bytes) {
        Ok(text) => SceneSpec::read_text(text, &name, Some(path)),
        Err(_) => {
            let mut sources = Sources::new();
            let id = sources.add_file(path, String::from_utf8_lossy(&bytes).into_owned());
            let issue = decode_utf8(&bytes, id)
                .err()
                .unwrap_or_else(|| Issue::new(Loc::file_start(id), "not UTF-8"));
            Err(sources.diagnostics(&[issue]))
        }
    }
}

fn stem(file_name: &str) -> String {
    Path::new(file_name)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string()
}

/// Whether `v` is meant as a scene: a mapping with at least one of the scene file's keys.
fn is_scene_document(v: &Value) -> bool {
    v.as_map().is_some_and(|entries| {
        entries
            .iter()
            .any(|(k, _)| k.as_str().is_some_and(|k| top_level_keys().contains(&k)))
    })
}

fn read_scene(v: &Value, name: String, issues: &mut Vec<Issue>) -> Option<SceneSpec> {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                Loc::file_start(v.loc.file),
                format!(
                    "a scene file must be a mapping, found {}",
                    crate::yaml::value::kind_of(v)
                ),
            )
            .label("expected `objects:` (and optionally `description:` and `goal:`)"),
        );
        return None;
    };
    // Not a scene file at all (a `.env`, a credentials file): one issue, quoting nothing.
    if !is_scene_document(v) {
        issues.push(
            Issue::new(
                Loc::file_start(v.loc.file),
                "this is not a scene file: it has none of `objects:`, `description:`, `goal:`",
            )
            .label("expected `objects:` (and optionally `description:` and `goal:`)")
            .help("name a scene file (see docs/scenes.md); nothing of this file is shown"),
        );
        return None;
    }
    let mut description = None;
    let mut objects_v = None;
    let mut goal_v = None;
    let mut sampler_v = None;
    let mut spots_v = None;
    let mut regions_v = None;
    for (k, val) in entries {
        match k.as_str() {
            Some("description") => match val.as_str() {
                Some(s) => description = Some(s.to_string()),
                None => issues.push(
                    Issue::new(
                        val.loc,
                        format!("`description` must be text, found {}", val.describe()),
                    )
                    .label("expected one line of text"),
                ),
            },
            Some("objects") => objects_v = Some((k.loc, val)),
            Some("goal") => goal_v = Some(val),
            Some("sampler") => sampler_v = Some(val),
            Some("spots") => spots_v = Some(val),
            Some("regions") => regions_v = Some(val),
            other => {
                let other = other.unwrap_or("?");
                issues.push(
                    Issue::new(k.loc, format!("unknown top-level key `{other}` in a scene file"))
                        .label(format!("expected {}", crate::yaml::de::list(top_level_keys())))
                        .maybe_help(did_you_mean(other, top_level_keys().iter().copied())),
                )
            }
        }
    }
    let Some((objects_key, objects_v)) = objects_v else {
        issues.push(
            Issue::new(v.loc, "the scene has no `objects:`")
                .label("expected `objects: {NAME: {block: {...}, pose: [x, y]}, ...}`")
                .help("see docs/scenes.md for the object kinds"),
        );
        return None;
    };
    let objects = read_objects(objects_v, issues);
    let mut scene = SceneSpec {
        name,
        description,
        objects,
        goal: Goal::default(),
        sampler: Sampler::default(),
        spots: Vec::new(),
        regions: Vec::new(),
    };
    if let Some(v) = spots_v {
        super::layout_keys::read_spots(v, &mut scene, issues);
    }
    if let Some(v) = regions_v {
        super::layout_keys::read_regions(v, &mut scene, issues);
    }
    if issues.is_empty() {
        super::layout_keys::resolve_layout(&mut scene, objects_v, issues);
    }
    let rejected = rejected_names(&scene, objects_v, spots_v);
    let goal = match goal_v {
        Some(g) => read_goal(g, &scene, &rejected, issues),
        None => Goal::default(),
    };
    let sampler = match sampler_v {
        Some(v) => read_sampler(v, &scene, issues),
        None => Sampler::default(),
    };
    let scene = SceneSpec {
        goal,
        sampler,
        ..scene
    };
    if issues.is_empty() {
        check_fixed_poses(&scene, objects_v, issues);
    }
    if issues.is_empty()
        && scene.randomized()
        && let Err(e) = sample_placement(&scene, 0, 0)
    {
        let at = e
            .object()
            .map_or(objects_key, |n| objects_v.loc_at(&[n, "random"]));
        issues.push(Issue::new(at, format!("the randomization cannot be met: {e}")).help(e.hint()));
    }
    if issues.is_empty() || !scene.objects.is_empty() {
        super::feasible::check_has_block(&scene, objects_key, issues);
    }
    Some(scene)
}

/// The object and spot names written under `objects:` and `spots:` that `scene` lacks: their
/// declarations were refused (each with its own issue).
fn rejected_names<'a>(scene: &SceneSpec, objects_v: &'a Value, spots_v: Option<&'a Value>) -> Rejected<'a> {
    let written = |v: Option<&'a Value>| {
        v.and_then(Value::as_map)
            .into_iter()
            .flatten()
            .filter_map(|(k, _)| k.as_str())
    };
    let objects = written(Some(objects_v)).filter(|n| scene.object(n).is_none());
    let spots = written(spots_v).filter(|n| scene.spot(n).is_none());
    objects.chain(spots).collect()
}

/// `sampler: objects | tutorial`; `tutorial` needs the scene's cube and bowl (one block and one
/// container, or the ones called `cube` and `bowl`), both randomized.
fn read_sampler(v: &Value, scene: &SceneSpec, issues: &mut Vec<Issue>) -> Sampler {
    match v.as_str() {
        Some("objects") => Sampler::Objects,
        Some("tutorial") => {
            let (cube, bowl) = (scene.legacy_cube(), scene.legacy_bowl());
            if let (Some(c), Some(b)) = (cube, bowl)
                && scene.objects[c].random.is_some()
                && scene.objects[b].random.is_some()
            {
                return Sampler::Tutorial;
            }
            if !scene.objects.is_empty() {
                issues.push(
                    Issue::new(
                        v.loc,
                        "`sampler: tutorial` draws the scene's cube and bowl, but this scene has no single randomized block and container",
                    )
                    .label("expected one block and one container (or ones called `cube` and `bowl`), each with `random:`")
                    .help("use `sampler: objects` (the default), which draws every object from its own `random:`"),
                );
            }
            Sampler::Objects
        }
        other => {
            let found = other.map_or_else(|| v.describe(), |s| format!("`{s}`"));
            issues.push(
                Issue::new(v.loc, format!("unknown sampler {found}"))
                    .label("expected `objects` or `tutorial`")
                    .maybe_help(other.and_then(|o| did_you_mean(o, ["objects", "tutorial"]))),
            );
            Sampler::Objects
        }
    }
}

fn read_objects(v: &Value, issues: &mut Vec<Issue>) -> Vec<ObjectSpec> {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                v.loc,
                format!(
                    "`objects` must be a mapping of names to objects, found {}",
                    v.describe()
                ),
            )
            .label("expected `NAME: {block: {...}, pose: [x, y]}`"),
        );
        return Vec::new();
    };
    if entries.len() > MAX_OBJECTS {
        issues.push(Issue::new(
            v.loc,
            format!(
                "a scene has at most {MAX_OBJECTS} objects, this one has {}",
                entries.len()
            ),
        ));
        return Vec::new();
    }
    let mut out = Vec::new();
    for (k, body) in entries {
        let Some(name) = k.as_str().filter(|n| is_object_name(n)) else {
            issues.push(
                Issue::new(
                    k.loc,
                    format!("`{}` is not a valid object name", k.as_str().unwrap_or("?")),
                )
                .label("expected lower-case letters, digits and `_`, starting with a letter (at most 32)"),
            );
            continue;
        };
        if let Some(o) = read_object(name, body, issues) {
            out.push(o);
        }
    }
    out
}

/// Push an issue at `path` under `v` when `x` is outside `[lo, hi]`.
fn check_range(
    v: &Value,
    path: &[&str],
    x: f64,
    bounds: Bounds,
    what: &str,
    issues: &mut Vec<Issue>,
) -> bool {
    if bounds.contains(x) {
        return true;
    }
    let range = bounds.text();
    issues.push(
        Issue::new(
            v.loc_at(path),
            format!("{what} must be within {range}, found {x}"),
        )
        .label(format!("expected {range}")),
    );
    false
}

fn read_object(name: &str, body: &Value, issues: &mut Vec<Issue>) -> Option<ObjectSpec> {
    let raw: ObjectRaw = match from_value(body) {
        Ok(r) => r,
        Err(e) => {
            let mut issue = e.into_issue(body.loc, |l| format!("{l:?}"));
            issue.message = format!("{} in object `{name}`", issue.message);
            issues.push(issue.help_or("see docs/scenes.md for what an object takes"));
            return None;
        }
    };
    let before = issues.len();
    let kinds = [
        raw.block.is_some(),
        raw.container.is_some(),
        raw.obstacle.is_some(),
    ];
    if kinds.iter().filter(|&&k| k).count() != 1 {
        issues.push(
            Issue::new(
                body.loc,
                format!("object `{name}` must be exactly one of `block`, `container`, `obstacle`"),
            )
            .label("expected e.g. `block: {size: 0.044, color: red}`"),
        );
        return None;
    }
    let (shape, color) = if let Some(b) = raw.block {
        check_range(
            body,
            &["block", "size"],
            b.size,
            BLOCK_EDGE,
            "a block's edge (m)",
            issues,
        );
        check_range(
            body,
            &["block", "mass"],
            b.mass,
            BLOCK_MASS,
            "a block's mass (kg)",
            issues,
        );
        check_range(
            body,
            &["block", "friction"],
            b.friction,
            BLOCK_FRICTION,
            "a block's friction",
            issues,
        );
        (
            Shape::Block {
                half: b.size / 2.0,
                mass: b.mass,
                friction: b.friction,
            },
            b.color,
        )
    } else if let Some(c) = raw.container {
        for (i, x) in c.inner.iter().enumerate() {
            check_range(
                body,
                &["container", "inner"],
                *x,
                CONTAINER_INNER,
                &format!("inner size {}", ["x", "y"][i]),
                issues,
            );
        }
        check_range(
            body,
            &["container", "wall_height"],
            c.wall_height,
            WALL_HEIGHT,
            "a wall height (m)",
            issues,
        );
        (
            Shape::Container {
                inner_half: [c.inner[0] / 2.0, c.inner[1] / 2.0],
                wall_height: c.wall_height,
            },
            c.color,
        )
    } else {
        let o = raw.obstacle.expect("one kind is set");
        for (i, x) in o.size.iter().enumerate() {
            check_range(
                body,
                &["obstacle", "size"],
                *x,
                if i == 2 { OBSTACLE_HEIGHT } else { OBSTACLE_SIDE },
                &format!("size {}", ["x", "y", "z"][i]),
                issues,
            );
        }
        (
            Shape::Obstacle {
                half: [o.size[0] / 2.0, o.size[1] / 2.0, o.size[2] / 2.0],
            },
            o.color,
        )
    };
    let kind = shape.kind();
    let pose = raw.pose.map(|p| Pose {
        x: p.x,
        y: p.y,
        yaw: p.yaw.unwrap_or(0.0),
        z: 0.0,
    });
    let z = match raw.z {
        None => 0.0,
        Some(z) if kind == ObjectKind::Block => {
            issues.push(
                Issue::new(
                    body.loc_at(&["z"]),
                    format!("block `{name}` takes no `z: {z}`: a block's height comes from what it rests on"),
                )
                .label("expected no `z:` on a block")
                .help("write `on: NAME` (a container, an obstacle or a block) to start it on something"),
            );
            0.0
        }
        Some(z) => {
            check_range(
                body,
                &["z"],
                z,
                BASE_HEIGHT,
                "the height of a base above the table (m)",
                issues,
            );
            z
        }
    };
    if raw.on.is_some() && kind != ObjectKind::Block {
        issues.push(
            Issue::new(
                body.loc_at(&["on"]),
                format!("{kind} `{name}` cannot rest on another object: only blocks take `on:`"),
            )
            .label(format!(
                "expected `z:` (the height of the {kind}'s base above the table, metres)"
            ))
            .help("raise containers and obstacles with `z:`, e.g. a shelf board on posts"),
        );
    }
    let mut on = raw.on.clone();
    let random = raw.random.map(|r| {
        let support = match (r.in_, r.on) {
            (Some(a), Some(b)) => {
                issues.push(
                    Issue::new(
                        body.loc_at(&["random"]),
                        "`random:` takes `in:` or `on:`, not both",
                    )
                    .label("expected `in: CONTAINER` or `on: OBSTACLE_OR_BLOCK`"),
                );
                Some(a).or(Some(b))
            }
            (a, b) => a.or(b),
        };
        if let Some(s) = &support {
            if kind != ObjectKind::Block {
                issues.push(
                    Issue::new(
                        body.loc_at(&["random"]),
                        format!("{kind} `{name}` cannot be drawn in or on another object: only blocks can"),
                    )
                    .label("expected `x:` and `y:` ranges")
                    .help("raise containers and obstacles with `z:`"),
                );
            } else if r.x.is_some() || r.y.is_some() {
                issues.push(
                    Issue::new(
                        body.loc_at(&["random", if r.x.is_some() { "x" } else { "y" }]),
                        format!("`{name}` is drawn over `{s}`: its x and y come from `{s}`'s top"),
                    )
                    .label("expected no `x:`/`y:` beside `in:`/`on:`")
                    .help("remove `x:` and `y:`, or remove `in:`/`on:` to draw on the table"),
                );
            }
            match &on {
                Some(o) if o != s => issues.push(
                    Issue::new(
                        body.loc_at(&["on"]),
                        format!("`{name}` rests on `{o}` but is drawn over `{s}`"),
                    )
                    .label("a block rests on one thing")
                    .help(format!("remove `on: {o}`, or draw over `{o}`")),
                ),
                _ => on = Some(s.clone()),
            }
        }
        let regions = match r.region {
            None => Vec::new(),
            Some(OneOrMany::One(n)) => vec![n],
            Some(OneOrMany::Many(v)) => v,
        };
        // Absent ranges: over a support they are unused; with regions they become the box
        // around the regions (resolved once the regions are read: NaN until then).
        let unset = if support.is_some() { 0.0 } else { f64::NAN };
        let need = support.is_none() && regions.is_empty();
        let mut range = |key: &str, v: Option<[f64; 2]>| -> [f64; 2] {
            match v {
                Some(range) => {
                    let ok = range.iter().all(|x| x.is_finite() && x.abs() <= 1.0) && range[0] <= range[1];
                    if !ok {
                        issues.push(
                            Issue::new(
                                body.loc_at(&["random", key]),
                                format!(
                                    "`{key}` must be a range [lo, hi] with lo ≤ hi, within ±1 m of the robot"
                                ),
                            )
                            .label("expected e.g. [0.30, 0.60] (metres)"),
                        );
                    }
                    range
                }
                None => {
                    if need {
                        issues.push(
                            Issue::new(
                                body.loc_at(&["random"]),
                                format!("`random:` of `{name}` has no `{key}:` range"),
                            )
                            .label(format!(
                                "expected `{key}: [lo, hi]` (metres), or `in:`, `on:` or `region:`"
                            )),
                        );
                    }
                    [unset, unset]
                }
            }
        };
        let x = range("x", r.x);
        let y = range("y", r.y);
        if let Some([lo, hi]) = r.yaw
            && !(lo.0 <= hi.0 && hi.0 - lo.0 <= std::f64::consts::TAU)
        {
            issues.push(
                Issue::new(
                    body.loc_at(&["random", "yaw"]),
                    "`yaw` must be a range [lo, hi] with lo ≤ hi, at most one turn wide",
                )
                .label("expected e.g. [deg(-45), deg(45)]"),
            );
        }
        check_range(
            body,
            &["random", "clearance"],
            r.clearance,
            CLEARANCE,
            "a clearance (m)",
            issues,
        );
        RandomPlacement {
            x,
            y,
            yaw: r.yaw.map(|[a, b]| [a.0, b.0]),
            clearance: r.clearance,
            support,
            regions,
        }
    });
    if pose.is_none() && random.is_none() && issues.len() == before {
        issues.push(
            Issue::new(
                body.loc,
                format!("object `{name}` has neither `pose:` nor `random:`"),
            )
            .label("expected `pose: [x, y]` and/or `random: {x: [lo, hi], y: [lo, hi]}`"),
        );
    }
    (issues.len() == before).then(|| ObjectSpec {
        name: name.to_string(),
        shape,
        color,
        pose,
        random,
        z,
        on,
    })
}

fn check_fixed_poses(scene: &SceneSpec, objects_v: &Value, issues: &mut Vec<Issue>) {
    if !scene.fully_posed() {
        // Mixed scenes are checked draw by draw when sampled; check each fixed pose alone.
        for (i, o) in scene.objects.iter().enumerate() {
            if let Some(p) = o.pose
                && let Err(e) = Placement::check_one(scene, i, &p)
            {
                issues.push(Issue::new(objects_v.loc_at(&[&o.name, "pose"]), e.to_string()).help(e.hint()));
            }
        }
        return;
    }
    let placement = Placement::fixed(scene).expect("fully posed");
    if let Err(e) = placement.check(scene) {
        let at = e
            .object()
            .map_or(objects_v.loc, |n| objects_v.loc_at(&[n, "pose"]));
        issues.push(Issue::new(at, e.to_string()).help(e.hint()));
    }
}

#[cfg(test)]
mod tests {
    use super::SceneFileSchema;
    use crate::scene::limits::{
        BASE_HEIGHT, BLOCK_EDGE, BLOCK_FRICTION, BLOCK_MASS, CLEARANCE, CONTAINER_INNER, OBSTACLE_HEIGHT,
        OBSTACLE_SIDE, WALL_HEIGHT,
    };
    use crate::yaml::Bounds;

    /// Every ranged key of a scene file: its schema description states the declared range, and
    /// a `minimum`/`maximum` in the schema, where there is one, is the declared one.
    #[test]
    fn the_scene_schema_states_every_range_as_declared() {
        let schema = serde_json::to_value(schemars::schema_for!(SceneFileSchema)).expect("schema");
        let defs = &schema["$defs"];
        let cases: [(&str, &str, Bounds); 9] = [
            ("BlockRaw", "size", BLOCK_EDGE),
            ("BlockRaw", "mass", BLOCK_MASS),
            ("BlockRaw", "friction", BLOCK_FRICTION),
            ("ContainerRaw", "inner", CONTAINER_INNER),
            ("ContainerRaw", "wall_height", WALL_HEIGHT),
            ("ObstacleRaw", "size", OBSTACLE_SIDE),
            ("ObstacleRaw", "size", OBSTACLE_HEIGHT),
            ("ObjectRaw", "z", BASE_HEIGHT),
            ("RandomRaw", "clearance", CLEARANCE),
        ];
        for (def, key, bounds) in cases {
            let property = &defs[def]["properties"][key];
            let description = property["description"].as_str().unwrap_or_default();
            assert!(
                description.contains(&bounds.text()),
                "{def}.{key}: the description `{description}` does not state {}",
                bounds.text()
            );
            if let Some(min) = property["minimum"].as_f64() {
                assert_eq!(min, bounds.lo, "{def}.{key}");
            }
            if let Some(max) = property["maximum"].as_f64() {
                assert_eq!(max, bounds.hi, "{def}.{key}");
            }
        }
    }
}
