//! The compiler from [`Spec`] to [`Plan`] (see the module docs of [`crate::plan`]).

use std::collections::HashMap;

use bonsai_bt::Behavior;

use super::{Check, Internal, LeafId, LeafInfo, NodeInfo, NodeTag, Plan};
use crate::kinds::Leaf;
use crate::kinds::leaves::fmt_num;
use crate::spec::{Diagnostic, Issue, Node, NodeKind, Sources, Spec};

/// Validate and compile a loaded spec.
pub fn compile_spec(spec: &Spec) -> Result<Plan, Vec<Diagnostic>> {
    let mut c = Compiler {
        sources: &spec.sources,
        nodes: Vec::new(),
        leaves: Vec::new(),
        internal: Vec::new(),
        issues: Vec::new(),
    };
    let behavior = c.wrapped(&spec.root, None, format!("main/{}", segment(&spec.root)));
    if !c.issues.is_empty() {
        return Err(spec.sources.diagnostics(&c.issues));
    }
    Ok(Plan {
        behavior,
        leaves: c.leaves,
        nodes: c.nodes,
        internal: c.internal,
        file: spec.sources.name(0).to_string(),
        description: spec.description.clone(),
        breakpoints: spec.breakpoints.clone(),
        scene: spec.scene_spec.clone(),
        warnings: spec.warnings.clone(),
        inputs: spec.inputs(),
    })
}

struct Compiler<'a> {
    sources: &'a Sources,
    nodes: Vec<NodeInfo>,
    leaves: Vec<LeafInfo>,
    internal: Vec<Internal>,
    issues: Vec<Issue>,
}

/// A node's path segment before sibling disambiguation.
fn segment(n: &Node) -> String {
    let kind = n.kind.kind_name();
    match (&n.name, &n.kind) {
        (Some(name), _) => format!("{kind}[{name}]"),
        (None, NodeKind::Subtree { reference, .. }) => format!("{kind}[{reference}]"),
        (None, _) => kind.to_string(),
    }
}

/// Child paths: `parent/segment`, with `#k` added where siblings share a segment.
fn child_paths(parent: &str, children: &[&Node]) -> Vec<String> {
    let segs: Vec<String> = children.iter().map(|c| segment(c)).collect();
    let mut totals: HashMap<&str, usize> = HashMap::new();
    for s in &segs {
        *totals.entry(s.as_str()).or_default() += 1;
    }
    let mut seen: HashMap<&str, usize> = HashMap::new();
    segs.iter()
        .map(|s| {
            if totals[s.as_str()] > 1 {
                let k = seen.entry(s.as_str()).or_default();
                *k += 1;
                format!("{parent}/{s}#{k}")
            } else {
                format!("{parent}/{s}")
            }
        })
        .collect()
}

/// Short summary of a leaf and its key parameters.
pub(crate) fn leaf_label(leaf: &Leaf) -> String {
    match leaf {
        Leaf::Action(c) | Leaf::Condition(c) => c.label(),
        Leaf::Wait(w) => format!("wait {} s", fmt_num(w.seconds)),
        Leaf::Select(sel) => format!("select {} → {{{}}}", sel.query().describe(), sel.var),
    }
}

fn node_label(n: &Node) -> String {
    let base = match &n.kind {
        NodeKind::Retry { attempts, .. } => format!("retry ×{attempts}"),
        NodeKind::Repeat { times, .. } => format!("repeat ×{times}"),
        NodeKind::ForEach {
            select,
            max_iterations,
            ..
        } => format!(
            "for_each {} → {{{}}} (≤ {max_iterations})",
            select.query().describe(),
            select.var
        ),
        NodeKind::Timeout { seconds, .. } => format!("timeout {} s", fmt_num(*seconds)),
        NodeKind::Subtree { reference, args, .. } => {
            if args.is_empty() {
                format!("subtree {reference}")
            } else {
                let a: Vec<String> = args.iter().map(|(k, v)| format!("{k}={v}")).collect();
                format!("subtree {reference}({})", a.join(", "))
            }
        }
        NodeKind::Leaf(l) => leaf_label(l),
        other => other.kind_name().to_string(),
    };
    match (&n.name, &n.kind) {
        (Some(name), _) => format!("{base} \"{name}\""),
        _ => base,
    }
}

/// Number of bonsai nodes in a behavior.
pub(crate) fn behavior_size(b: &Behavior<LeafId>) -> usize {
    use Behavior::*;
    1 + match b {
        Wait(_) | WaitForever | Action(_) => 0,
        Invert(c) | AlwaysSucceed(c) | Timeout(_, c) => behavior_size(c),
        If(a, b2, c) => behavior_size(a) + behavior_size(b2) + behavior_size(c),
        Select(v)
        | Sequence(v)
        | MemorylessSequence(v)
        | MemorylessSelector(v)
        | WhenAll(v)
        | WhenAny(v)
        | After(v)
        | Race(v) => v.iter().map(behavior_size).sum(),
        While(c, v) | WhileAll(c, v) => behavior_size(c) + v.iter().map(behavior_size).sum::<usize>(),
    }
}

