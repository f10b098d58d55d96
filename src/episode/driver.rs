//! [`MacroDriver`]: executes the tree's leaves on the simulated cell — macro actions through
//! their controllers, conditions as pure functions of the world snapshot.

use std::collections::HashMap;

use crate::actions::{Cell, ChecksRecorder, MacroAction, Progress};
use crate::factory::Factory;
use crate::failure::{Failure, FailureKind};
use crate::kinds::{ActionRole, Leaf, LeafCall};
use crate::plan::LeafId;
use crate::runtime::{LeafDriver, LeafOutcome, Selection};
use crate::scene::ObjectKind;
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
    /// Grasp leaves started (of kinds declared [`ActionRole::Grasp`]).
    pub grasp_attempts: u32,
    /// Carry leaves started (of kinds declared [`ActionRole::Carry`]).
    pub carries: u32,
    /// Leaves halted.
    pub halts: u32,
}

/// Executes leaves against a [`Cell`].
pub struct MacroDriver<'a> {
    cell: &'a mut Cell,
    factory: &'a Factory,
    active: HashMap<LeafId, Active>,
    /// The tutorial checks, accumulated.
    pub checks: ChecksRecorder,
    /// Leaf counters.
    pub counters: LeafCounters,
    /// The last action failure.
    pub last_failure: Option<Failure>,
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
    /// A driver acting on `cell`, running each leaf as `factory` binds its kind.
    pub fn new(cell: &'a mut Cell, factory: &'a Factory) -> Self {
        Self {
            cell,
            factory,
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

    /// A new controller for `action` (`None` if the call is not an action). Counts the grasps
    /// and carries the report needs, and tells the checks when the gripper opens, by the role
    /// the action's kind declares.
    fn start_action(&mut self, action: &LeafCall) -> Option<Box<dyn MacroAction>> {
        match action.role() {
            ActionRole::Grasp => self.counters.grasp_attempts += 1,
            ActionRole::Carry => self.counters.carries += 1,
            ActionRole::Release => self.checks.on_open(),
            ActionRole::Reach | ActionRole::Other => {}
        }
        self.factory.start(action)
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
            if matches!(leaf, Leaf::Action(a) if a.role() == ActionRole::Grasp) {
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
                return match self.factory.check(c, self.cell.world()) {
                    Some(Ok(true)) => LeafOutcome::Success,
                    Some(Ok(false)) => LeafOutcome::failure(FailureKind::ConditionFalse, "not satisfied"),
                    Some(Err(e)) => LeafOutcome::Failure(e),
                    None => {
                        LeafOutcome::Failure(Failure::other(format!("`{}` is not a condition", c.kind())))
                    }
                };
            }
            Leaf::Action(a) => a,
            Leaf::Wait(_) | Leaf::Select(_) => {
                return LeafOutcome::Failure(Failure::other(format!(
                    "`{}` is handled by the runtime, not the driver",
                    leaf.kind()
                )));
            }
        };
        if first || !self.active.contains_key(&id) {
            let Some(mut controller) = self.start_action(action) else {
                return LeafOutcome::Failure(Failure::other(format!("`{}` is not an action", action.kind())));
            };
            self.cell.notify_action_start(action.kind(), action.role());
            if let Err(reason) = controller.start(self.cell) {
                return self.finish(id, leaf, Progress::Failed(reason));
            }
            let now = self.cell.world().time;
            let timeout = action.timeout().unwrap_or(f64::INFINITY);
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
            progress = Progress::Failed(Failure::new(
                FailureKind::Timeout,
                format!("timeout after {:.2} s: {waiting}", active.timeout),
            ));
        }
        self.finish(id, leaf, progress)
    }

    fn select_object(&mut self, query: &Query) -> Result<Option<Selection>, Failure> {
        let w = self.cell.world();
        Ok(query::select(w, query).map(|i| Selection {
            object: w.name(i).to_string(),
            destination: goal::destination_name(w, i),
        }))
    }

    fn halt(&mut self, id: LeafId, _leaf: &Leaf) {
        if let Some(mut active) = self.active.remove(&id) {
            active.action.halt(self.cell);
            self.counters.halts += 1;
        }
    }
}
