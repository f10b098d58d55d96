//! The arm's motions checked and, when blocked, planned: every leaf motion is first tried as it
//! always was (a joint move, a straight line, a detour over an object) and checked along its
//! length with the cell's [`SceneChecker`]; only a motion that would collide is replaced by a
//! planned one ([`crate::sim::planning::plan_in_cell`]), so free-space moves stay exactly as
//! they were.
//!
//! Allowances (what may touch, see docs/motion.md "Contact allowances"):
//! - pairs already closer than the margin at the start of a motion may stay so during it (a block
//!   resting on the table as it is lifted, the fingers next to a block just released): the
//!   motion is blocked only by a pair that is not touching at its start;
//! - a straight final segment (a Cartesian `reach`, the carry's lift and set-down) counts only
//!   real contact (penetration), not the clearance margin, and contact with the object the leaf
//!   goes to (the reach's target, the carry's destination: a container's floor, not its walls)
//!   is intended;
//! - a planned motion keeps the full margin from everything except the pairs touching at its
//!   start, and ends at the pre-grasp or pre-place pose, never in contact;
//! - the look-ahead at a pick's descent from a pre-grasp ([`look_ahead_clear`]) allows nothing
//!   for touching at the start and keeps the arm's links the margin from everything but the
//!   block; a descent onto an object that would really run the arm's links into something else
//!   is refused before it moves (`reach`, kind `blocked`).

use std::time::{Duration, Instant};

use super::cell::Cell;
use super::plan_help::{PlanFor, plan_help};
use crate::failure::Failure;
use crate::kinds::PlanBudget;
use crate::motion::Trajectory;
use crate::motion::plan::edge::{Resolution, steps};
use crate::motion::plan::{
    Collision, CollisionChecker, FastChecks, GoalSet, JointSpare, PlannedMotion, PlannerConfig,
};
use crate::sim::collision::SceneChecker;

/// True when the robot–scene pair `c` names object `name` (the object itself or one of its
/// parts, e.g. `bin/wall_px`).
pub(crate) fn names(c: &Collision, name: &str) -> bool {
    let is = |s: &str| s == name || s.strip_prefix(name).is_some_and(|r| r.starts_with('/'));
    is(&c.a) || is(&c.b)
}

/// A checker that lets some pairs touch: the pairs touching at a motion's start and contact
/// with the objects the leaf means to reach.
pub(crate) struct Allowing<'a> {
    inner: &'a mut SceneChecker,
    /// Pairs `(a, b)` allowed to stay closer than the margin.
    pairs: Vec<(String, String)>,
    /// Objects contact with which is intended.
    intended: Vec<String>,
    /// Count only penetration, not the clearance margin.
    contact_only: bool,
    /// Configurations checked.
    pub(crate) checks: u64,
}

impl<'a> Allowing<'a> {
    /// Allows on `inner` the pairs touching at `start` and contact with `intended` objects;
    /// `contact_only` ignores the margin (straight final segments).
    pub(crate) fn new(
        inner: &'a mut SceneChecker,
        start: &[f64; 6],
        intended: &[String],
        contact_only: bool,
    ) -> Self {
        let pairs = inner.collisions(start).into_iter().map(|c| (c.a, c.b)).collect();
        Self {
            inner,
            pairs,
            intended: intended.to_vec(),
            contact_only,
            checks: 1,
        }
    }

    /// Allows on `inner` nothing for touching at the start, only contact with `intended`
    /// objects (the start is counted as one check, as in [`Allowing::new`]).
    fn strict(inner: &'a mut SceneChecker, intended: &[String]) -> Self {
        Self {
            inner,
            pairs: Vec::new(),
            intended: intended.to_vec(),
            contact_only: false,
            checks: 1,
        }
    }

    fn counts(&self, c: &Collision) -> bool {
        let near_only = self.contact_only && c.distance >= 0.0;
        let allowed = self.pairs.iter().any(|(a, b)| *a == c.a && *b == c.b);
        let intended = self.intended.iter().any(|o| names(c, o));
        !(near_only || allowed || intended)
    }