impl Compiler<'_> {
    fn internal_leaf(&mut self, i: Internal) -> Behavior<LeafId> {
        let id = LeafId(LeafId::INTERNAL | self.internal.len() as u32);
        self.internal.push(i);
        Behavior::Action(id)
    }

    /// Register `n` in the node table (preorder) and return its index.
    fn register(&mut self, n: &Node, parent: Option<usize>, path: &str) -> usize {
        let idx = self.nodes.len();
        let name = match (&n.name, &n.kind) {
            (Some(name), _) => Some(name.clone()),
            (None, NodeKind::Subtree { reference, .. }) => Some(reference.clone()),
            _ => None,
        };
        self.nodes.push(NodeInfo {
            path: path.to_string(),
            kind: n.kind.kind_name(),
            tag: NodeTag::of(&n.kind),
            category: n.kind.category(),
            name,
            parent,
            children: Vec::new(),
            leaf: None,
            label: node_label(n),
            source: self.sources.describe(n.loc),
        });
        if let Some(p) = parent {
            self.nodes[p].children.push(idx);
        }
        idx
    }

    fn add_leaf(&mut self, idx: usize, leaf: &Leaf, path: &str, check: Option<Check>) -> LeafId {
        let id = LeafId(self.leaves.len() as u32);
        self.leaves.push(LeafInfo {
            path: path.to_string(),
            kind: leaf.clone(),
            node: idx,
            check,
        });
        self.nodes[idx].leaf = Some(id);
        id
    }

    /// Compile `n` including its outcome probe (leaves are not wrapped).
    fn wrapped(&mut self, n: &Node, parent: Option<usize>, path: String) -> Behavior<LeafId> {
        let idx = self.register(n, parent, &path);
        if let NodeKind::Leaf(leaf) = &n.kind {
            return Behavior::Action(self.add_leaf(idx, leaf, &path, None));
        }
        let inner = self.body(n, idx, &path);
        let ok = self.internal_leaf(Internal::Probe {
            node: idx,
            success: true,
        });
        let fail = self.internal_leaf(Internal::Probe {
            node: idx,
            success: false,
        });
        Behavior::Select(vec![Behavior::Sequence(vec![inner, ok]), fail])
    }

    /// Compile a re-checked condition (a condition leaf, possibly under inverters).
    fn check(&mut self, n: &Node, parent: usize, path: String, continue_on: bool) -> Behavior<LeafId> {
        let mut inverters = Vec::new();
        let mut cur = n;
        let mut cur_parent = parent;
        let mut cur_path = path;
        loop {
            let idx = self.register(cur, Some(cur_parent), &cur_path);
            match &cur.kind {
                NodeKind::Inverter(child) => {
                    inverters.push(idx);
                    let p = child_paths(&cur_path, &[child]).remove(0);
                    cur_parent = idx;
                    cur_path = p;
                    cur = child;
                }
                NodeKind::Leaf(leaf) => {
                    let check = Check {
                        inverters,
                        continue_on,
                    };
                    return Behavior::Action(self.add_leaf(idx, leaf, &cur_path, Some(check)));
                }
                _ => {
                    // The spec parser only lets conditions (and inverters of them) through.
                    self.issues.push(
                        Issue::new(cur.loc, "internal error: expected a condition here")
                            .help("please report this tree as a bug"),
                    );
                    return Behavior::WaitForever;
                }
            }
        }
    }

    fn body(&mut self, n: &Node, idx: usize, path: &str) -> Behavior<LeafId> {
        let children = n.kind.children();
        let paths = child_paths(path, &children);
        match &n.kind {
            NodeKind::Sequence(c) | NodeKind::Fallback(c) | NodeKind::Parallel(c) | NodeKind::Race(c) => {
                let bs: Vec<_> = c
                    .iter()
                    .zip(paths)
                    .map(|(ch, p)| self.wrapped(ch, Some(idx), p))
                    .collect();
                match &n.kind {
                    NodeKind::Sequence(_) => Behavior::Sequence(bs),
                    NodeKind::Fallback(_) => Behavior::Select(bs),
                    NodeKind::Parallel(_) => Behavior::WhenAll(bs),
                    _ => Behavior::Race(bs),
                }
            }
            NodeKind::ReactiveSequence(c) | NodeKind::ReactiveFallback(c) => {
                let continue_on = matches!(n.kind, NodeKind::ReactiveSequence(_));
                let last = c.len() - 1;
                let mut bs = Vec::with_capacity(c.len());
                for (i, (ch, p)) in c.iter().zip(paths).enumerate() {
                    if i < last {
                        bs.push(self.check(ch, idx, p, continue_on));
                    } else {
                        bs.push(self.wrapped(ch, Some(idx), p));
                    }
                }
                Behavior::Race(bs)
            }
            NodeKind::Guard { condition, child } => {
                let mut paths = paths.into_iter();
                let cp = paths.next().unwrap_or_default();
                let xp = paths.next().unwrap_or_default();
                let c = self.check(condition, idx, cp, true);
                let x = self.wrapped(child, Some(idx), xp);
                Behavior::Race(vec![c, x])
            }
            NodeKind::Retry { attempts, child } => {
                let w = self.wrapped(child, Some(idx), paths.into_iter().next().unwrap_or_default());
                let next = self.internal_leaf(Internal::Next {
                    node: idx,
                    limit: *attempts,
                });
                let exit = self.internal_leaf(Internal::Exit {
                    node: idx,
                    flagged_success: false,
                });
                // A child success fails the inverted body and ends the loop; the inverted loop
                // then succeeds, and `exit` tells a success from attempts used up.
                let body = vec![Behavior::Invert(Box::new(w)), next];
                let looped = Behavior::While(Box::new(Behavior::WaitForever), body);
                Behavior::Sequence(vec![Behavior::Invert(Box::new(looped)), exit])
            }
            NodeKind::Repeat { times, child } => {
                let w = self.wrapped(child, Some(idx), paths.into_iter().next().unwrap_or_default());
                let next = self.internal_leaf(Internal::Next {
                    node: idx,
                    limit: *times,
                });
                let exit = self.internal_leaf(Internal::Exit {
                    node: idx,
                    flagged_success: true,
                });
                let looped = Behavior::While(Box::new(Behavior::WaitForever), vec![w, next]);
                Behavior::Select(vec![looped, exit])
            }
            NodeKind::ForEach {
                select,
                max_iterations,
                child,
            } => {
                let pick = self.internal_leaf(Internal::Pick {
                    node: idx,
                    select: select.clone(),
                    limit: *max_iterations,
                });
                let w = self.wrapped(child, Some(idx), paths.into_iter().next().unwrap_or_default());
                let next = self.internal_leaf(Internal::Next {
                    node: idx,
                    limit: *max_iterations,
                });
                let exit = self.internal_leaf(Internal::Exit {
                    node: idx,
                    flagged_success: true,
                });
                let looped = Behavior::While(Box::new(Behavior::WaitForever), vec![pick, w, next]);
                Behavior::Select(vec![looped, exit])
            }
            NodeKind::Timeout { seconds, child } => {
                let w = self.wrapped(child, Some(idx), paths.into_iter().next().unwrap_or_default());
                Behavior::Timeout(*seconds, Box::new(w))
            }
            NodeKind::Inverter(child) | NodeKind::ForceSuccess(child) | NodeKind::ForceFailure(child) => {
                let w = self.wrapped(child, Some(idx), paths.into_iter().next().unwrap_or_default());
                match &n.kind {
                    NodeKind::Inverter(_) => Behavior::Invert(Box::new(w)),
                    NodeKind::ForceSuccess(_) => Behavior::AlwaysSucceed(Box::new(w)),
                    _ => Behavior::Invert(Box::new(Behavior::AlwaysSucceed(Box::new(w)))),
                }
            }
            NodeKind::Subtree { body, .. } => {
                self.wrapped(body, Some(idx), paths.into_iter().next().unwrap_or_default())
            }
            NodeKind::Leaf(_) => Behavior::WaitForever, // handled by `wrapped`
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::plan::Loader;

    #[test]
    fn paths_are_unique_and_readable() {
        let plan = Loader::default().compile_str(
            "main:\n  sequence:\n    children:\n      - home: {}\n      - retry:\n          attempts: 3\n          child:\n            sequence:\n              name: pick\n              children:\n                - reach: {target: cube, offset: [0, 0, 0.15]}\n                - reach: {target: cube}\n                - grasp: {}\n      - home: {}\n",
            "t.yaml",
        )
        .unwrap();
        let paths: Vec<&str> = plan.nodes.iter().map(|n| n.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "main/sequence",
                "main/sequence/home#1",
                "main/sequence/retry",
                "main/sequence/retry/sequence[pick]",
                "main/sequence/retry/sequence[pick]/reach#1",
                "main/sequence/retry/sequence[pick]/reach#2",
                "main/sequence/retry/sequence[pick]/grasp",
                "main/sequence/home#2",
            ]
        );
        assert_eq!(plan.leaves.len(), 5);
        assert_eq!(plan.nodes[2].children, vec![3]);
        assert_eq!(plan.nodes[3].parent, Some(2));
        assert_eq!(plan.nodes[4].label, "reach cube +[0, 0, 0.15]");
        assert_eq!(plan.nodes[2].source, "t.yaml:5:9");
    }
}
