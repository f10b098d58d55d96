//! Scenario suites (`macrotree test`): YAML files that name a tree, a scene, faults,
//! substitutions, a number of scenarios and a seed, and what must hold over them — read with
//! located errors like trees and scenes, checked against a run's results, and reported as text,
//! JSON and JUnit XML. See `docs/testing_trees.md`.
//!
//! ```yaml
//! # yaml-language-server: $schema=../schema/scenario.schema.json
//! description: A missed first grasp is recovered by the re-centring branch.
//! tree: ../trees/recenter_and_grasp.yaml
//! count: 4
//! seed: 1
//! substitute:
//!   - {pattern: "main/**/subtree[taught_pick]/**/grasp", outcome: "failure"}
//! expect:
//!   min_success_rate: 1.0
//!   ran_in_every: ["main/**/subtree[recentre_and_grasp]"]
//! ```

mod counts;
mod discover;
mod expect;
mod file;
pub mod junit;
pub mod names;

pub use counts::{Bounds, CountExpect, MAX_BOUND, Per};
pub use discover::find_files;
pub use expect::{Checked, Expect, Outcome, SuiteOutcome, check, offending_commands};
pub use file::{
    FaultName, GoalName, MAX_COUNT, MAX_RULES, ScenarioFile, ScenarioFileRaw, is_scenario_file, join_clean,
    load_scenario_file, schema_text,
};
