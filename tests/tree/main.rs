//! Trees without physics: the YAML format, scenes, the registry of kinds, the runtime's node families on scripted leaves, substitutions, loops, tracing, fuzz regressions.
//!
//! One test binary (`cargo test --release --test tree`); one file per subject.

#[path = "../../fuzz/entry.rs"]
mod entry;
#[path = "../../fuzz/scene_entry.rs"]
mod scene_entry;
#[path = "../support/mod.rs"]
mod support;

mod common_mistakes;
mod forced_results;
mod fuzz_regressions;
mod hostile_input;
mod include_confinement;
mod loops;
mod nodes;
mod registry;
mod scene_fuzz_regressions;
mod scene_spec;
mod schema;
mod spec;
mod subplan;
mod substitutions;
mod tracing_events;
