//! `parallel` and `race`: children ticked together; the others halted when the outcome is known.

use super::*;

#[test]
fn parallel_succeeds_when_all_succeed() {
    let p = plan("main: {parallel: {children: [{home: {}}, {grasp: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("home", [Running, Running, Success]);
    d.script("grasp", [Running, Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 3));
    assert_eq!(d.ticks("grasp"), 2, "finished children are not ticked again");
    assert_eq!(d.halts("home") + d.halts("grasp"), 0);
}

#[test]
fn parallel_fails_as_soon_as_one_fails_and_halts_the_others() {
    let p = plan("main: {parallel: {children: [{home: {}}, {grasp: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("home", Running);
    d.script("grasp", [Running, fail("jammed")]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 2));
    assert_eq!(
        d.halts("home"),
        1,
        "the still-running sibling is halted in the same tick"
    );
    assert_eq!(r.status_of("main/parallel/home"), Some(NodeStatus::Halted));
}

#[test]
fn race_first_to_finish_wins_and_loser_is_halted() {
    let p = plan("main: {race: {children: [{home: {}}, {wait: {seconds: 0.3}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("home", Running);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 3));
    assert_eq!(d.halts("home"), 1);
    assert_eq!(r.status_of("main/race/home"), Some(NodeStatus::Halted));
    assert_eq!(r.status_of("main/race/wait"), Some(NodeStatus::Success));
    assert!(r.running_leaves().is_empty());
}