    /// The pairs that count at `q`.
    pub(crate) fn blocking(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        self.checks += 1;
        // What keeps the margin from everything by the screen's bounds is free whatever is
        // allowed; else one MuJoCo pass names the pairs.
        if self.inner.screen(q) == Some(true) {
            return Vec::new();
        }
        let mut all = self.inner.collisions(q);
        all.retain(|c| self.counts(c));
        all
    }
}

impl CollisionChecker for Allowing<'_> {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        self.blocking(q).is_empty()
    }

    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        let mut all = self.inner.collisions(q);
        all.retain(|c| self.counts(c));
        all
    }
}

impl FastChecks for Allowing<'_> {
    /// The inner checker's "certainly free" (what keeps the margin from everything is free
    /// whatever is allowed; its "blocked" may be an allowed pair). Counted as a check.
    fn screen(&mut self, q: &[f64; 6]) -> Option<bool> {
        let free = self.inner.screen(q) == Some(true);
        self.checks += u64::from(free);
        free.then_some(true)
    }

    /// The inner checker's "certainly free" and its spare (what keeps the margin and more from
    /// everything is free whatever is allowed). Counted as a check.
    fn screen_spare(&mut self, q: &[f64; 6], caps: &JointSpare) -> (Option<bool>, JointSpare) {
        let (verdict, spare) = self.inner.screen_spare(q, caps);
        let free = verdict == Some(true);
        self.checks += u64::from(free);
        (free.then_some(true), if free { spare } else { JointSpare::NONE })
    }
}

/// Resolution of the check of a leaf's direct motion: samples at most 0.05 rad of any joint
/// apart, and no displacement bound (the planner's edges add one of 1 cm). The check decides
/// whether to plan; it is coarser than the planner's own edges so that free-space moves cost
/// little beside the physics (`macrotree bench`), at the price of possibly missing a graze
/// between two samples.
pub(crate) const DIRECT_RESOLUTION: Resolution = Resolution {
    joint: 0.05,
    displacement: f64::INFINITY,
    lever_arms: [0.0; 6],
};

/// Configurations along `traj` from its start to its end, no two consecutive ones farther apart
/// than `res` (time-subdivided where the joint path bends).
fn samples(traj: &dyn Trajectory, res: &Resolution) -> Vec<[f64; 6]> {
    const COARSE: usize = 4;
    let d = traj.duration();
    let at = |t: f64| if t >= d { traj.end() } else { traj.sample(t).0 };
    let mut out = vec![at(0.0)];
    let (mut t0, mut q0) = (0.0, out[0]);
    for i in 1..=COARSE {
        let t1 = d * i as f64 / COARSE as f64;
        let q1 = at(t1);
        let n = steps(&q0, &q1, res).min(4096);
        for k in 1..n {
            out.push(at(t0 + (t1 - t0) * k as f64 / n as f64));
        }
        out.push(q1);
        (t0, q0) = (t1, q1);
    }
    out
}

/// The first configuration along `legs` (motions run one after the other; each leg's first
/// sample skipped, unless `check_start` and it is the first leg) where `allow` finds pairs that
/// `keep` counts, with those pairs; `None` when there is none.
fn first_blocked(
    allow: &mut Allowing,
    legs: &[&dyn Trajectory],
    check_start: bool,
    keep: impl Fn(&Collision) -> bool,
) -> Option<([f64; 6], Vec<Collision>)> {
    for (i, leg) in legs.iter().enumerate() {
        let skip = usize::from(i > 0 || !check_start);
        for q in samples(*leg, &DIRECT_RESOLUTION).into_iter().skip(skip) {
            let mut b = allow.blocking(&q);
            b.retain(&keep);
            if !b.is_empty() {
                return Some((q, b));
            }
        }
    }
    None
}

/// True for a pair whose moving part is one of the arm's links (not the fingers or a held block).
pub(crate) fn arm_link(c: &Collision) -> bool {
    c.a.starts_with(crate::sim::ARM_PREFIX)
}

