//! The `macrotree` binary end to end: exit codes, reports, limits, outputs, sweeps, scenario suites, datasets, camera images, files and signals.
//!
//! One test binary (`cargo test --release --test cli`); one file per subject.

#[path = "../support/mod.rs"]
mod support;

mod authoring;
mod bench;
mod closed_pipe;
mod collision_policy;
mod custom_leaf_example;
mod dataset;
mod files_signals_and_bounds;
mod limits;
mod outputs;
mod pixels;
mod plan;
mod reports_and_expectations;
mod run;
mod run_messages;
mod scenario_suites;
mod sweep;
mod sweep_resume;
