//! The built-in scene, compiled once per test binary, and the flagship tree.

#![allow(dead_code)]

use std::sync::{Arc, OnceLock};

use macrotree::plan::Plan;
use macrotree::sim::Scene;
use macrotree::sweep::{SweepConfig, SweepRun, run_sweep};

/// The built-in cell (UR5e, 2F-85, cube and bowl), compiled on first use.
pub fn scene() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(|| Scene::load().expect("scene (run tools/bootstrap)"))
}

/// `trees/cube_to_bowl.yaml`, compiled.
pub fn plan() -> Arc<Plan> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/trees/cube_to_bowl.yaml");
    Arc::new(
        macrotree::plan::Loader::default()
            .load(std::path::Path::new(path))
            .expect("flagship tree is valid"),
    )
}

/// The flagship tree swept on the built-in scene with the built-in leaves, results discarded as
/// they come (they are all in the returned run).
pub fn sweep_flagship(config: &SweepConfig) -> SweepRun {
    run_sweep(
        scene(),
        &plan(),
        &macrotree::factory::Factory::builtin(),
        config,
        |_| {},
    )
    .expect("thread pool")
}
