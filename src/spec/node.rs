//! The typed tree: one [`Node`] per YAML node, subtrees already expanded.

use crate::kinds::leaves::Leaf;
use crate::yaml::diag::Loc;

/// A node of the behavior tree as written (after subtree expansion), with its source location.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// What the node is and its children.
    pub kind: NodeKind,
    /// The optional `name:` given in YAML.
    pub name: Option<String>,
    /// Where the node's kind key is written (`sequence:` …).
    pub loc: Loc,
}

/// Every node kind. Semantics, halt behaviour and YAML examples are in `docs/tree_format.md`;
/// the one-line summary is on each variant.
#[derive(Clone, Debug, PartialEq)]
pub enum NodeKind {
    #[doc = include_str!("../../docs/nodes/sequence.md")]
    Sequence(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/fallback.md")]
    Fallback(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/reactive_sequence.md")]
    ReactiveSequence(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/reactive_fallback.md")]
    ReactiveFallback(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/parallel.md")]
    Parallel(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/race.md")]
    Race(Vec<Node>),
    #[doc = include_str!("../../docs/nodes/guard.md")]
    Guard {
        /// A condition leaf (or an `inverter` of one).
        condition: Box<Node>,
        /// The guarded node.
        child: Box<Node>,
    },
    #[doc = include_str!("../../docs/nodes/retry.md")]
    Retry {
        /// Total number of runs allowed (≥ 1).
        attempts: u32,
        /// The node to retry.
        child: Box<Node>,
    },
    #[doc = include_str!("../../docs/nodes/repeat.md")]
    Repeat {
        /// Number of successful runs required (≥ 1).
        times: u32,
        /// The node to repeat.
        child: Box<Node>,
    },
    #[doc = include_str!("../../docs/nodes/for_each.md")]
    ForEach {
        /// What each iteration selects, and the variables it writes.
        select: crate::kinds::leaves::Select,
        /// Most iterations (≥ 1); more matches after that fail the loop.
        max_iterations: u32,
        /// The node run once per selected object.
        child: Box<Node>,
    },
    #[doc = include_str!("../../docs/nodes/timeout.md")]
    Timeout {
        /// Simulated seconds (> 0).
        seconds: f64,
        /// The node to time-limit.
        child: Box<Node>,
    },
    #[doc = include_str!("../../docs/nodes/inverter.md")]
    Inverter(Box<Node>),
    #[doc = include_str!("../../docs/nodes/force_success.md")]
    ForceSuccess(Box<Node>),
    #[doc = include_str!("../../docs/nodes/force_failure.md")]
    ForceFailure(Box<Node>),
    #[doc = include_str!("../../docs/nodes/subtree.md")]
    Subtree {
        /// The subtree's name (`ref:`).
        reference: String,
        /// The arguments as given, rendered as compact YAML-ish text (for display).
        args: Vec<(String, String)>,
        /// The expanded body.
        body: Box<Node>,
    },
    /// A leaf (action, condition or wait).
    Leaf(Leaf),
}

impl NodeKind {
    /// What the node is: composite, decorator (a subtree call counts as one), action, condition
    /// or runtime leaf.
    pub fn category(&self) -> crate::kinds::Category {
        use crate::kinds::Category;
        match self {
            NodeKind::Sequence(_)
            | NodeKind::Fallback(_)
            | NodeKind::ReactiveSequence(_)
            | NodeKind::ReactiveFallback(_)
            | NodeKind::Parallel(_)
            | NodeKind::Race(_) => Category::Composite,
            NodeKind::Leaf(Leaf::Action(_)) => Category::Action,
            NodeKind::Leaf(Leaf::Condition(_)) => Category::Condition,
            NodeKind::Leaf(_) => Category::Runtime,
            _ => Category::Decorator,
        }
    }

    /// The YAML kind name (`sequence`, `retry`, `reach`, …).
    pub fn kind_name(&self) -> &'static str {
        match self {
            NodeKind::Sequence(_) => "sequence",
            NodeKind::Fallback(_) => "fallback",
            NodeKind::ReactiveSequence(_) => "reactive_sequence",
            NodeKind::ReactiveFallback(_) => "reactive_fallback",
            NodeKind::Parallel(_) => "parallel",
            NodeKind::Race(_) => "race",
            NodeKind::Guard { .. } => "guard",
            NodeKind::Retry { .. } => "retry",
            NodeKind::Repeat { .. } => "repeat",
            NodeKind::ForEach { .. } => "for_each",
            NodeKind::Timeout { .. } => "timeout",
            NodeKind::Inverter(_) => "inverter",
            NodeKind::ForceSuccess(_) => "force_success",
            NodeKind::ForceFailure(_) => "force_failure",
            NodeKind::Subtree { .. } => "subtree",
            NodeKind::Leaf(l) => l.kind(),
        }
    }

    /// The control kind of a composite, decorator or subtree call; `None` for a leaf.
    pub fn control_kind(&self) -> Option<crate::kinds::ControlKind> {
        use crate::kinds::ControlKind as C;
        Some(match self {
            NodeKind::Sequence(_) => C::Sequence,
            NodeKind::Fallback(_) => C::Fallback,
            NodeKind::ReactiveSequence(_) => C::ReactiveSequence,
            NodeKind::ReactiveFallback(_) => C::ReactiveFallback,
            NodeKind::Parallel(_) => C::Parallel,
            NodeKind::Race(_) => C::Race,
            NodeKind::Guard { .. } => C::Guard,
            NodeKind::Retry { .. } => C::Retry,
            NodeKind::Repeat { .. } => C::Repeat,
            NodeKind::ForEach { .. } => C::ForEach,
            NodeKind::Timeout { .. } => C::Timeout,
            NodeKind::Inverter(_) => C::Inverter,
            NodeKind::ForceSuccess(_) => C::ForceSuccess,
            NodeKind::ForceFailure(_) => C::ForceFailure,
            NodeKind::Subtree { .. } => C::Subtree,
            NodeKind::Leaf(_) => return None,
        })
    }

    /// The children in tick order (a guard's condition comes first).
    pub fn children(&self) -> Vec<&Node> {
        match self {
            NodeKind::Sequence(c)
            | NodeKind::Fallback(c)
            | NodeKind::ReactiveSequence(c)
            | NodeKind::ReactiveFallback(c)
            | NodeKind::Parallel(c)
            | NodeKind::Race(c) => c.iter().collect(),
            NodeKind::Guard { condition, child } => vec![condition, child],
            NodeKind::Retry { child, .. }
            | NodeKind::Repeat { child, .. }
            | NodeKind::ForEach { child, .. }
            | NodeKind::Timeout { child, .. }
            | NodeKind::Inverter(child)
            | NodeKind::ForceSuccess(child)
            | NodeKind::ForceFailure(child) => vec![child],
            NodeKind::Subtree { body, .. } => vec![body],
            NodeKind::Leaf(_) => vec![],
        }
    }
}

impl Node {
    /// Number of nodes in this subtree (itself included).
    pub fn count(&self) -> usize {
        1 + self.kind.children().iter().map(|c| c.count()).sum::<usize>()
    }

    /// The leaf, if this node is one.
    pub fn leaf(&self) -> Option<&Leaf> {
        match &self.kind {
            NodeKind::Leaf(l) => Some(l),
            _ => None,
        }
    }

    /// If this node is an instantaneous check usable as a guard or reactive condition — a
    /// condition leaf, or an `inverter` of one — return the condition node and whether it is
    /// inverted.
    pub fn as_check(&self) -> Option<(&Node, bool)> {
        match &self.kind {
            NodeKind::Leaf(Leaf::Condition(_)) => Some((self, false)),
            NodeKind::Inverter(c) => c.as_check().map(|(n, inv)| (n, !inv)),
            _ => None,
        }
    }
}
