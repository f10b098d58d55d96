//! `Action::Subtree`: a node of the environment's tree found by name or path, cut out of the
//! compiled plan ([`Plan::subplan`]) once and kept.

use std::collections::HashMap;
use std::sync::Arc;

use crate::error::Error;
use crate::plan::Plan;

/// The sub-plans of one tree, by node index.
#[derive(Default)]
pub(super) struct Subtrees {
    plans: HashMap<usize, Arc<Plan>>,
}

impl Subtrees {
    /// The sub-plan `name` names in `tree` (see [`find`]).
    pub fn get(&mut self, tree: &Arc<Plan>, name: &str) -> Result<Arc<Plan>, Error> {
        let node = find(tree, name)?;
        if node == 0 {
            return Ok(tree.clone());
        }
        if let Some(p) = self.plans.get(&node) {
            return Ok(p.clone());
        }
        let plan = Arc::new(tree.subplan(node).ok_or_else(|| Error::Action {
            message: format!(
                "subtree `{name}` ({}) cannot run alone: it is a condition re-checked by its parent; run the parent",
                tree.nodes[node].path
            ),
        })?);
        self.plans.insert(node, plan.clone());
        Ok(plan)
    }
}

/// The node of `tree` that `name` names: `main` or the root's path for the whole tree, a node
/// path, or a node's `name:` (a subtree call is named after its subtree) when one node has it
/// — or nested nodes only (a subtree call and its root of the same name): the outermost.
///
/// # Errors
/// [`Error::Action`] when no node or several nodes have that name, listing the names (with a
/// suggestion) or the paths to choose from.
pub fn find(tree: &Plan, name: &str) -> Result<usize, Error> {
    if name == "main" {
        return Ok(0);
    }
    if let Some(i) = tree.node_by_path(name) {
        return Ok(i);
    }
    let named: Vec<usize> = (0..tree.nodes.len())
        .filter(|&i| tree.nodes[i].name.as_deref() == Some(name))
        .collect();
    // A subtree call and its root often share the name: one chain of nodes, the outermost runs.
    let nested = named.windows(2).all(|w| is_below(tree, w[1], w[0]));
    match named.as_slice() {
        [first, ..] if nested => Ok(*first),
        [] => {
            let mut names: Vec<&str> = tree.nodes.iter().filter_map(|n| n.name.as_deref()).collect();
            names.sort_unstable();
            names.dedup();
            let hint = crate::yaml::suggest::closest(name, names.iter().copied())
                .map(|c| format!("did you mean `{c}`? "))
                .unwrap_or_default();
            Err(Error::Action {
                message: format!(
                    "the tree {} has no node named `{name}`; {hint}named nodes: {}; or give `main` or a node path",
                    tree.file,
                    names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
        }
        many => Err(Error::Action {
            message: format!(
                "{} nodes of the tree {} are named `{name}`; give one's path: {}",
                many.len(),
                tree.file,
                many.iter()
                    .map(|&i| tree.nodes[i].path.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }),
    }
}

/// Node `i` is below node `ancestor`.
fn is_below(tree: &Plan, i: usize, ancestor: usize) -> bool {
    let mut cur = tree.nodes[i].parent;
    while let Some(p) = cur {
        if p == ancestor {
            return true;
        }
        cur = tree.nodes[p].parent;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_are_found_by_name_path_or_main_and_misses_get_suggestions() {
        let text = "subtrees:\n  pick:\n    root: {sequence: {children: [{reach: {target: cube}}, {grasp: {}}]}}\nmain: {sequence: {name: all, children: [{subtree: {ref: pick}}, {home: {name: back}}, {home: {name: back}}]}}\n";
        let plan = crate::plan::Loader::default()
            .compile_str(text, "t.yaml")
            .unwrap();
        assert_eq!(find(&plan, "main").unwrap(), 0);
        assert_eq!(find(&plan, "all").unwrap(), 0);
        let pick = find(&plan, "pick").unwrap();
        assert_eq!(plan.nodes[pick].kind, "subtree");
        assert_eq!(find(&plan, &plan.nodes[pick].path).unwrap(), pick);
        let e = find(&plan, "pik").unwrap_err().to_string();
        assert!(e.contains("did you mean `pick`?"), "{e}");
        let e = find(&plan, "back").unwrap_err().to_string();
        assert!(e.contains("2 nodes") && e.contains("home"), "{e}");
    }
}
