//! [`TreeRunner`]: bonsai `BT` + leaf lifecycle + per-node statuses.

use std::sync::Arc;

use bonsai_bt::{BT, Event, Status, UpdateArgs};
use tracing::Level;

use super::blackboard::Blackboard;
use super::substitute::{Resolved, Scripted};
use super::{LeafDriver, LeafOutcome, NodeCounts, NodeStatus, Transition, TreeStatus};
use crate::failure::{Failure, FailureKind};
use crate::kinds::{Leaf, Select};
use crate::plan::{Internal, LeafId, NodeTag, Plan};

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

#[derive(Default)]
struct LeafRt {
    /// The last call returned Running (the leaf is mid-execution).
    running: bool,
    /// Tick of the last call.
    last_tick: u64,
    /// `wait` leaves: simulated seconds accumulated in the current execution.
    elapsed: f64,
    /// Open while the leaf runs.
    span: Option<tracing::Span>,
    /// The leaf reads a blackboard variable (resolved before every tick).
    reads_vars: bool,
    /// Its substitution, if any.
    scripted: Option<Scripted>,
    /// Activations so far (for `fail_first:N`).
    activations: u32,
    /// `running:N`: Running ticks answered in the current activation.
    scripted_ticks: u32,
    /// The current activation runs the real leaf (`fail_first:N` after N failures).
    real: bool,
}

struct RunState {
    statuses: Vec<NodeStatus>,
    reasons: Vec<Option<Failure>>,
    /// How each node last finished before it was reset to Idle (a retry starting its next
    /// attempt in the same tick), so a leaf halted by that attempt's end names the real cause.
    ended_as: Vec<Option<NodeStatus>>,
    touched: Vec<u64>,
    /// Root-first ancestors of each node, excluding the node itself.
    ancestors: Vec<Vec<usize>>,
    enclosing_retry: Vec<Option<usize>>,
    /// The attempt (of the enclosing retry) each node's current status belongs to: set when it
    /// leaves Idle.
    node_attempt: Vec<Option<u32>>,
    /// `inverter` nodes folded into a re-checked condition: their status is set with the
    /// condition's, never Running.
    instant: Vec<bool>,
    attempts: Vec<u32>,
    leaves: Vec<LeafRt>,
    yield_pending: Vec<bool>,
    /// Loop ends (`next`) that answered Running: (internal index, owning node, tick).
    pending_yields: Vec<(usize, usize, u64)>,
    /// Per loop node: the loop ended by its count or its query (see [`Internal::Exit`]).
    exit_flags: Vec<bool>,
    /// The blackboard: variables written by `select` and `for_each`.
    vars: Blackboard,
    /// Per node: activations, successes, failures, halts (same indices as `plan.nodes`).
    counts: Vec<NodeCounts>,
    last_failure: Option<Failure>,
    /// The node of the last leaf that failed.
    last_failed_node: Option<usize>,
    /// Blackboard writes since the last drain (bounded like the transitions).
    writes: Vec<super::BlackboardWrite>,
    transitions: Vec<Transition>,
    dropped: u64,
    tick: u64,
    sim_time: f64,
    finished: Option<TreeStatus>,
}

