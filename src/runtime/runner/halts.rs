//! Halts: nodes bonsai no longer ticks, or whose parent stopped running, are halted (their
//! running leaves told through the driver), preorder.

use super::book::RunState;
use crate::failure::{Failure, FailureKind};
use crate::kinds::Leaf;
use crate::plan::{LeafId, Plan};
use crate::runtime::{LeafDriver, NodeStatus};

impl RunState {
    /// After bonsai's tick: halt running nodes that were not ticked, or whose parent is no
    /// longer running. Preorder, so a halted parent halts its running children.
    pub(super) fn detect_halts(&mut self, plan: &Plan, driver: &mut dyn LeafDriver) {
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

    pub(super) fn halt_leaf(&mut self, plan: &Plan, driver: &mut dyn LeafDriver, id: LeafId) {
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
