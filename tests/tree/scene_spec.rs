//! Scene files and what trees say about them: loading with located diagnostics, the committed
//! JSON Schema, seeded placements, and the checks of object names and blackboard variables.

use std::path::{Path, PathBuf};

use macrotree::scene::{Placement, SceneSpec, sample_placement};
use macrotree::spec::Diagnostic;

use crate::support::cli;
use crate::support::files;

use cli::macrotree;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const SCHEMA: &str = "schema/scene.schema.json";

fn scene_files() -> Vec<PathBuf> {
    files::yaml_files(&Path::new(ROOT).join("scenes"))
}

fn scene_errors(text: &str) -> Vec<Diagnostic> {
    SceneSpec::from_str(text, "cell.yaml").expect_err("the scene is invalid")
}

/// The one diagnostic whose message contains `needle`.
fn find<'a>(diags: &'a [Diagnostic], needle: &str) -> &'a Diagnostic {
    diags
        .iter()
        .find(|d| d.message.contains(needle))
        .unwrap_or_else(|| panic!("no diagnostic with {needle:?} in {diags:#?}"))
}

#[test]
fn the_committed_scene_schema_is_what_the_binary_prints() {
    let out = macrotree(&["schema", "--scene"]);
    assert_eq!(out.status.code(), Some(0));
    let printed = String::from_utf8(out.stdout).unwrap();
    let path = Path::new(ROOT).join(SCHEMA);
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        std::fs::write(&path, &printed).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        printed == committed,
        "`macrotree schema --scene` differs from {SCHEMA}: run `UPDATE_SCHEMA=1 cargo test --release --test tree scene_spec`"
    );
}

#[test]
fn every_shipped_scene_loads_and_passes_the_schema() {
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(Path::new(ROOT).join(SCHEMA)).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).expect("a valid JSON Schema");
    let scenes = scene_files();
    assert!(scenes.len() >= 4, "{scenes:?}");
    for path in scenes {
        let text = std::fs::read_to_string(&path).unwrap();
        // `../schema/…` from `scenes/`, `../../schema/…` from `scenes/held_out/`.
        let depth = path
            .strip_prefix(Path::new(ROOT).join("scenes"))
            .map_or(1, |p| p.components().count());
        let header = format!(
            "# yaml-language-server: $schema={}schema/scene.schema.json",
            "../".repeat(depth)
        );
        assert!(
            text.starts_with(&header),
            "{}: starts with {header}",
            path.display()
        );
        let scene = macrotree::scene::load_scene_file(&path)
            .unwrap_or_else(|d| panic!("{}: {}", path.display(), d[0]));
        assert!(
            !scene.goal.is_empty(),
            "{}: every shipped scene has a goal",
            path.display()
        );
        let data: serde_json::Value = serde_saphyr::from_str(&text).unwrap();
        let errors: Vec<String> = validator.iter_errors(&data).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", path.display());
        let out = macrotree(&["validate", path.to_str().unwrap()]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("ok (scene:"));
    }
}

