//! The behavior-tree side panel of the live page: the node list (sent once), node statuses,
//! loop counters, the blackboard, the monitor's state and the latest trace events. Sent as JSON
//! **text** frames (binary frames are MeshCat commands).

use std::collections::{BTreeMap, VecDeque};

use serde::Serialize;
use serde_json::{Value, json};

/// How many trace events the server keeps for late joiners and slow readers.
pub const EVENT_HISTORY: usize = 200;
/// Most blackboard variables the panel keeps (a tree declares a handful; the bound keeps a
/// hostile driver from growing the server's state).
pub const MAX_BLACKBOARD_VARS: usize = 256;

/// One node of the behavior tree as the panel shows it (preorder; `parent` is the preorder
/// index of the parent, `None` for the root).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct TreeNodeView {
    /// Node path in the tree (e.g. `root/0/pick`).
    pub path: String,
    /// Node kind (`sequence`, `fallback`, `retry`, action or condition name, …).
    pub kind: String,
    /// Display name (variables written `{block}`; the page shows their current values).
    pub name: String,
    /// Preorder index of the parent node.
    pub parent: Option<usize>,
    /// Loops: attempts (`retry`), runs (`repeat`) or iterations allowed (`for_each`'s
    /// `max_iterations`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<u32>,
    /// `for_each`: the blackboard variable each iteration writes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub var: Option<String>,
    /// A leaf (its result can be forced from the page, live).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub leaf: bool,
    /// Where the node is written, `file:line:column` (empty when unknown).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub source: String,
}

/// The current value of one blackboard variable, as the panel's table shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlackboardEntry {
    /// The variable (without braces).
    pub var: String,
    /// Its value; `None` when the last write unset it.
    pub value: Option<String>,
    /// The node that wrote it.
    pub path: String,
    /// When, simulated seconds.
    pub t: f64,
}

/// Panel state held by the server (latest wins, bounded event history).
#[derive(Debug, Default)]
pub struct PanelState {
    tree: Option<String>,
    statuses: Vec<&'static str>,
    attempts: Vec<u32>,
    blackboard: BTreeMap<String, BlackboardEntry>,
    monitor: Value,
    events: VecDeque<(u64, Value)>,
    next_seq: u64,
    /// Bumped on every status change, so writers know whether to send.
    pub version: u64,
}

impl PanelState {
    /// Replaces the node list (and resets statuses to idle and the blackboard to empty).
    pub fn set_tree(&mut self, nodes: &[TreeNodeView]) {
        self.tree = Some(json!({ "type": "tree", "nodes": nodes }).to_string());
        self.statuses = vec!["idle"; nodes.len()];
        self.attempts = vec![0; nodes.len()];
        self.blackboard.clear();
        self.version += 1;
    }

    /// The `tree` message, if a tree was set.
    pub fn tree_message(&self) -> Option<&str> {
        self.tree.as_deref()
    }

    /// Records statuses, attempts (`None` = unchanged) and new events; blackboard events
    /// (`{"kind": "blackboard", "var", "value", "path", "t"}`) update the blackboard table.
    pub fn update(&mut self, statuses: Vec<&'static str>, attempts: Option<Vec<u32>>, events: Vec<Value>) {
        self.statuses = statuses;
        if let Some(attempts) = attempts {
            self.attempts = attempts;
        }
        for event in events {
            self.note_blackboard(&event);
            self.events.push_back((self.next_seq, event));
            self.next_seq += 1;
            while self.events.len() > EVENT_HISTORY {
                self.events.pop_front();
            }
        }
        self.version += 1;
    }

    /// The monitor's state (paused or not, where, breakpoints, forced results), as the page
    /// shows it; replaced whole.
    pub fn set_monitor(&mut self, monitor: Value) {
        self.monitor = monitor;
        self.version += 1;
    }

    fn note_blackboard(&mut self, event: &Value) {
        if event.get("kind").and_then(Value::as_str) != Some("blackboard") {
            return;
        }
        let Some(var) = event.get("var").and_then(Value::as_str) else {
            return;
        };
        if !self.blackboard.contains_key(var) && self.blackboard.len() >= MAX_BLACKBOARD_VARS {
            return;
        }
        let entry = BlackboardEntry {
            var: var.to_owned(),
            value: event.get("value").and_then(Value::as_str).map(str::to_owned),
            path: event.get("path").and_then(Value::as_str).unwrap_or("").to_owned(),
            t: event.get("t").and_then(Value::as_f64).unwrap_or(0.0),
        };
        self.blackboard.insert(var.to_owned(), entry);
    }

    /// The `status` message for a reader that has seen events up to (excluding) `seen`; returns
    /// the message and the new `seen`.
    pub fn status_message(&self, seen: u64) -> (String, u64) {
        let events: Vec<Value> = self
            .events
            .iter()
            .filter(|(seq, _)| *seq >= seen)
            .map(|(seq, ev)| json!({ "seq": seq, "event": ev }))
            .collect();
        let blackboard: Vec<&BlackboardEntry> = self.blackboard.values().collect();
        let msg = json!({
            "type": "status",
            "statuses": self.statuses,
            "attempts": self.attempts,
            "blackboard": blackboard,
            "monitor": self.monitor,
            "events": events,
        });
        (msg.to_string(), self.next_seq)
    }
}
