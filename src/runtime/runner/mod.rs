//! [`TreeRunner`]: bonsai `BT` + leaf lifecycle + per-node statuses.
//!
//! The runner's state is split by concern: the status book (per-node statuses, reasons,
//! counts, transitions: `book`), the leaf lifecycle (starting, ticking and substituting leaves,
//! `select`: `leaf`), the loops and decorators bonsai answers through internal leaves
//! (`loops`), and the halts of preempted nodes (`halts`).

mod book;
mod halts;
mod leaf;
mod loops;

use book::RunState;

use std::sync::Arc;

use bonsai_bt::{BT, Event, Status, UpdateArgs};

use super::blackboard::Blackboard;
use super::substitute::Resolved;
use super::{ForceError, ForcedResult, LeafDriver, NodeCounts, NodeStatus, Transition, TreeStatus};
use crate::failure::{Failure, FailureKind};
use crate::plan::{LeafId, Plan};

/// Pending transitions kept when nobody drains them; older ones are dropped (and counted).
const MAX_PENDING_TRANSITIONS: usize = 100_000;

/// Runs a [`Plan`] on simulated time.
///
/// Each [`tick`](Self::tick) ticks the bonsai tree once with the given `dt`, calls the driver
/// for the leaves bonsai reaches, then detects preempted nodes (see `docs/tick_semantics.md`),
/// calls [`LeafDriver::halt`] for preempted running leaves, and records status transitions.
pub struct TreeRunner {
    plan: Arc<Plan>,
    bt: BT<LeafId, ()>,
    st: RunState,
    subs: Resolved,
}
impl TreeRunner {
    /// A runner for `plan`, all nodes Idle.
    pub fn new(plan: Arc<Plan>) -> Self {
        Self::with_substitutions(plan, Resolved::default())
    }

    /// A runner for `plan` whose substituted leaves (see [`super::substitute`]) answer their
    /// scripted outcome instead of calling the driver.
    pub fn with_substitutions(plan: Arc<Plan>, subs: Resolved) -> Self {
        let bt = BT::new(plan.behavior.clone(), ());
        let st = RunState::new(&plan, &subs);
        Self { plan, bt, st, subs }
    }

    /// Per-node counts since the last reset (same indices as `plan.nodes`): activations,
    /// successes, failures and halts.
    pub fn node_counts(&self) -> &[NodeCounts] {
        &self.st.counts
    }

    /// The plan being run.
    pub fn plan(&self) -> &Arc<Plan> {
        &self.plan
    }

    /// One control tick of `dt` simulated seconds at time `sim_time` (seconds, the time at the
    /// start of the tick; used for logs). Returns the status of the whole tree.
    ///
    /// A non-finite or negative `dt` is treated as 0 (and logged). Once the tree has finished,
    /// further ticks do nothing and return the final status until [`reset`](Self::reset).
    pub fn tick(&mut self, sim_time: f64, dt: f64, driver: &mut dyn LeafDriver) -> TreeStatus {
        if let Some(done) = self.st.finished {
            return done;
        }
        let dt = if dt.is_finite() && dt >= 0.0 {
            dt
        } else {
            tracing::warn!(target: "macrotree::tree", dt, "invalid tick dt; using 0");
            0.0
        };
        let st = &mut self.st;
        st.tick += 1;
        st.sim_time = sim_time;
        let plan: &Plan = &self.plan;
        let event: Event = UpdateArgs { dt }.into();
        let result = self.bt.tick(&event, &mut |args, _bb: &mut ()| {
            st.on_leaf(plan, driver, *args.action, args.dt)
        });
        let status = match result {
            Some((Status::Success, _)) => TreeStatus::Success,
            Some((Status::Failure, _)) => TreeStatus::Failure,
            Some((Status::Running, _)) => TreeStatus::Running,
            None => TreeStatus::Failure, // bonsai says finished; cannot happen (we stop ticking first)
        };
        if status != TreeStatus::Running {
            st.finished = Some(status);
        }
        st.detect_halts(plan, driver);
        status
    }

    /// Status of every node (same indices as `plan.nodes`).
    pub fn node_statuses(&self) -> &[NodeStatus] {
        &self.st.statuses
    }

    /// Forces the result of the leaf at node index `node` at its next tick (the monitor's force
    /// buttons, Groot2's REPLACE hook): a running leaf is halted and ends with `result`; an idle
    /// one answers `result` when it is next ticked, without reaching the driver. A failure has
    /// the kind `overridden`; [`NodeCounts::overridden`] counts each forced result. A second
    /// call before that tick replaces the first; [`reset`](Self::reset) forgets it.
    ///
    /// # Errors
    /// The node does not exist or is not a leaf.
    pub fn force(&mut self, node: usize, result: ForcedResult) -> Result<(), ForceError> {
        let info = self.plan.nodes.get(node).ok_or(ForceError::NoSuchNode(node))?;
        let id = info.leaf.ok_or_else(|| ForceError::NotALeaf(info.path.clone()))?;
        self.st.forced[id.index()] = Some(result);
        Ok(())
    }

