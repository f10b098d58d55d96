//! Results forced on a leaf from outside the tree (the monitor's force buttons), on scripted
//! leaves: a running leaf is halted and ends with the forced result, an idle one answers it
//! without reaching the driver, composites cannot be forced, and the counts say which results
//! were forced.

use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::plan::{Loader, Plan};
use macrotree::runtime::{
    ForceError, ForcedResult, LeafOutcome, TreeRunner, TreeStatus, scripted::ScriptedDriver,
};

const TREE: &str = r#"
main:
  fallback:
    children:
      - reach: {target: cube, offset: [0, 0, 0.1], name: first choice}
      - home: {name: next child}
"#;

fn plan() -> Arc<Plan> {
    Arc::new(
        Loader::default()
            .compile_str(TREE, "t.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    )
}

fn node(plan: &Plan, kind: &str) -> usize {
    plan.nodes.iter().position(|n| n.kind == kind).unwrap()
}

#[test]
fn a_forced_failure_halts_the_running_leaf_and_the_fallback_runs_its_next_child() {
    let plan = plan();
    let mut driver = ScriptedDriver::new(&plan);
    driver.script(
        "reach[first choice]",
        std::iter::repeat_n(LeafOutcome::Running, 100),
    );
    driver.set_default(LeafOutcome::Success);
    let mut runner = TreeRunner::new(plan.clone());
    let reach = node(&plan, "reach");
    let home = node(&plan, "home");
    for k in 0..3 {
        assert_eq!(
            runner.tick(k as f64 * 0.02, 0.02, &mut driver),
            TreeStatus::Running
        );
    }
    runner.force(reach, ForcedResult::Failure).unwrap();
    assert_eq!(runner.forced(reach), Some(ForcedResult::Failure));
    let ticks_before = driver.ticks("reach[first choice]");
    let status = runner.tick(0.06, 0.02, &mut driver);
    assert_eq!(status, TreeStatus::Success, "the fallback's next child ran");
    assert_eq!(
        driver.ticks("reach[first choice]"),
        ticks_before,
        "the forced tick never reached the driver"
    );
    assert_eq!(
        driver.halts("reach[first choice]"),
        1,
        "the running reach was halted first"
    );
    assert_eq!(driver.starts("home[next child]"), 1);
    assert_eq!(runner.forced(reach), None, "a forced result is used once");
    let counts = runner.node_counts();
    assert_eq!(
        (
            counts[reach].activations,
            counts[reach].failures,
            counts[reach].overridden
        ),
        (1, 1, 1)
    );
    assert_eq!(counts[home].overridden, 0);
    let reason = runner.node_reasons()[reach].clone().unwrap();
    assert_eq!(reason.kind, FailureKind::Overridden);
}

#[test]
fn a_forced_success_answers_at_the_next_activation_without_the_driver() {
    let plan = plan();
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::failure(FailureKind::Unreachable, "scripted"));
    let mut runner = TreeRunner::new(plan.clone());
    let reach = node(&plan, "reach");
    runner.force(reach, ForcedResult::Success).unwrap();
    assert_eq!(runner.tick(0.0, 0.02, &mut driver), TreeStatus::Success);
    assert_eq!(driver.starts("reach[first choice]"), 0);
    assert_eq!(driver.starts("home[next child]"), 0, "the first choice succeeded");
    let c = runner.node_counts()[reach];
    assert_eq!((c.activations, c.successes, c.overridden), (1, 1, 1));
    // A reset forgets a pending forced result.
    runner.force(reach, ForcedResult::Success).unwrap();
    runner.reset();
    assert_eq!(runner.forced(reach), None);
}

#[test]
fn only_leaves_can_be_forced() {
    let plan = plan();
    let mut runner = TreeRunner::new(plan.clone());
    let fallback = node(&plan, "fallback");
    assert_eq!(
        runner.force(fallback, ForcedResult::Failure),
        Err(ForceError::NotALeaf(plan.nodes[fallback].path.clone()))
    );
    assert_eq!(
        runner.force(plan.nodes.len(), ForcedResult::Failure),
        Err(ForceError::NoSuchNode(plan.nodes.len()))
    );
    assert!("maybe".parse::<ForcedResult>().is_err());
    assert_eq!("failure".parse::<ForcedResult>(), Ok(ForcedResult::Failure));
}