#[test]
fn scene_mistakes_are_located_and_explained() {
    let d = scene_errors("objects:\n  red: {blok: {size: 0.04}, pose: [0.4, 0]}\n");
    let e = find(&d, "unknown parameter `blok`");
    assert_eq!((e.line, e.column), (2, 9));
    assert_eq!(e.help.as_deref(), Some("did you mean `block`?"));

    let d = scene_errors("objects:\n  red: {block: {size: 0.4}, pose: [0.4, 0]}\n");
    let e = find(&d, "a block's edge (m) must be within 0.02 … 0.07, found 0.4");
    assert_eq!((e.line, e.column), (2, 23));

    let d = scene_errors(
        "objects:\n  red: {block: {size: 0.04}, pose: [0.4, 0]}\n  bin: {container: {inner: [0.1, 0.1]}, pose: [0.4, 0.3]}\ngoal:\n  - in: {object: red, container: bni}\n",
    );
    let e = find(&d, "unknown object `bni`");
    assert_eq!((e.line, e.column), (5, 34));
    assert_eq!(e.help.as_deref(), Some("did you mean `bin`?"));

    let d = scene_errors(
        "objects:\n  red: {block: {size: 0.04}, pose: [0.4, 0]}\n  bin: {container: {inner: [0.1, 0.1]}, pose: [0.4, 0.3]}\ngoal:\n  - in: {object: bin, container: red}\n",
    );
    find(&d, "`bin` is a container, not a block");
    find(&d, "`red` is a block, not a container");

    // Two fixed objects on top of each other.
    let d = scene_errors(
        "objects:\n  red: {block: {size: 0.04}, pose: [0.4, 0]}\n  bin: {container: {inner: [0.1, 0.1]}, pose: [0.42, 0.0]}\n",
    );
    let e = find(&d, "`red` and `bin` overlap");
    assert!(e.help.as_deref().unwrap().contains("on: bin"), "{e}");

    // A block inside the robot's base, and one out of reach.
    find(
        &scene_errors("objects:\n  red: {block: {size: 0.04}, pose: [0.05, 0]}\n"),
        "robot's base",
    );
    find(
        &scene_errors("objects:\n  red: {block: {size: 0.04}, pose: [0.9, 0]}\n"),
        "picked from above",
    );

    // Randomization that cannot be met: six bins in a 10 cm square.
    let mut text = String::from("objects:\n");
    for i in 0..6 {
        text += &format!(
            "  b{i}: {{container: {{inner: [0.2, 0.2]}}, random: {{x: [0.4, 0.5], y: [0.0, 0.1]}}}}\n"
        );
    }
    let d = scene_errors(&text);
    let e = find(&d, "the randomization cannot be met");
    assert!(e.message.contains("no placement found"), "{e}");
}

/// The keys a scene file takes are the fields of its schema type: an unknown one is located,
/// lists them all and suggests the nearest.
#[test]
fn an_unknown_top_level_key_lists_the_keys_of_the_scene_file_schema() {
    let d = scene_errors("objects:\n  red: {block: {size: 0.04}, pose: [0.4, 0]}\nregoins: {}\n");
    let e = find(&d, "unknown top-level key `regoins` in a scene file");
    assert_eq!((e.line, e.column), (3, 1));
    assert_eq!(
        e.label.as_deref(),
        Some("expected one of `description`, `objects`, `goal`, `sampler`, `spots`, `regions`")
    );
    assert_eq!(e.help.as_deref(), Some("did you mean `regions`?"));
}

/// A pose or spot written in centimetres is reported once, at the number, naming the field (x,
/// y or yaw) and in metres — not as an angle — and the goals that name the refused object or
/// spot get no follow-on "unknown" error with a wrong did-you-mean.
#[test]
fn a_refused_declaration_names_its_field_and_causes_no_follow_on_errors() {
    let d = scene_errors(
        "objects:\n  a: {block: {size: 0.04}, pose: [40, -0.2]}\n  b: {block: {size: 0.04}, pose: [0.4, 0.2, 9]}\n  c: {block: {size: 0.04}, pose: [0.4, 0.0]}\nspots:\n  slot_1: [0.5, 0.1]\n  slot_2: [50, -30, deg(90)]\n  slot_3: [0.5, -30]\ngoal:\n  - at: {object: a, spot: slot_2}\n  - at: {object: b, spot: slot_3}\n  - at: {object: c, spot: slot_1}\n",
    );
    let x = find(&d, "x = 40 m is beyond the arm's full reach");
    assert_eq!((x.line, x.column), (2, 35));
    assert!(x.message.contains("object `a`"), "{x}");
    assert_eq!(
        x.help.as_deref(),
        Some("lengths are in metres: write 0.4 for 40 cm")
    );
    let yaw = find(&d, "yaw: `9` is more than a full turn");
    assert_eq!((yaw.line, yaw.column), (3, 45));
    let spot = find(&d, "x = 50 m");
    assert_eq!((spot.line, spot.column), (7, 12));
    assert!(spot.message.contains("spot `slot_2`"), "{spot}");
    let y = find(&d, "y = -30 m");
    assert_eq!((y.line, y.column), (8, 17));
    assert!(
        d.iter()
            .all(|e| !e.message.contains("unknown")
                && !e.message.contains("full turn as an angle in radians (2")),
        "{d:#?}"
    );
    assert_eq!(d.len(), 4, "{d:#?}");

    // A spot in centimetres that parses as metres is out of reach: the help gives it in metres.
    let d = scene_errors(
        "objects:\n  a: {block: {size: 0.04}, pose: [0.4, 0.1]}\nspots:\n  s: [0.5, 0.3]\n  t: [45, -30]\n",
    );
    let t = find(&d, "x = 45 m");
    assert_eq!(
        t.help.as_deref(),
        Some("lengths are in metres: write 0.45 for 45 cm")
    );
}

