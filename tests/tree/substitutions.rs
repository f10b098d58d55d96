//! Substitutions and per-node counts on scripted leaves (tree logic, no physics): what each
//! scripted outcome does, that the real leaf runs after `fail_first:N`, that counts follow the
//! execution exactly, and that rules that do not fit the tree are refused.

use std::sync::Arc;

use macrotree::plan::{Loader, Plan};
use macrotree::runtime::substitute::{Resolved, Substitution, resolve};
use macrotree::runtime::{LeafOutcome, NodeCounts, TreeRunner, TreeStatus, scripted::ScriptedDriver};

const TREE: &str = r#"
main:
  sequence:
    name: top
    children:
      - home: {}
      - retry:
          attempts: 3
          child:
            fallback:
              name: pick
              children:
                - sequence:
                    name: plain
                    children:
                      - grasp: {}
                      - cube_grasped: {}
                - sequence:
                    name: recovery
                    children:
                      - release: {retreat: 0.05}
                      - grasp: {name: again}
      - wait: {seconds: 0.1}
"#;

fn plan() -> Arc<Plan> {
    Arc::new(
        Loader::default()
            .compile_str(TREE, "t.yaml")
            .unwrap_or_else(|d| panic!("{}", d[0])),
    )
}

fn subs(plan: &Plan, rules: &[&str]) -> Resolved {
    let rules: Vec<Substitution> = rules.iter().map(|r| r.parse().unwrap()).collect();
    resolve(plan, &rules).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs to the end (at most 200 ticks of 0.05 s) and returns the status and the ticks used.
fn run(runner: &mut TreeRunner, driver: &mut ScriptedDriver) -> (TreeStatus, u64) {
    for k in 0..200 {
        let s = runner.tick(k as f64 * 0.05, 0.05, driver);
        if s != TreeStatus::Running {
            return (s, runner.tick_count());
        }
    }
    panic!("did not finish");
}

fn counts(runner: &TreeRunner, path_end: &str) -> NodeCounts {
    let plan = runner.plan();
    let i = plan
        .nodes
        .iter()
        .position(|n| n.path.ends_with(path_end))
        .unwrap_or_else(|| panic!("no node ending in {path_end}"));
    runner.node_counts()[i]
}

#[test]
fn fail_first_fails_then_runs_the_real_leaf() {
    let plan = plan();
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::Success);
    let mut runner = TreeRunner::with_substitutions(
        plan.clone(),
        subs(&plan, &["main/**/sequence[plain]/grasp=fail_first:1"]),
    );
    let (status, _) = run(&mut runner, &mut driver);
    assert_eq!(status, TreeStatus::Success);
    // The first activation of the plain grasp failed without reaching the driver; the recovery ran.
    let plain = counts(&runner, "sequence[plain]/grasp");
    assert_eq!((plain.activations, plain.successes, plain.failures), (1, 0, 1));
    assert_eq!(driver.starts("grasp[again]"), 1);
    assert_eq!(counts(&runner, "sequence[recovery]").successes, 1);
    // Only the real grasp reached the driver (the plain one never did).
    assert_eq!(driver.starts("sequence[plain]/grasp"), 0);
}

#[test]
fn fail_first_counts_activations_across_retries() {
    let plan = plan();
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::Success);
    // Both grasps fail their first two activations: attempts 1 and 2 fail, attempt 3 succeeds
    // through the real plain grasp.
    let mut runner =
        TreeRunner::with_substitutions(plan.clone(), subs(&plan, &["main/**/grasp*=fail_first:2"]));
    let (status, _) = run(&mut runner, &mut driver);
    assert_eq!(status, TreeStatus::Success);
    let plain = counts(&runner, "sequence[plain]/grasp");
    assert_eq!((plain.activations, plain.successes, plain.failures), (3, 1, 2));
    let retry = counts(&runner, "/retry");
    assert_eq!((retry.activations, retry.successes, retry.failures), (1, 1, 0));
    assert_eq!(driver.starts("sequence[plain]/grasp"), 1);
    assert_eq!(driver.starts("grasp[again]"), 0);
}

#[test]
fn failure_and_success_never_reach_the_driver() {
    let plan = plan();
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::failure(
        macrotree::FailureKind::Other,
        "real leaf ran",
    ));
    let mut runner = TreeRunner::with_substitutions(
        plan.clone(),
        subs(
            &plan,
            &[
                "main/*/home=success",
                "main/**/grasp*=failure",
                "main/**/release=success",
                "main/**/cube_grasped=success",
            ],
        ),
    );
    let (status, _) = run(&mut runner, &mut driver);
    assert_eq!(status, TreeStatus::Failure);
    let reason = runner.node_reasons()[0].clone().unwrap();
    assert!(reason.message.contains("substituted"), "{reason}");
    assert_eq!(reason.kind, macrotree::FailureKind::Substituted);
    assert_eq!(reason.root_cause().kind, macrotree::FailureKind::Substituted);
    assert_eq!(counts(&runner, "/retry").failures, 1);
    assert_eq!(counts(&runner, "grasp[again]").activations, 3);
    assert_eq!(
        driver.starts("home") + driver.starts("grasp") + driver.starts("release"),
        0
    );
}

