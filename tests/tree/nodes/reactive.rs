//! `reactive_sequence` and `reactive_fallback`: conditions checked again every tick, running children halted.

use super::*;

#[test]
fn reactive_sequence_rechecks_condition_and_halts_running_child() {
    let p = plan("main: {reactive_sequence: {children: [{cube_grasped: {}}, {carry: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("cube_grasped", [Success, Success, fail("slipped")]);
    d.set("carry", Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 3));
    assert_eq!(
        d.ticks("cube_grasped"),
        3,
        "the condition is re-checked every tick"
    );
    assert_eq!(d.ticks("carry"), 2);
    assert_eq!(
        d.starts("carry"),
        1,
        "the running child keeps running (not restarted each tick)"
    );
    assert_eq!(d.halts("carry"), 1);
    assert_eq!(
        r.status_of("main/reactive_sequence/carry"),
        Some(NodeStatus::Halted)
    );
    assert_eq!(
        r.status_of("main/reactive_sequence/cube_grasped"),
        Some(NodeStatus::Failure)
    );
}

#[test]
fn reactive_fallback_preempts_child_when_goal_condition_becomes_true() {
    let p = plan("main: {reactive_fallback: {children: [{cube_in_bowl: {}}, {carry: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("cube_in_bowl", [fail("not yet"), fail("not yet"), Success]);
    d.set("carry", Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 3));
    assert_eq!(d.halts("carry"), 1);
    assert_eq!(d.starts("carry"), 1);
}
