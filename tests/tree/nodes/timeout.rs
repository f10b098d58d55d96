//! `timeout`: fails after simulated seconds and halts its child, else passes the result through.

use super::*;

#[test]
fn timeout_fails_after_simulated_seconds_and_halts_child() {
    let p = plan("main: {timeout: {seconds: 1.0, child: {home: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("home", Running);
    let mut r = TreeRunner::new(p.clone());
    let mut ticks = 0;
    let mut status = TreeStatus::Running;
    while status == TreeStatus::Running && ticks < 100 {
        status = r.tick(ticks as f64 * 0.25, 0.25, &mut d);
        ticks += 1;
    }
    assert_eq!((status, ticks), (TreeStatus::Failure, 4));
    assert_eq!(d.halts("home"), 1);
    assert_eq!(r.status_of("main/timeout/home"), Some(NodeStatus::Halted));
    assert_eq!(reason_of(&r, 0), Some("timeout 1 s expired"));
    assert_eq!(r.failure().unwrap().kind, FailureKind::Timeout);
}

#[test]
fn timeout_passes_child_result_through() {
    let p = plan("main: {timeout: {seconds: 1.0, child: {home: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("home", [Running, fail("collision")]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 2));
    assert_eq!(d.halts("home"), 0);
    assert_eq!(reason_of(&r, 0), Some("home: collision"));
    assert_eq!(r.failure().unwrap().kind, FailureKind::GraspFailed);
}