/// The first configuration along `legs` (motions run one after the other) where something
/// that is not allowed touches, with the pairs; `None` when the motion is free or the cell has no
/// checker. Straight final segments pass `contact_only`; `intended` names the objects the leaf
/// goes to.
pub(crate) fn check_motion(
    cell: &mut Cell,
    legs: &[&dyn Trajectory],
    intended: &[String],
    contact_only: bool,
) -> Option<([f64; 6], Vec<Collision>)> {
    let t = Instant::now();
    let start = legs.first()?.sample(0.0).0;
    let checker = cell.checker()?;
    let mut allow = Allowing::new(checker, &start, intended, contact_only);
    let hit = first_blocked(&mut allow, legs, false, |_| true);
    let checks = allow.checks;
    let tally = cell.planning_mut();
    tally.motions_checked += 1;
    tally.add_checks(checks, t);
    hit
}

/// The pairs a pick's straight descent `mv` (a look-ahead from a pre-grasp) would bring too
/// close, but the `intended` objects: real contact of anything, and the arm's links (`ur5e/…`;
/// not the fingers, which straddle the block beside its neighbours) closer than the checker's
/// clearance margin. Nothing is allowed for touching at the start. `None` when it is clear. Its
/// checks count in the tally's `collision_checks`, not as a motion checked.
pub(crate) fn look_ahead_clear(
    cell: &mut Cell,
    mv: &dyn Trajectory,
    intended: &[String],
) -> Option<Vec<Collision>> {
    let t = Instant::now();
    let checker = cell.checker()?;
    let mut allow = Allowing::strict(checker, intended);
    let hit = first_blocked(&mut allow, &[mv], true, |c| c.distance < 0.0 || arm_link(c));
    let checks = allow.checks;
    cell.planning_mut().add_checks(checks, t);
    hit.map(|(_, pairs)| pairs)
}

/// Checks a straight segment (`what`: "descent", "lift", "set-down") along its length, only
/// real contact counting and contact with `intended` objects allowed; a hit is logged and
/// counted in the tally, and the segment runs anyway (the leaf asked for a straight line, and
/// its physics is what it was before the check) unless the caller refuses it: the pairs at the
/// first configuration that touches, `None` when it is free.
pub(crate) fn check_straight(
    cell: &mut Cell,
    what: &str,
    mv: &dyn Trajectory,
    intended: &[String],
) -> Option<Vec<Collision>> {
    let (q, pairs) = check_motion(cell, &[mv], intended, true)?;
    let p = crate::motion::fk(&q).translation.vector;
    tracing::debug!(target: "macrotree::plan", "the straight {what} touches {} (pinch at ({:.3}, {:.3}, {:.3}) m)", describe(&pairs), p.x, p.y, p.z);
    cell.planning_mut().straight_contacts += 1;
    Some(pairs)
}

/// Pairs as text for messages: `a–b (−1.2 mm)`, at most four.
pub(crate) fn describe(pairs: &[Collision]) -> String {
    let mut s: Vec<String> = pairs
        .iter()
        .take(4)
        .map(|c| format!("{} with {} ({:+.1} mm)", c.a, c.b, c.distance * 1e3))
        .collect();
    if pairs.len() > 4 {
        s.push(format!("{} more", pairs.len() - 4));
    }
    s.join(", ")
}

/// The planner's settings for the `plans`-th plan of an episode under a leaf with `budget`:
/// seeded by the count (an episode replays the same plans), the leaf's check budget and time
/// cap where it sets them, the planner's defaults otherwise.
pub(crate) fn leaf_config(budget: PlanBudget, plans: u32) -> PlannerConfig {
    let defaults = PlannerConfig::default();
    PlannerConfig {
        seed: 0x6d61_6372_6f74_7265 ^ u64::from(plans),
        time_cap: Some(budget.time_cap.map_or(LEAF_TIME_CAP, Duration::from_secs_f64)),
        max_checks: budget.max_checks.unwrap_or(defaults.max_checks),
        ..defaults
    }
}

