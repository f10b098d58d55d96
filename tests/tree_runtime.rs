//! Runtime semantics of every composite and decorator, driven by the scripted driver.

use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::plan::{Loader, Plan};
use macrotree::runtime::scripted::{Call, ScriptedDriver};
use macrotree::runtime::{LeafOutcome, NodeStatus, TreeRunner, TreeStatus};

use LeafOutcome::{Running, Success};

/// A scripted failure (of kind `grasp_failed`, so tests can see the kind carried up the tree).
fn fail(why: &str) -> LeafOutcome {
    LeafOutcome::failure(FailureKind::GraspFailed, why)
}

/// The message of node `i`'s last failure or halt.
fn reason_of(r: &TreeRunner, i: usize) -> Option<&str> {
    r.node_reasons()[i].as_ref().map(|f| f.message.as_str())
}

fn plan(yaml: &str) -> Arc<Plan> {
    match Loader::default().compile_str(yaml, "test.yaml") {
        Ok(p) => Arc::new(p),
        Err(diags) => {
            for d in &diags {
                eprintln!("{d}");
            }
            panic!("test tree does not compile");
        }
    }
}

const DT: f64 = 0.1;

/// Tick until the tree finishes (or `max` ticks); returns the status and the number of ticks.
fn run(runner: &mut TreeRunner, d: &mut ScriptedDriver, max: usize) -> (TreeStatus, usize) {
    for i in 0..max {
        let s = runner.tick(i as f64 * DT, DT, d);
        if s != TreeStatus::Running {
            return (s, i + 1);
        }
    }
    (TreeStatus::Running, max)
}

fn ticked_paths(d: &ScriptedDriver) -> Vec<String> {
    d.log
        .iter()
        .filter_map(|c| match c {
            Call::Tick { path, .. } => Some(path.rsplit('/').next().unwrap_or("").to_string()),
            Call::Halt { .. } => None,
        })
        .collect()
}

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

#[test]
fn fallback_tries_children_until_one_succeeds() {
    let p = plan("main: {fallback: {children: [{cube_in_bowl: {}}, {home: {}}, {release: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    d.set("cube_in_bowl", fail("no"));
    d.script("home", [Running, Success]);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 2));
    assert_eq!(
        d.ticks("cube_in_bowl"),
        1,
        "fallback has memory: the failed check is not re-run"
    );
    assert_eq!(d.ticks("release"), 0);

    let mut d = ScriptedDriver::new(&p);
    d.set_default(fail("nope"));
    let mut r = TreeRunner::new(p);
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Failure, 1));
    assert_eq!(ticked_paths(&d), ["cube_in_bowl", "home", "release"]);
}

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
fn guard_with_inverted_condition_regression_inverter_logged_running_every_tick() {
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

#[test]
fn repeat_runs_child_n_times_one_tick_apart() {
    let p = plan("main: {repeat: {times: 3, child: {grasp: {}}}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    assert_eq!(run(&mut r, &mut d, 20), (TreeStatus::Success, 3));
    assert_eq!(d.starts("grasp"), 3);

    let mut d = ScriptedDriver::new(&p);
    d.script("grasp", [Success, fail("dropped")]);
    let mut r = TreeRunner::new(p);
    assert_eq!(run(&mut r, &mut d, 20), (TreeStatus::Failure, 2));
    assert_eq!(d.starts("grasp"), 2);
}

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

#[test]
fn inverter_and_force_decorators() {
    for (yaml, leaf, expected) in [
        (
            "main: {inverter: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Failure,
        ),
        (
            "main: {inverter: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Success,
        ),
        (
            "main: {force_success: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Success,
        ),
        (
            "main: {force_success: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Success,
        ),
        (
            "main: {force_failure: {child: {cube_in_bowl: {}}}}",
            Success,
            TreeStatus::Failure,
        ),
        (
            "main: {force_failure: {child: {cube_in_bowl: {}}}}",
            fail("x"),
            TreeStatus::Failure,
        ),
    ] {
        let p = plan(yaml);
        let mut d = ScriptedDriver::new(&p);
        d.set("cube_in_bowl", leaf.clone());
        let mut r = TreeRunner::new(p);
        assert_eq!(run(&mut r, &mut d, 5), (expected, 1), "{yaml} with {leaf:?}");
    }
}

#[test]
fn wait_counts_simulated_time_and_passes_leftover_dt_on() {
    let p = plan("main: {sequence: {children: [{wait: {seconds: 0.25}}, {home: {}}]}}");
    let mut d = ScriptedDriver::new(&p);
    let mut r = TreeRunner::new(p.clone());
    // 0.1 + 0.1 + 0.1 ≥ 0.25: done on tick 3, and `home` runs in that same tick.
    assert_eq!(run(&mut r, &mut d, 10), (TreeStatus::Success, 3));
    assert_eq!(d.ticks("home"), 1);
}

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
