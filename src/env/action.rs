//! [`Action`]: what one [`super::MacroEnv::step`] does — a registered leaf given as a mapping,
//! one of the reference tutorial's primitives, one control period of low-level targets, or a
//! named subtree of the tree.

use super::primitive::Primitive;
use crate::error::Error;
use crate::motion::{CLOSED_CTRL, JOINT_LIMITS, OPEN_CTRL};

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
    /// Low-level control: six arm joint targets (radians, within
    /// [`crate::motion::JOINT_LIMITS`]) and the gripper command (0 open … 255 closed), held for
    /// exactly one control period (`EnvConfig::control_period`, default 4 ms = 2 physics steps
    /// of 2 ms). The layout is the dataset's `action` ([`super::Observation::command`]); the
    /// arm servos track the target with the same gravity feedforward as every leaf (zero target
    /// velocity and acceleration).
    Ctrl([f64; 7]),
    /// A node of the environment's tree, by its `name:` (a subtree call is named after its
    /// subtree: `pick`), by its node path (`main/sequence[cube to bowl]/…`), or `main` for the
    /// whole tree: it runs until it finishes, ticked exactly as inside the whole tree.
    Subtree(String),
}

impl Action {
    /// A short name of the action for messages (`leaf`, `reach_pose`, `ctrl`, `subtree`).
    pub fn name(&self) -> &'static str {
        match self {
            Action::Leaf(_) => "leaf",
            Action::Primitive(p) => p.name(),
            Action::Ctrl(_) => "ctrl",
            Action::Subtree(_) => "subtree",
        }
    }
}

/// The arm targets and gripper command of a `Ctrl`, checked: finite, joints within their
/// limits, the command within 0 … 255.
pub(super) fn check_ctrl(u: &[f64; 7]) -> Result<([f64; 6], f64), Error> {
    let mut q = [0.0; 6];
    for (i, (&v, (lo, hi))) in u.iter().zip(JOINT_LIMITS).enumerate() {
        if !(v.is_finite() && (lo..=hi).contains(&v)) {
            return Err(Error::Action {
                message: format!(
                    "ctrl[{i}] ({} target) is {v}; expected radians within {lo} … {hi}",
                    crate::motion::ARM_JOINTS[i]
                ),
            });
        }
        q[i] = v;
    }
    let g = u[6];
    if !(g.is_finite() && (OPEN_CTRL..=CLOSED_CTRL).contains(&g)) {
        return Err(Error::Action {
            message: format!(
                "ctrl[6] (gripper command) is {g}; expected {OPEN_CTRL} (open) … {CLOSED_CTRL} (closed)"
            ),
        });
    }
    Ok((q, g))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ctrl_values_out_of_range_are_refused_with_the_index_and_the_range() {
        let home = crate::motion::HOME_Q;
        let ok = [home[0], home[1], home[2], home[3], home[4], home[5], 100.0];
        assert_eq!(check_ctrl(&ok).unwrap(), (home, 100.0));
        for (i, bad) in [
            (0, f64::NAN),
            (2, 3.5),
            (5, f64::INFINITY),
            (6, -1.0),
            (6, 256.0),
            (6, f64::NAN),
        ] {
            let mut u = ok;
            u[i] = bad;
            let e = check_ctrl(&u).unwrap_err();
            assert_eq!(e.kind(), "invalid_action");
            assert!(e.to_string().contains(&format!("ctrl[{i}]")), "{e}");
        }
    }
}
