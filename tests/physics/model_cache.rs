//! The compiled-model cache: a model loaded from the cache runs an episode bit for bit like a
//! freshly compiled one; a changed scene or a changed Menagerie file is a different key (the
//! model is compiled again); a corrupt cache file is never used.

use crate::support::cli;

use std::path::Path;
use std::sync::Arc;

use cli::{s, scratch};
use macrotree::episode::{EpisodeConfig, EpisodeReport, NoObserver, run_episode};
use macrotree::scene::SceneSpec;
use macrotree::sim::{
    ModelOrigin, SCENE_XML, Scene, menagerie_dir, model_key, model_key_stamped, model_path,
};

fn episode(scene: &Scene) -> EpisodeReport {
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .load("trees/cube_to_bowl.yaml".as_ref())
            .expect("tree"),
    );
    run_episode(
        scene,
        plan,
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut NoObserver,
    )
}

/// The report without its wall-clock times (the episode's and its planning's), as JSON (every
/// float printed round-trip exact).
fn outcome(r: &EpisodeReport) -> String {
    let mut v = serde_json::to_value(r).unwrap();
    without_wall_times(&mut v);
    v.to_string()
}

fn without_wall_times(v: &mut serde_json::Value) {
    v.as_object_mut().unwrap().remove("wall_time_s");
    v["planning"].as_object_mut().unwrap().remove("planning_wall_s");
}

fn cached(spec: &SceneSpec, dir: &Path) -> (Scene, ModelOrigin) {
    Scene::build_with_cache(spec, &menagerie_dir(), Some(dir)).expect("scene")
}

#[test]
fn a_cached_model_runs_the_episode_bit_for_bit_like_a_compiled_one() {
    let dir = scratch("model-cache-identical");
    let spec = SceneSpec::builtin();
    let (fresh, origin) = Scene::build_with_cache(&spec, &menagerie_dir(), None).unwrap();
    assert_eq!(origin, ModelOrigin::Compiled);
    let (_, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::CompiledAndStored, "an empty cache is filled");
    let (from_cache, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::Cache, "the second load is a hit");
    let a = episode(&fresh);
    let b = episode(&from_cache);
    assert!(a.outcome.success, "{:?}", a.outcome.failure_reason);
    assert_eq!(outcome(&a), outcome(&b));
    assert_eq!(a.outcome.physics_steps, b.outcome.physics_steps);
}

#[test]
fn a_scene_built_while_another_of_its_model_lives_shares_the_model() {
    let dir = scratch("model-cache-shared");
    let spec = SceneSpec::builtin();
    let (first, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::CompiledAndStored);
    let (second, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::Shared);
    assert!(
        std::sync::Arc::ptr_eq(&first.model, &second.model),
        "one model in memory"
    );
    let other = macrotree::scene::load_scene_file("scenes/sort_three.yaml".as_ref()).expect("scene");
    let (third, origin) = cached(&other, &dir);
    assert_eq!(
        origin,
        ModelOrigin::CompiledAndStored,
        "another model is never shared"
    );
    assert!(!std::sync::Arc::ptr_eq(&first.model, &third.model));
    assert!(episode(&second).outcome.success);
    drop((first, second));
    let (_, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::Cache, "a dropped model is read again");
}

#[test]
fn another_scene_is_another_key_and_is_compiled() {
    let dir = scratch("model-cache-stale");
    let builtin = SceneSpec::builtin();
    let (_, origin) = cached(&builtin, &dir);
    assert_eq!(origin, ModelOrigin::CompiledAndStored);
    let other = macrotree::scene::load_scene_file("scenes/sort_three.yaml".as_ref()).expect("scene");
    let (scene, origin) = cached(&other, &dir);
    assert_eq!(
        origin,
        ModelOrigin::CompiledAndStored,
        "a changed scene is never served the old model"
    );
    assert_eq!(scene.objects.len(), other.objects.len());
    let models = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".mjb")
        })
        .count();
    assert_eq!(models, 2, "one file per model");
}

#[test]
fn a_corrupt_cache_file_is_ignored_and_replaced() {
    let dir = scratch("model-cache-corrupt");
    let spec = SceneSpec::builtin();
    let (_, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::CompiledAndStored);
    let key = model_key(&macrotree::sim::cell_mjcf(SCENE_XML, &spec), &menagerie_dir()).unwrap();
    let path = model_path(&dir, &key);
    let mut bytes = std::fs::read(&path).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    let (scene, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::CompiledAndStored, "a flipped bit is caught");
    assert!(episode(&scene).outcome.success);
    // While it lives, a scene of the same model would share it instead of reading the file.
    drop(scene);
    std::fs::write(&path, &bytes[..1000]).unwrap();
    let (_, origin) = cached(&spec, &dir);
    assert_eq!(
        origin,
        ModelOrigin::CompiledAndStored,
        "a truncated file is caught"
    );
    let (_, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::Cache);
}

/// The `.mjb` files of `dir`, smallest first.
fn mjb_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "mjb"))
        .collect();
    files.sort_by_key(|p| std::fs::metadata(p).unwrap().len());
    files
}

/// `model` in MuJoCo's binary format.
fn mjb(model: &mujoco_rs::prelude::MjModel) -> Vec<u8> {
    let mut bytes = vec![0u8; model.size()];
    model.save_to_buffer(&mut bytes).unwrap();
    bytes
}

