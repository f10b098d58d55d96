//! [`CommandLimits`]: how fast a command may ask the arm to move, and how a command is clamped
//! to them — one rule for the environment's `ctrl` action, residual steps and the `policy`
//! leaf's full commands.

use super::command::CellCommand;
use super::gripper::{CLOSED_CTRL, OPEN_CTRL};
use super::ur5e::JOINT_LIMITS;

/// The bounds a command's velocities, accelerations and set-point steps are clamped to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandLimits {
    /// Largest joint speed, rad/s: also bounds how far a set point may be from the arm's
    /// current one (`max_joint_speed × period`).
    pub max_joint_speed: f64,
    /// Largest joint acceleration, rad/s².
    pub max_joint_acc: f64,
}

/// The limits of every `ctrl` action: the UR5e's rated π rad/s, which no leaf exceeds, and
/// 40 rad/s².
pub const CTRL_LIMITS: CommandLimits = CommandLimits {
    max_joint_speed: super::ur5e::RATED_JOINT_SPEED,
    max_joint_acc: 40.0,
};

/// A command after [`CommandLimits::clamp`], and how many of its values were changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClampedCommand {
    /// The command the physics runs.
    pub command: CellCommand,
    /// Values clamped.
    pub clamped: u32,
}

impl CommandLimits {
    /// `command` (finite values) clamped: set points to the joint limits and to within
    /// `max_joint_speed × period` of the arm's set point `from` (radians; `period` in
    /// seconds), so no command asks for a faster motion; velocities and accelerations to these
    /// limits; the gripper command to 0 … 255. Counts the values changed.
    pub fn clamp(&self, mut command: CellCommand, from: &[f64; 6], period: f64) -> ClampedCommand {
        let mut clamped = 0;
        let mut clamp = |v: &mut f64, lo: f64, hi: f64| {
            let c = v.clamp(lo, hi);
            if c != *v {
                clamped += 1;
                *v = c;
            }
        };
        let step = self.max_joint_speed * period * (1.0 + 1e-9);
        for i in 0..6 {
            let (lo, hi) = JOINT_LIMITS[i];
            // Within the joint limits first, then within one period's step (which wins: a set
            // point the arm can reach from where it is commanded).
            let q = command.arm.q[i].clamp(lo, hi);
            let q = q.clamp(from[i] - step, from[i] + step);
            clamp(&mut command.arm.q[i], q, q);
            let v = self.max_joint_speed;
            clamp(&mut command.arm.qd[i], -v, v);
            let a = self.max_joint_acc;
            clamp(&mut command.arm.qdd[i], -a, a);
        }
        clamp(&mut command.gripper, OPEN_CTRL, CLOSED_CTRL);
        ClampedCommand { command, clamped }
    }
}
