//! What every node shares: conditions answer at once, a finished tree stays finished, halts, transitions logged once with reasons, the `first` flag after a halt.

use super::*;

#[test]
fn condition_answering_running_is_a_failure() {
    let p = plan("main: {cube_grasped: {}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("cube_grasped", Running);
    let mut r = TreeRunner::new(p);
    assert_eq!(run(&mut r, &mut d, 5), (TreeStatus::Failure, 1));
}

#[test]
fn finished_tree_stays_finished_until_reset() {
    let p = plan("main: {sequence: {children: [{home: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(r.tick(0.0, DT, &mut d), TreeStatus::Success);
    assert_eq!(r.tick(0.1, DT, &mut d), TreeStatus::Success);
    assert_eq!(d.ticks("home"), 1);
    r.reset();
    assert!(r.node_statuses().iter().all(|s| *s == NodeStatus::Idle));
    assert_eq!(r.tick(0.2, DT, &mut d), TreeStatus::Success);
    assert_eq!(d.ticks("home"), 2);
}

#[test]
fn halt_all_halts_running_leaves() {
    let p = plan("main: {parallel: {children: [{home: {}}, {grasp: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.set_default(Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(r.tick(0.0, DT, &mut d), TreeStatus::Running);
    assert_eq!(r.running_leaves().len(), 2);
    r.halt_all(&mut d);
    assert_eq!(d.halts("home") + d.halts("grasp"), 2);
    assert!(r.node_statuses().iter().all(|s| *s == NodeStatus::Halted));
    assert_eq!(r.tick(0.1, DT, &mut d), TreeStatus::Failure);
}

#[test]
fn transitions_are_logged_once_per_change_with_reasons() {
    let p = plan("main: {sequence: {children: [{home: {}}, {grasp: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("home", [Running, Running, Success]);
    d.script("grasp", [fail("jammed")]);
    let mut r = TreeRunner::new(p.clone());
    run(&mut r, &mut d, 10);
    let t = r.drain_transitions();
    let summary: Vec<(u64, &str, &str, &str)> = t
        .iter()
        .map(|t| (t.tick, t.path.as_str(), t.from.as_str(), t.to.as_str()))
        .collect();
    assert_eq!(
        summary,
        [
            (1, "main/sequence", "idle", "running"),
            (1, "main/sequence/home", "idle", "running"),
            (3, "main/sequence/home", "running", "success"),
            (3, "main/sequence/grasp", "idle", "failure"),
            (3, "main/sequence", "running", "failure"),
        ]
    );
    assert_eq!(t[3].reason.as_deref(), Some("grasp: jammed"));
    assert!(r.drain_transitions().is_empty());
}

#[test]
fn halted_transition_names_the_preempting_node() {
    let p = plan("main: {timeout: {seconds: 0.2, child: {sequence: {children: [{home: {}}]}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("home", Running);
    let mut r = TreeRunner::new(p.clone());
    run(&mut r, &mut d, 10);
    let t = r.drain_transitions();
    let halted: Vec<_> = t.iter().filter(|t| t.to == NodeStatus::Halted).collect();
    assert_eq!(halted.len(), 2, "{t:#?}");
    assert_eq!(halted[0].path, "main/timeout/sequence");
    assert_eq!(
        halted[0].reason.as_deref(),
        Some("preempted: `main/timeout` failed (timeout 0.2 s expired)")
    );
    assert_eq!(halted[1].path, "main/timeout/sequence/home");
    // The sequence between them was halted in the same pass: the leaf names the timeout that
    // finished, not the halted sequence.
    assert_eq!(halted[1].reason, halted[0].reason);
}

#[test]
fn first_flag_is_set_again_after_a_halt() {
    let p = plan("main: {retry: {attempts: 2, child: {timeout: {seconds: 0.15, child: {home: {}}}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("home", Running);
    let mut r = TreeRunner::new(p.clone());
    run(&mut r, &mut d, 20);
    let firsts: Vec<bool> = d
        .log
        .iter()
        .filter_map(|c| match c {
            Call::Tick { first, .. } => Some(*first),
            Call::Halt { .. } => None,
        })
        .collect();
    assert_eq!(firsts, [true, false, true, false]);
    assert_eq!(d.halts("home"), 2);
    assert_eq!(d.starts("home"), 2);
}
