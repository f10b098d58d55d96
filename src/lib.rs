//! # macrotree
//!
//! Behavior trees written in YAML that drive a MuJoCo simulation of a Universal Robots UR5e
//! arm with a Robotiq 2F-85 gripper through pick-and-place macro actions.
//!
//! The crate is layered the way the data flows. A module uses only modules of lower layers
//! (`tests/system/module_layers.rs` reads this table and fails on any `use crate::` that goes sideways
//! or up, so the table stays true):
//!
//! | layer | module | what it holds | MuJoCo? |
//! |---|---|---|---|
//! | 0 | [`motion`] | UR5e kinematics, closed-form IK, trajectories, gripper calibration | no |
//! | 0 | `cleanup` | temporary files and staging folders removed on exit, on SIGINT/SIGTERM, or by a later run | no |
//! | 1 | [`output`] | safe output files (every file the CLI writes) | no |
//! | 0 | `failure` | typed failures: a stable kind, a message, the node, the cause | no |
//! | 1 | [`yaml`] | located YAML: values with file:line:column, typed reads, diagnostics, units | no |
//! | 2 | [`scene`] | scene files: named objects, placements, the goal | no |
//! | 2 | `error` | the library's typed [`Error`] | no |
//! | 3 | [`world`] | typed world snapshot, condition predicates, goal, object queries | no |
//! | 4 | [`kinds`] | what each node kind *is*: name, category, doc, parameters, schema | no |
//! | 5 | [`spec`] | tree files → typed, expanded spec (includes, subtrees, object checks) | no |
//! | 6 | [`plan`] | spec → validated, compiled plan (a bonsai `Behavior`); the [`plan::Loader`] | no |
//! | 7 | [`runtime`] | the running tree: ticks, halts, blackboard, scripted leaves, trace events | no |
//! | 8 | `sim` | the MuJoCo adapter: scene composition, stepping, world extraction | yes |
//! | 9 | `actions` | the macro-action controllers (reach, grasp, carry, …) on the cell | yes |
//! | 9 | `render` | camera images through MuJoCo's offscreen renderer | yes |
//! | 10 | `factory` | how each node kind *runs*: controllers and condition checks by kind | yes |
//! | 10 | `faults` | faults injected through physics | yes |
//! | 10 | `video` | H.264 through the pinned ffmpeg | yes |
//! | 11 | `episode` | one episode: tree + cell → report; the leaf driver | yes |
//! | 12 | `app` | the library entry point: register, load, run | yes |
//! | 12 | `sweep` | parallel seeded sweeps, summaries, shards, resume | yes |
//! | 12 | `viewer` | MeshCat in the browser, live and replay | yes |
//! | 13 | `env` | a step-wise environment: reset, one macro action per step, observations; vector env | yes |
//! | 13 | `dataset` | LeRobot v3.0 datasets | yes |
//! | 13 | `suite` | scenario suites (`macrotree test`): files, expectations, JUnit | yes |
//! | 14 | `cli` | the command line | yes |
//!
//! Layers 8 and up need the cargo feature `sim` (on by default); without it (`cargo build -p
//! macrotree --no-default-features`) the library loads, validates and compiles trees and scenes,
//! gives the JSON Schema and the diagrams, and ticks trees on scripted leaves — and links no
//! MuJoCo.
//!
//! Units everywhere: metres, radians, seconds, unless a name says otherwise.
//!
//! The command line, the viewer, the sweep, rendering and datasets are behind the cargo features
//! `cli`, `viewer`, `sweep`, `render` and `dataset` (all on by default, each with `sim`).
//!
//! # Your own nodes
//!
//! A leaf is a parameter type (`Deserialize` + `JsonSchema`, documented with units) plus, for an
//! action, a controller with `start`/`update`/`halt` on the [`actions::Cell`], or, for a
//! condition, a pure function of the [`world::World`]. Register them next to the built-in kinds
//! and trees can use them in YAML, with the same located errors, suggestions, schema, `nodes`
//! docs and diagrams as the built-in ones. This is `examples/custom_leaf.rs` in short (run it with
//! `cargo run --release --example custom_leaf`; `docs/custom_nodes.md` walks through it):
//!
//! ```no_run
//! use macrotree::actions::{Cell, MacroAction, Progress, object_index};
//! use macrotree::episode::{EpisodeConfig, Goal};
//! use macrotree::kinds::{ObjectRef, ObjectRole};
//! use macrotree::world::World;
//! use macrotree::{App, Failure, FailureKind, Params};
//! use schemars::JsonSchema;
//! use serde::{Deserialize, Serialize};
//!
//! /// `push: {object, distance}`.
//! #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
//! #[serde(deny_unknown_fields)]
//! struct Push {
//!     /// The block (a name or `{var}`).
//!     object: ObjectRef,
//!     /// How far its centre moves, metres.
//!     #[serde(deserialize_with = "macrotree::yaml::units::distance")]
//!     distance: f64,
//! }
//!
//! impl Params for Push {
//!     const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
//!     fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
//!         vec![&mut self.object]
//!     }
//!     fn timeout(&self) -> Option<f64> {
//!         Some(10.0) // simulated seconds
//!     }
//!     fn failure_kinds() -> &'static [&'static str] {
//!         &["short_push"] // its own failure kind, besides the built-in ones
//!     }
//! }
//!
//! struct PushAction(Push);
//!
//! impl MacroAction for PushAction {
//!     fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
//!         let block = object_index(&self.0.object, cell.world())?;
//!         // … plan the motion from the world, start it with `cell.track(…)` …
//!         # let _ = block;
//!         Ok(())
//!     }
//!     fn update(&mut self, cell: &mut Cell) -> Progress {
//!         if !cell.arm_motion_finished() {
//!             return Progress::Running;
//!         }
//!         # let pushed = 0.1;
//!         if pushed < self.0.distance {
//!             // Every failure is typed: a built-in kind or one the node kind declares.
//!             return Progress::Failed(Failure::new(FailureKind::Custom("short_push"), "the block moved too little"));
//!         }
//!         Progress::Done
//!     }
//! }
//!
//! /// `near: {object, point}`.
//! #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
//! #[serde(deny_unknown_fields)]
//! struct Near {
//!     /// The block (a name or `{var}`).
//!     object: ObjectRef,
//!     /// `[x, y]` on the table, world metres.
//!     point: [f64; 2],
//! }
//!
//! impl Params for Near {
//!     const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
//!     fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
//!         vec![&mut self.object]
//!     }
//! }
//!
//! fn near(w: &World, p: &Near) -> Result<bool, Failure> {
//!     let c = w.objects[object_index(&p.object, w)?].pos;
//!     Ok((c.x - p.point[0]).hypot(c.y - p.point[1]) <= 0.01)
//! }
//!
//! const PUSH_DOC: &str = "Slide a block along the table.\n\nHalt: the arm holds where it is.\n\n```yaml\npush: {object: cube, distance: 0.1}\n```\n";
//! const NEAR_DOC: &str = "The block's centre is near a point.\n\nHalt: nothing to halt (instantaneous).\n\n```yaml\nnear: {object: cube, point: [0.45, -0.28]}\n```\n";
//!
//! let mut app = App::new();
//! app.register_action("push", PUSH_DOC, |p: &Push| Box::new(PushAction(p.clone())))?
//!     .register_condition("near", NEAR_DOC, near)?;
//! let plan = app.compile_str(
//!     "main: {sequence: {children: [{push: {object: cube, distance: 0.1}}, {near: {object: cube, point: [0.55, -0.18]}}]}}",
//!     "push.yaml",
//! )?;
//! let report = app.run_episode(&plan, &EpisodeConfig { goal: Goal::Tree, ..EpisodeConfig::default() })?;
//! println!("{}", serde_json::to_string_pretty(&report).unwrap());
//! // Or the whole `macrotree` command line, with `push` and `near` in it:
//! // std::process::exit(i32::from(app.run_cli() != std::process::ExitCode::SUCCESS));
//! # Ok::<(), macrotree::Error>(())
//! ```