/// Wall-clock safety cap of a plan under the leaves unless the leaf sets `plan_time_cap`, seconds: the planner's deterministic
/// collision-check budget ([`PlannerConfig::max_checks`], 0.1–0.2 s of checks) ends a search long
/// before it, so the cap only fires on a machine stalled by 10× or more; it is the only
/// outcome of a plan that depends on the machine (`no_path`, "planning stopped at its time cap").
pub(crate) const LEAF_TIME_CAP: Duration = Duration::from_secs(2);

/// Plans the arm from `start` to any of `goals` in the cell, the pairs touching at `start`
/// allowed, within the leaf's `budget` (its `max_checks` and `plan_time_cap` parameters,
/// range-checked by the tree reader; `None`: the planner's check budget and
/// [`LEAF_TIME_CAP`]), the pinch at most `tool_speed` m/s along the timed path (`None`: the
/// joint limits alone; a carry passes its `speed`, the held block's); logs the query; counts
/// it in the tally. The cell's `n`-th plan of the episode is seeded with `n`, so an episode
/// replays the same plans.
///
/// # Errors
/// The planner's typed failure ([`crate::sim::planning::plan_failure`]).
pub(crate) fn plan_motion(
    cell: &mut Cell,
    what: PlanFor,
    start: &[f64; 6],
    goals: &GoalSet,
    budget: PlanBudget,
    tool_speed: Option<f64>,
) -> Result<PlannedMotion, Failure> {
    let t = Instant::now();
    let config = PlannerConfig {
        tool_speed: tool_speed.unwrap_or(f64::INFINITY),
        ..leaf_config(budget, cell.planning().plans)
    };
    let sim_time = cell.sim().time();
    let Some(checker) = cell.checker() else {
        return Err(Failure::new(
            crate::failure::FailureKind::NoPath,
            format!(
                "{}: the direct motion collides and the cell has no collision checker to plan with",
                what.name()
            ),
        ));
    };
    let mut allow = Allowing::new(checker, start, &[], false);
    let result = crate::sim::planning::plan_in_cell(&mut allow, start, goals, &config).map_err(|e| {
        let f = crate::sim::planning::plan_failure(&e);
        match plan_help(&e.reason, what, budget) {
            Some(help) => f.with_help(&help),
            None => f,
        }
    });
    let checks = allow.checks;
    let tally = cell.planning_mut();
    tally.plans += 1;
    tally.collision_checks += checks;
    tally.add_time(t.elapsed());
    match &result {
        Ok(m) => {
            tracing::debug!(target: "macrotree::plan", sim_time, "plan {}: {} goals; {}", what.name(), goals.len(), m.stats.summary());
        }
        Err(f) => {
            tally.plan_failures += 1;
            tracing::debug!(target: "macrotree::plan", sim_time, "plan {}: {} goals; failed: {f}", what.name(), goals.len());
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leaf_budget_sets_the_check_budget_and_the_time_cap_of_its_plans() {
        let defaults = PlannerConfig::default();
        let none = leaf_config(PlanBudget::default(), 0);
        assert_eq!(none.time_cap, Some(LEAF_TIME_CAP));
        assert_eq!(none.max_checks, defaults.max_checks);
        let set = leaf_config(
            PlanBudget {
                max_checks: Some(500),
                time_cap: Some(0.25),
            },
            3,
        );
        assert_eq!(set.time_cap, Some(Duration::from_millis(250)));
        assert_eq!(set.max_checks, 500);
        assert!(set.check().is_ok());
        // Each plan of an episode has its own seed, the same in every run.
        assert_ne!(set.seed, leaf_config(PlanBudget::default(), 4).seed);
        assert_eq!(set.seed, leaf_config(PlanBudget::default(), 3).seed);
        // The other settings are the planner's.
        assert_eq!(set.resolution, defaults.resolution);
        assert_eq!(set.shortcut_attempts, defaults.shortcut_attempts);
    }
}
