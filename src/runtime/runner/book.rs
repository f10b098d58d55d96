//! The status book: every node's status, reason, attempt and counts, the transitions and
//! the blackboard writes, as the runner records them.

use crate::kinds::ControlKind;
use tracing::Level;

use super::{MAX_PENDING_TRANSITIONS, display_name};
use crate::failure::{Failure, FailureKind};
use crate::plan::{NodeTag, Plan};
use crate::runtime::blackboard::Blackboard;
use crate::runtime::substitute::{Resolved, Scripted};
use crate::runtime::{ForcedResult, NodeCounts, NodeStatus, Transition, TreeStatus};

#[derive(Default)]
pub(super) struct LeafRt {
    /// The last call returned Running (the leaf is mid-execution).
    pub(super) running: bool,
    /// Tick of the last call.
    pub(super) last_tick: u64,
    /// `wait` leaves: simulated seconds accumulated in the current execution.
    pub(super) elapsed: f64,
    /// Open while the leaf runs.
    pub(super) span: Option<tracing::Span>,
    /// The leaf reads a blackboard variable (resolved before every tick).
    pub(super) reads_vars: bool,
    /// Its substitution, if any.
    pub(super) scripted: Option<Scripted>,
    /// Activations so far (for `fail_first:N`).
    pub(super) activations: u32,
    /// `running:N`: Running ticks answered in the current activation.
    pub(super) scripted_ticks: u32,
    /// The current activation runs the real leaf (`fail_first:N` after N failures).
    pub(super) real: bool,
}

pub(super) struct RunState {
    pub(super) statuses: Vec<NodeStatus>,
    pub(super) reasons: Vec<Option<Failure>>,
    /// How each node last finished before it was reset to Idle (a retry starting its next
    /// attempt in the same tick), so a leaf halted by that attempt's end names the real cause.
    pub(super) ended_as: Vec<Option<NodeStatus>>,
    pub(super) touched: Vec<u64>,
    /// Root-first ancestors of each node, excluding the node itself.
    pub(super) ancestors: Vec<Vec<usize>>,
    pub(super) enclosing_retry: Vec<Option<usize>>,
    /// The attempt (of the enclosing retry) each node's current status belongs to: set when it
    /// leaves Idle.
    pub(super) node_attempt: Vec<Option<u32>>,
    /// `inverter` nodes folded into a re-checked condition: their status is set with the
    /// condition's, never Running.
    pub(super) instant: Vec<bool>,
    pub(super) attempts: Vec<u32>,
    pub(super) leaves: Vec<LeafRt>,
    /// Per leaf: the result forced on its next tick ([`TreeRunner::force`](super::TreeRunner::force)).
    pub(super) forced: Vec<Option<ForcedResult>>,
    pub(super) yield_pending: Vec<bool>,
    /// Loop ends (`next`) that answered Running: (internal index, owning node, tick).
    pub(super) pending_yields: Vec<(usize, usize, u64)>,
    /// Per loop node: the loop ended by its count or its query (see [`Internal::Exit`]).
    pub(super) exit_flags: Vec<bool>,
    /// The blackboard: variables written by `select` and `for_each`.
    pub(super) vars: Blackboard,
    /// Per node: activations, successes, failures, halts (same indices as `plan.nodes`).
    pub(super) counts: Vec<NodeCounts>,
    pub(super) last_failure: Option<Failure>,
    /// The node of the last leaf that failed.
    pub(super) last_failed_node: Option<usize>,
    /// Blackboard writes since the last drain (bounded like the transitions).
    pub(super) writes: Vec<crate::runtime::BlackboardWrite>,
    pub(super) transitions: Vec<Transition>,
    pub(super) dropped: u64,
    pub(super) tick: u64,
    pub(super) sim_time: f64,
    pub(super) finished: Option<TreeStatus>,
}

