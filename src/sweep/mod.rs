//! Sweeps: a tree run over many seeded, randomized layouts (optionally with a fault), in
//! parallel, with results in scenario order — the library behind `macrotree sweep`.
//!
//! Scenario `k` of sweep seed `S` ([`SweepConfig::scenario`]) depends only on `(S, k)`, so a sweep gives
//! the same results for any number of jobs, and the shards `K/M` of a sweep (the scenarios with
//! `k ≡ K mod M`) concatenate into the full sweep. One [`Cell`](crate::actions::Cell) (one `MjData` of the shared model)
//! per worker thread is reset before every scenario.
//!
//! ```no_run
//! use std::sync::Arc;
//! use macrotree::sweep::{SweepConfig, run_sweep};
//!
//! let scene = macrotree::sim::Scene::load().unwrap();
//! let app = macrotree::App::new();
//! let plan = Arc::new(app.load_tree("trees/cube_to_bowl.yaml".as_ref()).unwrap());
//! let config = SweepConfig { scenarios: 100, seed: 1, ..SweepConfig::default() };
//! let run = run_sweep(&scene, &plan, app.factory(), &config, |r| println!("{}", r.to_jsonl())).unwrap();
//! println!("{} of {} succeeded", run.results.iter().filter(|r| r.outcome.success).count(), run.results.len());
//! ```

mod config;
pub mod digest;
mod indices;
mod report;
mod result;
pub mod resume;
mod run;
mod shard;
mod summary;
pub mod tally;
mod timing;

use crate::episode::scenario as layout;
pub use config::{MAX_JOBS, SweepConfig};
pub use indices::ScenarioIndices;
pub use layout::{Region, Scenario, ScenarioLayout, sample_layout, sample_layout_in};
pub use report::{MAX_LINES, MergeError, Merged, Source, merge_results};
pub use result::ScenarioResult;
pub(crate) use result::shell_quote;
pub use run::{
    REORDER_WINDOW, SweepRun, run_scenario, run_sweep, run_sweep_from, run_sweep_streaming, run_sweep_with,
};
pub use shard::{MAX_AUTO_SHARDS, Shard, ShardSpec};
pub use summary::{Coverage, Failure, FailureGroup, NodeTotals, Summary, percentile, wilson_interval};
pub use timing::{MAX_RUNS, MAX_TIMING_BYTES, RunTiming, Timings, Total};
