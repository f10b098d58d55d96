//! [`ArmCommand`] and [`CellCommand`]: what the arm's servos and the gripper are told for one
//! control period — the one action of macrotree. The built-in leaves command it (sampled from
//! their trajectory at the start of each period), the step-wise environment's `ctrl` action is
//! it, and a dataset's `action` column records it, so a recorded episode replays.
//!
//! Over the period the arm command is a second-order hold: at `τ` seconds into the period the
//! servos track `q + q̇ τ + ½ q̈ τ²` at `q̇ + q̈ τ` with feedforward `q̈`
//! ([`ArmCommand::at`]). Units: radians, rad/s, rad/s²; the gripper in actuator units.

use super::ur5e::{arm_joint_names, joined_names};

/// The arm's command at the start of a control period: joint set points, velocities and
/// accelerations (the servos' feedforward).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmCommand {
    /// Joint set points, radians.
    pub q: [f64; 6],
    /// Joint velocities, rad/s.
    pub qd: [f64; 6],
    /// Joint accelerations, rad/s².
    pub qdd: [f64; 6],
}

impl ArmCommand {
    /// Holding still at `q` (radians): zero velocity and acceleration.
    pub const fn hold(q: [f64; 6]) -> Self {
        Self {
            q,
            qd: [0.0; 6],
            qdd: [0.0; 6],
        }
    }

    /// The command `tau` seconds into the period (the second-order hold); exactly `self` at 0.
    pub fn at(&self, tau: f64) -> Self {
        if tau == 0.0 {
            return *self;
        }
        let mut out = *self;
        for i in 0..6 {
            out.q[i] = self.q[i] + self.qd[i] * tau + 0.5 * self.qdd[i] * tau * tau;
            out.qd[i] = self.qd[i] + self.qdd[i] * tau;
        }
        out
    }
}

/// Values in a [`CellCommand`] as a flat vector ([`CellCommand::to_vector`]): six set points,
/// six velocities, six accelerations, the gripper command.
pub const COMMAND_LEN: usize = 19;

/// Names of the values of a flat command vector, in order (the dataset's `action` names).
pub const COMMAND_NAMES: [&str; COMMAND_LEN] = joined_names(&[
    &arm_joint_names!(".pos"),
    &arm_joint_names!(".vel"),
    &arm_joint_names!(".acc"),
    &["gripper"],
]);

/// One control period's command of the whole cell: the arm's and the gripper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellCommand {
    /// The arm's command at the start of the period.
    pub arm: ArmCommand,
    /// The gripper actuator command, [`super::OPEN_CTRL`] (0, open) … [`super::CLOSED_CTRL`]
    /// (255, closed).
    pub gripper: f64,
}

impl CellCommand {
    /// The flat vector: `q` (6, rad), `q̇` (6, rad/s), `q̈` (6, rad/s²), gripper (0 … 255).
    pub fn to_vector(&self) -> [f64; COMMAND_LEN] {
        let mut v = [0.0; COMMAND_LEN];
        v[..6].copy_from_slice(&self.arm.q);
        v[6..12].copy_from_slice(&self.arm.qd);
        v[12..18].copy_from_slice(&self.arm.qdd);
        v[18] = self.gripper;
        v
    }

    /// The command of a flat vector laid out as [`Self::to_vector`] gives it (unchecked).
    pub fn from_vector(v: &[f64; COMMAND_LEN]) -> Self {
        let mut arm = ArmCommand::hold([0.0; 6]);
        arm.q.copy_from_slice(&v[..6]);
        arm.qd.copy_from_slice(&v[6..12]);
        arm.qdd.copy_from_slice(&v[12..18]);
        Self { arm, gripper: v[18] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hold_is_exact_at_the_start_and_second_order_within_the_period() {
        let c = ArmCommand {
            q: [0.1, -0.2, 0.3, -0.4, 0.5, -0.6],
            qd: [1.0, 0.0, -1.0, 0.5, 0.0, 2.0],
            qdd: [2.0, 4.0, 0.0, -2.0, 1.0, 0.0],
        };
        assert_eq!(c.at(0.0), c);
        let later = c.at(0.5);
        assert!((later.q[0] - (0.1 + 0.5 + 0.25)).abs() < 1e-15);
        assert!((later.qd[1] - 2.0).abs() < 1e-15);
        assert_eq!(later.qdd, c.qdd);
        assert_eq!(ArmCommand::hold(c.q).at(0.02).q, c.q);
    }

    #[test]
    fn a_command_round_trips_through_its_flat_vector() {
        let c = CellCommand {
            arm: ArmCommand {
                q: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
                qd: [7.0, 8.0, 9.0, 10.0, 11.0, 12.0],
                qdd: [13.0, 14.0, 15.0, 16.0, 17.0, 18.0],
            },
            gripper: 255.0,
        };
        let v = c.to_vector();
        assert_eq!(v[18], 255.0);
        assert_eq!(CellCommand::from_vector(&v), c);
        assert!(COMMAND_NAMES[..6].iter().all(|n| n.ends_with(".pos")));
    }
}
