//! What an environment is built from: the scene and tree files, and the settings, checked.

use std::path::Path;
use std::sync::Arc;

use macrotree::App;
use macrotree::env::EnvConfig;
use macrotree::plan::Plan;
use macrotree::sim::Scene;
use pyo3::prelude::*;

use crate::error::{to_py, value};

/// The pieces of a `MacroEnv` / `VecEnv`.
pub struct Parts {
    pub app: App,
    pub scene: Scene,
    pub tree: Option<Arc<Plan>>,
    pub config: EnvConfig,
}

/// Settings as Python passes them.
pub struct Settings<'a> {
    pub scene: Option<&'a str>,
    pub tree: Option<&'a str>,
    pub control_period: f64,
    pub max_sim_time: f64,
    pub fault: Option<&'a str>,
    /// `JOINT_SIGMA[,GRIPPER_SIGMA]`, as `sweep --noise` reads it.
    pub noise: Option<&'a str>,
    /// Camera images' `(width, height)`, pixels (the observation space holds images of this
    /// size, so it is checked before anything is built).
    pub image_size: (u32, u32),
}

/// Loads the scene (a file, or the tree's `scene:`) and the tree (checked against that scene).
pub fn build(s: &Settings<'_>) -> PyResult<Parts> {
    macrotree::render::check_image_size(s.image_size.0, s.image_size.1).map_err(value)?;
    let app = App::new();
    let (spec, tree) = match (s.scene, s.tree) {
        (Some(scene), Some(tree)) => {
            let plan = app
                .load_tree_for_scene(Path::new(tree), Path::new(scene))
                .map_err(to_py)?;
            (plan.scene.clone(), Some(Arc::new(plan)))
        }
        (None, Some(tree)) => {
            let plan = app.load_tree(Path::new(tree)).map_err(to_py)?;
            (plan.scene.clone(), Some(Arc::new(plan)))
        }
        (Some(scene), None) => {
            let spec = macrotree::scene::load_scene_file(Path::new(scene)).map_err(|diagnostics| {
                to_py(macrotree::Error::Scene {
                    file: scene.to_string(),
                    diagnostics,
                })
            })?;
            (Arc::new(spec), None)
        }
        (None, None) => return Err(value("an environment needs a scene file, a tree file, or both")),
    };
    let scene = Scene::load_spec(&spec).map_err(|e| {
        to_py(macrotree::Error::Simulator {
            message: e.to_string(),
        })
    })?;
    let fault = match s.fault {
        None => None,
        Some(name) => Some(name.parse().map_err(|e: String| value(e))?),
    };
    let noise = match s.noise {
        None => None,
        Some(text) => {
            Some(macrotree::faults::ActionNoise::parse(text).map_err(|e| value(format!("noise: {e}")))?)
        }
    };
    let config = EnvConfig {
        control_period: s.control_period,
        max_sim_time: s.max_sim_time,
        fault,
        noise,
        ..EnvConfig::default()
    };
    config.check().map_err(to_py)?;
    Ok(Parts {
        app,
        scene,
        tree,
        config,
    })
}