#[test]
fn running_n_takes_n_ticks_then_succeeds() {
    let plan = plan();
    let base = {
        let mut driver = ScriptedDriver::new(&plan);
        driver.set_default(LeafOutcome::Success);
        let mut runner = TreeRunner::new(plan.clone());
        run(&mut runner, &mut driver).1
    };
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::Success);
    let mut runner = TreeRunner::with_substitutions(plan.clone(), subs(&plan, &["main/*/home=running:7"]));
    let (status, ticks) = run(&mut runner, &mut driver);
    assert_eq!(status, TreeStatus::Success);
    assert_eq!(ticks, base + 7, "seven extra ticks of Running");
    let home = counts(&runner, "/home");
    assert_eq!((home.activations, home.successes), (1, 1));
}

#[test]
fn halts_are_counted() {
    let plan = Arc::new(
        Loader::default()
            .compile_str("main: {timeout: {seconds: 0.2, child: {home: {}}}}", "t.yaml")
            .unwrap(),
    );
    let mut driver = ScriptedDriver::new(&plan);
    driver.set_default(LeafOutcome::Running);
    let mut runner = TreeRunner::new(plan.clone());
    let (status, _) = run(&mut runner, &mut driver);
    assert_eq!(status, TreeStatus::Failure);
    let home = counts(&runner, "/home");
    assert_eq!(
        (home.activations, home.successes, home.failures, home.halts),
        (1, 0, 0, 1)
    );
    assert_eq!(driver.halts("home"), 1);
    // A halted substitute is not a driver halt.
    let mut driver = ScriptedDriver::new(&plan);
    let mut runner =
        TreeRunner::with_substitutions(plan.clone(), subs(&plan, &["main/**/home=running:1000"]));
    run(&mut runner, &mut driver);
    assert_eq!(counts(&runner, "/home").halts, 1);
    assert_eq!(driver.halts("home"), 0);
}

#[test]
fn counts_are_deterministic_and_reset() {
    let plan = plan();
    let go = || {
        let mut driver = ScriptedDriver::new(&plan);
        driver.set_default(LeafOutcome::Success);
        let mut runner =
            TreeRunner::with_substitutions(plan.clone(), subs(&plan, &["main/**/grasp*=fail_first:1"]));
        run(&mut runner, &mut driver);
        let c = runner.node_counts().to_vec();
        runner.reset();
        assert!(runner.node_counts().iter().all(|c| *c == NodeCounts::default()));
        c
    };
    assert_eq!(go(), go());
}

#[test]
fn rules_that_do_not_fit_are_refused_with_close_paths() {
    let plan = plan();
    let check = |rule: &str, needle: &str| {
        let r: Substitution = rule.parse().unwrap();
        let e = resolve(&plan, &[r]).unwrap_err().to_string();
        assert!(e.contains(needle), "{rule}: {e}");
    };
    check("main/**/graps=failure", "matches no node");
    check("main/**/graps=failure", "sequence[plain]/grasp");
    check("main/**/fallback[pick]=failure", "only composite");
    check("main/**/cube_grasped=running:3", "condition");
    let two: Vec<Substitution> = ["main/**/grasp=failure", "**/sequence[plain]/*=success"]
        .iter()
        .map(|r| r.parse().unwrap())
        .collect();
    assert!(
        resolve(&plan, &two)
            .unwrap_err()
            .to_string()
            .contains("also matched")
    );
}

#[test]
fn a_resolution_is_reused_only_for_its_own_rules_and_a_plan_with_the_same_leaves() {
    let plan = plan();
    let rules: Vec<Substitution> = vec!["main/**/grasp[again]=failure".parse().unwrap()];
    let resolved = resolve(&plan, &rules).unwrap_or_else(|e| panic!("{e}"));
    assert!(resolved.is_for(&plan, &rules));
    // The same tree compiled again: another plan, the same leaves.
    assert!(resolved.is_for(&self::plan(), &rules));
    // Other rules against the same plan.
    let other: Vec<Substitution> = vec!["main/**/grasp[again]=success".parse().unwrap()];
    assert!(!resolved.is_for(&plan, &other));
    assert!(!resolved.is_for(&plan, &[]));
    // A plan with as many leaves as this one, at other paths.
    let renamed = Loader::default()
        .compile_str(&TREE.replace("name: again", "name: twice"), "t.yaml")
        .unwrap_or_else(|d| panic!("{}", d[0]));
    assert_eq!(renamed.leaves.len(), plan.leaves.len());
    assert!(!resolved.is_for(&renamed, &rules));
}
