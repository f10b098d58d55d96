//! Placement goals: `at` (a block at a point, at a yaw) and `stack` with `base_at`, read from
//! scene files with located errors, and judged on real MuJoCo — an `at` goal holds after a real
//! place and not while the block is still in the gripper.

use crate::support::cli;

use cli::{macrotree, s, scratch};
use macrotree::scene::{GoalAtom, SceneSpec};
use macrotree::spec::Diagnostic;

const OBJECTS: &str = "objects:\n  red: {block: {size: 0.04}, pose: [0.40, -0.20]}\n  blue: {block: {size: 0.04}, pose: [0.40, 0.20]}\n  green: {block: {size: 0.04}, pose: [0.50, 0.0]}\n  bin: {container: {inner: [0.15, 0.15]}, pose: [0.60, -0.25]}\n";

fn scene(goal: &str) -> Result<SceneSpec, Vec<Diagnostic>> {
    SceneSpec::from_str(&format!("{OBJECTS}goal:\n{goal}"), "cell.yaml")
}

fn errors(goal: &str) -> Vec<Diagnostic> {
    scene(goal).expect_err("the goal is invalid")
}

fn find<'a>(diags: &'a [Diagnostic], needle: &str) -> &'a Diagnostic {
    diags
        .iter()
        .find(|d| d.message.contains(needle))
        .unwrap_or_else(|| panic!("no diagnostic with {needle:?} in {diags:#?}"))
}

