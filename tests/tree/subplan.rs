//! `Plan::subplan`: a node of a compiled tree run on its own ticks exactly its part of the tree.

use std::sync::Arc;

use macrotree::plan::Loader;
use macrotree::runtime::scripted::ScriptedDriver;
use macrotree::runtime::{LeafOutcome, TreeRunner, TreeStatus};

const TREE: &str = "subtrees:\n  pick:\n    root: {sequence: {name: pick, children: [{reach: {target: cube}}, {grasp: {}}, {cube_grasped: {}}]}}\nmain:\n  sequence:\n    children:\n      - home: {}\n      - retry: {attempts: 2, child: {subtree: {ref: pick}}}\n      - guard: {condition: {cube_grasped: {}}, child: {carry: {to: bowl}}}\n";

#[test]
fn a_subplan_ticks_its_leaves_in_order_and_finishes() {
    let plan = Loader::default().compile_str(TREE, "t.yaml").unwrap();
    let i = plan.node_by_path(&plan.nodes[plan.leaves[0].node].path).unwrap();
    assert_eq!(plan.nodes[i].kind, "home");
    let retry = plan.nodes.iter().position(|n| n.kind == "retry").unwrap();
    let sub = Arc::new(plan.subplan(retry).unwrap());
    let mut driver = ScriptedDriver::new(&sub);
    driver.script("reach", [LeafOutcome::Running, LeafOutcome::Success]);
    driver.script("grasp", [LeafOutcome::Success]);
    driver.script("cube_grasped", [LeafOutcome::Success]);
    let mut runner = TreeRunner::new(sub);
    let mut status = TreeStatus::Running;
    for k in 0..10 {
        status = runner.tick(k as f64 * 0.1, 0.1, &mut driver);
        if status != TreeStatus::Running {
            break;
        }
    }
    assert_eq!(status, TreeStatus::Success);
    assert_eq!(driver.starts("reach"), 1);
    assert_eq!(driver.starts("cube_grasped"), 1);
    let kinds: Vec<&str> = runner.plan().leaves.iter().map(|l| l.kind.kind()).collect();
    assert_eq!(kinds, ["reach", "grasp", "cube_grasped"], "no home, no carry");
}
