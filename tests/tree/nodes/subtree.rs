//! `subtree`: arguments reach the leaves.

use super::*;

#[test]
fn subtree_arguments_reach_the_leaves() {
    let p = plan(
        "subtrees:\n  pick:\n    params: {approach: 0.15, speed: 0.5}\n    root:\n      sequence:\n        children:\n          - reach: {target: cube, offset: [0, 0, $approach], speed: $speed}\n          - grasp: {}\nmain:\n  sequence:\n    children:\n      - subtree: {ref: pick, args: {approach: 0.12}}\n      - subtree: {ref: pick}\n",
    );
    let offsets: Vec<f64> = p
        .leaves
        .iter()
        .filter_map(|l| l.kind.params::<macrotree::kinds::Reach>().map(|r| r.offset[2]))
        .collect();
    assert_eq!(offsets, [0.12, 0.15]);
    assert_eq!(p.nodes[1].path, "main/sequence/subtree[pick]#1");
    assert_eq!(p.nodes[1].label, "subtree pick(approach=0.12)");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 1));
    assert_eq!(d.starts("grasp"), 2);
}
