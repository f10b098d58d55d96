//! Spec → validated, compiled plan: a bonsai [`Behavior<LeafId>`](bonsai_bt::Behavior) plus
//! tables describing every node and leaf.
//!
//! # How node kinds map onto bonsai 0.14
//!
//! Every non-leaf node `X` is compiled to `B(X)` and wrapped in a *probe* so that the runtime
//! learns exactly how bonsai finished it (bonsai itself reports only leaf calls):
//!
//! ```text
//! W(X) = Select([ Sequence([ B(X), ok_probe(X) ]), fail_probe(X) ])
//! ```
//!
//! Probes are internal leaves ([`Internal::Probe`]) that record the outcome and pass the whole
//! remaining `dt` on, so they cost no simulated time. `B(X)` is:
//!
//! | YAML | bonsai |
//! |---|---|
//! | `sequence` / `fallback` | `Sequence` / `Select` (with memory) |
//! | `parallel` | `WhenAll` |
//! | `race` | `Race` |
//! | `reactive_sequence [c.., x]` / `guard {c, x}` | `Race([check(c).., W(x)])`, a check reports Running while its condition holds and Failure otherwise |
//! | `reactive_fallback [c.., x]` | `Race([check(c).., W(x)])`, a check reports Running while its condition fails and Success otherwise |
//! | `retry N` | `Sequence([Invert(While(WaitForever, [Invert(W(x)), next(N)])), exit])` |
//! | `repeat N` | `Select([While(WaitForever, [W(x), next(N)]), exit])` |
//! | `for_each {select, max_iterations: N}` | `Select([While(WaitForever, [pick(N), W(x), next]), exit])` |
//! | `timeout S` | `Timeout(S, W(x))` |
//! | `inverter` / `force_success` / `force_failure` | `Invert` / `AlwaysSucceed` / `Invert(AlwaysSucceed)` |
//! | `subtree` | `W(body)` |
//! | leaf | `Action(LeafId)` |
//!
//! Loops keep their counters in the runtime (BehaviorTree.CPP's way), not copies of the child:
//! bonsai's `While` restarts its body with a fresh state each time round, `next`
//! ([`Internal::Next`]) ends an iteration — Running on the tick it is reached and Success on the
//! next one, so each retry attempt / repeat or for_each iteration after the first starts on a
//! fresh tick, after the world has been stepped and re-read — and sets an exit flag when the
//! count is used up; `exit` ([`Internal::Exit`]) turns the `While`'s end into the loop's
//! outcome, and `pick` ([`Internal::Pick`]) selects the object of a `for_each` iteration. See
//! `docs/tick_semantics.md`.

#![warn(missing_docs)]

mod compile;
mod loader;
mod render;
mod subplan;

use serde::Serialize;

use crate::kinds::Leaf;
use crate::yaml::Diagnostic;

pub use compile::compile_spec;
pub use loader::Loader;
pub use render::{to_dot, to_mermaid};

/// Index of a leaf: `plan.leaves[id.index()]` for ordinary leaves; internal leaves (probes and
/// yields, see [`Internal`]) have the top bit set and index `plan.internal`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct LeafId(pub u32);

impl LeafId {
    /// The bit that marks internal leaves.
    pub const INTERNAL: u32 = 1 << 31;

    /// True for probes and yields.
    pub fn is_internal(self) -> bool {
        self.0 & Self::INTERNAL != 0
    }

    /// Index into `plan.leaves` (or `plan.internal` for internal leaves).
    pub fn index(self) -> usize {
        (self.0 & !Self::INTERNAL) as usize
    }
}

/// How a condition leaf that is re-checked every tick (by a `guard` or a reactive composite)
/// reports to bonsai.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Check {
    /// `inverter` nodes between the check's owner and the condition leaf, outermost first; the
    /// condition's result is flipped once per inverter.
    pub inverters: Vec<usize>,
    /// The (inverted) result that lets the guarded child run: `true` (Success) for `guard` and
    /// `reactive_sequence`, `false` (Failure) for `reactive_fallback`. That result is reported
    /// to bonsai as Running; the other one is reported as is.
    pub continue_on: bool,
}

/// One leaf of the plan (an action, a condition or a `wait`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LeafInfo {
    /// The node path, e.g. `main/sequence/retry/sequence[pick]/reach#2`.
    pub path: String,
    /// The leaf with all parameters resolved.
    pub kind: Leaf,
    /// Index of the leaf's node in `plan.nodes`.
    pub node: usize,
    /// Set when the leaf is a re-checked condition of a guard / reactive composite.
    pub check: Option<Check>,
}

/// What a compiled node is, for the code that acts on it (the runner, the diagrams): a typed
/// tag, where [`NodeInfo::kind`] is the YAML name shown to people.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum NodeTag {
    /// A control node (composite, decorator or subtree call), by its kind.
    Control(crate::kinds::ControlKind),
    /// A leaf: an action, a condition, `wait` or `select`.
    Leaf,
}

impl NodeTag {
    /// The tag of a parsed node.
    pub fn of(kind: &crate::spec::NodeKind) -> NodeTag {
        kind.control_kind().map_or(NodeTag::Leaf, NodeTag::Control)
    }
}

