//! A scene's named spots as places a tree names: `carry: {to: SPOT}`, `reach: {target: SPOT}`,
//! `place: {spot: "{var}"}` with the variable written by `for_each … goal_as`, and the `at`
//! condition with `spot:`. Spot names are checked when the tree is loaded (located errors, with a
//! did-you-mean); the motions are checked on real MuJoCo.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use macrotree::actions::Cell;
use macrotree::episode::{EpisodeReport, Goal};
use macrotree::plan::Loader;
use macrotree::spec::Diagnostic;
use macrotree::world::World;
use nalgebra::Vector2;

use crate::support::cell_run;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Two 40 mm blocks, a bin, and three spots (one turned 25°, two turned 30° for a kit).
const SCENE: &str = "description: spots as targets
objects:
  red: {block: {size: 0.04, color: red}, pose: [0.45, -0.20, deg(10)]}
  blue: {block: {size: 0.04, color: blue}, pose: [0.35, -0.05, deg(-15)]}
  bin: {container: {inner: [0.16, 0.16], wall_height: 0.04}, pose: [0.60, 0.25]}
spots:
  buffer: [0.40, 0.15, deg(25)]
  kit_1: [0.50, -0.05, deg(30)]
  kit_2: [0.50, 0.05, deg(30)]
goal:
  - at: {object: red, spot: kit_1, yaw: deg(30)}
  - at: {object: blue, spot: kit_2, yaw: deg(30)}
";

