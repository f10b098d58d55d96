//! `for_each`, `select` and the blackboard on scripted leaves (no physics): iterations follow the
//! selections, variables reach the leaves that read them, limits and failures end the loop.

use std::sync::Arc;

use macrotree::plan::Loader;
use macrotree::runtime::scripted::ScriptedDriver;
use macrotree::runtime::{LeafOutcome, Selection, TreeRunner, TreeStatus};

const TREE: &str = "main:
  for_each:
    as: block
    goal_as: dest
    select: {where: [pending]}
    max_iterations: 3
    child:
      sequence:
        children:
          - grasp: {object: \"{block}\"}
          - carry: {to: \"{dest}\"}
";

fn selection(object: &str, dest: &str) -> Selection {
    Selection {
        object: object.into(),
        destination: Some(dest.into()),
    }
}

/// Ticks until the tree finishes (at most 1000 ticks); the final status.
fn run(runner: &mut TreeRunner, driver: &mut ScriptedDriver) -> TreeStatus {
    for k in 0..1000 {
        let status = runner.tick(k as f64 * 0.004, 0.004, driver);
        if status != TreeStatus::Running {
            return status;
        }
    }
    panic!("the tree did not finish in 1000 ticks");
}

fn setup(src: &str) -> (TreeRunner, ScriptedDriver) {
    // The scripted leaves stand for any scene: check names against the built-in one is not the
    // point here, so only variables are used.
    let plan = Arc::new(
        Loader::default()
            .compile_str(src, "loop.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    (TreeRunner::new(plan.clone()), ScriptedDriver::new(&plan))
}

#[test]
fn for_each_runs_the_child_once_per_selected_object_then_succeeds() {
    let (mut runner, mut d) = setup(TREE);
    d.selections
        .extend([selection("red", "red_bin"), selection("blue", "blue_bin")]);
    assert_eq!(run(&mut runner, &mut d), TreeStatus::Success);
    assert_eq!(d.starts("grasp"), 2);
    assert_eq!(d.starts("carry"), 2);
    assert_eq!(runner.blackboard().get("block"), Some("blue"));
    assert_eq!(runner.blackboard().get("dest"), Some("blue_bin"));
}

#[test]
fn blackboard_writes_are_events_in_order() {
    let (mut runner, mut d) = setup(TREE);
    d.selections.extend([selection("red", "red_bin")]);
    run(&mut runner, &mut d);
    let writes: Vec<(String, Option<String>)> = runner
        .drain_blackboard_writes()
        .into_iter()
        .map(|w| (w.var, w.value))
        .collect();
    assert_eq!(
        writes,
        [
            ("block".to_string(), Some("red".to_string())),
            ("dest".to_string(), Some("red_bin".to_string()))
        ]
    );
}

#[test]
fn for_each_fails_when_objects_still_match_after_max_iterations() {
    let (mut runner, mut d) = setup(TREE);
    d.selections.extend((0..5).map(|_| selection("red", "red_bin")));
    assert_eq!(run(&mut runner, &mut d), TreeStatus::Failure);
    assert_eq!(d.starts("grasp"), 3, "exactly max_iterations iterations ran");
    let reason = runner.node_reasons()[0].clone().unwrap();
    assert!(reason.message.contains("after 3 iteration(s)"), "{reason}");
    assert_eq!(reason.kind, macrotree::FailureKind::MaxIterations);
}

#[test]
fn for_each_fails_when_its_child_fails_and_stops_selecting() {
    let (mut runner, mut d) = setup(TREE);
    d.selections
        .extend([selection("red", "red_bin"), selection("blue", "blue_bin")]);
    d.set(
        "carry",
        LeafOutcome::failure(macrotree::FailureKind::GraspLost, "grasp lost"),
    );
    assert_eq!(run(&mut runner, &mut d), TreeStatus::Failure);
    assert_eq!(d.starts("grasp"), 1);
    assert_eq!(d.selections.len(), 1, "no selection after the failed iteration");
}

#[test]
fn a_loop_with_nothing_to_do_succeeds_without_running_its_child() {
    let (mut runner, mut d) = setup(TREE);
    assert_eq!(run(&mut runner, &mut d), TreeStatus::Success);
    assert_eq!(d.starts("grasp"), 0);
}

#[test]
fn reading_a_variable_before_it_is_written_fails_the_leaf_with_the_reason() {
    let (mut runner, mut d) = setup(
        "main:\n  fallback:\n    children:\n      - select: {as: block, where: [pending]}\n      - grasp: {object: \"{block}\"}\n",
    );
    // Nothing matches: the select fails, so the fallback ticks the grasp with `{block}` unset.
    assert_eq!(run(&mut runner, &mut d), TreeStatus::Failure);
    let reasons: Vec<String> = runner
        .node_reasons()
        .iter()
        .flatten()
        .map(|f| f.message.clone())
        .collect();
    assert!(
        reasons
            .iter()
            .any(|r| r.contains("the variable `{block}` is not set")),
        "{reasons:?}"
    );
    assert_eq!(d.starts("grasp"), 0, "the driver never saw the unresolved leaf");
}
