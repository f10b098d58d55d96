//! Collision-aware joint-space motion planning for the UR5e, against any [`CollisionChecker`]
//! (MuJoCo's geometry in `sim::collision`, or a synthetic [`JointBoxes`] model in tests), in pure
//! Rust: no MuJoCo here.
//!
//! [`plan`] takes a start, a [`GoalSet`] (e.g. every IK branch of a pose and its equivalent grasp
//! yaws) and a [`PlannerConfig`], and returns a [`PlannedMotion`] whose [`PathTrajectory`] the
//! cell tracks like any [`Trajectory`](crate::motion::Trajectory), or a [`PlanError`] with a typed
//! [`PlanFailure`] naming the colliding pairs. The search is seeded RRT-Connect towards all free
//! goals at once after the direct segment is tried, asking the checker's fast screen first
//! (re-checking the final path without it); the path is shortcut (seeded), its corners
//! blended with checked arcs, and timed within per-joint [`JointLimits`]. Same checker, query and
//! seed → the same path, bit for bit; see `docs/motion.md`.
//!
//! | module | what |
//! |---|---|
//! | `checker` | the [`CollisionChecker`] trait, [`Collision`] pairs |
//! | `config` | [`PlannerConfig`], [`JointLimits`], the UR5e's rated speed |
//! | `goal` | [`GoalSet`]: goal configurations from IK branches and symmetric yaws |
//! | `edge` | segments checked at a resolution, in bisection order |
//! | `rrt` | RRT-Connect from a start to a goal set |
//! | `shortcut` | seeded random shortcuts and vertex dropping |
//! | `blend` | corner arcs within a deviation, collision-checked |
//! | `timing` | [`PathTrajectory`]: the smoothed path timed within the joint limits |
//! | `reason` | [`PlanFailure`], [`PlanError`] |
//! | `spare` | [`JointSpare`]: spare clearance by joint range, and how far it reaches |
//! | `stats` | [`PlanStats`] and joint-space distances |
//! | `planner` | [`plan`]: one query, stage by stage |
//! | `boxes` | [`JointBoxes`]: obstacles as boxes in joint space, for tests and benchmarks |

pub(crate) mod blend;
pub(crate) mod boxes;
pub(crate) mod checker;
pub(crate) mod config;
pub(crate) mod edge;
pub(crate) mod goal;
pub(crate) mod planner;
pub(crate) mod reason;
mod rng;
pub(crate) mod rrt;
pub(crate) mod shortcut;
pub(crate) mod spare;
pub(crate) mod stats;
pub(crate) mod timing;

#[cfg(test)]
mod tests;

pub use boxes::{JointBox, JointBoxes};
pub use checker::{Collision, CollisionChecker, FastChecks};
pub use config::{HELD_BLOCK_REACH, JointLimits, PlannerConfig};
pub use edge::{Resolution, check_segment};
pub use goal::GoalSet;
pub use planner::{PlannedMotion, plan};
pub use reason::{PlanError, PlanFailure, SearchBudget};
pub use spare::{JointSpare, SPARE_CAP};
pub use stats::PlanStats;
pub use timing::PathTrajectory;