/// One node of the plan (composite, decorator, subtree call or leaf), in preorder.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeInfo {
    /// Stable, unique, readable path: `main/<segment>/…` where a segment is the node kind,
    /// `[name]` if the node has a `name:` (for subtree calls, the subtree's name), and `#k`
    /// (1-based) when siblings would otherwise share the segment.
    pub path: String,
    /// The YAML node kind (`sequence`, `retry`, `reach`, …), as shown to people.
    pub kind: &'static str,
    /// What the node is, for the code that acts on it.
    #[serde(skip)]
    pub tag: NodeTag,
    /// What the node is (composite, decorator, action, condition, runtime leaf).
    pub category: crate::kinds::Category,
    /// The `name:` given in YAML (for a subtree call without a name: the subtree's name).
    pub name: Option<String>,
    /// Parent node index (`None` for the root).
    pub parent: Option<usize>,
    /// Child node indices, in tick order (a guard's condition first).
    pub children: Vec<usize>,
    /// The leaf, for leaf nodes.
    pub leaf: Option<LeafId>,
    /// Short human-readable summary with the key parameters, e.g. `retry ×3`,
    /// `reach cube +[0, 0, 0.15]`.
    pub label: String,
    /// Where the node is written, `file:line:column`.
    pub source: String,
}

/// Runtime-internal leaves inserted by the compiler; they never reach a driver.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum Internal {
    /// Records that `node` finished with Success (`success == true`) or Failure, and returns that
    /// status with the whole remaining `dt`.
    Probe {
        /// The node whose outcome this probe records.
        node: usize,
        /// Which outcome.
        success: bool,
    },
    /// The end of one iteration of the loop node `node` (`retry`, `repeat`, `for_each`). While
    /// iterations remain it is Running on the tick it is reached (the iteration counter goes up)
    /// and Success on the next tick, so the next iteration starts on a fresh tick, after the
    /// world has been stepped and re-read. When `retry`/`repeat` has used all `limit`
    /// iterations it sets the loop's exit flag and fails, which ends the loop in the same tick.
    Next {
        /// The loop node.
        node: usize,
        /// Attempts (`retry`), successful runs (`repeat`) or iterations (`for_each`) allowed.
        limit: u32,
    },
    /// After the loop node `node`'s bonsai `While` ended: reads (and clears) the exit flag. With
    /// the flag set it answers Success when `flagged_success`, Failure otherwise; without it, the
    /// opposite.
    Exit {
        /// The loop node.
        node: usize,
        /// What a set flag means.
        flagged_success: bool,
    },
    /// The start of an iteration of the `for_each` node `node`: selects the next object with
    /// `query` (through the driver) and writes it to the blackboard. When nothing matches it
    /// sets the exit flag and fails (the loop then succeeds); when something still matches after
    /// `limit` iterations it fails (the loop fails).
    Pick {
        /// The `for_each` node.
        node: usize,
        /// What to select, and where to write it.
        select: crate::kinds::Select,
        /// Iterations allowed.
        limit: u32,
    },
}

/// A validated, compiled tree, ready to be run by [`crate::runtime::TreeRunner`].
#[derive(Clone, Debug)]
pub struct Plan {
    /// The bonsai behavior; actions are [`LeafId`]s.
    pub behavior: bonsai_bt::Behavior<LeafId>,
    /// Ordinary leaves, indexed by [`LeafId::index`].
    pub leaves: Vec<LeafInfo>,
    /// Every node in preorder; index 0 is the root.
    pub nodes: Vec<NodeInfo>,
    /// Internal leaves (probes, yields), indexed by [`LeafId::index`] of internal ids.
    pub internal: Vec<Internal>,
    /// The main file's name.
    pub file: String,
    /// The tree's `description:`, if any.
    pub description: Option<String>,
    /// The tree file's `breakpoints:`, for the live monitor (`run --view` pauses there as at
    /// `--break`); nothing else reads them.
    pub breakpoints: Vec<crate::spec::DeclaredBreakpoint>,
    /// The scene the tree's object names were checked against, which it runs on.
    pub scene: std::sync::Arc<crate::scene::SceneSpec>,
    /// Warnings about the tree file: accepted, but probably not what was meant.
    pub warnings: Vec<Diagnostic>,
    /// Every file the tree was read from: the main file and its includes (canonical paths,
    /// sorted), then the scene file its `scene:` names, if any. A command's outputs may
    /// name none of them.
    pub inputs: Vec<std::path::PathBuf>,
}

impl Plan {
    /// The ordinary leaf with this id (`None` for internal ids).
    pub fn leaf(&self, id: LeafId) -> Option<&LeafInfo> {
        if id.is_internal() {
            None
        } else {
            self.leaves.get(id.index())
        }
    }

    /// The internal leaf with this id (`None` for ordinary ids).
    pub fn internal(&self, id: LeafId) -> Option<&Internal> {
        if id.is_internal() {
            self.internal.get(id.index())
        } else {
            None
        }
    }

    /// Index of the node with this path.
    pub fn node_by_path(&self, path: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.path == path)
    }

    /// The leaf whose node path is `path`.
    pub fn leaf_by_path(&self, path: &str) -> Option<LeafId> {
        self.leaves
            .iter()
            .position(|l| l.path == path)
            .map(|i| LeafId(i as u32))
    }

    /// Number of bonsai behavior nodes (a measure of the compiled size).
    pub fn behavior_size(&self) -> usize {
        compile::behavior_size(&self.behavior)
    }
}
