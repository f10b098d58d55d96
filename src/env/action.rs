//! [`Action`]: what one [`super::MacroEnv::step`] does — a registered leaf given as a mapping,
//! one of the reference tutorial's primitives, one control period of low-level targets, or a
//! named subtree of the tree.

use super::primitive::Primitive;
use crate::error::Error;
use crate::motion::{
    ArmCommand, CLOSED_CTRL, COMMAND_LEN, CTRL_LIMITS, CellCommand, ClampedCommand, JOINT_LIMITS, OPEN_CTRL,
};

/// Values of a set-point action ([`Action::Setpoint`]): six joint set points and the gripper
/// command.
pub const SETPOINT_LEN: usize = 7;

/// One step's action. Every action runs to completion on simulated time, closed loop inside
/// (the leaf's or primitive's controller acts every control period); the caller decides again
/// after it.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Any registered leaf — built-in or the app's own — as a YAML or JSON mapping, e.g.
    /// `{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}` or `grasp: {}`: an action runs
    /// until it succeeds or fails (its own `timeout:` applies), a condition answers at once
    /// (0 physics steps), `wait: {seconds: S}` waits. Parsed and checked by the tree loader
    /// ([`crate::plan::Loader`]) against the environment's scene, with the same located errors
    /// (`action:LINE:COLUMN` in the given text, did-you-mean suggestions, unknown object names).
    Leaf(String),
    /// One of the reference tutorial's macro primitives ([`Primitive`]).
    Primitive(Primitive),
    /// Low-level control, the one action every leaf commands and a dataset's `action` column
    /// records ([`CellCommand::to_vector`]): six arm joint set points (radians, within
    /// [`crate::motion::JOINT_LIMITS`]), six joint velocities (rad/s), six joint accelerations
    /// (rad/s²) and the gripper command (0 open … 255 closed), for exactly one control period
    /// (`EnvConfig::control_period`, default 4 ms = 2 physics steps of 2 ms), held over it as
    /// [`ArmCommand::at`] says, with the servos' feedforward of every leaf. Velocities and
    /// accelerations beyond [`CTRL_LIMITS`], and set points further from the arm's current set
    /// point than the largest speed allows in one period, are clamped
    /// ([`super::StepResult::ctrl_clamped`] counts them); values that are not finite, set
    /// points outside the joint limits and gripper commands outside 0 … 255 are refused.
    Ctrl([f64; COMMAND_LEN]),
    /// Plain set points: six arm joint targets (radians) and the gripper command, with zero
    /// velocity and acceleration — [`Action::Ctrl`] with its velocities and accelerations zero.
    Setpoint([f64; SETPOINT_LEN]),
    /// A node of the environment's tree, by its `name:` (a subtree call is named after its
    /// subtree: `pick`), by its node path (`main/sequence[cube to bowl]/…`), or `main` for the
    /// whole tree: it runs until it finishes, ticked exactly as inside the whole tree.
    Subtree(String),
    /// Residual control: one control period of the environment's tree, the base controller,
    /// with this correction added to the command it gives (six joint set-point offsets in
    /// radians, then a gripper-command offset; [`super::RESIDUAL_LEN`] values). The tree is
    /// ticked once per residual step, exactly as `run_episode` ticks it (its first tick after a
    /// reset starts it from the root), so an all-zero residual runs the scripted episode bit
    /// for bit; the offsets, clamped to [`super::RESIDUAL_LIMITS`], are added to the base's set
    /// points and gripper command (its velocities and accelerations stay), and the sum is
    /// clamped like a `ctrl` command. Non-finite values are refused. The result's
    /// [`super::StepResult::base`] holds the base command and the tree's status; a failed base
    /// tree fails the step. Another kind of action ends the base run (its running leaves are
    /// halted); the next residual step starts the tree again.
    Residual([f64; super::RESIDUAL_LEN]),
}

impl Action {
    /// A short name of the action for messages (`leaf`, `reach_pose`, `ctrl`, `subtree`).
    pub fn name(&self) -> &'static str {
        match self {
            Action::Leaf(_) => "leaf",
            Action::Primitive(p) => p.name(),
            Action::Ctrl(_) => "ctrl",
            Action::Setpoint(_) => "setpoint",
            Action::Subtree(_) => "subtree",
            Action::Residual(_) => "residual",
        }
    }
}

/// The `ctrl` vector a `ctrl` or `setpoint` action stands for, unchecked.
#[derive(Clone, Copy)]
pub(super) struct CtrlValues {
    /// The values, laid out as [`CellCommand::to_vector`] (a set point's velocities and
    /// accelerations zero).
    pub vector: [f64; COMMAND_LEN],
    /// The name of value `i` of `vector` in messages, as the caller wrote it (`ctrl[18]`,
    /// `setpoint[6]`).
    pub name: fn(usize) -> String,
}

