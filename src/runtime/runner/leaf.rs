//! The leaf lifecycle: a leaf is started, ticked (by the driver, or by its substitution),
//! finished; `select` writes the blackboard.

use bonsai_bt::Status;

use super::MAX_PENDING_TRANSITIONS;
use super::book::RunState;
use crate::failure::{Failure, FailureKind};
use crate::kinds::{Leaf, Select};
use crate::plan::{LeafId, Plan};
use crate::runtime::substitute::Scripted;
use crate::runtime::{ForcedResult, LeafDriver, LeafOutcome, NodeStatus};

impl RunState {
    pub(super) fn on_leaf(
        &mut self,
        plan: &Plan,
        driver: &mut dyn LeafDriver,
        id: LeafId,
        dt: f64,
    ) -> (Status, f64) {
        if let Some(internal) = plan.internal(id) {
            return self.on_internal(plan, driver, id, internal, dt);
        }
        let Some(info) = plan.leaf(id) else {
            return (Status::Failure, dt);
        };
        let node = info.node;
        self.touch(plan, node);
        let forced = self.forced[id.index()].take();
        let first = !self.leaves[id.index()].running;
        if forced.is_some() && !first {
            // The running activation ends with the forced result: stop the real leaf first.
            self.halt_leaf(plan, driver, id);
        }
        let rt = &mut self.leaves[id.index()];
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
            _ if forced.is_some() => {
                self.counts[node].overridden += 1;
                let outcome = match forced {
                    Some(ForcedResult::Failure) => LeafOutcome::failure(
                        FailureKind::Overridden,
                        "failure forced from outside the tree (the monitor)",
                    ),
                    _ => LeafOutcome::Success,
                };
                tracing::info!(target: "macrotree::tree", path = %info.path, "forced result: {outcome:?}");
                (outcome, dt)
            }
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

    /// A `select` leaf: ask the driver, write the blackboard.
    pub(super) fn select(
        &mut self,
        plan: &Plan,
        node: usize,
        driver: &mut dyn LeafDriver,
        sel: &Select,
    ) -> LeafOutcome {
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
    pub(super) fn write_selection(
        &mut self,
        plan: &Plan,
        node: usize,
        sel: &Select,
        found: crate::runtime::Selection,
    ) {
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
            self.writes.push(crate::runtime::BlackboardWrite {
                tick: self.tick,
                sim_time: self.sim_time,
                path: info.path.clone(),
                var: var.clone(),
                value: value.clone(),
            });
            self.vars.set(&var, value);
        }
    }
}