#![warn(missing_docs)]

#[cfg(feature = "sim")]
pub use app::{App, ProgramInfo};
pub use error::Error;
pub use failure::{Failure, FailureKind, MAX_CUSTOM_KINDS, MAX_CUSTOM_NAME};
pub use kinds::{Category, ParamError, Params, Registry};

#[cfg(feature = "sim")]
pub mod actions;
#[cfg(feature = "sim")]
mod app;
mod cleanup;
#[cfg(feature = "cli")]
pub mod cli;
#[cfg(feature = "sim")]
pub mod dataset;
#[cfg(feature = "sim")]
pub mod env;
#[cfg(feature = "sim")]
pub mod episode;
mod error;
#[cfg(feature = "sim")]
pub mod factory;
mod failure;
#[cfg(feature = "sim")]
pub mod faults;
pub mod kinds;
pub mod motion;
pub mod output;
pub mod plan;
#[cfg(feature = "sim")]
pub mod render;
pub mod runtime;
pub mod scene;
#[cfg(feature = "sim")]
pub mod sim;
pub mod spec;
#[cfg(feature = "sweep")]
pub mod suite;
#[cfg(feature = "sweep")]
pub mod sweep;
#[cfg(feature = "sim")]
pub mod video;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod world;
pub mod yaml;