impl RunState {
    fn new(plan: &Plan, subs: &Resolved) -> Self {
        let n = plan.nodes.len();
        let mut ancestors = vec![Vec::new(); n];
        let mut enclosing_retry = vec![None; n];
        for i in 0..n {
            if let Some(p) = plan.nodes[i].parent {
                let mut a = ancestors[p].clone();
                a.push(p);
                ancestors[i] = a;
                enclosing_retry[i] = if plan.nodes[p].tag == NodeTag::Retry {
                    Some(p)
                } else {
                    enclosing_retry[p]
                };
            }
            if plan.nodes[i].tag == NodeTag::Retry {
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

    fn level(plan: &Plan, node: usize) -> Level {
        let info = &plan.nodes[node];
        if info.leaf.is_some()
            || info.parent.is_none()
            || matches!(
                info.tag,
                NodeTag::Retry
                    | NodeTag::Guard
                    | NodeTag::Timeout
                    | NodeTag::ReactiveSequence
                    | NodeTag::ReactiveFallback
            )
        {
            Level::INFO
        } else {
            Level::DEBUG
        }
    }

    /// The attempt of `node`'s enclosing retry now (the retry's own for a retry).
    fn current_attempt(&self, node: usize) -> Option<u32> {
        self.enclosing_retry[node].map(|r| self.attempts[r].max(1))
    }

    /// Set a node's status; log a transition if it changed. A node that starts running again
    /// after it finished (re-entered by a loop) is first reset to Idle, with its own event.
    fn set(&mut self, plan: &Plan, node: usize, to: NodeStatus, reason: Option<Failure>) {
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
    fn reset_node(&mut self, plan: &Plan, node: usize) {
        if self.statuses[node] != NodeStatus::Idle {
            if self.statuses[node] != NodeStatus::Running {
                self.ended_as[node] = Some(self.statuses[node]);
            }
            self.record(plan, node, NodeStatus::Idle, None);
        }
    }

    /// Every finished node below the loop `node` back to Idle, before its next attempt or
    /// iteration starts (running ones are reset when they are re-entered); how many.
    fn reset_below(&mut self, plan: &Plan, node: usize) -> usize {
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
    fn record(&mut self, plan: &Plan, node: usize, to: NodeStatus, reason: Option<String>) {
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
    fn touch(&mut self, plan: &Plan, node: usize) {
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
                    NodeTag::Retry | NodeTag::Repeat | NodeTag::ForEach
                ) {
                    self.attempts[a] = 1;
                }
                self.counts[a].activations += 1;
                self.set(plan, a, NodeStatus::Running, None);
            }
        }
        self.touched[node] = tick;
    }

    fn on_leaf(&mut self, plan: &Plan, driver: &mut dyn LeafDriver, id: LeafId, dt: f64) -> (Status, f64) {
        if let Some(internal) = plan.internal(id) {
            return self.on_internal(plan, driver, id, internal, dt);
        }
        let Some(info) = plan.leaf(id) else {
            return (Status::Failure, dt);
        };
        let node = info.node;
        self.touch(plan, node);
        let rt = &mut self.leaves[id.index()];
        let first = !rt.running;
        rt.last_tick = self.tick;
        if first {
            rt.elapsed = 0.0;
            rt.scripted_ticks = 0;
            rt.activations = rt.activations.saturating_add(1);
            rt.real = match rt.scripted {
                None => true,
                Some(Scripted::FailFirst(n)) => rt.activations > n,
                Some(_) => false,
            };
            self.counts[node].activations += 1;
            rt.span = Some(
                tracing::info_span!(target: "macrotree::tree", "leaf", path = %info.path, kind = info.kind.kind()),
            );
        }
        let (outcome, leftover) = match &info.kind {
            _ if !rt.real => {
                let outcome = match rt.scripted {
                    Some(Scripted::Running(n)) if rt.scripted_ticks < n => {
                        rt.scripted_ticks += 1;
                        LeafOutcome::Running
                    }
                    Some(Scripted::Failure | Scripted::FailFirst(_)) => LeafOutcome::failure(
                        FailureKind::Substituted,
                        format!(
                            "substituted: scripted failure ({})",
                            rt.scripted.map_or(String::new(), |s| s.to_string())
                        ),
                    ),
                    _ => LeafOutcome::Success,
                };
                let running = matches!(outcome, LeafOutcome::Running);
                if !running {
                    tracing::debug!(target: "macrotree::tree", path = %info.path, "substituted leaf answers {outcome:?}");
                }
                (outcome, if running { 0.0 } else { dt })
            }
            Leaf::Select(sel) => (self.select(plan, node, driver, sel), dt),
            Leaf::Wait(w) => {
                rt.elapsed += dt;
                if rt.elapsed >= w.seconds {
                    (LeafOutcome::Success, rt.elapsed - w.seconds)
                } else {
                    (LeafOutcome::Running, 0.0)
                }
            }
            leaf => {
                let span = rt.span.clone().unwrap_or_else(tracing::Span::none);
                let out = if rt.reads_vars {
                    match self.vars.resolve(leaf) {
                        Ok(l) => span.in_scope(|| driver.tick(id, &l, first)),
                        Err(unset) => LeafOutcome::Failure(Failure::other(unset)),
                    }
                } else {
                    span.in_scope(|| driver.tick(id, leaf, first))
                };
                let out = match (leaf, out) {
                    (Leaf::Condition(c), LeafOutcome::Running) => {
                        tracing::warn!(target: "macrotree::tree", path = %info.path, "condition `{}` answered Running; conditions must answer at once, treating it as Failure", c.kind());
                        LeafOutcome::Failure(Failure::other(format!(
                            "condition `{}` answered Running",
                            c.kind()
                        )))
                    }
                    (_, o) => o,
                };
                (out, dt)
            }
        };
        let rt = &mut self.leaves[id.index()];
        let raw = match outcome {
            LeafOutcome::Running => {
                rt.running = true;
                self.set(plan, node, NodeStatus::Running, None);
                return (Status::Running, 0.0);
            }
            LeafOutcome::Success => {
                rt.running = false;
                rt.span = None;
                self.counts[node].successes += 1;
                self.set(plan, node, NodeStatus::Success, None);
                true
            }
            LeafOutcome::Failure(reason) => {
                rt.running = false;
                rt.span = None;
                self.counts[node].failures += 1;
                let reason = reason.prefixed(&format!("{}: ", info.kind.kind())).at(&info.path);
                self.last_failure = Some(reason.clone());
                self.last_failed_node = Some(node);
                self.set(plan, node, NodeStatus::Failure, Some(reason));
                false
            }
        };
        let Some(check) = &info.check else {
            return (if raw { Status::Success } else { Status::Failure }, leftover);
        };
        // A re-checked condition: apply inverters (innermost first), then decide.
        let mut effective = raw;
        for &inv in check.inverters.iter().rev() {
            effective = !effective;
            self.touched[inv] = self.tick;
            self.counts[inv].activations += 1;
            if effective {
                self.counts[inv].successes += 1;
            } else {
                self.counts[inv].failures += 1;
            }
            let (st, reason) = if effective {
                (NodeStatus::Success, None)
            } else {
                (
                    NodeStatus::Failure,
                    Some(
                        Failure::new(
                            FailureKind::Inverted,
                            format!("inverted: `{}` succeeded", info.kind.kind()),
                        )
                        .at(&plan.nodes[inv].path),
                    ),
                )
            };
            if !effective {
                self.last_failure = reason.clone();
            }
            self.set(plan, inv, st, reason);
        }
        if effective == check.continue_on {
            (Status::Running, 0.0)
        } else if effective {
            (Status::Success, leftover)
        } else {
            (Status::Failure, leftover)
        }
    }

    fn on_internal(
        &mut self,
        plan: &Plan,
        driver: &mut dyn LeafDriver,
        id: LeafId,
        internal: &Internal,
        dt: f64,
    ) -> (Status, f64) {
        match *internal {
            Internal::Probe { node, success } => {
                if success {
                    self.counts[node].successes += 1;
                    self.set(plan, node, NodeStatus::Success, None);
                    (Status::Success, dt)
                } else {
                    let reason = self.failure_reason(plan, node);
                    self.last_failure = Some(reason.clone());
                    self.counts[node].failures += 1;
                    self.set(plan, node, NodeStatus::Failure, Some(reason));
                    (Status::Failure, dt)
                }
            }
            Internal::Next { node, limit } => {
                let i = id.index();
                self.touch(plan, node);
                if self.yield_pending[i] {
                    self.yield_pending[i] = false;
                    self.pending_yields.retain(|(y, _, _)| *y != i);
                    return (Status::Success, dt);
                }
                let info = &plan.nodes[node];
                let done = self.attempts[node].max(1);
                if info.kind != "for_each" && done >= limit {
                    // Attempts (retry) or runs (repeat) used up: end the loop in this tick.
                    self.exit_flags[node] = true;
                    return (Status::Failure, dt);
                }
                self.yield_pending[i] = true;
                self.pending_yields.push((i, node, self.tick));
                let iteration = done + 1;
                let reset = self.reset_below(plan, node);
                self.attempts[node] = iteration;
                let info = &plan.nodes[node];
                if info.tag == NodeTag::Retry {
                    tracing::info!(
                        target: "macrotree::tree",
                        tick = self.tick,
                        sim_time = self.sim_time,
                        path = %info.path,
                        kind = info.kind,
                        attempt = iteration,
                        reset,
                        reason = self.last_failure.as_ref().map(|f| f.message.as_str()),
                        "{}: reset {} node(s) to idle; attempt {} of {} starts next tick",
                        display_name(info),
                        reset,
                        iteration,
                        limit
                    );
                } else {
                    tracing::debug!(
                        target: "macrotree::tree",
                        tick = self.tick,
                        sim_time = self.sim_time,
                        path = %info.path,
                        kind = info.kind,
                        iteration,
                        reset,
                        "{}: reset {} node(s) to idle; iteration {} of {} starts next tick",
                        display_name(info),
                        reset,
                        iteration,
                        limit
                    );
                }
                (Status::Running, 0.0)
            }
            Internal::Exit {
                node,
                flagged_success,
            } => {
                let flagged = std::mem::take(&mut self.exit_flags[node]);
                if flagged == flagged_success {
                    (Status::Success, dt)
                } else {
                    (Status::Failure, dt)
                }
            }
            Internal::Pick {
                node,
                ref select,
                limit,
            } => {
                self.touch(plan, node);
                let iteration = self.attempts[node].max(1);
                let info = &plan.nodes[node];
                match driver.select_object(&select.query()) {
                    Ok(None) => {
                        self.exit_flags[node] = true;
                        tracing::debug!(target: "macrotree::tree", path = %info.path, "{}: no {} left", display_name(info), select.query().describe());
                        (Status::Failure, dt)
                    }
                    Ok(Some(found)) if iteration > limit => {
                        self.last_failure = Some(
                            Failure::new(
                                FailureKind::MaxIterations,
                                format!(
                                    "for_each: {} still matches ({}) after {limit} iteration(s) (max_iterations)",
                                    select.query().describe(),
                                    found.object
                                ),
                            )
                            .at(&info.path),
                        );
                        (Status::Failure, dt)
                    }
                    Ok(Some(found)) => {
                        self.write_selection(plan, node, select, found);
                        (Status::Success, dt)
                    }
                    Err(reason) => {
                        self.last_failure = Some(reason.prefixed("for_each: ").at(&info.path));
                        (Status::Failure, dt)
                    }
                }
            }
        }
    }

    /// A `select` leaf: ask the driver, write the blackboard.
    fn select(&mut self, plan: &Plan, node: usize, driver: &mut dyn LeafDriver, sel: &Select) -> LeafOutcome {
        match driver.select_object(&sel.query()) {
            Ok(Some(found)) => {
                self.write_selection(plan, node, sel, found);
                LeafOutcome::Success
            }
            Ok(None) => {
                LeafOutcome::Failure(Failure::other(format!("no {} matches", sel.query().describe())))
            }
            Err(reason) => LeafOutcome::Failure(reason),
        }
    }

    /// Writes a selection to the blackboard and logs each write as an event
    /// (`{block} = "red"`, target `macrotree::blackboard`).
    fn write_selection(&mut self, plan: &Plan, node: usize, sel: &Select, found: super::Selection) {
        let info = &plan.nodes[node];
        let mut writes = vec![(sel.var.clone(), Some(found.object))];
        if let Some(g) = &sel.goal_var {
            writes.push((g.clone(), found.destination));
        }
        for (var, value) in writes {
            tracing::info!(
                target: "macrotree::blackboard",
                tick = self.tick,
                sim_time = self.sim_time,
                path = %info.path,
                var = %var,
                value = value.as_deref(),
                "{{{var}}} = {}",
                value.as_deref().map_or("(unset: no goal)".to_string(), |v| format!("\"{v}\""))
            );
            if self.writes.len() >= MAX_PENDING_TRANSITIONS {
                self.writes.remove(0);
            }
            self.writes.push(super::BlackboardWrite {
                tick: self.tick,
                sim_time: self.sim_time,
                path: info.path.clone(),
                var: var.clone(),
                value: value.clone(),
            });
            self.vars.set(&var, value);
        }
    }

    /// Why node `node` failed, from its kind and its children's statuses: the last failure
    /// below it, wrapped (with it as the cause) by a retry or a guard, or the node's own (a
    /// timeout that expired, an inverter whose child succeeded).
    fn failure_reason(&self, plan: &Plan, node: usize) -> Failure {
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
            NodeTag::Timeout => {
                let child_failed = info.children.first().is_some_and(|&c| {
                    self.statuses[c] == NodeStatus::Failure && self.touched[c] == self.tick
                });
                if child_failed {
                    last
                } else {
                    Failure::new(FailureKind::Timeout, format!("{} expired", info.label)).at(&info.path)
                }
            }
            NodeTag::Retry => wrap(format!(
                "all {} attempts failed; last: {last}",
                self.attempts[node].max(1)
            )),
            NodeTag::Inverter => {
                Failure::new(FailureKind::Inverted, "inverter: child succeeded").at(&info.path)
            }
            NodeTag::ForceFailure => {
                Failure::new(FailureKind::Forced, "force_failure: child succeeded").at(&info.path)
            }
            NodeTag::Guard | NodeTag::ReactiveSequence => {
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

    /// After bonsai's tick: halt running nodes that were not ticked, or whose parent is no
    /// longer running. Preorder, so a halted parent halts its running children.
    fn detect_halts(&mut self, plan: &Plan, driver: &mut dyn LeafDriver) {
        for i in 0..plan.nodes.len() {
            if self.statuses[i] != NodeStatus::Running {
                continue;
            }
            let parent = plan.nodes[i].parent;
            let parent_running = parent.is_none_or(|p| self.statuses[p] == NodeStatus::Running);
            if self.touched[i] == self.tick && parent_running {
                continue;
            }
            let reason = match parent {
                Some(_) if !parent_running => {
                    // The preempting node is the nearest ancestor that finished (a guard whose
                    // condition failed, a timeout that fired); ancestors halted in this pass
                    // were preempted themselves. Without one, the topmost stopped ancestor.
                    let stopped: Vec<usize> = self.ancestors[i]
                        .iter()
                        .rev()
                        .copied()
                        .take_while(|&a| self.statuses[a] != NodeStatus::Running)
                        .collect();
                    // A node already reset for the next attempt counts as it finished.
                    let ended = |a: usize| match self.statuses[a] {
                        NodeStatus::Idle => self.ended_as[a].unwrap_or(NodeStatus::Idle),
                        s => s,
                    };
                    let by = stopped
                        .iter()
                        .copied()
                        .find(|&a| ended(a) != NodeStatus::Halted)
                        .or(stopped.last().copied())
                        .unwrap_or(i);
                    let mut reason = Failure::new(
                        FailureKind::Halted,
                        format!(
                            "preempted: `{}` {}",
                            plan.nodes[by].path,
                            match ended(by) {
                                NodeStatus::Halted => "was halted",
                                NodeStatus::Success => "succeeded",
                                _ => "failed",
                            }
                        ),
                    );
                    if ended(by) == NodeStatus::Failure
                        && let Some(why) = &self.reasons[by]
                    {
                        reason.message.push_str(&format!(" ({why})"));
                        reason = reason.caused_by(why.clone());
                    }
                    reason
                }
                _ => Failure::new(FailureKind::Halted, "preempted: no longer ticked by its parent"),
            };
            let reason = reason.at(&plan.nodes[i].path);
            if let Some(id) = plan.nodes[i].leaf {
                self.halt_leaf(plan, driver, id);
            }
            self.counts[i].halts += 1;
            self.set(plan, i, NodeStatus::Halted, Some(reason));
            // Halted because its attempt failed, after the next attempt was announced: it is
            // reset with the rest of its attempt.
            if self.node_attempt[i].is_some() && self.node_attempt[i] < self.current_attempt(i) {
                self.reset_node(plan, i);
            }
        }
        // A yield that answered Running is only completed by its own execution: reset it when it
        // was not ticked this tick or its retry/repeat stopped running (preempted).
        let tick = self.tick;
        let yp = &mut self.yield_pending;
        let statuses = &self.statuses;
        self.pending_yields.retain(|&(y, node, t)| {
            let keep = t == tick && statuses[node] == NodeStatus::Running;
            if !keep {
                yp[y] = false;
            }
            keep
        });
    }

    fn halt_leaf(&mut self, plan: &Plan, driver: &mut dyn LeafDriver, id: LeafId) {
        let Some(info) = plan.leaf(id) else { return };
        let rt = &mut self.leaves[id.index()];
        if !rt.running {
            return;
        }
        rt.running = false;
        let span = rt.span.take().unwrap_or_else(tracing::Span::none);
        if rt.real && !matches!(info.kind, Leaf::Wait(_)) {
            span.in_scope(|| driver.halt(id, &info.kind));
        }
    }
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
