//! The motion layer: kinematics, inverse kinematics, trajectories and gripper calibration of the
//! Menagerie UR5e + Robotiq 2F-85, in pure nalgebra (no MuJoCo), so everything here is testable
//! without physics. `tests/motion_*.rs` cross-check it against the simulator.
//!
//! Units: metres, radians, seconds; poses are of the 2F-85 `pinch` site in the world frame.
//!
//! | module | what |
//! |---|---|
//! | [`ur5e`] | the UR5e's facts: joints, [`JOINT_LIMITS`], rated speed, dimensions, [`HOME_Q`], lever arms |
//! | [`kinematics`] | [`fk`], [`jacobian`] of the pinch, the tool's length |
//! | [`body`] | the arm's and gripper's links as capsules along the chain ([`body::arm_capsules`]) |
//! | [`mod@ik`] | closed-form [`ik()`] with nearest-to-seed branch choice, every branch ([`ik_all`]), [`ik_down`], [`down_pose`], [`IkError`], [`ik_benchmark`] |
//! | [`mod@plan`] | collision-aware joint-space planning: RRT-Connect to goal sets, shortcutting, blends, timing, typed failure reasons |
//! | [`trajectory`] | the [`Trajectory`] trait, [`JointMove`], [`CartesianMove`], [`Hold`], [`MotionLimits`] |
//! | [`gripper`] | command ↔ opening calibration of the simulated 2F-85 |
//! | [`command`] | [`ArmCommand`] and [`CellCommand`]: one control period's command, the one action |
//! | [`command_limits`] | [`CommandLimits`]: the speeds and accelerations a command is clamped to ([`CTRL_LIMITS`]) |

pub mod body;
pub mod command;
pub mod command_limits;
pub mod gripper;
pub mod ik;
pub mod kinematics;
pub mod plan;
pub mod trajectory;
pub mod ur5e;

pub use command::{ArmCommand, COMMAND_LEN, COMMAND_NAMES, CellCommand};
pub use command_limits::{CTRL_LIMITS, ClampedCommand, CommandBounds, CommandLimits};
pub use gripper::{CLOSED_CTRL, OPEN_CTRL, ctrl_for_width, width_for_ctrl};
pub use ik::{IkError, down_pose, ik, ik_all, ik_benchmark, ik_down, ik_down_with_pose};
pub use kinematics::{fk, jacobian};
pub use trajectory::{ACC_DIFF_STEP, CartesianMove, Hold, JointMove, MotionLimits, Trajectory};
pub use ur5e::{ARM_JOINTS, HOME_Q, JOINT_LIMITS};
