//! [`MacroDriver`]: executes the tree's leaves on the simulated cell — macro actions through
//! their controllers, conditions as pure functions of the world snapshot.

use std::collections::HashMap;

use crate::actions::{Cell, ChecksRecorder, MacroAction, Progress};
use crate::factory::Factory;
use crate::failure::{Failure, FailureKind};
use crate::kinds::{ActionRole, Leaf, LeafCall};
use crate::plan::LeafId;
use crate::runtime::{LeafDriver, LeafOutcome, Selection};
use crate::world::goal;
use crate::world::query::{self, Query};

use super::collision::{Collision, CollisionPolicy};

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
    /// What a collision does ([`CollisionPolicy::Fail`]: [`Self::collision_failure`]).
    pub collision_policy: CollisionPolicy,
    /// With [`CollisionPolicy::Fail`], the failure (kind `collision`, at the running leaf) of the
    /// first collision; the episode ends on it.
    pub collision_failure: Option<Failure>,
    /// The plan's leaf paths, by leaf index (names the leaf running when a collision is seen).
    leaf_paths: Vec<String>,
    /// The action leaf ticked last that is still running.
    current: Option<LeafId>,
}

/// What a [`MacroDriver`] keeps of one episode between uses, without the cell it borrows: the
/// running controllers, the checks, the counters and the collisions seen
/// ([`MacroDriver::suspend`], [`MacroDriver::resume`]). Lets a tree run across calls that each
/// borrow the cell for one control period (the environment's residual mode).
pub struct DriverState {
    active: HashMap<LeafId, Active>,
    checks: ChecksRecorder,
    counters: LeafCounters,
    last_failure: Option<Failure>,
    collisions: Vec<Collision>,
    collision_policy: CollisionPolicy,
    collision_failure: Option<Failure>,
    leaf_paths: Vec<String>,
    current: Option<LeafId>,
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
            collision_policy: CollisionPolicy::Count,
            collision_failure: None,
            leaf_paths: Vec::new(),
            current: None,
        }
    }

    /// Ends this use of the cell, keeping what the driver knows of the episode (running
    /// controllers included) for [`Self::resume`].
    pub fn suspend(self) -> DriverState {
        DriverState {
            active: self.active,
            checks: self.checks,
            counters: self.counters,
            last_failure: self.last_failure,
            collisions: self.collisions,
            collision_policy: self.collision_policy,
            collision_failure: self.collision_failure,
            leaf_paths: self.leaf_paths,
            current: self.current,
        }
    }

    /// A driver on `cell` that carries on where [`Self::suspend`] left `state` (the same cell,
    /// the same episode).
    pub fn resume(cell: &'a mut Cell, factory: &'a Factory, state: DriverState) -> Self {
        Self {
            cell,
            factory,
            active: state.active,
            checks: state.checks,
            counters: state.counters,
            last_failure: state.last_failure,
            collisions: state.collisions,
            collision_policy: state.collision_policy,
            collision_failure: state.collision_failure,
            leaf_paths: state.leaf_paths,
            current: state.current,
        }
    }

    /// Names collisions by the running leaf's path: `paths[i]` is leaf `i`'s (the plan's
    /// [`crate::plan::LeafInfo::path`]s).
    pub fn set_leaf_paths(&mut self, paths: Vec<String>) {
        self.leaf_paths = paths;
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

    /// Notes contacts that should not happen (see [`super::collision::classify`]), each logged and
    /// recorded once, by name, with the running leaf's path; with [`CollisionPolicy::Fail`] the
    /// first one becomes [`Self::collision_failure`].
    fn watch_contacts(&mut self) {
        let w = self.cell.world();
        if w.touches.is_empty() {
            return;
        }
        for mut c in super::collision::classify(w) {
            if self.collisions.iter().any(|seen| seen.what == c.what) {
                continue;
            }
            // The running leaf's path, looked up only for a contact not seen before (the pads on
            // a held block touch it every step).
            let node = self
                .current
                .filter(|id| !id.is_internal())
                .and_then(|id| self.leaf_paths.get(id.0 as usize).cloned());
            c.node = node.clone();
            tracing::info!(target: "macrotree::actions", sim_time = w.time, node = node.as_deref(), "collision: {}", c.what);
            if self.collision_policy == CollisionPolicy::Fail && self.collision_failure.is_none() {
                let f = Failure::new(
                    FailureKind::Collision,
                    format!("collision ({}): {} at {:.2} s", c.label(), c.what, c.time),
                );
                self.collision_failure = Some(match &node {
                    Some(n) => f.at(n.clone()),
                    None => f,
                });
            }
            self.collisions.push(c);
        }
    }

    fn finish(&mut self, id: LeafId, leaf: &Leaf, progress: Progress) -> LeafOutcome {
        if !matches!(progress, Progress::Running) {
            self.active.remove(&id);
            if self.current == Some(id) {
                self.current = None;
            }
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
            Leaf::Action(a) => {
                self.current = Some(id);
                a
            }
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
        if self.current == Some(id) {
            self.current = None;
        }
        if let Some(mut active) = self.active.remove(&id) {
            active.action.halt(self.cell);
            self.counters.halts += 1;
        }
    }
}