/// The `ctrl` values of a `ctrl` or `setpoint` action; `None` for other actions.
pub(super) fn ctrl_of(action: &Action) -> Option<CtrlValues> {
    match action {
        Action::Ctrl(u) => Some(CtrlValues {
            vector: *u,
            name: |i| format!("ctrl[{i}]"),
        }),
        Action::Setpoint(u) => {
            let arm = ArmCommand::hold([u[0], u[1], u[2], u[3], u[4], u[5]]);
            Some(CtrlValues {
                vector: CellCommand { arm, gripper: u[6] }.to_vector(),
                name: |i| format!("setpoint[{}]", if i == COMMAND_LEN - 1 { 6 } else { i }),
            })
        }
        _ => None,
    }
}

/// A `ctrl` vector checked: finite, set points within the joint limits, the gripper command
/// within 0 … 255 (else refused, naming the value as `name` does and the range); then clamped
/// to [`CTRL_LIMITS`].
pub(super) fn check_ctrl(values: &CtrlValues, from: &[f64; 6], period: f64) -> Result<ClampedCommand, Error> {
    let CtrlValues { vector: u, name } = values;
    let bad = |message: String| Error::Action { message };
    if let Some(i) = u.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!(
            "{} is {}; every value must be finite",
            name(i),
            u[i]
        )));
    }
    let command = CellCommand::from_vector(u);
    for (i, (&q, &(lo, hi))) in command.arm.q.iter().zip(&JOINT_LIMITS).enumerate() {
        if !(lo..=hi).contains(&q) {
            return Err(bad(format!(
                "{} ({} set point) is {q}; expected radians within {lo} … {hi}",
                name(i),
                crate::motion::ARM_JOINTS[i]
            )));
        }
    }
    let g = command.gripper;
    if !(OPEN_CTRL..=CLOSED_CTRL).contains(&g) {
        return Err(bad(format!(
            "{} (gripper command) is {g}; expected {OPEN_CTRL} (open) … {CLOSED_CTRL} (closed)",
            name(COMMAND_LEN - 1)
        )));
    }
    Ok(CTRL_LIMITS.clamp(command, from, period))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ctrl_values_out_of_range_are_refused_with_the_index_and_the_range() {
        let home = crate::motion::HOME_Q;
        let setpoint = Action::Setpoint([home[0], home[1], home[2], home[3], home[4], home[5], 100.0]);
        let values = ctrl_of(&setpoint).unwrap();
        let checked = check_ctrl(&values, &home, 0.004).unwrap();
        let ok = values.vector;
        assert_eq!(checked.command.arm.q, home);
        assert_eq!(checked.command.gripper, 100.0);
        assert_eq!(checked.clamped, 0);
        for (i, bad) in [
            (0, f64::NAN),
            (2, 3.5),
            (5, f64::INFINITY),
            (7, f64::NAN),
            (18, -1.0),
            (18, 256.0),
            (18, f64::NAN),
        ] {
            let mut u = ok;
            u[i] = bad;
            let e = check_ctrl(&ctrl_of(&Action::Ctrl(u)).unwrap(), &home, 0.004).unwrap_err();
            assert_eq!(e.kind(), "invalid_action");
            assert!(e.to_string().contains(&format!("ctrl[{i}]")), "{e}");
        }
        // A set point's values are named as the caller wrote them.
        let mut u = ok;
        u[18] = 300.0;
        let e = check_ctrl(&CtrlValues { vector: u, ..values }, &home, 0.004).unwrap_err();
        assert!(e.to_string().contains("setpoint[6] (gripper command)"), "{e}");
        u[18] = 0.0;
        u[2] = 9.0;
        let e = check_ctrl(&CtrlValues { vector: u, ..values }, &home, 0.004).unwrap_err();
        assert!(e.to_string().contains("setpoint[2] (elbow"), "{e}");
    }

    #[test]
    fn ctrl_speeds_accelerations_and_jumps_are_clamped_and_counted() {
        let home = crate::motion::HOME_Q;
        let setpoint = Action::Setpoint([home[0] + 0.5, home[1], home[2], home[3], home[4], home[5], 0.0]);
        let mut values = ctrl_of(&setpoint).unwrap();
        let u = &mut values.vector;
        u[6] = 30.0;
        u[13] = -1000.0;
        let c = check_ctrl(&values, &home, 0.004).unwrap();
        assert_eq!(c.clamped, 3);
        let step = CTRL_LIMITS.max_joint_speed * 0.004;
        assert!((c.command.arm.q[0] - (home[0] + step)).abs() < 1e-9);
        assert_eq!(c.command.arm.qd[0], CTRL_LIMITS.max_joint_speed);
        assert_eq!(c.command.arm.qdd[1], -CTRL_LIMITS.max_joint_acc);
    }
}