impl RunState {
    pub(super) fn new(plan: &Plan, subs: &Resolved) -> Self {
        let n = plan.nodes.len();
        let mut ancestors = vec![Vec::new(); n];
        let mut enclosing_retry = vec![None; n];
        for i in 0..n {
            if let Some(p) = plan.nodes[i].parent {
                let mut a = ancestors[p].clone();
                a.push(p);
                ancestors[i] = a;
                enclosing_retry[i] = if plan.nodes[p].tag == NodeTag::Control(ControlKind::Retry) {
                    Some(p)
                } else {
                    enclosing_retry[p]
                };
            }
            if plan.nodes[i].tag == NodeTag::Control(ControlKind::Retry) {
                enclosing_retry[i] = Some(i);
            }
        }
        let mut instant = vec![false; n];
        for l in &plan.leaves {
            for &inv in l.check.iter().flat_map(|c| c.inverters.iter()) {
                instant[inv] = true;
            }
        }
        Self {
            statuses: vec![NodeStatus::Idle; n],
            instant,
            reasons: vec![None; n],
            ended_as: vec![None; n],
            touched: vec![0; n],
            ancestors,
            enclosing_retry,
            node_attempt: vec![None; n],
            attempts: vec![0; n],
            leaves: plan
                .leaves
                .iter()
                .enumerate()
                .map(|(i, l)| LeafRt {
                    reads_vars: l.kind.has_vars(),
                    scripted: subs.by_leaf.get(i).copied().flatten(),
                    ..LeafRt::default()
                })
                .collect(),
            forced: vec![None; plan.leaves.len()],
            yield_pending: vec![false; plan.internal.len()],
            pending_yields: Vec::new(),
            exit_flags: vec![false; n],
            vars: Blackboard::default(),
            counts: vec![NodeCounts::default(); n],
            last_failure: None,
            last_failed_node: None,
            writes: Vec::new(),
            transitions: Vec::new(),
            dropped: 0,
            tick: 0,
            sim_time: 0.0,
            finished: None,
        }
    }

    pub(super) fn level(plan: &Plan, node: usize) -> Level {
        let info = &plan.nodes[node];
        if info.leaf.is_some()
            || info.parent.is_none()
            || matches!(
                info.tag,
                NodeTag::Control(ControlKind::Retry)
                    | NodeTag::Control(ControlKind::Guard)
                    | NodeTag::Control(ControlKind::Timeout)
                    | NodeTag::Control(ControlKind::ReactiveSequence)
                    | NodeTag::Control(ControlKind::ReactiveFallback)
            )
        {
            Level::INFO
        } else {
            Level::DEBUG
        }
    }

    /// The attempt of `node`'s enclosing retry now (the retry's own for a retry).
    pub(super) fn current_attempt(&self, node: usize) -> Option<u32> {
        self.enclosing_retry[node].map(|r| self.attempts[r].max(1))
    }

    /// Set a node's status; log a transition if it changed. A node that starts running again
    /// after it finished (re-entered by a loop) is first reset to Idle, with its own event.
    pub(super) fn set(&mut self, plan: &Plan, node: usize, to: NodeStatus, reason: Option<Failure>) {
        let from = self.statuses[node];
        let message = reason.as_ref().map(|f| f.message.clone());
        if to == NodeStatus::Failure || to == NodeStatus::Halted {
            self.reasons[node] = reason;
        }
        if from == to {
            return;
        }
        if to == NodeStatus::Running && from != NodeStatus::Idle {
            self.reset_node(plan, node);
        }
        self.record(plan, node, to, message);
    }

    /// Back to Idle (a loop starts its child again), logged at debug level.
    pub(super) fn reset_node(&mut self, plan: &Plan, node: usize) {
        if self.statuses[node] != NodeStatus::Idle {
            if self.statuses[node] != NodeStatus::Running {
                self.ended_as[node] = Some(self.statuses[node]);
            }
            self.record(plan, node, NodeStatus::Idle, None);
        }
    }

    /// Every finished node below the loop `node` back to Idle, before its next attempt or
    /// iteration starts (running ones are reset when they are re-entered); how many.
    pub(super) fn reset_below(&mut self, plan: &Plan, node: usize) -> usize {
        let mut n = 0;
        for i in node + 1..plan.nodes.len() {
            if !self.ancestors[i].contains(&node) {
                continue;
            }
            if matches!(
                self.statuses[i],
                NodeStatus::Success | NodeStatus::Failure | NodeStatus::Halted
            ) {
                self.ended_as[i] = Some(self.statuses[i]);
                self.record(plan, i, NodeStatus::Idle, None);
                n += 1;
            }
        }
        n
    }

