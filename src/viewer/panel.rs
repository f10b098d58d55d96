//! The behavior-tree side panel of the live page: the node list (sent once), node statuses,
//! retry attempts and the latest trace events. Sent as JSON **text** frames (binary frames are
//! MeshCat commands).

use std::collections::VecDeque;

use serde::Serialize;
use serde_json::{Value, json};

/// How many trace events the server keeps for late joiners and slow readers.
pub const EVENT_HISTORY: usize = 200;

/// One node of the behavior tree as the panel shows it (preorder; `parent` is the preorder
/// index of the parent, `None` for the root).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TreeNodeView {
    /// Node path in the tree (e.g. `root/0/pick`).
    pub path: String,
    /// Node kind (`sequence`, `fallback`, `retry`, action or condition name, …).
    pub kind: String,
    /// Display name.
    pub name: String,
    /// Preorder index of the parent node.
    pub parent: Option<usize>,
}

/// The statuses a node can show.
pub const STATUSES: [&str; 5] = ["idle", "running", "success", "failure", "halted"];

/// Panel state held by the server (latest wins, bounded event history).
#[derive(Debug, Default)]
pub struct PanelState {
    tree: Option<String>,
    statuses: Vec<&'static str>,
    attempts: Vec<u32>,
    events: VecDeque<(u64, Value)>,
    next_seq: u64,
    /// Bumped on every status change, so writers know whether to send.
    pub version: u64,
}

impl PanelState {
    /// Replaces the node list (and resets statuses to idle).
    pub fn set_tree(&mut self, nodes: &[TreeNodeView]) {
        self.tree = Some(json!({ "type": "tree", "nodes": nodes }).to_string());
        self.statuses = vec!["idle"; nodes.len()];
        self.attempts = vec![0; nodes.len()];
        self.version += 1;
    }

    /// The `tree` message, if a tree was set.
    pub fn tree_message(&self) -> Option<&str> {
        self.tree.as_deref()
    }

    /// Records statuses, attempts (empty = unchanged) and new events.
    pub fn update(&mut self, statuses: Vec<&'static str>, attempts: Option<Vec<u32>>, events: Vec<Value>) {
        self.statuses = statuses;
        if let Some(attempts) = attempts {
            self.attempts = attempts;
        }
        for event in events {
            self.events.push_back((self.next_seq, event));
            self.next_seq += 1;
            while self.events.len() > EVENT_HISTORY {
                self.events.pop_front();
            }
        }
        self.version += 1;
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
        let msg = json!({
            "type": "status",
            "statuses": self.statuses,
            "attempts": self.attempts,
            "events": events,
        });
        (msg.to_string(), self.next_seq)
    }
}
