//! `guard`: the child runs while its condition holds and is halted, with the guard named, when it fails.

use super::*;

#[test]
fn guard_keeps_child_state_while_condition_holds_and_halts_it_when_it_fails() {
    let p = plan(
        "main:\n  guard:\n    condition: {cube_grasped: {}}\n    child:\n      sequence:\n        children: [{reach: {target: bowl}}, {carry: {}}]\n",
    );
    let mut d = ScriptedDriver::new(&p);
    d.script("cube_grasped", [Success, Success, Success, fail("slipped")]);
    d.script("reach", [Success]);
    d.set("carry", Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 4));
    assert_eq!(
        d.ticks("reach"),
        1,
        "the guarded sequence is not restarted each tick"
    );
    assert_eq!(d.ticks("carry"), 3);
    assert_eq!(d.halts("carry"), 1);
    let guard = p.node_by_path("main/guard").unwrap();
    let reason = r.node_reasons()[guard].clone().unwrap();
    assert!(
        reason.message.contains("condition failed") && reason.message.contains("slipped"),
        "{reason}"
    );
    // The guard's failure wraps its condition's, and keeps its kind.
    assert_eq!(reason.kind, FailureKind::GraspFailed);
    assert_eq!(reason.node.as_deref(), Some("main/guard"));
    assert_eq!(reason.cause.as_ref().unwrap().message, "cube_grasped: slipped");
}

#[test]
fn guard_with_an_inverted_condition_logs_the_inverter_once_per_change() {
    let p = plan(
        "main:\n  guard:\n    condition: {inverter: {child: {cube_on_table: {}}}}\n    child: {carry: {}}\n",
    );
    let mut d = ScriptedDriver::new(&p);
    d.script("cube_on_table", [fail("lifted"), fail("lifted"), Success]);
    d.set("carry", Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 3));
    assert_eq!(d.halts("carry"), 1);
    assert_eq!(r.status_of("main/guard/inverter"), Some(NodeStatus::Failure));
}

/// Issue 13, item 16: a guard whose condition fails halts its running child, and the child's
/// halt reason names the guard (its path) and the condition — not an ancestor further up.
#[test]
fn a_failing_guard_is_named_in_its_childs_halt_reason() {
    let p = plan(
        "main: {retry: {attempts: 2, child: {fallback: {children: [{sequence: {children: [{guard: {name: held, condition: {cube_grasped: {}}, child: {carry: {}}}}]}}]}}}}",
    );
    let mut d = ScriptedDriver::new(&p);
    d.set("carry", Running);
    d.script("cube_grasped", [Success, Success]);
    d.eventually("cube_grasped", fail("slipped"));
    let mut r = TreeRunner::new(p.clone());
    run(&mut r, &mut d, 4);
    let t = r.drain_transitions();
    let halted: Vec<_> = t
        .iter()
        .filter(|t| t.to == NodeStatus::Halted && t.kind == "carry")
        .collect();
    assert!(!halted.is_empty(), "{t:#?}");
    let guard = t
        .iter()
        .find(|t| t.kind == "guard" && t.to == NodeStatus::Failure)
        .expect("the guard failed");
    assert_eq!(halted[0].tick, guard.tick);
    assert_eq!(
        halted[0].reason.as_deref(),
        Some(
            format!(
                "preempted: `{}` failed (condition failed: cube_grasped: slipped)",
                guard.path
            )
            .as_str()
        ),
        "{t:#?}"
    );
}
