//! Running a tree written in a test on a scene written in the test, on real MuJoCo: the files
//! written under `target/`, the plan loaded by the one loader, the episode run in a cell the test
//! can inspect afterwards. Include `support/oracle.rs` as `oracle` beside it.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeReport, Goal, NoObserver, run_in_cell};
use macrotree::plan::Plan;
use macrotree::sim::{Layout, Scene};

/// Writes `scene` (a scene file's YAML) as `cell.yaml` in `dir` and a tree `tree.yaml` on it
/// whose `main:` is `main` (YAML, indented two spaces); the tree's path.
pub fn write_cell_tree(dir: &Path, scene: &str, main: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("cell.yaml"), scene).unwrap();
    let tree = dir.join("tree.yaml");
    std::fs::write(&tree, format!("scene: cell.yaml\nmain:\n{main}")).unwrap();
    tree
}

/// Runs `plan` on its scene's default layout with the built-in nodes, `goal` judging success
/// and at most `max_sim_time` simulated seconds; checks MuJoCo raised no warning (`name` in the
/// message). The report and the cell in its final state.
pub fn run_plan(plan: Arc<Plan>, goal: Goal, max_sim_time: f64, name: &str) -> (EpisodeReport, Cell) {
    let scene = Scene::load_spec(&plan.scene).expect("scene compiles");
    let mut cell = Cell::new(&scene, &Layout::default(), CONTROL_PERIOD);
    let config = EpisodeConfig {
        goal,
        max_sim_time,
        ..EpisodeConfig::default()
    };
    let r = run_in_cell(
        &mut cell,
        plan,
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut NoObserver,
    );
    super::oracle::assert_no_warning(cell.sim(), name);
    (r, cell)
}
