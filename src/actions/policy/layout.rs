//! [`ActionLayout`]: the two actions a model may return — plain set points, or the cell's full
//! command with its feedforward — and the one form both take inside the leaf.

use crate::motion::COMMAND_LEN;

/// Values of a [`ActionLayout::Setpoint`] action.
const SETPOINT_LEN: usize = 7;

/// What a model's action holds, read from the last dimension of its output (`[1, n]` or a
/// chunk `[1, k, n]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActionLayout {
    /// 7 values: six joint set points (radians, or offsets) and the gripper command (0 open …
    /// 255 closed). The leaf moves the set points linearly to them over the model's period.
    Setpoint,
    /// 19 values, the cell's full command as a dataset's `action` column records it
    /// ([`crate::motion::CellCommand::to_vector`]): six joint set points (radians, or offsets),
    /// six velocities (rad/s), six accelerations (rad/s²) and the gripper command. The leaf
    /// holds it over the model's period as the environment's `ctrl` action is held
    /// ([`crate::motion::ArmCommand::at`]), so a model cloned from a dataset's actions commands
    /// what the demonstrations commanded.
    Command,
}

/// One action in the command layout, whatever the model's layout: a set point's velocities and
/// accelerations are zero, its gripper command last.
pub type ModelAction = [f32; COMMAND_LEN];

impl ActionLayout {
    /// Both layouts.
    pub const ALL: [ActionLayout; 2] = [ActionLayout::Setpoint, ActionLayout::Command];

    /// Values per action.
    pub const fn width(self) -> usize {
        match self {
            ActionLayout::Setpoint => SETPOINT_LEN,
            ActionLayout::Command => COMMAND_LEN,
        }
    }

    /// The layout of an action of `n` values.
    pub fn of_len(n: usize) -> Option<ActionLayout> {
        Self::ALL.into_iter().find(|l| l.width() == n)
    }

    /// `values` (this layout's [`Self::width`] of them) as a [`ModelAction`].
    pub fn expand(self, values: &[f32]) -> ModelAction {
        let mut a = [0.0; COMMAND_LEN];
        match self {
            ActionLayout::Setpoint => {
                a[..6].copy_from_slice(&values[..6]);
                a[COMMAND_LEN - 1] = values[6];
            }
            ActionLayout::Command => a.copy_from_slice(&values[..COMMAND_LEN]),
        }
        a
    }

    /// The values of `action` this layout has, in its order (the inverse of [`Self::expand`]).
    pub fn compact(self, action: &ModelAction) -> Vec<f32> {
        match self {
            ActionLayout::Setpoint => {
                let mut v = action[..6].to_vec();
                v.push(action[COMMAND_LEN - 1]);
                v
            }
            ActionLayout::Command => action.to_vec(),
        }
    }

    /// What the values are, for messages.
    pub const fn describe(self) -> &'static str {
        match self {
            ActionLayout::Setpoint => "six joint set points (radians) and the gripper command (0 … 255)",
            ActionLayout::Command => {
                "six joint set points (radians), six velocities (rad/s), six accelerations (rad/s²) and the gripper command (0 … 255)"
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_layouts_expand_to_the_command_layout_and_back() {
        let set: Vec<f32> = (1..=7).map(|v| v as f32).collect();
        let a = ActionLayout::Setpoint.expand(&set);
        assert_eq!(&a[..6], &set[..6]);
        assert!(a[6..18].iter().all(|&v| v == 0.0));
        assert_eq!(a[18], 7.0);
        assert_eq!(ActionLayout::Setpoint.compact(&a), set);
        let full: Vec<f32> = (1..=19).map(|v| v as f32).collect();
        let a = ActionLayout::Command.expand(&full);
        assert_eq!(ActionLayout::Command.compact(&a), full);
        assert_eq!(ActionLayout::of_len(7), Some(ActionLayout::Setpoint));
        assert_eq!(ActionLayout::of_len(19), Some(ActionLayout::Command));
        assert_eq!(ActionLayout::of_len(6), None);
    }
}