    /// Record and log a status change of `node` to `to`.
    pub(super) fn record(&mut self, plan: &Plan, node: usize, to: NodeStatus, reason: Option<String>) {
        let from = self.statuses[node];
        self.statuses[node] = to;
        // Label the event with the attempt it belongs to: a node leaving Idle joins the current
        // attempt; a node finishing (or halted, or reset) belongs to the attempt it started in,
        // even when the retry has already moved on to the next one.
        let attempt = if from == NodeStatus::Idle || self.enclosing_retry[node] == Some(node) {
            let now = self.current_attempt(node);
            self.node_attempt[node] = now;
            now
        } else {
            self.node_attempt[node].or_else(|| self.current_attempt(node))
        };
        let info = &plan.nodes[node];
        let t = Transition {
            tick: self.tick,
            sim_time: self.sim_time,
            node,
            path: info.path.clone(),
            kind: info.kind,
            from,
            to,
            reason: if matches!(to, NodeStatus::Failure | NodeStatus::Halted) {
                reason
            } else {
                None
            },
            attempt,
        };
        macro_rules! emit {
            ($mac:ident) => {
                tracing::$mac!(
                    target: "macrotree::tree",
                    tick = t.tick,
                    sim_time = t.sim_time,
                    path = %t.path,
                    kind = t.kind,
                    from = t.from.as_str(),
                    to = t.to.as_str(),
                    reason = t.reason.as_deref(),
                    attempt = t.attempt,
                    "{} {} → {}",
                    display_name(info),
                    t.from,
                    t.to
                )
            };
        }
        if Self::level(plan, node) == Level::INFO && to != NodeStatus::Idle {
            emit!(info);
        } else {
            emit!(debug);
        }
        if self.transitions.len() >= MAX_PENDING_TRANSITIONS {
            self.transitions.remove(0);
            self.dropped += 1;
        }
        self.transitions.push(t);
    }

    /// A leaf below `node` is being ticked: every ancestor that is not running starts running.
    pub(super) fn touch(&mut self, plan: &Plan, node: usize) {
        let tick = self.tick;
        for k in 0..self.ancestors[node].len() {
            let a = self.ancestors[node][k];
            if self.instant[a] || (self.touched[a] == tick && self.statuses[a] == NodeStatus::Running) {
                continue;
            }
            self.touched[a] = tick;
            if self.statuses[a] != NodeStatus::Running {
                if matches!(
                    plan.nodes[a].tag,
                    NodeTag::Control(ControlKind::Retry)
                        | NodeTag::Control(ControlKind::Repeat)
                        | NodeTag::Control(ControlKind::ForEach)
                ) {
                    self.attempts[a] = 1;
                }
                self.counts[a].activations += 1;
                self.set(plan, a, NodeStatus::Running, None);
            }
        }
        self.touched[node] = tick;
    }

    /// Why node `node` failed, from its kind and its children's statuses: the last failure
    /// below it, wrapped (with it as the cause) by a retry or a guard, or the node's own (a
    /// timeout that expired, an inverter whose child succeeded).
    pub(super) fn failure_reason(&self, plan: &Plan, node: usize) -> Failure {
        let info = &plan.nodes[node];
        let last = self
            .last_failure
            .clone()
            .unwrap_or_else(|| Failure::other("a child failed").at(&info.path));
        let wrap = |message: String| {
            Failure::new(last.kind, message)
                .at(&info.path)
                .caused_by(last.clone())
        };
        match info.tag {
            NodeTag::Control(ControlKind::Timeout) => {
                let child_failed = info.children.first().is_some_and(|&c| {
                    self.statuses[c] == NodeStatus::Failure && self.touched[c] == self.tick
                });
                if child_failed {
                    last
                } else {
                    Failure::new(FailureKind::Timeout, format!("{} expired", info.label)).at(&info.path)
                }
            }
            NodeTag::Control(ControlKind::Retry) => wrap(format!(
                "all {} attempts failed; last: {last}",
                self.attempts[node].max(1)
            )),
            NodeTag::Control(ControlKind::Inverter) => {
                Failure::new(FailureKind::Inverted, "inverter: child succeeded").at(&info.path)
            }
            NodeTag::Control(ControlKind::ForceFailure) => {
                Failure::new(FailureKind::Forced, "force_failure: child succeeded").at(&info.path)
            }
            NodeTag::Control(ControlKind::Guard) | NodeTag::Control(ControlKind::ReactiveSequence) => {
                let cond_failed = info
                    .children
                    .iter()
                    .take(info.children.len().saturating_sub(1))
                    .any(|&c| self.touched[c] == self.tick && self.statuses[c] == NodeStatus::Failure);
                if cond_failed {
                    wrap(format!("condition failed: {last}"))
                } else {
                    last
                }
            }
            _ => last,
        }
    }
}
