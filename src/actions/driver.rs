//! [`MacroDriver`]: executes the tree's leaves on the simulated cell — macro actions through
//! their controllers, conditions as pure functions of the world snapshot.

use std::collections::HashMap;

use super::carry::Carry;
use super::cell::Cell;
use super::checks::ChecksRecorder;
use super::grasp::Grasp;
use super::joints::MoveJoints;
use super::macro_action::{MacroAction, Progress};
use super::reach::Reach;
use super::release::Release;
use crate::plan::LeafId;
use crate::runtime::{LeafDriver, LeafOutcome};
use crate::spec::{ActionLeaf, ConditionLeaf, Leaf};
use crate::world::conditions as cond;

/// A running macro action and when it must be done by.
struct Active {
    action: Box<dyn MacroAction>,
    deadline: f64,
    timeout: f64,
}

/// Counters the episode report needs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LeafCounters {
    /// Grasp leaves started.
    pub grasp_attempts: u32,
    /// Carry leaves started.
    pub carries: u32,
    /// Leaves halted.
    pub halts: u32,
}

/// Executes leaves against a [`Cell`].
pub struct MacroDriver<'a> {
    cell: &'a mut Cell,
    active: HashMap<LeafId, Active>,
    /// The tutorial checks, accumulated.
    pub checks: ChecksRecorder,
    /// Leaf counters.
    pub counters: LeafCounters,
    /// The reason of the last action that failed.
    pub last_failure: Option<String>,
}

impl<'a> MacroDriver<'a> {
    /// A driver acting on `cell`.
    pub fn new(cell: &'a mut Cell) -> Self {
        Self {
            cell,
            active: HashMap::new(),
            checks: ChecksRecorder::default(),
            counters: LeafCounters::default(),
            last_failure: None,
        }
    }

    /// The cell.
    pub fn cell(&mut self) -> &mut Cell {
        self.cell
    }

    /// Advances the physics by one control period and updates the checks.
    pub fn advance(&mut self) {
        self.cell.advance();
        let closed = self.cell.gripper_command() > 0.0;
        self.checks.on_tick(self.cell.world(), closed);
    }

    fn start_action(&mut self, leaf: &ActionLeaf) -> Box<dyn MacroAction> {
        match leaf {
            ActionLeaf::Reach(s) => Box::new(Reach::new(s.clone())),
            ActionLeaf::MoveJoints(s) => Box::new(MoveJoints::new(s.joints)),
            ActionLeaf::Home(_) => Box::new(MoveJoints::home()),
            ActionLeaf::Grasp(s) => {
                self.counters.grasp_attempts += 1;
                Box::new(Grasp::new(s.clone()))
            }
            ActionLeaf::Carry(s) => {
                self.counters.carries += 1;
                Box::new(Carry::new(s.clone()))
            }
            ActionLeaf::Release(s) => {
                self.checks.on_open();
                Box::new(Release::new(s.clone()))
            }
        }
    }

    fn condition(&self, leaf: &ConditionLeaf) -> bool {
        let w = self.cell.world();
        match leaf {
            ConditionLeaf::CubeGrasped(c) => cond::cube_grasped(w, c.off_axis),
            ConditionLeaf::CubeLifted(c) => cond::cube_lifted(w, c.min_height),
            ConditionLeaf::CubeInBowl(c) => cond::cube_in_bowl(w, c.rest_speed),
            ConditionLeaf::CubeOnTable(c) => cond::cube_on_table(w, c.tolerance, c.rest_speed),
            ConditionLeaf::CubeAt(c) => cond::cube_at(
                w,
                c.point,
                c.tolerance,
                cond::Tolerances::ON_TABLE_HEIGHT,
                c.rest_speed,
            ),
            ConditionLeaf::GripperOpen(c) => cond::gripper_open(w, c.min_width),
            ConditionLeaf::AtHome(c) => cond::at_home(w, c.tolerance),
        }
    }

    fn finish(&mut self, id: LeafId, leaf: &Leaf, progress: Progress) -> LeafOutcome {
        if !matches!(progress, Progress::Running) {
            self.active.remove(&id);
            if matches!(leaf, Leaf::Action(ActionLeaf::Grasp(_))) {
                self.checks.after_grasp(self.cell.world());
            }
        }
        match progress {
            Progress::Running => LeafOutcome::Running,
            Progress::Done => LeafOutcome::Success,
            Progress::Failed(reason) => {
                self.last_failure = Some(reason.clone());
                LeafOutcome::Failure(reason)
            }
        }
    }
}

impl LeafDriver for MacroDriver<'_> {
    fn tick(&mut self, id: LeafId, leaf: &Leaf, first: bool) -> LeafOutcome {
        let action = match leaf {
            Leaf::Condition(c) => {
                return if self.condition(c) {
                    LeafOutcome::Success
                } else {
                    LeafOutcome::Failure("not satisfied".into())
                };
            }
            Leaf::Action(a) => a,
            Leaf::Wait(_) => {
                return LeafOutcome::Failure("wait is handled by the runtime, not the driver".into());
            }
        };
        if first || !self.active.contains_key(&id) {
            let mut controller = self.start_action(action);
            self.cell.notify_action_start(action.kind());
            if let Err(reason) = controller.start(self.cell) {
                return self.finish(id, leaf, Progress::Failed(reason));
            }
            let now = self.cell.world().time;
            let timeout = action.timeout();
            self.active.insert(
                id,
                Active {
                    action: controller,
                    deadline: now + timeout,
                    timeout,
                },
            );
            return LeafOutcome::Running;
        }
        let now = self.cell.world().time;
        let active = self.active.get_mut(&id).expect("checked above");
        let mut progress = active.action.update(self.cell);
        if progress == Progress::Running && now >= active.deadline {
            active.action.halt(self.cell);
            progress = Progress::Failed(format!("timeout: not done after {:.2} s", active.timeout));
        }
        self.finish(id, leaf, progress)
    }

    fn halt(&mut self, id: LeafId, _leaf: &Leaf) {
        if let Some(mut active) = self.active.remove(&id) {
            active.action.halt(self.cell);
            self.counters.halts += 1;
        }
    }
}
