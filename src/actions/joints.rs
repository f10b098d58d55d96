//! `home` and `move_joints`: joint-space moves to a named or given configuration.

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::plan_help::PlanFor;
use super::planning::{check_motion, describe, plan_motion};
use crate::failure::FailureKind;
use crate::kinds::PlanBudget;
use crate::motion::plan::{GoalSet, PlannerConfig};
use crate::motion::{JointMove, MotionLimits};

/// How many times the planner's default check budget a joint move without its own
/// `max_checks` gets for a second search (a new seed) when the first runs out: a wrist wound a turn
/// from its goal leaves a narrow passage past the forearm that one seed may miss.
const SECOND_SEARCH_BUDGET: u64 = 3;

/// Moves the arm in joint space to fixed joint angles (radians).
pub struct MoveJoints {
    goal_q: [f64; 6],
    budget: PlanBudget,
    arrival: Arrival,
}

impl MoveJoints {
    /// A joint move to `goal_q` (radians).
    pub fn new(goal_q: [f64; 6]) -> Self {
        Self {
            goal_q,
            budget: PlanBudget::default(),
            arrival: Arrival::default(),
        }
    }

    /// The planner, when the direct move collides, may spend at most the `budget`'s collision
    /// checks and wall-clock time (`None`: the defaults of the leaves); past them the move fails
    /// with `no_path`.
    pub fn with_budget(mut self, budget: PlanBudget) -> Self {
        self.budget = budget;
        self
    }

    /// A joint move to the UR5e home configuration.
    pub fn home() -> Self {
        Self::new(crate::sim::HOME_Q)
    }
}

impl MacroAction for MoveJoints {
    fn start(&mut self, cell: &mut Cell) -> Result<(), crate::failure::Failure> {
        let from = cell.arm_setpoint();
        let mv = JointMove::new(from, self.goal_q, &MotionLimits::default());
        if let Some((_, pairs)) = check_motion(cell, &[&mv], &[], false) {
            // The straight joint move would collide: plan around whatever is in the way to
            // exactly these joint angles.
            tracing::debug!(target: "macrotree::actions", "move_joints: the direct joint move would touch {}; planning", describe(&pairs));
            let goals = GoalSet::configs(vec![self.goal_q]);
            let motion = match plan_motion(cell, PlanFor::Joints, &from, &goals, self.budget, None) {
                Err(e) if e.kind == FailureKind::NoPath && self.budget.max_checks.is_none() => {
                    let checks = SECOND_SEARCH_BUDGET * PlannerConfig::default().max_checks;
                    tracing::debug!(target: "macrotree::actions", "move_joints: {e}; searching once more with {checks} checks");
                    let budget = PlanBudget {
                        max_checks: Some(checks),
                        ..self.budget
                    };
                    plan_motion(cell, PlanFor::Joints, &from, &goals, budget, None)?
                }
                planned => planned?,
            };
            cell.track(Box::new(motion.trajectory));
            return Ok(());
        }
        cell.track(Box::new(mv));
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        self.arrival.progress(cell, &self.goal_q)
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        self.arrival.waiting_for(cell, &self.goal_q)
    }
}
