//! `carry`'s spot choice in a container packs the blocks the scene's goal sends there, on real
//! MuJoCo: a spot that leaves room for the blocks still to come, not the roomiest one for the
//! block in hand.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use macrotree::actions::Cell;
use macrotree::episode::{EpisodeReport, Goal};
use macrotree::plan::Loader;

use crate::support::cell_run;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Runs `main` (the tree's body, YAML) on a scene file `scene` (YAML), the scene's goal judging
/// success; the report and the cell in its final state.
fn run(name: &str, scene: &str, main: &str) -> (EpisodeReport, Cell) {
    let dir: PathBuf = Path::new(ROOT)
        .join("target")
        .join(format!("container_packing_{name}"));
    let tree = cell_run::write_cell_tree(&dir, scene, main);
    let plan = Arc::new(
        Loader::default()
            .load(&tree)
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    cell_run::run_plan(plan, Goal::Scene, 60.0, name)
}

/// The steps `clear_table`'s `move_one` runs for `block` into `bin` (pre-shape, above, down,
/// close, carry, release to 56 mm), as sequence children.
fn move_one(block: &str) -> String {
    format!(
        "      - release: {{width: 0.065, retreat: 0}}\n      - reach: {{target: {block}, offset: [0, 0, 0.12]}}\n      - reach: {{target: {block}, path: cartesian}}\n      - grasp: {{object: {block}}}\n      - carry: {{to: bin, lift: 0.15, place_height: 0.02}}\n      - release: {{width: 0.056, retreat: 0.10}}\n"
    )
}

/// The bug: in a 20 cm bin with 12 cm walls (`scenes/held_out/deep_bin_near_base.yaml`,
/// scenario 1 of sweep seed 1), the first block went to the roomiest spot — the centre, held
/// diagonally — and the bin "could not take" the 50 mm block next (it held one): no spot was left where the
/// opened hand cleared the walls and the first block. Three blocks of 40–50 mm fit in a row
/// across the fingers' closing axis; the spot choice now keeps room for the blocks the goal still
/// sends into the bin.
#[test]
fn a_twenty_centimetre_bin_could_not_take_three_blocks() {
    let scene = r#"description: three blocks and a deep 20 cm bin near the base
objects:
  a:
    block: {size: 0.04, color: red}
    pose: [0.561, -0.204, deg(30.0)]
  b:
    block: {size: 0.044, color: yellow}
    pose: [0.438, 0.262, deg(-34.8)]
  c:
    block: {size: 0.05, color: blue}
    pose: [0.591, -0.093, deg(-3.8)]
  bin:
    container: {inner: [0.20, 0.20], wall_height: 0.12, color: gray}
    pose: [0.337, 0.006]
goal:
  - all_in: {container: bin}
"#;
    let steps: String = ["b", "c", "a"].iter().map(|b| move_one(b)).collect();
    let (r, cell) = run(
        "twenty_cm_bin",
        scene,
        &format!("  sequence:\n    children:\n      - home: {{}}\n{steps}"),
    );
    assert!(
        r.outcome.success,
        "three blocks into the 20 cm bin: {:?} ({:?}) at {:?}",
        r.outcome.failure_reason, r.outcome.failure_kind, r.outcome.failed_node
    );
    assert!(r.outcome.collisions.is_empty(), "{:?}", r.outcome.collisions);
    let w = cell.world();
    let bin = w.index_of("bin").unwrap();
    for b in ["a", "b", "c"] {
        let i = w.index_of(b).unwrap();
        assert!(w.inside(i, bin), "{b} in the bin: {:?}", w.objects[i].pos);
    }
}
