//! Why a planning query has no motion: a typed reason per cause, with the names of what
//! collides, for messages a person can act on.

use std::fmt;

use super::checker::Collision;
use super::stats::PlanStats;

/// The cause of a failed plan. Each has a stable name ([`PlanFailure::name`]) a higher layer maps
/// to a failure kind.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanFailure {
    /// The query itself is malformed: a non-finite or out-of-bounds start, or a bad setting.
    InvalidQuery {
        /// What is wrong, and what to do.
        reason: String,
    },
    /// The arm is in collision where it starts.
    StartInCollision {
        /// The colliding pairs at the start (may be empty if the checker cannot name them).
        collisions: Vec<Collision>,
    },
    /// No goal configuration exists: no IK solution, or none inside the joint bounds.
    NoGoal {
        /// Why: IK's reason, or how many goals lay outside the bounds.
        reason: String,
    },
    /// Every goal configuration is in collision.
    GoalInCollision {
        /// Goal configurations offered.
        goals: usize,
        /// Of those, outside the planner's joint bounds.
        out_of_bounds: usize,
        /// Of those, in collision.
        in_collision: usize,
        /// The colliding pairs, most frequent first, with how many goals each blocks.
        collisions: Vec<(Collision, usize)>,
    },
    /// The search used its iteration, node or collision-check budget without connecting start
    /// and goal (deterministic: the same query always ends here).
    SearchExhausted {
        /// The budget that ran out.
        spent: SearchBudget,
        /// Iterations run.
        iterations: usize,
        /// Nodes in both trees.
        nodes: usize,
        /// Collision checks of the whole query.
        checks: u64,
        /// The pairs that blocked the search most (sampled from blocked extensions), most
        /// frequent first, with their counts.
        blocking: Vec<(Collision, usize)>,
    },
    /// The wall-clock safety cap ended the search: the only outcome that depends on the
    /// machine's speed (the budgets of [`PlanFailure::SearchExhausted`] normally end a search
    /// first).
    TimeCap {
        /// The cap, seconds.
        cap_s: f64,
        /// Iterations run before it.
        iterations: usize,
    },
}

/// Which of a search's budgets ran out, with its limit ([`super::PlannerConfig`]'s
/// `max_iterations`, `max_nodes` or `max_checks`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SearchBudget {
    /// The iteration budget.
    Iterations(usize),
    /// The node budget (both trees together).
    Nodes(usize),
    /// The collision-check budget of the whole query: the start, the goals and the direct
    /// segments are checked first and count against it, so a small budget can leave the search
    /// none at all. Checks refused past it are not collisions.
    Checks(u64),
}

impl fmt::Display for SearchBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SearchBudget::Iterations(n) => write!(f, "its iteration budget ({n}) ran out"),
            SearchBudget::Nodes(n) => write!(f, "its node budget ({n}) ran out"),
            SearchBudget::Checks(n) => write!(
                f,
                "its collision-check budget ({n}, `max_checks`) ran out — raise it if the motion should exist"
            ),
        }
    }
}

impl PlanFailure {
    /// The stable name of the cause: `invalid_query`, `start_in_collision`, `no_goal`,
    /// `goal_in_collision`, `search_exhausted`, `time_cap`.
    pub fn name(&self) -> &'static str {
        match self {
            PlanFailure::InvalidQuery { .. } => "invalid_query",
            PlanFailure::StartInCollision { .. } => "start_in_collision",
            PlanFailure::NoGoal { .. } => "no_goal",
            PlanFailure::GoalInCollision { .. } => "goal_in_collision",
            PlanFailure::SearchExhausted { .. } => "search_exhausted",
            PlanFailure::TimeCap { .. } => "time_cap",
        }
    }
}

fn list(c: &[Collision]) -> String {
    if c.is_empty() {
        return "(the checker names no pair)".into();
    }
    c.iter()
        .take(4)
        .map(Collision::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

fn counted(c: &[(Collision, usize)]) -> String {
    if c.is_empty() {
        return "(the checker names no pair)".into();
    }
    c.iter()
        .take(4)
        .map(|(c, n)| format!("{} ×{n}", c.pair()))
        .collect::<Vec<_>>()
        .join(", ")
}

impl fmt::Display for PlanFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanFailure::InvalidQuery { reason } => write!(f, "invalid planning query: {reason}"),
            PlanFailure::StartInCollision { collisions } => {
                write!(f, "the start configuration is in collision: {}", list(collisions))
            }
            PlanFailure::NoGoal { reason } => write!(f, "the goal is unreachable: {reason}"),
            PlanFailure::GoalInCollision {
                goals,
                out_of_bounds,
                in_collision,
                collisions,
            } => write!(
                f,
                "every goal configuration is blocked ({goals} IK solutions: {in_collision} in collision, {out_of_bounds} outside the joint bounds): {}",
                counted(collisions)
            ),
            PlanFailure::SearchExhausted {
                spent,
                iterations,
                nodes,
                checks,
                blocking,
            } => write!(
                f,
                "no collision-free path found: {spent} after {iterations} iterations ({nodes} nodes, {checks} collision checks); blocked most by {}",
                counted(blocking)
            ),
            PlanFailure::TimeCap { cap_s, iterations } => write!(
                f,
                "planning stopped at its {:.0} ms time cap after {iterations} iterations",
                cap_s * 1e3
            ),
        }
    }
}

/// A failed plan: its reason and what the attempt cost.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanError {
    /// Why there is no motion.
    pub reason: PlanFailure,
    /// The attempt's statistics (boxed: keeps the error small).
    pub stats: Box<PlanStats>,
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.reason.fmt(f)
    }
}

impl std::error::Error for PlanError {}

/// Tallies colliding pairs over several configurations: each pair once per configuration, most
/// frequent first, ties by name (deterministic).
pub(crate) fn tally(per_config: impl IntoIterator<Item = Vec<Collision>>) -> Vec<(Collision, usize)> {
    let mut out: Vec<(Collision, usize)> = Vec::new();
    for cs in per_config {
        let mut seen: Vec<String> = Vec::new();
        for c in cs {
            let pair = c.pair();
            if seen.contains(&pair) {
                continue;
            }
            seen.push(pair.clone());
            match out.iter_mut().find(|(o, _)| o.pair() == pair) {
                Some((o, n)) => {
                    *n += 1;
                    if c.distance < o.distance {
                        *o = c;
                    }
                }
                None => out.push((c, 1)),
            }
        }
    }
    out.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.pair().cmp(&b.0.pair())));
    out
}
