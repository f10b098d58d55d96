//! The macro-action controllers on the simulated cell: `reach`, `move_joints`, `home`, `grasp`,
//! `carry`, `place`, `release`. `crate::factory` binds them to their node kinds, and the episode's leaf
//! driver starts them when the tree runs.
//!
//! Each action is a small controller ([`MacroAction`]) in its own file: planned on its first
//! tick from the current world (IK, trajectories from [`crate::motion`]), checked every tick
//! after, halted (arm holds its commanded pose) when the tree preempts it.

mod carry;
mod cell;
mod checks;
mod clearance;
mod grasp;
mod grasp_yaw;
mod joints;
mod macro_action;
mod packing;
mod place;
mod plan_help;
mod planning;
mod planning_tally;
#[cfg(feature = "policy")]
pub mod policy;
mod reach;
mod release;
mod release_room;
mod side;
mod side_set_down;
mod targets;
mod tilted;

pub(crate) use carry::Carry as CarryAction;
pub use cell::{CONTROL_PERIOD, Cell, MAX_CONTROL_PERIOD, StepObserver, check_control_period};
pub use checks::{Checks, ChecksRecorder, pad_block_distance};
pub(crate) use grasp::Grasp as GraspAction;
pub(crate) use joints::MoveJoints as MoveJointsAction;
pub use macro_action::{Arrival, MacroAction, Progress};
pub(crate) use place::Place as PlaceAction;
pub use planning_tally::{PlanCounts, PlanningTally};
pub(crate) use reach::Reach as ReachAction;
pub(crate) use release::Release as ReleaseAction;
pub use targets::{
    object_index, object_point, resolve, spot, target_block, target_object, target_spot, tool_yaw,
};
