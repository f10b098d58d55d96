//! What to change when a leaf's motion cannot be planned: one `help:` for each planner reason,
//! naming the leaf's parameter, the object in the way or the goal, as the loader's diagnostics
//! do. Made from the typed reason and the colliding pairs, never from a message's text.

use crate::kinds::PlanBudget;
use crate::motion::plan::{Collision, PlanFailure, PlannerConfig, SearchBudget};
use crate::sim::ARM_PREFIX;

/// Prefix of the gripper's bodies and geoms in the cell.
const GRIPPER_PREFIX: &str = "gripper/";

/// The motion a leaf planned, for advice that names what the leaf can change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PlanFor {
    /// A `reach` to a pose (a pre-grasp, a point, a spot), straight down, tilted or from a side.
    Reach,
    /// A `carry` or `place` transfer to the pre-place pose, `lift` metres (the leaf's `lift:`)
    /// above the surface.
    Transfer {
        /// The leaf's `lift:`, metres.
        lift: f64,
    },
    /// A `move_joints` or `home` to fixed joint angles.
    Joints,
}

impl PlanFor {
    /// The name used in messages (`reach`, `carry transfer`, `move_joints`).
    pub(crate) fn name(self) -> &'static str {
        match self {
            PlanFor::Reach => "reach",
            PlanFor::Transfer { .. } => "carry transfer",
            PlanFor::Joints => "move_joints",
        }
    }
}

/// What moves in a colliding pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mover {
    /// One of the arm's links.
    Arm,
    /// The gripper: its base, pads or fingers.
    Fingers,
    /// The block the gripper holds.
    HeldBlock,
}

fn mover(c: &Collision) -> Mover {
    if c.a.starts_with(ARM_PREFIX) {
        Mover::Arm
    } else if c.a.starts_with(GRIPPER_PREFIX) {
        Mover::Fingers
    } else {
        Mover::HeldBlock
    }
}

/// The scene object a pair's second part belongs to (`bin` for `bin/floor`).
fn object(c: &Collision) -> &str {
    c.b.split('/').next().unwrap_or(&c.b)
}

/// The `help:` for a plan of `what` that failed with `reason` under the leaf's `budget`; `None`
/// for a malformed query (a bug of the caller, with nothing for the user to change).
pub(crate) fn plan_help(reason: &PlanFailure, what: PlanFor, budget: PlanBudget) -> Option<String> {
    match reason {
        PlanFailure::InvalidQuery { .. } => None,
        PlanFailure::StartInCollision { collisions } => Some(match collisions.first() {
            Some(c) => format!(
                "the motion starts with {} touching `{}`: end the leaf before it clear of `{}` (a higher `lift:`, or a `reach` above it first)",
                part(mover(c)),
                object(c),
                object(c)
            ),
            None => "end the leaf before this one clear of the objects around the gripper".into(),
        }),
        PlanFailure::NoGoal { .. } => Some(match what {
            PlanFor::Joints => "choose joint angles inside the UR5e's joint limits".into(),
            _ => "move the goal within the arm's reach (about 0.85 m from its base, not straight above it) or lower it".into(),
        }),
        PlanFailure::GoalInCollision { collisions, .. } => Some(match collisions.first() {
            Some((c, _)) => goal_blocked(c, what),
            None => "move the goal away from the objects around it".into(),
        }),
        PlanFailure::SearchExhausted { spent, blocking, .. } => {
            let around = blocking
                .first()
                .map_or(String::new(), |(c, _)| format!(" around `{}`", object(c)));
            Some(match spent {
                SearchBudget::Checks(n) => format!(
                    "raise the leaf's `max_checks:` (now {n}; at most 10000000) if the motion should exist, or move what is in the way{around}"
                ),
                SearchBudget::Iterations(_) | SearchBudget::Nodes(_) => format!(
                    "add a waypoint (a `reach` or `move_joints` leaf) that leads{around}, or move what is in the way (now {} checks allowed; `max_checks:` raises it)",
                    budget.max_checks.unwrap_or(PlannerConfig::default().max_checks)
                ),
            })
        }
        PlanFailure::TimeCap { cap_s, .. } => Some(format!(
            "the machine was too slow for the cap: raise the leaf's `plan_time_cap:` (now {cap_s} s; at most 60)"
        )),
    }
}

fn part(m: Mover) -> &'static str {
    match m {
        Mover::Arm => "the arm",
        Mover::Fingers => "the fingers",
        Mover::HeldBlock => "the held block",
    }
}

