//! [`CommandLimits`]: how fast a command may ask the arm to move, and how a command is clamped
//! to them — one rule for the environment's `ctrl` action, residual steps and the `policy`
//! leaf's full commands.

use super::command::{COMMAND_LEN, CellCommand};
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

/// The box a command vector ([`CellCommand::to_vector`]) is held to, value by value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandBounds {
    /// Lowest values: joint limits (rad), −speed (rad/s), −acceleration (rad/s²), open gripper.
    pub low: [f64; COMMAND_LEN],
    /// Highest values: joint limits (rad), speed (rad/s), acceleration (rad/s²), closed gripper.
    pub high: [f64; COMMAND_LEN],
}

impl CommandLimits {
    /// The bounds of a command vector under these limits (a `ctrl` action's space): set points
    /// within [`JOINT_LIMITS`], velocities and accelerations within ± these limits, the gripper
    /// within 0 … 255.
    pub const fn bounds(&self) -> CommandBounds {
        let mut low = [0.0; COMMAND_LEN];
        let mut high = [0.0; COMMAND_LEN];
        let mut i = 0;
        while i < 6 {
            (low[i], high[i]) = JOINT_LIMITS[i];
            (low[6 + i], high[6 + i]) = (-self.max_joint_speed, self.max_joint_speed);
            (low[12 + i], high[12 + i]) = (-self.max_joint_acc, self.max_joint_acc);
            i += 1;
        }
        (low[18], high[18]) = (OPEN_CTRL, CLOSED_CTRL);
        CommandBounds { low, high }
    }

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

#[cfg(test)]
mod tests {
    use super::{CTRL_LIMITS, CellCommand};
    use crate::motion::{ArmCommand, HOME_Q};

    fn command(value: f64) -> CellCommand {
        CellCommand {
            arm: ArmCommand {
                q: [value; 6],
                qd: [value; 6],
                qdd: [value; 6],
            },
            gripper: value,
        }
    }

    #[test]
    fn a_command_clamped_from_either_side_lands_on_its_bounds() {
        let bounds = CTRL_LIMITS.bounds();
        // A period long enough that the set-point step does not bind: only the bounds do.
        let high = CTRL_LIMITS.clamp(command(1e6), &HOME_Q, 1e3).command.to_vector();
        let low = CTRL_LIMITS.clamp(command(-1e6), &HOME_Q, 1e3).command.to_vector();
        assert_eq!(high, bounds.high);
        assert_eq!(low, bounds.low);
    }
}
