//! `sequence`: children in order, progress kept, the first failure ends it.

use super::*;

#[test]
fn sequence_runs_children_in_order_within_one_tick_when_they_finish_at_once() {
    let p = plan("main: {sequence: {children: [{home: {}}, {grasp: {}}, {release: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 1));
    assert_eq!(ticked_paths(&d), ["home", "grasp", "release"]);
    assert!(r.node_statuses().iter().all(|s| *s == NodeStatus::Success));
}

#[test]
fn sequence_remembers_progress_and_stops_at_first_failure() {
    let p = plan("main: {sequence: {children: [{home: {}}, {grasp: {}}, {release: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("grasp", [Running, Running, fail("stalled")]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 3));
    assert_eq!(
        d.ticks("home"),
        1,
        "a sequence with memory does not re-tick finished children"
    );
    assert_eq!(d.ticks("grasp"), 3);
    assert_eq!(d.starts("grasp"), 1);
    assert_eq!(d.ticks("release"), 0);
    assert_eq!(r.status_of("main/sequence/grasp"), Some(NodeStatus::Failure));
    assert_eq!(r.status_of("main/sequence/release"), Some(NodeStatus::Idle));
    assert_eq!(reason_of(&r, 0), Some("grasp: stalled"));
    let f = r.failure().unwrap();
    assert_eq!(f.kind, FailureKind::GraspFailed);
    assert_eq!(f.node.as_deref(), Some("main/sequence/grasp"));
}