fn dir(name: &str) -> PathBuf {
    let d = Path::new(ROOT)
        .join("target")
        .join(format!("spot_targets_{name}"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes the scene and a tree whose `main:` is `main` (YAML, indented two spaces); loads it.
fn load(name: &str, main: &str) -> Result<Arc<macrotree::plan::Plan>, Vec<Diagnostic>> {
    let tree = cell_run::write_cell_tree(&dir(name), SCENE, main);
    Loader::default().load(&tree).map(Arc::new)
}

fn errors(name: &str, main: &str) -> Vec<Diagnostic> {
    load(name, main).expect_err("the tree is invalid")
}

fn find<'a>(diags: &'a [Diagnostic], needle: &str) -> &'a Diagnostic {
    diags
        .iter()
        .find(|d| d.message.contains(needle))
        .unwrap_or_else(|| panic!("no diagnostic with {needle:?} in {diags:#?}"))
}

/// Runs `main` with the tree's own outcome as success; the report and the final cell.
fn run(name: &str, main: &str) -> (EpisodeReport, Cell) {
    let plan = load(name, main).unwrap_or_else(|d| panic!("{}", d[0]));
    cell_run::run_plan(plan, Goal::Tree, 90.0, name)
}

fn assert_success(r: &EpisodeReport, what: &str) {
    assert!(
        r.outcome.success,
        "{what}: {:?} ({:?}) at {:?}",
        r.outcome.failure_reason, r.outcome.failure_kind, r.outcome.failed_node
    );
    assert!(
        r.outcome.collisions.is_empty(),
        "{what}: collisions {:?}",
        r.outcome.collisions
    );
}

/// Yaw error of object `i` modulo a quarter turn, degrees.
fn yaw_error_deg(w: &World, i: usize, want_deg: f64) -> f64 {
    let d = w.yaw(i).to_degrees() - want_deg;
    ((d + 45.0).rem_euclid(90.0) - 45.0).abs()
}

/// Pre-shape, above `block`, straight down, close (children of a sequence, indented 6).
fn pick(block: &str) -> String {
    format!(
        "      - release: {{width: 0.065, retreat: 0}}\n      - reach: {{target: {block}, offset: [0, 0, 0.12]}}\n      - reach: {{target: {block}, path: cartesian}}\n      - grasp: {{object: {block}}}\n"
    )
}

#[test]
fn carry_to_a_spot_sets_the_block_down_there_turned_to_the_spot_yaw() {
    let main = format!(
        "  sequence:\n    children:\n{}      - carry: {{to: buffer, place_height: 0.003}}\n      - release: {{width: 0.07, retreat: 0.10}}\n      - at: {{object: red, spot: buffer, yaw: deg(25), tolerance: 0.006}}\n",
        pick("red")
    );
    let (r, cell) = run("carry", &main);
    assert_success(&r, "carry to a spot, then `at` the spot");
    let w = cell.world();
    let red = w.index_of("red").unwrap();
    let off = (w.objects[red].pos.xy() - Vector2::new(0.40, 0.15)).norm();
    assert!(off < 0.006, "{:.1} mm from the spot", off * 1e3);
    assert!(
        (w.objects[red].pos.z - 0.02).abs() < 0.003,
        "on the table: z {:.4} m",
        w.objects[red].pos.z
    );
    let e = yaw_error_deg(w, red, 25.0);
    assert!(e < 3.0, "turned to the spot's 25°: off by {e:.2}°");
}

#[test]
fn reach_to_a_spot_goes_to_its_point_on_the_table_top() {
    let main = "  reach: {target: kit_2, offset: [0, 0, 0.10]}\n";
    let (r, cell) = run("reach", main);
    assert_success(&r, "reach a spot");
    let p = cell.world().pinch_pos;
    let off = (p - nalgebra::Vector3::new(0.50, 0.05, 0.10)).norm();
    assert!(
        off < 0.003,
        "pinch {p:?} is {:.1} mm from the spot + offset",
        off * 1e3
    );
}

#[test]
fn for_each_goal_as_hands_each_block_its_goal_spot_through_a_variable() {
    let main = "  sequence:
    children:
      - for_each:
          select: {kind: block, where: [pending], order: name}
          as: block
          goal_as: where
          max_iterations: 4
          child:
            sequence:
              children:
                - release: {width: 0.065, retreat: 0}
                - reach: {target: \"{block}\", offset: [0, 0, 0.12]}
                - reach: {target: \"{block}\", path: cartesian}
                - grasp: {object: \"{block}\"}
                - place: {spot: \"{where}\", lift: 0.12}
                - at: {object: \"{block}\", spot: \"{where}\", yaw: deg(30)}
      - goal_met: {}
";
    let (r, cell) = run("for_each", main);
    assert_success(&r, "kit two blocks through `{where}`");
    let w = cell.world();
    for (block, x, y) in [("red", 0.50, -0.05), ("blue", 0.50, 0.05)] {
        let i = w.index_of(block).unwrap();
        let off = (w.objects[i].pos.xy() - Vector2::new(x, y)).norm();
        assert!(off < 0.01, "{block}: {:.1} mm from its spot", off * 1e3);
        let e = yaw_error_deg(w, i, 30.0);
        assert!(e < 5.0, "{block}: yaw off by {e:.2}°");
    }
}

#[test]
fn spot_names_are_checked_when_the_tree_is_loaded() {
    // A misspelt spot: located at the name, with a did-you-mean among the spots.
    let d = errors("unknown", "  place: {spot: bufer}\n");
    let e = find(&d, "unknown spot `bufer` in `place` (did you mean `buffer`?)");
    assert_eq!((e.line, e.column), (3, 17));
    // A reach target may be an object or a spot: the did-you-mean looks at both.
    let d = errors("unknown_target", "  reach: {target: kit_3}\n");
    find(&d, "unknown target `kit_3` in `reach` (did you mean `kit_1`?)");
    // A spot where a block is needed, and an object where a spot is needed.
    let d = errors("spot_as_block", "  grasp: {object: kit_1}\n");
    find(&d, "`kit_1` is a spot, but `grasp` needs a block here");
    let d = errors("bin_as_spot", "  place: {spot: bin}\n");
    find(&d, "`bin` is a container, but `place` needs a spot here");
    let d = errors("at_bin", "  at: {object: red, spot: bin}\n");
    find(&d, "`bin` is a container, but `at` needs a spot here");
    // Spots are fine where a place is named.
    for ok in [
        "  carry: {to: buffer}\n",
        "  reach: {target: kit_1, offset: [0, 0, 0.1]}\n",
        "  at: {object: red, spot: kit_1}\n",
    ] {
        load("ok", ok).unwrap_or_else(|d| panic!("{ok}: {}", d[0]));
    }
}

#[test]
fn a_spot_variable_must_hold_a_spot() {
    // `{block}` holds a block: it cannot be where a block is placed.
    let main = "  for_each:
    select: {kind: block}
    as: block
    max_iterations: 2
    child: {place: {spot: \"{block}\"}}
";
    let d = errors("var_block", main);
    find(&d, "`{block}` holds a block, but `place` needs a spot here");
    // `goal_as` holds the goal's destination, which for an `at` goal is its spot.
    let main = "  for_each:
    select: {kind: block}
    as: block
    goal_as: where
    max_iterations: 2
    child: {place: {spot: \"{where}\"}}
";
    load("var_goal", main).unwrap_or_else(|d| panic!("{}", d[0]));
}

#[test]
fn the_at_condition_takes_a_point_or_a_spot_not_both_nor_neither() {
    let d = errors("at_both", "  at: {object: red, point: [0.5, 0.0], spot: kit_1}\n");
    find(&d, "give `point` or `spot`, not both");
    let d = errors("at_neither", "  at: {object: red}\n");
    find(&d, "`at` needs where");
}
