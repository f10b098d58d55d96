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
use super::targets::object_index;
use crate::plan::LeafId;
use crate::runtime::{LeafDriver, LeafOutcome, Selection};
use crate::scene::ObjectKind;
use crate::spec::{ActionLeaf, ConditionLeaf, Leaf, ObjectRef};
use crate::world::conditions as cond;
use crate::world::query::{self, Query};
use crate::world::{Part, Piece, goal};

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
    /// Contacts that should not happen, by name, in the order first seen.
    pub collisions: Vec<Collision>,
}

/// A contact that should not happen (the fingers on a wall, the carried block on an obstacle).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Collision {
    /// Simulated time it was first seen, seconds.
    pub time: f64,
    /// What hit what, e.g. `the fingers hit bowl wall`.
    pub what: String,
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
            collisions: Vec::new(),
        }
    }

    /// The cell.
    pub fn cell(&mut self) -> &mut Cell {
        self.cell
    }

    /// Advances the physics by one control period and updates the checks.
    pub fn advance(&mut self) {
        self.cell.advance();
        self.watch_contacts();
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

    fn condition(&self, leaf: &ConditionLeaf) -> Result<bool, String> {
        let w = self.cell.world();
        let obj = |o: &ObjectRef| object_index(o, w);
        Ok(match leaf {
            ConditionLeaf::Grasped(c) => w.holds(obj(&c.object)?, c.off_axis),
            ConditionLeaf::Lifted(c) => w.bottom(obj(&c.object)?) >= c.min_height,
            ConditionLeaf::In(c) => goal::rests_in(w, obj(&c.object)?, obj(&c.container)?, c.rest_speed),
            ConditionLeaf::On(c) => goal::rests_on(w, obj(&c.object)?, obj(&c.support)?, c.rest_speed),
            ConditionLeaf::OnTable(c) => cond::on_table(w, obj(&c.object)?, c.tolerance, c.rest_speed),
            ConditionLeaf::At(c) => {
                let i = obj(&c.object)?;
                let p = w.objects[i].pos;
                let near = (p.x - c.point[0]).hypot(p.y - c.point[1]) <= c.tolerance;
                let turned = c.yaw.is_none_or(|target| {
                    crate::world::snapshot::fold_quarter_turn(w.yaw(i) - target.0).abs() <= c.yaw_tolerance
                });
                cond::on_table(w, i, cond::Tolerances::ON_TABLE_HEIGHT, c.rest_speed) && near && turned
            }
            ConditionLeaf::GoalMet(c) => match &c.object {
                Some(o) => goal::done(w, obj(o)?),
                None => goal::goal_holds(w),
            },
            ConditionLeaf::CubeGrasped(c) => cond::cube_grasped(w, c.off_axis),
            ConditionLeaf::CubeLifted(c) => cond::cube_lifted(w, c.min_height),
            ConditionLeaf::CubeInBowl(c) => cond::cube_in_bowl(w, c.rest_speed),
            ConditionLeaf::CubeOnTable(c) => cond::cube_on_table(w, c.tolerance, c.rest_speed),
            ConditionLeaf::CubeAt(c) => {
                let turned = c.yaw.is_none_or(|target| {
                    crate::world::snapshot::fold_quarter_turn(w.cube_yaw() - target.0).abs()
                        <= c.yaw_tolerance
                });
                turned
                    && cond::cube_at(
                        w,
                        c.point,
                        c.tolerance,
                        cond::Tolerances::ON_TABLE_HEIGHT,
                        c.rest_speed,
                    )
            }
            ConditionLeaf::GripperOpen(c) => cond::gripper_open(w, c.min_width),
            ConditionLeaf::AtHome(c) => cond::at_home(w, c.tolerance),
        })
    }

    /// Notes contacts that should not happen: the fingers on a container or an obstacle, and the
    /// held block on a wall or an obstacle. Each is logged and recorded once, by name.
    fn watch_contacts(&mut self) {
        let w = self.cell.world();
        if w.touches.is_empty() {
            return;
        }
        let held = w.held_block(cond::Tolerances::GRASP_OFF_AXIS);
        for &(a, b) in &w.touches {
            for (me, other) in [(a, b), (b, a)] {
                let Part::Object { index, piece } = other else {
                    continue;
                };
                let kind = w.spec(index).kind();
                let fingers = matches!(me, Part::Fingers | Part::Robot) && kind != ObjectKind::Block;
                let carried = matches!(me, Part::Object { index: h, .. } if Some(h) == held && h != index)
                    && (piece == Piece::Wall || kind == ObjectKind::Obstacle);
                if !(fingers || carried) {
                    continue;
                }
                let who = match me {
                    Part::Object { index: h, .. } => format!("the carried {}", w.name(h)),
                    Part::Robot => "the arm".to_string(),
                    _ => "the fingers".to_string(),
                };
                let what = format!("{who} hit {}", w.describe(other));
                if !self.collisions.iter().any(|c| c.what == what) {
                    tracing::info!(target: "macrotree::actions", sim_time = w.time, "collision: {what}");
                    self.collisions.push(Collision { time: w.time, what });
                }
            }
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
                return match self.condition(c) {
                    Ok(true) => LeafOutcome::Success,
                    Ok(false) => LeafOutcome::Failure("not satisfied".into()),
                    Err(e) => LeafOutcome::Failure(e),
                };
            }
            Leaf::Action(a) => a,
            Leaf::Wait(_) | Leaf::Select(_) => {
                return LeafOutcome::Failure(format!(
                    "`{}` is handled by the runtime, not the driver",
                    leaf.kind()
                ));
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
            let waiting = active.action.waiting_for(self.cell);
            active.action.halt(self.cell);
            progress = Progress::Failed(format!("timeout after {:.2} s: {waiting}", active.timeout));
        }
        self.finish(id, leaf, progress)
    }

    fn select_object(&mut self, query: &Query) -> Result<Option<Selection>, String> {
        let w = self.cell.world();
        Ok(query::select(w, query).map(|i| Selection {
            object: w.name(i).to_string(),
            destination: goal::destination(w, i).map(|d| w.name(d).to_string()),
        }))
    }

    fn halt(&mut self, id: LeafId, _leaf: &Leaf) {
        if let Some(mut active) = self.active.remove(&id) {
            active.action.halt(self.cell);
            self.counters.halts += 1;
        }
    }
}