#[test]
fn at_goals_read_a_point_a_yaw_and_tolerances() {
    let s = scene(
        "  - at: {object: red, point: [0.35, 0.05], yaw: deg(90), tolerance: 0.005, yaw_tolerance: deg(2)}\n  - at: {object: blue, point: [0.35, -0.05]}\n",
    )
    .unwrap();
    let GoalAtom::At { object, place } = &s.goal.atoms[0] else {
        panic!("{:?}", s.goal.atoms[0]);
    };
    assert_eq!(object, "red");
    assert_eq!(place.point, [0.35, 0.05]);
    assert!((place.yaw.unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(place.tolerance, 0.005);
    assert!((place.yaw_tolerance - 2f64.to_radians()).abs() < 1e-12);
    let blue = s.goal.atoms[1].place().unwrap();
    assert_eq!(
        (blue.yaw, blue.tolerance),
        (None, 0.01),
        "defaults: any yaw, 1 cm"
    );
    assert!(
        (blue.yaw_tolerance - 5f64.to_radians()).abs() < 1e-12,
        "default 5°"
    );
    assert_eq!(s.goal.atoms[1].to_string(), "blue at (0.350, -0.050)");
    assert_eq!(
        s.goal.atoms[1].destination(),
        None,
        "a bare point has no name for goal_as"
    );
}

#[test]
fn a_stack_can_say_where_its_bottom_block_rests_and_the_list_form_still_reads() {
    let s =
        scene("  - stack: {blocks: [red, blue, green], base_at: {point: [0.45, 0.10], yaw: 0}}\n").unwrap();
    let atoms: Vec<String> = s.goal.atoms.iter().map(ToString::to_string).collect();
    assert_eq!(
        atoms,
        ["red on blue", "blue on green", "green at (0.450, 0.100) yaw 0.0°"]
    );
    let s = scene("  - stack: [red, blue]\n").unwrap();
    assert_eq!(s.goal.atoms.len(), 2 - 1);
    let s = scene("  - stack: {blocks: [red, blue]}\n").unwrap();
    assert_eq!(s.goal.atoms[0].to_string(), "red on blue");
}

/// An `at` goal is judged on whatever the block rests on: the table, a container's floor, an
/// obstacle's top. One where the block can rest on nothing — inside a thin wall's footprint, or
/// on a shelf board too close under the next — is refused at load, located at the goal, whether
/// it names a point or a spot (the shelf's upper board here a 3 cm rail, too narrow to hold the
/// block either); a place under a high board, on a pedestal or on a shelf board with room above
/// it is not.
#[test]
fn an_at_goal_where_the_block_can_rest_on_nothing_is_refused_where_it_is_written() {
    let cell = |goal: &str| {
        SceneSpec::from_str(
            &format!(
                "objects:
  red: {{block: {{size: 0.04}}, pose: [0.40, 0.20]}}
  wall: {{obstacle: {{size: [0.02, 0.30, 0.20]}}, pose: [0.55, 0.0]}}
  board: {{obstacle: {{size: [0.10, 0.10, 0.02]}}, pose: [0.45, -0.30], z: 0.10}}
  pedestal: {{obstacle: {{size: [0.10, 0.10, 0.10]}}, pose: [0.30, -0.15]}}
  tight_low: {{obstacle: {{size: [0.12, 0.12, 0.02]}}, pose: [0.30, 0.40]}}
  tight_top: {{obstacle: {{size: [0.03, 0.12, 0.02]}}, pose: [0.30, 0.40], z: 0.05}}
spots:
  by_wall: [0.55, 0.05]
  under_board: [0.45, -0.30]
  on_pedestal: [0.30, -0.15]
  tight: [0.30, 0.40]
goal:
{goal}"
            ),
            "cell.yaml",
        )
    };
    for (goal, needle) in [
        (
            "  - at: {object: red, point: [0.55, -0.05]}\n",
            "`wall`'s top holds 0.010 m",
        ),
        (
            "  - at: {object: red, spot: by_wall}\n",
            "`wall`'s top holds 0.010 m",
        ),
        (
            "  - at: {object: red, spot: tight}\n",
            "room under the next board",
        ),
    ] {
        let d = cell(goal).expect_err(goal);
        let e = find(&d, "can never be `at`");
        assert_eq!((e.line, e.column), (14, 5), "{e}");
        assert!(e.message.contains(needle), "{e}");
        assert_eq!(d.len(), 1, "{d:#?}");
    }
    // Under a board 0.10 m up a 0.04 m block fits on the table; a pedestal's top holds it.
    cell("  - at: {object: red, spot: under_board}\n").expect("a block fits under the board");
    cell("  - at: {object: red, spot: on_pedestal}\n").expect("a pedestal's top holds the block");
}

/// A block resting on an obstacle's top (a pedestal, a shelf board) is graded by its `at` goal
/// and by an `on` goal naming the obstacle, on real MuJoCo: the goal holds there, and not at a
/// point beside it.
#[test]
fn at_and_on_goals_hold_for_a_block_resting_on_a_pedestal() {
    let dir = scratch("at-on-pedestal");
    let scene = dir.join("pedestal.yaml");
    let write_goal = |point: &str, goal: &str| {
        std::fs::write(
            &scene,
            format!(
                "objects:
  red: {{block: {{size: 0.04}}, pose: [0.45, -0.10], on: pedestal}}
  pedestal: {{obstacle: {{size: [0.10, 0.10, 0.08]}}, pose: [0.45, -0.10]}}
spots:
  top: {point}
goal:
  - {goal}
"
            ),
        )
        .unwrap();
    };
    let write = |point: &str| write_goal(point, "at: {object: red, spot: top}");
    let tree = dir.join("wait.yaml");
    std::fs::write(&tree, "main: {wait: {seconds: 0.5}}\n").unwrap();
    write("[0.45, -0.10]");
    let r = json(&macrotree(&["run", s(&tree), "--scene", s(&scene), "--json"]));
    let z = r["objects"][0]["final"][2].as_f64().unwrap();
    assert!(
        (z - 0.10).abs() < 0.005,
        "the block rests on the 8 cm pedestal: {r}"
    );
    assert_eq!(r["goal"][0]["holds"], true, "{r}");
    assert_eq!(r["success"], true, "{r}");
    // 3 cm beside it, still on the pedestal's top: the tolerance (1 cm) decides, not the support.
    write("[0.45, -0.07]");
    let r = json(&macrotree(&["run", s(&tree), "--scene", s(&scene), "--json"]));
    assert_eq!(r["goal"][0]["holds"], false, "{r}");
    // `on` takes an obstacle as the support, and holds for the block on its top.
    write_goal("[0.45, -0.10]", "on: {object: red, support: pedestal}");
    let r = json(&macrotree(&["run", s(&tree), "--scene", s(&scene), "--json"]));
    assert_eq!(r["goal"][0]["predicate"], "red on pedestal", "{r}");
    assert_eq!(r["goal"][0]["holds"], true, "{r}");
}

#[test]
fn placement_goal_mistakes_are_located_and_explained() {
    let d = errors("  - at: {object: rde, point: [0.4, 0.1]}\n");
    let e = find(&d, "unknown object `rde`");
    assert_eq!((e.line, e.column), (7, 18));
    assert_eq!(e.help.as_deref(), Some("did you mean `red`?"));

    let d = errors("  - at: {object: red, pointt: [0.4, 0.1]}\n");
    let e = find(&d, "`pointt`");
    assert_eq!(e.help.as_deref(), Some("did you mean `point`?"));

    let d = errors("  - at: {object: red}\n");
    let e = find(&d, "give `point: [x, y]` or `spot: NAME`");
    assert_eq!(e.line, 7);

    let d = errors("  - at: {object: red, point: [0.4, 0.1], spot: slot_a}\n");
    find(&d, "give `point` or `spot`, not both");

    let d = errors("  - at: {object: red, spot: slot_a}\n");
    let e = find(&d, "unknown spot `slot_a`");
    assert_eq!((e.line, e.column), (7, 29));
    let help = e.help.as_deref().unwrap();
    assert!(help.contains("declares no spots"), "{e}");
    // The form the help suggests is one the loader takes.
    let form = help.split('`').nth(1).unwrap();
    assert_eq!(form, "spots: {NAME: [x, y]}", "{help}");
    let fixed = format!(
        "{OBJECTS}{}\ngoal:\n  - at: {{object: red, spot: slot_a}}\n",
        form.replace("NAME", "slot_a").replace("[x, y]", "[0.4, 0.1]")
    );
    SceneSpec::from_str(&fixed, "cell.yaml").expect("the suggested spots form loads");

    let d = errors("  - at: {object: red, point: [0.9, 0.1]}\n");
    let e = find(&d, "outside the reach");
    assert_eq!((e.line, e.column), (7, 30));

    let d = errors("  - at: {object: red, point: [0.4, 0.1], tolerance: 0}\n");
    find(&d, "`tolerance` must be > 0");
    let d = errors("  - at: {object: red, point: [0.4, 0.1], yaw: 0, yaw_tolerance: deg(60)}\n");
    let e = find(&d, "`yaw_tolerance` must be > 0 and at most 45°");
    assert_eq!(e.line, 7);

    let d = errors("  - at: {object: bin, point: [0.4, 0.1]}\n");
    find(&d, "`bin` is a container, not a block");
    // `on` rests a block on a block or an obstacle's top, never on a container (that is `in`).
    let d = errors("  - on: {object: red, support: bin}\n");
    find(&d, "`bin` is a container, not a block or obstacle");

    // Two blocks that can never both be at their points.
    let d =
        errors("  - at: {object: red, point: [0.40, 0.10]}\n  - at: {object: blue, point: [0.41, 0.11]}\n");
    let e = find(&d, "cannot both be there");
    assert_eq!(e.line, 8);

    // One goal per block: a stack's base and an `at` of the same block.
    let d = errors(
        "  - stack: {blocks: [red, blue], base_at: {point: [0.4, 0.1]}}\n  - at: {object: blue, point: [0.3, 0.0]}\n",
    );
    find(&d, "block `blue` has two goals");

    let d = errors("  - stack: {blocks: [red], base_at: {point: [0.4, 0.1]}}\n");
    find(&d, "at least two blocks");
    let d = errors("  - stack: {blocks: [red, blu]}\n");
    let e = find(&d, "unknown object `blu`");
    assert_eq!((e.line, e.column), (7, 27));
}

/// The built-in cell with an `at` goal: the cube square at (0.32, −0.30), where
/// `trees/place_on_table.yaml` sets it down.
fn spot_scene(dir: &std::path::Path) -> std::path::PathBuf {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cube_bowl.yaml")).unwrap();
    let text = text.replace(
        "goal:\n  - in: {object: cube, container: bowl}\n",
        "goal:\n  - at: {object: cube, point: [0.32, -0.30], yaw: 0, yaw_tolerance: deg(3)}\n",
    );
    assert!(text.contains("at: {object: cube"));
    let p = dir.join("cube_spot.yaml");
    std::fs::write(&p, text).unwrap();
    p
}

fn json(out: &std::process::Output) -> serde_json::Value {
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.trim()).unwrap_or_else(|e| {
        panic!(
            "{e}: stdout {text}\nstderr {}",
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

#[test]
fn an_at_goal_holds_after_a_real_place() {
    let dir = scratch("at-placed");
    let scene = spot_scene(&dir);
    let out = macrotree(&["run", "trees/place_on_table.yaml", "--scene", s(&scene), "--json"]);
    let r = json(&out);
    assert_eq!(r["success"], true, "{r}");
    assert_eq!(r["goal"][0]["predicate"], "cube at (0.320, -0.300) yaw 0.0°");
    assert_eq!(r["goal"][0]["holds"], true);
    assert!(
        r["goal_checked"]
            .as_str()
            .unwrap()
            .contains("scene's goal (1 predicate)"),
        "{r}"
    );
}

#[test]
fn a_block_square_to_a_quarter_turned_goal_holds_and_the_report_names_the_yaw_it_matched() {
    let dir = scratch("at-quarter-turn");
    let scene = spot_scene(&dir);
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "yaw: 0, yaw_tolerance: deg(3)",
        "yaw: deg(90), yaw_tolerance: deg(3)",
    );
    std::fs::write(&scene, text).unwrap();
    let out = macrotree(&["run", "trees/place_on_table.yaml", "--scene", s(&scene), "--json"]);
    let r = json(&out);
    assert_eq!(r["goal"][0]["predicate"], "cube at (0.320, -0.300) yaw 90.0°");
    assert_eq!(
        r["goal"][0]["holds"], true,
        "a cube's faces repeat every quarter turn: {r}"
    );
    // The block was set down square (about 0°); the report says which yaw matched 90°.
    let matched = r["goal"][0]["matched_yaw_deg"].as_f64().unwrap();
    assert!((matched - 90.0).abs() <= 3.0, "{r}");
    let final_yaw = r["objects"][0]["final"][3].as_f64().unwrap();
    assert!(final_yaw.abs() <= 3.0, "set down square: {final_yaw}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("at the quarter turn nearest the goal's: {matched:.1}°")),
        "{stderr}"
    );
    // Goals without a yaw carry no matched yaw.
    let plain = macrotree(&["run", "trees/cube_to_bowl.yaml", "--json"]);
    assert!(json(&plain)["goal"][0].get("matched_yaw_deg").is_none());
}

/// Regression: `at`, `cube_at` and `on_table` held while the block was still between the pads
/// (pressed onto the table at the spot), so a retry's "already there?" passed and the `home`
/// after it carried the block off the table. A block in the gripper is not placed.
#[test]
fn an_at_goal_does_not_hold_while_the_block_is_still_in_the_gripper() {
    let dir = scratch("at-held");
    let scene = spot_scene(&dir);
    let tree = dir.join("still_holding.yaml");
    std::fs::write(
        &tree,
        "\
main:
  sequence:
    name: set down, still holding
    children:
      - home: {}
      - release: {name: pre-shape, width: 0.065, retreat: 0}
      - reach: {name: above cube, target: cube, offset: [0, 0, 0.12]}
      - reach: {name: descend, target: cube, offset: [0, 0, 0.0], path: cartesian}
      - grasp: {}
      - carry: {name: over the spot, to: [0.32, -0.30, 0.0], lift: 0.10, place_height: 0.03}
      - reach: {name: set down square, target: [0.32, -0.30, 0.025], yaw: 0, path: cartesian, speed: 0.1}
      - wait: {seconds: 0.5}
      - cube_grasped: {name: still held?}
      - inverter: {child: {cube_at: {name: there?, point: [0.32, -0.30], tolerance: 0.01}}}
      - inverter: {child: {at: {name: at there?, object: cube, point: [0.32, -0.30], tolerance: 0.01}}}
      - inverter: {child: {cube_on_table: {name: on the table?}}}
",
    )
    .unwrap();
    let out = macrotree(&["run", s(&tree), "--scene", s(&scene), "--json"]);
    let r = json(&out);
    // The tree succeeded: the block is held, and none of the placement conditions holds.
    assert_eq!(r["tree_status"], "success", "{r}");
    // The block sits on the table at the spot, square — but in the gripper: the goal fails.
    let end = &r["objects"][0]["final"];
    let (x, y, z) = (
        end[0].as_f64().unwrap(),
        end[1].as_f64().unwrap(),
        end[2].as_f64().unwrap(),
    );
    assert!(
        (x - 0.32).hypot(y + 0.30) < 0.01 && z < 0.03,
        "the block is at the spot: {end}"
    );
    assert_eq!(r["success"], false);
    assert_eq!(r["failure_kind"], "goal_not_met", "{r}");
    assert_eq!(r["goal"][0]["holds"], false);
}

#[test]
fn goal_scene_on_a_scene_without_a_goal_warns_and_says_what_was_checked() {
    let dir = scratch("no-goal");
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cube_bowl.yaml")).unwrap();
    let text = text.replace("goal:\n  - in: {object: cube, container: bowl}\n", "");
    let scene = dir.join("no_goal.yaml");
    std::fs::write(&scene, text).unwrap();
    let tree = dir.join("home.yaml");
    std::fs::write(&tree, "main: {home: {}}\n").unwrap();
    let out = macrotree(&["run", s(&tree), "--scene", s(&scene), "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: --goal scene, but scene `no_goal` declares no goal"),
        "{err}"
    );
    let r = json(&out);
    assert_eq!(r["success"], true);
    assert_eq!(
        r["goal_checked"],
        "the tree's result only (the scene declares no goal)"
    );
    let out = macrotree(&[
        "sweep",
        s(&tree),
        "--scene",
        s(&scene),
        "--scenarios",
        "1",
        "--jobs",
        "1",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("success judged by the tree's result only (the scene declares no goal)"),
        "{text}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("declares no goal"));
    // `--goal tree` says so itself: no warning.
    let out = macrotree(&["run", s(&tree), "--scene", s(&scene), "--goal", "tree"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("declares no goal"));
}
