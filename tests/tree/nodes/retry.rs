//! `retry`: attempts counted, started on the next tick, reset when the retry is entered again or preempted.

use super::*;

#[test]
fn retry_exhausts_attempts_then_fails() {
    let p = plan("main: {retry: {attempts: 3, child: {grasp: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("grasp", fail("missed"));
    let mut r = TreeRunner::new(p.clone());
    let (status, ticks) = run(&mut r, &mut d, 20);
    assert_eq!(status, TreeStatus::Failure);
    assert_eq!(ticks, 3, "attempt k+1 starts on the tick after attempt k failed");
    assert_eq!(d.starts("grasp"), 3);
    assert_eq!(r.attempt(0), 3);
    let reason = r.node_reasons()[0].clone().unwrap();
    assert!(reason.message.starts_with("all 3 attempts failed"), "{reason}");
    assert_eq!(reason.kind, FailureKind::GraspFailed);
    assert_eq!(reason.root_cause().node.as_deref(), Some("main/retry/grasp"));
}

#[test]
fn retry_succeeds_on_attempt_two_with_exactly_two_starts() {
    let p = plan(
        "main: {retry: {attempts: 3, child: {sequence: {children: [{reach: {target: cube}}, {grasp: {}}]}}}}",
    );
    let mut d = ScriptedDriver::new(&p);
    d.script("grasp", [fail("slipped"), Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 20), (TreeStatus::Success, 2));
    assert_eq!(d.starts("grasp"), 2);
    assert_eq!(d.starts("reach"), 2);
    assert_eq!(r.attempt(0), 2);
    // The attempt number is on the leaves' transitions; before attempt 2 the failed grasp is
    // reset to idle (an event of attempt 1), and attempt 2 starts it from idle.
    let t = r.drain_transitions();
    let grasp: Vec<_> = t
        .iter()
        .filter(|t| t.path.ends_with("/grasp"))
        .map(|t| (t.from, t.to, t.attempt))
        .collect();
    assert_eq!(
        grasp,
        [
            (NodeStatus::Idle, NodeStatus::Failure, Some(1)),
            (NodeStatus::Failure, NodeStatus::Idle, Some(1)),
            (NodeStatus::Idle, NodeStatus::Success, Some(2)),
        ]
    );
    let reach: Vec<_> = t
        .iter()
        .filter(|t| t.path.ends_with("/reach"))
        .map(|t| (t.from, t.to, t.attempt))
        .collect();
    assert_eq!(
        reach,
        [
            (NodeStatus::Idle, NodeStatus::Success, Some(1)),
            (NodeStatus::Success, NodeStatus::Idle, Some(1)),
            (NodeStatus::Idle, NodeStatus::Success, Some(2)),
        ],
        "re-entered from idle, after an explicit reset"
    );
}

#[test]
fn retry_next_attempt_starts_on_the_next_tick_not_the_same_one() {
    let p = plan("main: {retry: {attempts: 2, child: {grasp: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    d.script("grasp", [fail("slipped"), Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(r.tick(0.0, DT, &mut d), TreeStatus::Running);
    assert_eq!(d.ticks("grasp"), 1, "no second attempt inside the failing tick");
    assert_eq!(r.status_of("main/retry"), Some(NodeStatus::Running));
    assert_eq!(r.tick(DT, DT, &mut d), TreeStatus::Success);
    assert_eq!(d.ticks("grasp"), 2);
    assert!(matches!(&d.log[1], Call::Tick { first: true, .. }));
}

/// Regression (forester#65 bug class): decorators must start from scratch when re-entered.
#[test]
fn retry_counter_resets_when_the_retry_is_re_entered() {
    let p =
        plan("main:\n  repeat:\n    times: 2\n    child:\n      retry: {attempts: 2, child: {grasp: {}}}\n");
    let mut d = ScriptedDriver::new(&p);
    // First run of the retry: fail, succeed (2 attempts). Second run: fail, succeed again —
    // only possible if the retry's attempts were reset.
    d.script("grasp", [fail("a"), Success, fail("b"), Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 20).0, TreeStatus::Success);
    assert_eq!(d.starts("grasp"), 4);
}

/// Regression: a yield that was pending when its retry got preempted must not let the next
/// execution skip the yield.
#[test]
fn retry_yield_pending_at_preemption_is_reset() {
    let p = plan(
        "main:\n  repeat:\n    times: 2\n    child:\n      force_success:\n        child:\n          timeout:\n            seconds: 0.05\n            child: {retry: {attempts: 2, child: {grasp: {}}}}\n",
    );
    let mut d = ScriptedDriver::new(&p);
    // tick 1: grasp fails → yield (Running) → the timeout (0.05 s < dt) fires.
    // tick 2: repeat's own yield. tick 3: second run, grasp fails again → must yield again.
    d.set("grasp", fail("miss"));
    let mut r = TreeRunner::new(p.clone());
    r.tick(0.0, DT, &mut d);
    assert_eq!(d.ticks("grasp"), 1);
    r.tick(0.1, DT, &mut d);
    r.tick(0.2, DT, &mut d);
    assert_eq!(
        d.ticks("grasp"),
        2,
        "the second run starts with attempt 1 and yields after its failure"
    );
}
