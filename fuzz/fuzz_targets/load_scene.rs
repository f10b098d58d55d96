//! Arbitrary bytes through the scene loader (`macrotree::scene::SceneSpec::from_str`) and what a
//! run or a sweep does with a loaded scene before MuJoCo (placement checks, a sweep draw, the
//! objects' MJCF): every input must give `Ok` or located diagnostics, never a panic, a hang
//! (`-timeout`) or a memory blow-up (`-rss_limit_mb`). See docs/fuzzing.md.

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../scene_entry.rs"]
mod scene_entry;

fuzz_target!(|data: &[u8]| {
    let _ = scene_entry::load_scene(data);
});