/// A spot may name what a block set down there rests on (`{at: [x, y, yaw], on: NAME}`): an
/// obstacle or block under the point. Anything else is refused at the `on:` value, saying what
/// to write.
#[test]
fn a_spot_on_a_support_names_an_obstacle_or_block_under_it() {
    let base = "objects:\n  board: {obstacle: {size: [0.10, 0.40, 0.02]}, pose: [0.60, 0.0], z: 0.10}\n  top: {obstacle: {size: [0.10, 0.40, 0.02]}, pose: [0.60, 0.0], z: 0.22}\n  bin: {container: {inner: [0.2, 0.2], wall_height: 0.06}, pose: [0.35, 0.3]}\n  a: {block: {size: 0.04}, pose: [0.4, -0.2]}\nspots:\n";
    let spec = SceneSpec::from_str(
        &format!("{base}  slot: {{at: [0.60, 0.05, deg(90)], on: board}}\n"),
        "cell.yaml",
    )
    .unwrap();
    let slot = spec.spot("slot").unwrap();
    assert_eq!((slot.x, slot.y, slot.on.as_deref()), (0.60, 0.05, Some("board")));
    assert!((slot.yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    for (spot, says, help) in [
        (
            "{at: [0.60, 0.05], on: bord}",
            "not an object of this scene",
            "board, top, a",
        ),
        ("{at: [0.35, 0.30], on: bin}", "a container", "needs no `on:`"),
        (
            "{at: [0.45, 0.05], on: board}",
            "is not over `board`",
            "move the spot onto",
        ),
    ] {
        let d = scene_errors(&format!("{base}  slot: {spot}\n"));
        let e = find(&d, says);
        assert_eq!(
            (e.line, e.column),
            (7, 9 + spot.find("on:").unwrap() as u32 + 4),
            "{e}"
        );
        assert!(e.help.as_deref().unwrap_or("").contains(help), "{e}");
    }
    let d = scene_errors(&format!("{base}  slot: {{at: [0.60, 0.05], under: board}}\n"));
    assert!(d.iter().any(|e| e.message.contains("under")), "{d:#?}");
}

#[test]
fn sorted_by_color_needs_one_bin_per_block_colour() {
    let d = scene_errors(
        "objects:\n  red: {block: {size: 0.04, color: red}, pose: [0.4, 0]}\n  bin: {container: {inner: [0.1, 0.1], color: blue}, pose: [0.4, 0.3]}\ngoal:\n  - sorted_by_color: {}\n",
    );
    find(&d, "exactly one container of block `red`'s colour (red), found 0");
}

#[test]
fn placements_are_seeded_and_keep_every_constraint() {
    let scene = macrotree::scene::load_scene_file(&Path::new(ROOT).join("scenes/clear_table.yaml")).unwrap();
    let (seed_a, a) = sample_placement(&scene, 5, 17).unwrap();
    let (seed_b, b) = sample_placement(&scene, 5, 17).unwrap();
    assert_eq!(
        (seed_a, &a),
        (seed_b, &b),
        "a scenario depends only on (seed, index)"
    );
    assert_ne!(sample_placement(&scene, 5, 18).unwrap().1, a);
    for k in 0..200 {
        let (_, p) = sample_placement(&scene, 1, k).unwrap();
        p.check(&scene).unwrap_or_else(|e| panic!("scenario {k}: {e}"));
        for (o, pose) in scene.objects.iter().zip(&p.poses) {
            let r = o.random.as_ref().unwrap();
            assert!((r.x[0]..=r.x[1]).contains(&pose.x) && (r.y[0]..=r.y[1]).contains(&pose.y));
        }
    }
    // A hand-made placement that overlaps is refused by name.
    let mut bad: Placement = sample_placement(&scene, 1, 0).unwrap().1;
    bad.poses[1] = bad.poses[0];
    let e = bad.check(&scene).unwrap_err().to_string();
    assert!(e.contains("`a` and `b`"), "{e}");
}

fn tree_errors(text: &str) -> Vec<Diagnostic> {
    let path = Path::new(ROOT).join("trees").join("check_test.yaml");
    macrotree::plan::Loader::default()
        .compile_str(text, path.to_str().unwrap())
        .expect_err("the tree is invalid")
}

#[test]
fn trees_name_objects_of_their_scene() {
    let d = tree_errors(
        "scene: ../scenes/sort_three.yaml\nmain:\n  sequence:\n    children:\n      - reach: {target: gren}\n      - in: {object: red, container: green}\n      - grasp: {}\n      - cube_grasped: {}\n",
    );
    let e = find(&d, "unknown target `gren` in `reach` (did you mean `green`?)");
    assert_eq!((e.line, e.column), (5, 25));
    find(&d, "`green` is a block, but `in` needs a container here");
    // The legacy `cube` condition needs a scene with exactly one block.
    let e = find(&d, "refers to the scene's only block (`cube`)");
    assert!(e.message.contains("it has 3 blocks: red, green, blue"), "{e}");
    // The built-in scene (no `scene:`) has `cube` and `bowl` and nothing else.
    let d = tree_errors("main: {reach: {target: red}}\n");
    find(&d, "unknown target `red`");
}

#[test]
fn blackboard_variables_are_checked_when_the_tree_is_loaded() {
    let d = tree_errors(
        "scene: ../scenes/sort_three.yaml\nmain:\n  sequence:\n    children:\n      - select: {as: block, kind: block}\n      - reach: {target: \"{blok}\"}\n      - in: {object: \"{block}\", container: \"{block}\"}\n",
    );
    let e = find(&d, "undefined variable `{blok}` in `reach`");
    assert_eq!((e.line, e.column), (6, 25));
    assert_eq!(e.help.as_deref(), Some("did you mean `{block}`?"));
    find(&d, "`{block}` holds a block, but `in` needs a container here");
    // One variable, two types.
    let d = tree_errors(
        "scene: ../scenes/sort_three.yaml\nmain:\n  sequence:\n    children:\n      - select: {as: x, kind: block}\n      - select: {as: x, kind: container}\n",
    );
    find(&d, "variable `x` is written as a container here");
    // Bare `{var}` in YAML flow style reads as the variable too.
    let ok = macrotree::plan::Loader::default().compile_str(
        "scene: ../scenes/sort_three.yaml\nmain:\n  sequence:\n    children:\n      - select: {as: block}\n      - reach: {target: {block}, offset: [0, 0, 0.1]}\n",
        Path::new(ROOT).join("trees/x.yaml").to_str().unwrap(),
    );
    assert!(ok.is_ok(), "{:?}", ok.err());
}

#[test]
fn a_scene_override_rechecks_the_tree() {
    // sort_by_color names no object directly (it selects them), so it runs on any scene with a
    // goal; the cube-to-bowl tree does not fit a scene with three blocks.
    let out = macrotree(&[
        "validate",
        "trees/cube_to_bowl.yaml",
        "--scene",
        "scenes/sort_three.yaml",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("scene `sort_three` is ambiguous"), "{err}");
    let out = macrotree(&[
        "validate",
        "trees/sort_by_color.yaml",
        "--scene",
        "scenes/clear_table.yaml",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Issue 18: the reference tutorial's sampler is a setting of the scene file (`sampler:
/// tutorial`), not a comparison with the built-in scene; it needs the scene's one randomized cube
/// and bowl, and a wrong value is located.
#[test]
fn the_tutorial_sampler_is_a_scene_setting_that_needs_a_cube_and_a_bowl() {
    let builtin = SceneSpec::builtin();
    assert_eq!(builtin.sampler, macrotree::scene::Sampler::Tutorial);
    let shipped = std::fs::read_to_string(Path::new(ROOT).join("scenes/cube_bowl.yaml")).unwrap();
    assert!(shipped.contains("\nsampler: tutorial\n"));
    // Without the line, the same cell samples its objects one by one.
    let plain =
        SceneSpec::from_str(&shipped.replace("\nsampler: tutorial\n", "\n"), "cube_bowl.yaml").unwrap();
    assert_eq!(plain.sampler, macrotree::scene::Sampler::Objects);
    // A copy under another name keeps the setting.
    let copy = SceneSpec::from_str(&shipped, "my_cell.yaml").unwrap();
    assert_eq!(copy.sampler, macrotree::scene::Sampler::Tutorial);
    let d = scene_errors(
        "sampler: tutorial\nobjects:\n  a: {block: {size: 0.04}, random: {x: [0.3, 0.6], y: [-0.3, -0.1]}}\n  b: {block: {size: 0.04}, random: {x: [0.3, 0.6], y: [0.1, 0.3]}}\n",
    );
    let text = d[0].to_string();
    assert!(
        text.contains("sampler: tutorial") && text.contains("cell.yaml:1:10"),
        "{text}"
    );
    let d = scene_errors("sampler: tutorail\nobjects:\n  a: {block: {size: 0.04}, pose: [0.45, 0.1]}\n");
    let text = d[0].to_string();
    assert!(
        text.contains("unknown sampler `tutorail`") && text.contains("did you mean `tutorial`?"),
        "{text}"
    );
}

#[test]
fn a_placement_yaw_that_is_not_a_finite_angle_within_a_turn_is_refused_as_a_yaw() {
    let scene = macrotree::spec::builtin_scene();
    let fixed = Placement::fixed(&scene).expect("the built-in scene has fixed poses");
    assert_eq!(fixed.check(&scene), Ok(()));
    for yaw in [f64::NAN, f64::INFINITY, 1e300, -7.0] {
        let mut p = fixed.clone();
        p.poses[0].yaw = yaw;
        let e = p.check(&scene).expect_err("a bad yaw");
        assert_eq!(
            e.constraint(),
            format!("bad_yaw {}", scene.objects[0].name),
            "{e}"
        );
        let text = e.to_string();
        assert!(text.contains("yaw") && !text.contains("x and y"), "{text}");
        // A hostile number is printed shortly, not as 301 digits.
        assert!(text.len() < 160, "{text}");
    }
}

#[test]
fn the_at_condition_defaults_to_the_scene_goals_at_tolerances() {
    let plan = macrotree::plan::Loader::default()
        .compile_str(
            "main: {sequence: {children: [{at: {object: cube, point: [0.4, 0.1], yaw: 0}}, {cube_at: {point: [0.4, 0.1], yaw: 0}}]}}\n",
            "t.yaml",
        )
        .expect("compiles");
    let at = plan.leaves[0]
        .kind
        .params::<macrotree::kinds::At>()
        .expect("an at");
    let cube_at = plan.leaves[1]
        .kind
        .params::<macrotree::kinds::CubeAt>()
        .expect("a cube_at");
    let scene = SceneSpec::from_str(
        "objects:\n  cube: {block: {size: 0.04}, pose: [0.45, 0.0]}\ngoal:\n  - at: {object: cube, point: [0.4, 0.1], yaw: 0}\n",
        "cell.yaml",
    )
    .unwrap();
    let goal = scene.goal.atoms[0].place().unwrap();
    // One check, one default: the condition and the goal agree on what `at` means.
    assert_eq!(
        (at.tolerance, at.yaw_tolerance),
        (goal.tolerance, goal.yaw_tolerance)
    );
    assert_eq!(
        (cube_at.tolerance, cube_at.yaw_tolerance),
        (goal.tolerance, goal.yaw_tolerance)
    );
    assert_eq!(goal.yaw_tolerance, macrotree::scene::AT_YAW_TOLERANCE);
}
