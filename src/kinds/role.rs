//! [`ActionRole`]: what an action kind does in the pick-and-place cycle, declared with the kind,
//! so that the episode's counters and checks and the faults follow any kind that plays the part
//! (a custom pick declared as a [`ActionRole::Grasp`] is counted, checked and faulted as a grasp).

use serde::Serialize;

/// What an action kind does in the pick-and-place cycle (declared with the kind:
/// [`Registry::declare_action_as`](super::Registry::declare_action_as)). The episode and the
/// faults act on the role, never on the kind's name.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ActionRole {
    /// None of the parts below: nothing is counted, checked or armed when it starts.
    #[default]
    Other,
    /// Moves the gripper to a place (`reach`): the `bump` fault pushes the block while one runs.
    Reach,
    /// Closes the gripper on a block (`grasp`): counted in the report's `grasp_attempts`, the
    /// tutorial's grasp checks are taken when it ends, and the `nudge` fault arms when it starts.
    Grasp,
    /// Carries the held block (`carry`): counted in the report's carries, and the `slip` and
    /// `late_bowl` faults arm when it starts.
    Carry,
    /// Opens the gripper to let the block go (`release`): the tutorial's checks note the opening.
    Release,
}
