//! Loops and decorators bonsai answers through internal leaves: retry attempts, repeats,
//! `for_each` iterations, timeouts, guards.

use crate::kinds::ControlKind;
use bonsai_bt::Status;

use super::book::RunState;
use super::display_name;
use crate::failure::{Failure, FailureKind};
use crate::plan::{Internal, LeafId, NodeTag, Plan};
use crate::runtime::{LeafDriver, NodeStatus};

impl RunState {
    pub(super) fn on_internal(
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
                if info.tag == NodeTag::Control(ControlKind::Retry) {
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
}
