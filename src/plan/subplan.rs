//! [`Plan::subplan`]: the part of a compiled plan under one node, as a plan of its own — what
//! runs when a caller asks for one named subtree of a tree (`env::Action::Subtree`).
//!
//! The sub-plan is cut out of the compiled plan, not recompiled: its bonsai behavior is the
//! node's own wrapped behavior (`W(X)`, see the module docs of [`crate::plan`]), so the subtree
//! ticks exactly as it does inside the whole tree. Node, leaf and internal indices are renumbered
//! from 0; node paths stay those of the whole tree, so failures name the node where it is
//! written.

use std::collections::HashMap;

use bonsai_bt::Behavior;

use super::{Internal, LeafId, Plan};

impl Plan {
    /// The part of this plan under node `node` (an index into [`Plan::nodes`]) as a plan of its
    /// own, rooted at that node. `None` when there is no such node or it cannot run alone: a
    /// condition re-checked by a `guard` or a reactive composite, or an `inverter` folded into
    /// one.
    pub fn subplan(&self, node: usize) -> Option<Plan> {
        if node == 0 {
            return Some(self.clone());
        }
        let info = self.nodes.get(node)?;
        let end = (node + 1..self.nodes.len())
            .find(|&i| !self.is_below(i, node))
            .unwrap_or(self.nodes.len());
        let behavior = match info.leaf {
            Some(id) => {
                if self.leaf(id)?.check.is_some() {
                    return None;
                }
                Behavior::Action(id)
            }
            None => find_wrapped(&self.behavior, node, self)?.clone(),
        };
        let in_range = |i: usize| (node..end).contains(&i);
        let renode = |i: usize| i - node;
        // Leaves and internal leaves of the node's range, renumbered in order.
        let mut leaf_map = HashMap::new();
        let mut leaves = Vec::new();
        for (i, l) in self.leaves.iter().enumerate() {
            if in_range(l.node) {
                leaf_map.insert(i as u32, leaves.len() as u32);
                let mut l = l.clone();
                l.node = renode(l.node);
                if let Some(c) = &mut l.check {
                    c.inverters.iter_mut().for_each(|n| *n = renode(*n));
                }
                if info.leaf.is_some() {
                    l.check = None;
                }
                leaves.push(l);
            }
        }
        let mut internal_map = HashMap::new();
        let mut internal = Vec::new();
        for (i, x) in self.internal.iter().enumerate() {
            let owner = match x {
                Internal::Probe { node, .. }
                | Internal::Next { node, .. }
                | Internal::Exit { node, .. }
                | Internal::Pick { node, .. } => *node,
            };
            if in_range(owner) {
                internal_map.insert(i as u32, internal.len() as u32);
                let mut x = x.clone();
                match &mut x {
                    Internal::Probe { node, .. }
                    | Internal::Next { node, .. }
                    | Internal::Exit { node, .. }
                    | Internal::Pick { node, .. } => *node = renode(*node),
                }
                internal.push(x);
            }
        }
        let nodes = self.nodes[node..end]
            .iter()
            .map(|n| {
                let mut n = n.clone();
                n.parent = n.parent.filter(|&p| in_range(p)).map(renode);
                n.children.iter_mut().for_each(|c| *c = renode(*c));
                n.leaf = n.leaf.map(|id| LeafId(leaf_map[&id.0]));
                n
            })
            .collect();
        let behavior = remap(&behavior, &|id: LeafId| {
            if id.is_internal() {
                LeafId(LeafId::INTERNAL | internal_map[&(id.index() as u32)])
            } else {
                LeafId(leaf_map[&id.0])
            }
        });
        Some(Plan {
            behavior,
            leaves,
            nodes,
            internal,
            file: self.file.clone(),
            description: self.description.clone(),
            breakpoints: Vec::new(),
            scene: self.scene.clone(),
            warnings: Vec::new(),
            inputs: self.inputs.clone(),
        })
    }

    /// Node `i` is a descendant of node `ancestor`.
    fn is_below(&self, i: usize, ancestor: usize) -> bool {
        let mut cur = self.nodes[i].parent;
        while let Some(p) = cur {
            if p == ancestor {
                return true;
            }
            cur = self.nodes[p].parent;
        }
        false
    }
}

