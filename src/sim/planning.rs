//! Planned motions in the cell: the planner ([`crate::motion::plan`]) on the cell's MuJoCo
//! geometry ([`SceneChecker`](super::collision::SceneChecker)), its reasons turned into typed [`Failure`]s.
//!
//! | planner reason | failure kind |
//! |---|---|
//! | `start_in_collision` | [`FailureKind::StartInCollision`] |
//! | `goal_in_collision` | [`FailureKind::GoalInCollision`] |
//! | `no_goal` (no IK solution, or none inside the joint bounds) | [`FailureKind::Unreachable`] |
//! | `search_exhausted`, `time_cap` | [`FailureKind::NoPath`] |
//! | `invalid_query` (a bad setting or start: a bug of the caller) | [`FailureKind::Other`] |

use crate::failure::{Failure, FailureKind};
use crate::motion::plan::{FastChecks, GoalSet, PlanError, PlanFailure, PlannedMotion, PlannerConfig, plan};

/// The failure kind of a planner reason (see the module table).
pub fn failure_kind(reason: &PlanFailure) -> FailureKind {
    match reason {
        PlanFailure::StartInCollision { .. } => FailureKind::StartInCollision,
        PlanFailure::GoalInCollision { .. } => FailureKind::GoalInCollision,
        PlanFailure::NoGoal { .. } => FailureKind::Unreachable,
        PlanFailure::SearchExhausted { .. } | PlanFailure::TimeCap { .. } => FailureKind::NoPath,
        PlanFailure::InvalidQuery { .. } => FailureKind::Other,
    }
}

/// A planner error as a typed [`Failure`]: the kind of its reason, and its message followed by
/// the attempt's cost.
pub fn plan_failure(e: &PlanError) -> Failure {
    Failure::new(
        failure_kind(&e.reason),
        format!(
            "{} (planning: {:.1} ms, {} checks)",
            e.reason,
            e.stats.planning_time.as_secs_f64() * 1e3,
            e.stats.collision_checks
        ),
    )
}

/// Plans the arm from `start` to any of `goals` (radians) against the checker's snapshot of the
/// cell (a [`SceneChecker`](super::collision::SceneChecker), or one wrapping it with
/// allowances). Logs each plan at debug level (query, time, nodes, path length, duration).
///
/// # Errors
/// The planner's [`PlanError`] when there is no motion ([`plan_failure`] makes it a typed
/// [`Failure`]; a leaf adds what to change).
pub fn plan_in_cell<C: FastChecks + ?Sized>(
    checker: &mut C,
    start: &[f64; 6],
    goals: &GoalSet,
    config: &PlannerConfig,
) -> Result<PlannedMotion, PlanError> {
    match plan(checker, start, goals, config) {
        Ok(m) => {
            tracing::debug!(target: "macrotree::plan", goals = goals.len(), stats = %m.stats.summary(), "planned");
            Ok(m)
        }
        Err(e) => {
            tracing::debug!(target: "macrotree::plan", reason = e.reason.name(), stats = %e.stats.summary(), "no plan: {e}");
            Err(e)
        }
    }
}
