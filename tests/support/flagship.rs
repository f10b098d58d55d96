//! The built-in scene, compiled once per test binary, and the flagship tree.

#![allow(dead_code)]

use std::sync::{Arc, OnceLock};

use macrotree::plan::Plan;
use macrotree::sim::Scene;

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
