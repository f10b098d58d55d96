//! The monitor's controls: breakpoints, pause, step, resume and forced results, sent by the
//! live page (JSON text frames `{"type": "monitor", "op": …}`) or declared on the command line
//! (`run --view --break PATTERN`), and the debugger state they drive.
//!
//! A paused episode is simply not advanced: the simulation thread waits inside the episode
//! observer, so simulated time stops and the physics stays deterministic. Given the same forced
//! results at the same ticks, an episode is bit-identical with or without pauses.

use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

use serde_json::{Value, json};

use crate::plan::Plan;
use crate::runtime::substitute::glob_match;
use crate::runtime::{ForcedResult, NodeStatus, Transition};

/// Longest node path a monitor command may name, characters.
pub const MAX_COMMAND_PATH: usize = 1000;
/// Most breakpoints one episode keeps.
pub const MAX_BREAKPOINTS: usize = 256;

/// When a breakpoint pauses the episode.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum BreakWhen {
    /// When the node starts: on the tick it becomes Running (or finishes at once), before the
    /// physics advances under it.
    Before,
    /// When the node finishes (success or failure), before the physics advances.
    After,
}

impl BreakWhen {
    /// The stable name: `before` or `after`.
    pub fn as_str(self) -> &'static str {
        match self {
            BreakWhen::Before => "before",
            BreakWhen::After => "after",
        }
    }
}

impl FromStr for BreakWhen {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "before" => Ok(BreakWhen::Before),
            "after" => Ok(BreakWhen::After),
            other => Err(format!("{other:?}: a breakpoint is `before` or `after` its node")),
        }
    }
}

/// A breakpoint declared by pattern (`run --break 'main/**/grasp@after'`): every node whose
/// path matches the glob (the substitution patterns' syntax) pauses `when`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BreakSpec {
    /// Node path glob: `*` within a segment, `?` one character, `**` any number of segments.
    pub pattern: String,
    /// Before (the default) or after the node.
    pub when: BreakWhen,
}

impl FromStr for BreakSpec {
    type Err = String;
    /// `PATTERN`, `PATTERN@before` or `PATTERN@after`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (pattern, when) = match s.rsplit_once('@') {
            Some((p, w)) if w == "before" || w == "after" => (p, w.parse()?),
            _ => (s, BreakWhen::Before),
        };
        crate::runtime::substitute::Substitution::check_pattern(pattern)?;
        Ok(BreakSpec {
            pattern: pattern.to_owned(),
            when,
        })
    }
}

impl fmt::Display for BreakSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}@{}", self.pattern, self.when.as_str())
    }
}

/// One command from the page.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MonitorCommand {
    /// Pause at the next tick.
    Pause,
    /// Run on (until the next breakpoint).
    Resume,
    /// Advance one control period, then pause again.
    Step,
    /// Set (`Some`) or clear (`None`) the breakpoint of the node at `path`.
    Break {
        /// The node's path.
        path: String,
        /// When it pauses; `None` clears it.
        when: Option<BreakWhen>,
    },
    /// Force the result of the leaf at `path` at its next tick.
    Force {
        /// The leaf's path.
        path: String,
        /// The result.
        result: ForcedResult,
    },
}

impl MonitorCommand {
    /// Reads a `{"type": "monitor", "op": …}` message: `pause`, `resume`, `step`,
    /// `{"op": "break", "path", "when": "before"|"after"|null}`,
    /// `{"op": "force", "path", "result": "success"|"failure"}`.
    ///
    /// # Errors
    /// Not a monitor message, or a field missing, unknown or too long.
    pub fn parse(msg: &Value) -> Result<Self, String> {
        if msg.get("type").and_then(Value::as_str) != Some("monitor") {
            return Err("not a monitor message".into());
        }
        let path = || -> Result<String, String> {
            match msg.get("path").and_then(Value::as_str) {
                Some(p) if !p.is_empty() && p.chars().count() <= MAX_COMMAND_PATH => Ok(p.to_owned()),
                Some(_) => Err(format!("`path` must be 1 to {MAX_COMMAND_PATH} characters")),
                None => Err("`path` is missing".into()),
            }
        };
        match msg.get("op").and_then(Value::as_str) {
            Some("pause") => Ok(Self::Pause),
            Some("resume") => Ok(Self::Resume),
            Some("step") => Ok(Self::Step),
            Some("break") => {
                let when = match msg.get("when") {
                    None | Some(Value::Null) => None,
                    Some(w) => Some(w.as_str().unwrap_or("").parse()?),
                };
                Ok(Self::Break { path: path()?, when })
            }
            Some("force") => {
                let result = msg.get("result").and_then(Value::as_str).unwrap_or("").parse()?;
                Ok(Self::Force {
                    path: path()?,
                    result,
                })
            }
            Some(other) => Err(format!("unknown monitor op {other:?}")),
            None => Err("`op` is missing".into()),
        }
    }
}