    /// The result forced on the leaf at node index `node` that its next tick will answer, if any.
    pub fn forced(&self, node: usize) -> Option<ForcedResult> {
        let id = self.plan.nodes.get(node)?.leaf?;
        self.st.forced.get(id.index()).copied().flatten()
    }

    /// The last failure / halt reason of every node (same indices as `plan.nodes`).
    pub fn node_reasons(&self) -> &[Option<Failure>] {
        &self.st.reasons
    }

    /// Why the tree failed: the root's failure (its message names the failing leaf or condition,
    /// e.g. "all 3 attempts failed; last: …"), once it has failed or was halted.
    pub fn failure(&self) -> Option<&Failure> {
        self.st.reasons.first().and_then(Option::as_ref)
    }

    /// Status of the node at `path` (`None` if there is no such node).
    pub fn status_of(&self, path: &str) -> Option<NodeStatus> {
        self.plan.node_by_path(path).map(|i| self.st.statuses[i])
    }

    /// Status transitions since the last drain, in the order they happened.
    pub fn drain_transitions(&mut self) -> Vec<Transition> {
        std::mem::take(&mut self.st.transitions)
    }

    /// Transitions dropped because nobody drained them (more than 100 000 pending).
    pub fn dropped_transitions(&self) -> u64 {
        self.st.dropped
    }

    /// Leaves running now (mid-execution).
    pub fn running_leaves(&self) -> Vec<LeafId> {
        (0..self.st.leaves.len())
            .filter(|&i| self.st.leaves[i].running)
            .map(|i| LeafId(i as u32))
            .collect()
    }

    /// Number of ticks that ticked the tree since the last reset.
    pub fn tick_count(&self) -> u64 {
        self.st.tick
    }

    /// The final status, once the tree has finished.
    pub fn finished(&self) -> Option<TreeStatus> {
        self.st.finished
    }

    /// Attempt (retry) or iteration (repeat) number of the node at index `node`: 0 before its
    /// first run, then 1, 2, …
    pub fn attempt(&self, node: usize) -> u32 {
        self.st.attempts.get(node).copied().unwrap_or(0)
    }

    /// Blackboard writes since the last drain, in the order they happened.
    pub fn drain_blackboard_writes(&mut self) -> Vec<super::BlackboardWrite> {
        std::mem::take(&mut self.st.writes)
    }

    /// The path of the last leaf that failed (since the last reset).
    pub fn last_failed_path(&self) -> Option<String> {
        self.st.last_failed_node.map(|n| self.plan.nodes[n].path.clone())
    }

    /// The blackboard (variables written by `select` and `for_each`).
    pub fn blackboard(&self) -> &Blackboard {
        &self.st.vars
    }

    /// Stop the tree now: halt every running leaf (calling [`LeafDriver::halt`]) and mark every
    /// running node Halted. The tree is then finished (Failure) until [`reset`](Self::reset).
    pub fn halt_all(&mut self, driver: &mut dyn LeafDriver) {
        let plan: &Plan = &self.plan;
        let st = &mut self.st;
        for i in 0..plan.nodes.len() {
            if st.statuses[i] == NodeStatus::Running {
                if let Some(id) = plan.nodes[i].leaf {
                    st.halt_leaf(plan, driver, id);
                }
                st.counts[i].halts += 1;
                let path = &plan.nodes[i].path;
                st.set(
                    plan,
                    i,
                    NodeStatus::Halted,
                    Some(Failure::new(FailureKind::Halted, "preempted: the tree was stopped").at(path)),
                );
            }
        }
        st.finished.get_or_insert(TreeStatus::Failure);
    }

    /// Start over: fresh bonsai state, all nodes Idle, counters and pending transitions cleared.
    /// Running leaves are *not* halted here (no driver); call [`halt_all`](Self::halt_all) first
    /// if the tree may be running.
    pub fn reset(&mut self) {
        self.bt.reset_bt();
        self.st = RunState::new(&self.plan, &self.subs);
    }
}

/// How log messages name a node: its `name:` with its kind (`"above cube" (reach)`), or its
/// label with the key parameters (`reach cube +[0, 0, 0.12]`).
fn display_name(info: &crate::plan::NodeInfo) -> String {
    match &info.name {
        Some(name) => format!("\"{name}\" ({})", info.kind),
        None => info.label.clone(),
    }
}
