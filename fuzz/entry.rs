//! The fuzzed entry point, shared by the fuzz target (`fuzz/fuzz_targets/load_tree.rs`) and its
//! replay in `tests/tree/fuzz_regressions.rs`, so both exercise exactly the same code.

use std::path::{Path, PathBuf};

use macrotree::plan::{Loader, Plan};
use macrotree::spec::Diagnostic;

/// The name fuzz inputs are loaded under: a file (that does not exist) in
/// `tests/fixtures/trees/`, so that relative `include:`s of the seeds (`lib/pick_place.yaml`)
/// resolve and the fuzzer reaches include handling and subtree expansion.
pub fn input_name(repo_root: &Path) -> PathBuf {
    repo_root.join("tests/fixtures/trees/fuzz_input.yaml")
}

/// Load and compile `data` as a tree file, and render every diagnostic the way the CLI prints
/// it. Panics only if the loader, the compiler or the rendering panics.
pub fn load_tree(data: &[u8], repo_root: &Path) -> Result<Plan, Vec<Diagnostic>> {
    let name = input_name(repo_root);
    let result = Loader::default().compile_bytes(data, &name.to_string_lossy());
    match &result {
        Ok(plan) => {
            std::hint::black_box(plan.behavior_size());
        }
        Err(diags) => {
            for d in diags {
                std::hint::black_box(d.to_string());
            }
        }
    }
    result
}