/// The wrapped behavior `Select([Sequence([B(X), ok]), fail])` of node `node`: the `Select`
/// whose last child is `node`'s failure probe.
fn find_wrapped<'a>(b: &'a Behavior<LeafId>, node: usize, plan: &Plan) -> Option<&'a Behavior<LeafId>> {
    use Behavior::*;
    if let Select(v) = b
        && let [_, Action(id)] = v.as_slice()
        && matches!(plan.internal(*id), Some(Internal::Probe { node: n, success: false }) if *n == node)
    {
        return Some(b);
    }
    match b {
        Wait(_) | WaitForever | Action(_) => None,
        Invert(c) | AlwaysSucceed(c) | Timeout(_, c) => find_wrapped(c, node, plan),
        If(a, t, e) => [a, t, e].into_iter().find_map(|c| find_wrapped(c, node, plan)),
        Select(v)
        | Sequence(v)
        | MemorylessSequence(v)
        | MemorylessSelector(v)
        | WhenAll(v)
        | WhenAny(v)
        | After(v)
        | Race(v) => v.iter().find_map(|c| find_wrapped(c, node, plan)),
        While(c, v) | WhileAll(c, v) => {
            find_wrapped(c, node, plan).or_else(|| v.iter().find_map(|x| find_wrapped(x, node, plan)))
        }
    }
}

/// `b` with every action id replaced by `f(id)`.
fn remap(b: &Behavior<LeafId>, f: &dyn Fn(LeafId) -> LeafId) -> Behavior<LeafId> {
    use Behavior::*;
    let all = |v: &Vec<Behavior<LeafId>>| v.iter().map(|c| remap(c, f)).collect::<Vec<_>>();
    let one = |c: &Behavior<LeafId>| Box::new(remap(c, f));
    match b {
        Wait(t) => Wait(*t),
        WaitForever => WaitForever,
        Action(id) => Action(f(*id)),
        Invert(c) => Invert(one(c)),
        AlwaysSucceed(c) => AlwaysSucceed(one(c)),
        Timeout(t, c) => Timeout(*t, one(c)),
        If(a, t, e) => If(one(a), one(t), one(e)),
        Select(v) => Select(all(v)),
        Sequence(v) => Sequence(all(v)),
        MemorylessSequence(v) => MemorylessSequence(all(v)),
        MemorylessSelector(v) => MemorylessSelector(all(v)),
        WhenAll(v) => WhenAll(all(v)),
        WhenAny(v) => WhenAny(all(v)),
        After(v) => After(all(v)),
        Race(v) => Race(all(v)),
        While(c, v) => While(one(c), all(v)),
        WhileAll(c, v) => WhileAll(one(c), all(v)),
    }
}

#[cfg(test)]
mod tests {
    use crate::plan::Loader;

    const TREE: &str = "subtrees:\n  pick:\n    root: {sequence: {name: pick, children: [{reach: {target: cube}}, {grasp: {}}, {cube_grasped: {}}]}}\nmain:\n  sequence:\n    children:\n      - home: {}\n      - retry: {attempts: 2, child: {subtree: {ref: pick}}}\n      - guard: {condition: {cube_grasped: {}}, child: {carry: {to: bowl}}}\n";

    #[test]
    fn a_subplan_holds_the_nodes_below_its_root_renumbered_with_the_whole_trees_paths() {
        let plan = Loader::default().compile_str(TREE, "t.yaml").unwrap();
        let i = plan
            .nodes
            .iter()
            .position(|n| n.name.as_deref() == Some("pick") && n.kind == "subtree")
            .unwrap();
        let sub = plan.subplan(i).unwrap();
        assert_eq!(sub.nodes[0].path, plan.nodes[i].path);
        assert_eq!(sub.nodes[0].parent, None);
        let kinds: Vec<&str> = sub.leaves.iter().map(|l| l.kind.kind()).collect();
        assert_eq!(kinds, ["reach", "grasp", "cube_grasped"]);
        for (k, n) in sub.nodes.iter().enumerate() {
            for &c in &n.children {
                assert_eq!(sub.nodes[c].parent, Some(k));
            }
        }
    }

    #[test]
    fn a_guards_re_checked_condition_cannot_run_alone_but_a_plain_leaf_can() {
        let plan = Loader::default().compile_str(TREE, "t.yaml").unwrap();
        let guard = plan.nodes.iter().position(|n| n.kind == "guard").unwrap();
        let check = plan.nodes[guard].children[0];
        assert!(plan.subplan(check).is_none());
        let leaf = plan.subplan(plan.leaves[0].node).unwrap();
        assert_eq!(leaf.leaves.len(), 1);
        assert_eq!(leaf.nodes.len(), 1);
        assert!(plan.subplan(plan.nodes.len()).is_none());
        assert_eq!(plan.subplan(guard).unwrap().leaves.len(), 2);
    }
}