#[test]
fn the_collision_model_is_cached_beside_its_model_and_read_back_the_same() {
    let dir = scratch("model-cache-collision");
    let spec = SceneSpec::builtin();
    let (uncached, _) = Scene::build_with_cache(&spec, &menagerie_dir(), None).unwrap();
    let compiled = mjb(&uncached.collision_model().unwrap());
    let (first, _) = cached(&spec, &dir);
    assert_eq!(mjb_files(&dir).len(), 1, "compiled when first needed, not before");
    assert_eq!(mjb(&first.collision_model().unwrap()), compiled);
    let files = mjb_files(&dir);
    assert_eq!(files.len(), 2, "the model and its collision model");
    drop(first);
    let (second, origin) = cached(&spec, &dir);
    assert_eq!(origin, ModelOrigin::Cache);
    assert_eq!(mjb(&second.collision_model().unwrap()), compiled);
    drop(second);
    // A flipped bit in the collision model's file: compiled again and the file replaced.
    let mut bytes = std::fs::read(&files[0]).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&files[0], &bytes).unwrap();
    let (third, _) = cached(&spec, &dir);
    assert_eq!(mjb(&third.collision_model().unwrap()), compiled);
    assert_ne!(
        std::fs::read(&files[0]).unwrap(),
        bytes,
        "the corrupt file is replaced"
    );
    assert!(episode(&third).outcome.success);
}

#[cfg(unix)]
#[test]
fn a_changed_menagerie_file_changes_the_key() {
    let dir = scratch("model-cache-menagerie");
    let real = menagerie_dir();
    let arm = dir.join("universal_robots_ur5e");
    std::fs::create_dir_all(&arm).unwrap();
    std::os::unix::fs::symlink(real.join("robotiq_2f85"), dir.join("robotiq_2f85")).unwrap();
    std::os::unix::fs::symlink(real.join("universal_robots_ur5e/assets"), arm.join("assets")).unwrap();
    std::os::unix::fs::symlink(real.join("universal_robots_ur5e/LICENSE"), arm.join("LICENSE")).unwrap();
    let xml = std::fs::read_to_string(real.join("universal_robots_ur5e/ur5e.xml")).unwrap();
    std::fs::write(arm.join("ur5e.xml"), &xml).unwrap();
    let scene = macrotree::sim::cell_mjcf(SCENE_XML, &SceneSpec::builtin());
    let original = model_key(&scene, &real).unwrap();
    assert_eq!(
        model_key(&scene, &dir).unwrap(),
        original,
        "the same bytes are the same key"
    );
    std::fs::write(
        arm.join("ur5e.xml"),
        xml.replace("</mujoco>", "<!-- edited --></mujoco>"),
    )
    .unwrap();
    assert_ne!(model_key(&scene, &dir).unwrap(), original, "an edited file");
    assert_ne!(
        model_key(&scene.replace("<mujoco", "<mujoco "), &real).unwrap(),
        original,
        "an edited scene MJCF"
    );
    // The remembered digest gives the same keys, and notices the edit.
    let stamps = dir.join("stamps");
    std::fs::write(arm.join("ur5e.xml"), &xml).unwrap();
    assert_eq!(
        model_key_stamped(&scene, &dir, &stamps).unwrap(),
        original,
        "hashed"
    );
    assert_eq!(
        model_key_stamped(&scene, &dir, &stamps).unwrap(),
        original,
        "remembered"
    );
    std::fs::write(
        arm.join("ur5e.xml"),
        xml.replace("</mujoco>", "<!-- edited --></mujoco>"),
    )
    .unwrap();
    assert_ne!(
        model_key_stamped(&scene, &dir, &stamps).unwrap(),
        original,
        "edited after"
    );
    assert_eq!(
        model_key_stamped(&scene, &dir, &stamps).unwrap(),
        model_key(&scene, &dir).unwrap()
    );
}

#[test]
fn the_command_line_uses_the_cache_and_can_turn_it_off() {
    let dir = scratch("model-cache-cli");
    let run = |cache: &str| {
        std::process::Command::new(cli::BIN)
            .args(["run", "trees/cube_to_bowl.yaml", "--json", "-v"])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env_remove("RUST_LOG")
            .env("MACROTREE_CACHE_DIR", cache)
            .output()
            .unwrap()
    };
    let first = run(s(&dir));
    assert!(first.status.success());
    let log = String::from_utf8_lossy(&first.stderr);
    assert!(log.contains("model cache: stored"), "{log}");
    assert!(log.contains("model cache: collision model stored"), "{log}");
    let second = run(s(&dir));
    assert!(second.status.success());
    let log = String::from_utf8_lossy(&second.stderr);
    assert!(log.contains("model cache: hit"), "{log}");
    assert!(log.contains("model cache: collision model hit"), "{log}");
    let off = run("off");
    assert!(off.status.success());
    assert!(!String::from_utf8_lossy(&off.stderr).contains("model cache"));
    let last = |o: &std::process::Output| {
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        let line = text.lines().last().unwrap().to_string();
        let mut v: serde_json::Value = serde_json::from_str(&line).unwrap();
        without_wall_times(&mut v);
        v
    };
    assert_eq!(last(&first), last(&second));
    assert_eq!(last(&first), last(&off));
}
