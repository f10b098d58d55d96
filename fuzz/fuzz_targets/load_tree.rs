//! Arbitrary bytes through the tree loader and compiler (`macrotree::plan::compile_bytes`): every
//! input must give `Ok` or located diagnostics, never a panic, a hang (`-timeout`) or a memory
//! blow-up (`-rss_limit_mb`). See docs/fuzzing.md.

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../entry.rs"]
mod entry;

fuzz_target!(|data: &[u8]| {
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let _ = entry::load_tree(data, root);
});
