//! The fuzzed entry point of the scene loader, shared by the fuzz target
//! (`fuzz/fuzz_targets/load_scene.rs`) and its replay in `tests/tree/scene_fuzz_regressions.rs`, so
//! both exercise exactly the same code.

use macrotree::scene::{Placement, SceneSpec, sample_placement};
use macrotree::spec::Diagnostic;

/// The name fuzz inputs are loaded under (its stem becomes the scene's name).
pub const INPUT_NAME: &str = "fuzz_input.yaml";

/// Read `data` as a scene file the way `load_scene_file` does after reading the file (UTF-8,
/// YAML under its limits, objects, ranges, goal, fixed poses, the first sweep draw), render
/// every diagnostic the way the CLI prints it, and for a scene that loads, go on to what a run
/// and a sweep do with it before MuJoCo: check its fixed placement, draw a second sweep
/// scenario, and write the objects' MJCF. Panics only if one of those panics.
pub fn load_scene(data: &[u8]) -> Result<SceneSpec, Vec<Diagnostic>> {
    let result = match std::str::from_utf8(data) {
        Ok(text) => SceneSpec::from_str(text, INPUT_NAME),
        // Not UTF-8: the tree target covers the decoder's located error; nothing else is reached.
        Err(_) => return Err(Vec::new()),
    };
    match &result {
        Ok(scene) => {
            if let Some(p) = Placement::fixed(scene) {
                std::hint::black_box(p.check(scene).map_err(|e| e.to_string()).err());
            }
            if scene.randomized() {
                let drawn = sample_placement(scene, 0x5eed, 3);
                std::hint::black_box(drawn.map_err(|e| e.to_string()).err());
            }
            std::hint::black_box(macrotree::sim::objects_mjcf(scene));
            for atom in &scene.goal.atoms {
                std::hint::black_box(atom.to_string());
            }
        }
        Err(diags) => {
            for d in diags {
                std::hint::black_box(d.to_string());
            }
        }
    }
    result
}