/// Why the episode is paused.
#[derive(Clone, Debug, PartialEq)]
pub struct Pause {
    /// What stopped it: `before`/`after` a node, `step`, or `pause` (the page's button).
    pub reason: String,
    /// The node whose breakpoint hit, if any.
    pub path: Option<String>,
    /// Simulated time, seconds.
    pub t: f64,
}

/// A result forced from the page, as recorded in the trace.
#[derive(Clone, Debug, PartialEq)]
pub struct ForcedRecord {
    /// The leaf.
    pub path: String,
    /// The result.
    pub result: ForcedResult,
    /// When it was asked for, simulated seconds.
    pub t: f64,
}

/// The debugger state of one live episode: breakpoints by node index, a pending pause or
/// step, the current pause, and the results forced so far.
#[derive(Debug, Default)]
pub struct Monitor {
    breakpoints: BTreeMap<usize, BreakWhen>,
    /// A pause due at the next tick, and why (`pause` or `step`).
    pause_requested: Option<&'static str>,
    paused: Option<Pause>,
    forced: Vec<ForcedRecord>,
}

impl Monitor {
    /// A monitor with the breakpoints `specs` set on every node they match.
    ///
    /// # Errors
    /// A pattern matching no node of `plan`.
    pub fn new(plan: &Plan, specs: &[BreakSpec]) -> Result<Self, String> {
        let mut monitor = Self::default();
        for spec in specs {
            let mut matched = false;
            for (i, node) in plan.nodes.iter().enumerate() {
                if glob_match(&spec.pattern, &node.path) {
                    monitor.breakpoints.insert(i, spec.when);
                    matched = true;
                }
            }
            if !matched {
                let close = crate::runtime::substitute::close_paths(plan, &spec.pattern);
                return Err(format!(
                    "breakpoint {spec}: the pattern matches no node of the tree; paths close to it: {}",
                    close.join(", ")
                ));
            }
        }
        Ok(monitor)
    }

    /// The breakpoint of node `node`, if any.
    pub fn breakpoint(&self, node: usize) -> Option<BreakWhen> {
        self.breakpoints.get(&node).copied()
    }

    /// Sets or clears a breakpoint (at most `MAX_BREAKPOINTS`).
    pub fn set_breakpoint(&mut self, node: usize, when: Option<BreakWhen>) {
        match when {
            Some(w) if self.breakpoints.len() < MAX_BREAKPOINTS || self.breakpoints.contains_key(&node) => {
                self.breakpoints.insert(node, w);
            }
            Some(_) => {}
            None => {
                self.breakpoints.remove(&node);
            }
        }
    }

    /// Asks for a pause at the next tick (the page's pause button, or a step).
    pub fn request_pause(&mut self) {
        self.pause_requested = Some("pause");
    }

    /// Whether the episode is paused now.
    pub fn paused(&self) -> Option<&Pause> {
        self.paused.as_ref()
    }

    /// Results forced so far.
    pub fn forced(&self) -> &[ForcedRecord] {
        &self.forced
    }

    /// Notes a forced result.
    pub fn record_forced(&mut self, record: ForcedRecord) {
        self.forced.push(record);
    }

    /// Decides whether this tick's `transitions` (the tree was ticked; the physics has not
    /// advanced) pause the episode at sim time `t`, and enters the pause if so.
    pub fn check(&mut self, plan: &Plan, transitions: &[Transition], t: f64) -> bool {
        let hit = transitions.iter().find_map(|tr| {
            let when = self.breakpoints.get(&tr.node)?;
            let starts = tr.from != NodeStatus::Running
                && matches!(
                    tr.to,
                    NodeStatus::Running | NodeStatus::Success | NodeStatus::Failure
                );
            let ends = matches!(tr.to, NodeStatus::Success | NodeStatus::Failure);
            match when {
                BreakWhen::Before if starts => Some(("before", tr.node)),
                BreakWhen::After if ends => Some(("after", tr.node)),
                _ => None,
            }
        });
        if let Some((reason, node)) = hit {
            self.pause_requested = None;
            self.paused = Some(Pause {
                reason: reason.into(),
                path: Some(plan.nodes[node].path.clone()),
                t,
            });
        } else if let Some(reason) = self.pause_requested.take() {
            self.paused = Some(Pause {
                reason: reason.into(),
                path: None,
                t,
            });
        }
        self.paused.is_some()
    }

    /// Leaves the pause; with `step`, pauses again at the next tick.
    pub fn resume(&mut self, step: bool) {
        self.paused = None;
        self.pause_requested = step.then_some("step");
    }

    /// The state as the page shows it.
    pub fn to_json(&self, plan: &Plan) -> Value {
        let breakpoints: Vec<Value> = self
            .breakpoints
            .iter()
            .map(|(&i, w)| json!({ "path": plan.nodes[i].path, "when": w.as_str() }))
            .collect();
        let forced: Vec<Value> = self
            .forced
            .iter()
            .map(|f| json!({ "path": f.path, "result": f.result.as_str(), "t": f.t }))
            .collect();
        json!({
            "paused": self.paused.as_ref().map(|p| json!({ "reason": p.reason, "path": p.path, "t": p.t })),
            "breakpoints": breakpoints,
            "forced": forced,
        })
    }
}
