//! [`PlanningTally`]: what motion checking and planning cost in one episode, and its
//! [`PlanCounts`].

use std::time::{Duration, Instant};

use serde::Serialize;

/// What motion checking and planning cost in one episode (reported per episode in `run --json`
/// and sweep JSONL).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PlanningTally {
    /// Leaf motions checked along their length before they ran.
    pub motions_checked: u32,
    /// Motions that would have collided and went to the planner.
    pub plans: u32,
    /// Plans that failed (the leaf failed with the planner's reason).
    pub plan_failures: u32,
    /// Straight segments (Cartesian approach, lift, set-down) that the check found touching
    /// something not allowed; they run anyway (see docs/motion.md).
    pub straight_contacts: u32,
    /// Configurations given to the collision checker, checks and plans together.
    pub collision_checks: u64,
    /// Wall-clock time spent checking and planning, seconds (for reports only).
    pub planning_wall_s: f64,
}

/// The counts of a [`PlanningTally`] (no wall-clock term: a sweep's JSONL stays the same for
/// any `--jobs` and machine).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct PlanCounts {
    /// Leaf motions checked along their length before they ran.
    pub motions_checked: u32,
    /// Motions that would have collided and went to the planner.
    pub plans: u32,
    /// Plans that failed.
    pub plan_failures: u32,
    /// Straight segments found touching something not allowed (they ran anyway).
    pub straight_contacts: u32,
}

impl PlanningTally {
    /// The counts, without the wall-clock time.
    pub fn counts(&self) -> PlanCounts {
        PlanCounts {
            motions_checked: self.motions_checked,
            plans: self.plans,
            plan_failures: self.plan_failures,
            straight_contacts: self.straight_contacts,
        }
    }

    pub(super) fn add_time(&mut self, t: Duration) {
        self.planning_wall_s += t.as_secs_f64();
    }

    /// Counts `checks` collision checks and the time since `since`.
    pub(super) fn add_checks(&mut self, checks: u64, since: Instant) {
        self.collision_checks += checks;
        self.add_time(since.elapsed());
    }
}
