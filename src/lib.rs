//! # macrotree
//!
//! Behavior trees written in YAML that drive a MuJoCo simulation of a Universal Robots UR5e
//! arm with a Robotiq 2F-85 gripper through pick-and-place macro actions.
//!
//! The crate is layered the way the data flows:
//!
//! | layer | module | depends on MuJoCo? |
//! |---|---|---|
//! | YAML tree → typed spec (with source spans) | [`spec`] | no |
//! | spec → validated, compiled plan (a bonsai `Behavior`) | [`plan`] | no |
//! | plan → running tree (ticks, halts, trace events) | [`runtime`] | no |
//! | scene files: named objects, placements, goal | [`scene`] | no |
//! | typed world snapshot, condition leaves, goal, queries | [`world`] | no |
//! | kinematics, IK, trajectories, gripper calibration | [`motion`] | no |
//! | MuJoCo scene, stepping, world extraction | [`sim`] | yes |
//! | macro-action leaves (reach, grasp, carry, …) | [`actions`] | through [`sim`] |
//! | one episode: tree + cell → report | [`episode`] | yes |
//! | scenario suites (`macrotree test`): files, expectations, JUnit | [`suite`] | through [`sweep`] |
//! | command-line interface | [`cli`] | yes |
//! | safe output files (every file the CLI writes) | [`output`] | no |
//!
//! | the registry of node kinds (built-in and yours) | [`registry`] | no |
//! | the library entry point: register, load, run, CLI | [`App`] | yes |
//!
//! Units everywhere: metres, radians, seconds, unless a name says otherwise.
//!
//! The command line, the viewer and the sweep are behind the cargo features `cli`, `viewer` and
//! `sweep` (all on by default); `default-features = false` gives the library alone.
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
//! use macrotree::spec::ObjectRef;
//! use macrotree::world::World;
//! use macrotree::{App, Params};
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
//!     #[serde(deserialize_with = "macrotree::spec::units::distance")]
//!     distance: f64,
//! }
//!
//! impl Params for Push {
//!     fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
//!         vec![&mut self.object]
//!     }
//!     fn timeout(&self) -> Option<f64> {
//!         Some(10.0) // simulated seconds
//!     }
//! }
//!
//! struct PushAction(Push);
//!
//! impl MacroAction for PushAction {
//!     fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
//!         let block = object_index(&self.0.object, cell.world())?;
//!         // … plan the motion from the world, start it with `cell.track(…)` …
//!         # let _ = block;
//!         Ok(())
//!     }
//!     fn update(&mut self, cell: &mut Cell) -> Progress {
//!         if cell.arm_motion_finished() { Progress::Done } else { Progress::Running }
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
//!     fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
//!         vec![&mut self.object]
//!     }
//! }
//!
//! fn near(w: &World, p: &Near) -> Result<bool, String> {
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

pub use app::App;
pub use error::Error;
pub use registry::{Category, Params, Registry};

pub mod actions;
pub mod app;
pub mod cleanup;
#[cfg(feature = "cli")]
pub mod cli;
pub mod dataset;
pub mod episode;
pub mod error;
pub mod faults;
pub mod motion;
pub mod output;
pub mod plan;
pub mod registry;
pub mod render;
pub mod runtime;
pub mod scene;
pub mod sim;
pub mod spec;
#[cfg(feature = "sweep")]
pub mod suite;
#[cfg(feature = "sweep")]
pub mod sweep;
pub mod video;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod world;
