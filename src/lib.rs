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
//! | command-line interface | [`cli`] | yes |
//! | safe output files (every file the CLI writes) | [`output`] | no |
//!
//! Units everywhere: metres, radians, seconds, unless a name says otherwise.

#![warn(missing_docs)]

pub mod actions;
pub mod cli;
pub mod dataset;
pub mod episode;
pub mod faults;
pub mod motion;
pub mod output;
pub mod plan;
pub mod render;
pub mod runtime;
pub mod scene;
pub mod sim;
pub mod spec;
pub mod sweep;
pub mod video;
pub mod viewer;
pub mod world;
