//! Diagrams of a plan with our node names and key parameters: Graphviz DOT and Mermaid.

use crate::kinds::ControlKind;
use std::fmt::Write as _;

use super::{NodeTag, Plan};

/// Visual family of a node: its category, with subtree calls on their own.
fn family(n: &super::NodeInfo) -> &'static str {
    if n.tag == NodeTag::Control(ControlKind::Subtree) {
        "subtree"
    } else {
        n.category.as_str()
    }
}

fn dot_escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"").replace('\n', "\\n")
}

/// Graphviz DOT of the plan: one box per node (composites rounded, decorators hexagons, actions
/// filled, conditions ellipses), labelled with the node's label (kind, name, key parameters).
/// Render with `dot -Tsvg`.
pub fn to_dot(plan: &Plan) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph tree {{");
    let _ = writeln!(out, "  rankdir=TB;");
    let _ = writeln!(out, "  node [fontname=\"Helvetica\", fontsize=10];");
    let _ = writeln!(out, "  edge [arrowsize=0.6, fontname=\"Helvetica\", fontsize=9];");
    for (i, n) in plan.nodes.iter().enumerate() {
        let style = match family(n) {
            "composite" => "shape=box, style=\"rounded,bold\"",
            "decorator" => "shape=hexagon",
            "subtree" => "shape=box, style=dashed",
            "condition" => "shape=ellipse, style=filled, fillcolor=\"#fff4cc\"",
            "runtime" => "shape=box, style=filled, fillcolor=\"#eeeeee\"",
            _ => "shape=box, style=filled, fillcolor=\"#d6e9ff\"",
        };
        let _ = writeln!(
            out,
            "  n{i} [label=\"{}\", tooltip=\"{} ({})\", {style}];",
            dot_escape(&n.label),
            dot_escape(&n.path),
            dot_escape(&n.source)
        );
    }
    for (i, n) in plan.nodes.iter().enumerate() {
        for (k, c) in n.children.iter().enumerate() {
            if n.tag == NodeTag::Control(ControlKind::Guard) && k == 0 {
                let _ = writeln!(out, "  n{i} -> n{c} [label=\"while\", style=dashed];");
            } else {
                let _ = writeln!(out, "  n{i} -> n{c};");
            }
        }
    }
    out.push_str("}\n");
    out
}

fn mermaid_escape(s: &str) -> String {
    s.replace('"', "#quot;")
        .replace('<', "#lt;")
        .replace('>', "#gt;")
        .replace('\n', " ")
}

/// Mermaid `flowchart` of the plan (renders in GitHub/GitLab markdown):
/// composites `[ ]`, decorators `{{ }}`, conditions `([ ])`, subtrees `[[ ]]`.
pub fn to_mermaid(plan: &Plan) -> String {
    let mut out = String::from("flowchart TD\n");
    for (i, n) in plan.nodes.iter().enumerate() {
        let l = mermaid_escape(&n.label);
        let shape = match family(n) {
            "decorator" => format!("{{{{\"{l}\"}}}}"),
            "condition" => format!("([\"{l}\"])"),
            "subtree" => format!("[[\"{l}\"]]"),
            "composite" => format!("[\"{l}\"]"),
            _ => format!("(\"{l}\")"),
        };
        let _ = writeln!(out, "  n{i}{shape}");
    }
    for (i, n) in plan.nodes.iter().enumerate() {
        for (k, c) in n.children.iter().enumerate() {
            if n.tag == NodeTag::Control(ControlKind::Guard) && k == 0 {
                let _ = writeln!(out, "  n{i} -. while .-> n{c}");
            } else {
                let _ = writeln!(out, "  n{i} --> n{c}");
            }
        }
    }
    for (i, n) in plan.nodes.iter().enumerate() {
        let class = match family(n) {
            "action" => "action",
            "condition" => "condition",
            _ => continue,
        };
        let _ = writeln!(out, "  class n{i} {class}");
    }
    out.push_str("  classDef action fill:#d6e9ff,stroke:#3a6ea5\n");
    out.push_str("  classDef condition fill:#fff4cc,stroke:#b08800\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::Loader;

    const TREE: &str = "main:\n  sequence:\n    name: pick \"it\"\n    children:\n      - retry: {attempts: 3, child: {reach: {target: cube, offset: [0, 0, 0.15]}}}\n      - guard: {condition: {cube_grasped: {}}, child: {carry: {}}}\n";

    #[test]
    fn dot_has_every_node_and_edge() {
        let plan = Loader::default().compile_str(TREE, "t.yaml").unwrap();
        let dot = to_dot(&plan);
        assert!(dot.starts_with("digraph tree {"));
        assert!(
            dot.contains("n0 [label=\"sequence \\\"pick \\\"it\\\"\\\"\""),
            "{dot}"
        );
        assert!(dot.contains("label=\"retry ×3\""));
        assert!(dot.contains("label=\"reach cube +[0, 0, 0.15]\""));
        assert!(dot.contains("n3 -> n4 [label=\"while\""));
        assert_eq!(dot.matches(" -> ").count(), plan.nodes.len() - 1);
    }

    #[test]
    fn mermaid_has_every_node_and_edge() {
        let plan = Loader::default().compile_str(TREE, "t.yaml").unwrap();
        let m = to_mermaid(&plan);
        assert!(m.starts_with("flowchart TD\n"));
        assert!(m.contains("n1{{\"retry ×3\"}}"), "{m}");
        assert!(m.contains("n4([\"cube_grasped?\"])"), "{m}");
        assert!(m.contains("#quot;it#quot;"));
        assert_eq!(
            m.matches("-->").count() + m.matches(".->").count(),
            plan.nodes.len() - 1
        );
    }
}