/// Advice for goal configurations blocked first by `c`.
fn goal_blocked(c: &Collision, what: PlanFor) -> String {
    let o = object(c);
    match (mover(c), what) {
        (_, PlanFor::Joints) => format!(
            "the joint angles themselves put {} into `{o}`: choose other angles, or move `{o}`",
            part(mover(c))
        ),
        (Mover::Arm, PlanFor::Transfer { lift }) => format!(
            "the arm reaches down into `{o}` above the goal: raise the leaf's `lift:` (now {lift} m) so it comes in higher, or move the goal farther from `{o}`"
        ),
        (Mover::Arm, PlanFor::Reach) => format!(
            "the arm cannot take that pose without touching `{o}`: move the target (or `{o}`), or try another `approach:`"
        ),
        (Mover::Fingers, _) => format!(
            "the open fingers would touch `{o}` at the goal: move the goal farther from `{o}`'s sides or walls"
        ),
        (Mover::HeldBlock, PlanFor::Transfer { lift }) => format!(
            "the held block would meet `{o}` above the goal: choose a goal clear of `{o}` (`macrotree validate` checks spots and goals against fixed obstacles), or raise `lift:` (now {lift} m) to pass over it"
        ),
        (Mover::HeldBlock, PlanFor::Reach) => {
            format!("the held block would meet `{o}` at the goal: choose a goal clear of `{o}`")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(a: &str, b: &str) -> Collision {
        Collision {
            a: a.into(),
            b: b.into(),
            distance: -0.01,
        }
    }

    fn blocked(a: &str, b: &str) -> PlanFailure {
        PlanFailure::GoalInCollision {
            goals: 4,
            out_of_bounds: 0,
            in_collision: 4,
            collisions: vec![(pair(a, b), 4)],
        }
    }

    #[test]
    fn a_transfer_blocked_by_the_arm_says_to_raise_lift_with_its_value() {
        let help = plan_help(
            &blocked("ur5e/forearm_link", "bin/floor"),
            PlanFor::Transfer { lift: 0.15 },
            PlanBudget::default(),
        )
        .unwrap();
        assert!(
            help.contains("`lift:` (now 0.15 m)") && help.contains("`bin`"),
            "{help}"
        );
    }

    #[test]
    fn a_goal_blocked_by_the_held_block_names_the_obstacle_not_lift_for_a_reach() {
        let help = plan_help(&blocked("red", "wall"), PlanFor::Reach, PlanBudget::default()).unwrap();
        assert!(
            help.contains("clear of `wall`") && !help.contains("lift"),
            "{help}"
        );
        let help = plan_help(
            &blocked("gripper/left_pad1", "bin/wall_px"),
            PlanFor::Reach,
            PlanBudget::default(),
        )
        .unwrap();
        assert!(help.contains("fingers") && help.contains("`bin`"), "{help}");
    }

    #[test]
    fn a_spent_search_names_the_budget_to_raise_with_its_current_value() {
        let spent = |spent| PlanFailure::SearchExhausted {
            spent,
            iterations: 10,
            nodes: 20,
            checks: 500,
            blocking: vec![(pair("ur5e/wrist_1_link", "shelf_top"), 9)],
        };
        let help = plan_help(
            &spent(SearchBudget::Checks(500)),
            PlanFor::Reach,
            PlanBudget::default(),
        )
        .unwrap();
        assert!(
            help.contains("`max_checks:` (now 500") && help.contains("`shelf_top`"),
            "{help}"
        );
        let budget = PlanBudget {
            max_checks: Some(7000),
            time_cap: None,
        };
        let help = plan_help(&spent(SearchBudget::Iterations(100)), PlanFor::Joints, budget).unwrap();
        assert!(
            help.contains("waypoint") && help.contains("now 7000 checks"),
            "{help}"
        );
    }

    #[test]
    fn every_reason_a_user_can_act_on_has_help_and_a_malformed_query_has_none() {
        let b = PlanBudget::default();
        let reasons = [
            PlanFailure::StartInCollision { collisions: vec![] },
            PlanFailure::NoGoal {
                reason: "no IK".into(),
            },
            blocked("ur5e/upper_arm_link", "shelf_low"),
            PlanFailure::TimeCap {
                cap_s: 2.0,
                iterations: 3,
            },
        ];
        for r in &reasons {
            for what in [PlanFor::Reach, PlanFor::Transfer { lift: 0.2 }, PlanFor::Joints] {
                assert!(plan_help(r, what, b).is_some_and(|h| !h.is_empty()), "{r}");
            }
        }
        let bad = PlanFailure::InvalidQuery { reason: "NaN".into() };
        assert_eq!(plan_help(&bad, PlanFor::Reach, b), None);
    }
}
