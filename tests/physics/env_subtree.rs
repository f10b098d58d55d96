//! `Action::Subtree`: a named subtree of the flagship tree, or the whole tree, run to completion
//! from the environment — ticked exactly as inside the tree.

use std::sync::Arc;

use macrotree::App;
use macrotree::env::{Action, EnvConfig, MacroEnv, Reset, Status};
use macrotree::episode::{EpisodeObserver, run_episode};

use crate::support::flagship;

fn env() -> MacroEnv {
    let plan = Arc::new((*flagship::plan()).clone());
    MacroEnv::new(
        &App::new(),
        flagship::scene().clone(),
        Some(plan),
        EnvConfig::default(),
    )
    .expect("env")
}

#[test]
fn the_pick_subtree_then_the_guarded_carry_run_to_completion() {
    let mut env = env();
    let names = env.subtree_names();
    assert!(
        names.contains(&"pick".to_string()) && names.contains(&"carry while held".to_string()),
        "{names:?}"
    );
    let r = env.step(&Action::Subtree("pick".into())).unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    assert!(r.observation.object("cube").unwrap().grasped);
    assert!(r.sim_time > 0.5);
    let r = env.step(&Action::Subtree("carry while held".into())).unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    let r = env
        .step(&Action::Leaf("release: {retreat: 0.10}".into()))
        .unwrap();
    assert!(r.success());
    // The goal holds once the cube rests, released, in the bowl.
    let r = env.step(&Action::Leaf("home: {}".into())).unwrap();
    assert_eq!((r.reward, r.terminated), (1.0, true), "{:?}", r.goal);
    assert!(r.goal_ticks > 0);
}

#[test]
fn a_failing_subtree_reports_the_failure_with_the_node_path_in_the_whole_tree() {
    let mut env = env();
    // The gripper closed before the pick: the grasp cannot close on the cube.
    assert!(env.step(&Action::Leaf("grasp: {}".into())).unwrap().status == Status::Failure);
    let r = env.step(&Action::Subtree("pick".into())).unwrap();
    assert_eq!(r.status, Status::Failure);
    let f = r.failure.unwrap();
    let node = f.node.clone().unwrap_or_default();
    assert!(
        node.starts_with("main/") && node.contains("subtree[pick]"),
        "{f:?}"
    );
}

/// The physics state after every control period.
#[derive(Default)]
struct States(Vec<(u64, Vec<u64>)>);

impl EpisodeObserver for States {
    fn on_tick(&mut self, cell: &macrotree::actions::Cell, _: &mut macrotree::runtime::TreeRunner) {
        self.0.push((cell.sim().steps(), cell.sim().state_fingerprint()));
    }
}

#[test]
fn the_whole_tree_as_one_step_is_run_episode_bit_for_bit() {
    let mut env = env();
    env.reset(&Reset::Scenario {
        index: 2,
        sweep_seed: 7,
    })
    .unwrap();
    let r = env.step(&Action::Subtree("main".into())).unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    assert_eq!((r.reward, r.terminated, r.truncated), (1.0, true, false));
    let sweep = macrotree::sweep::SweepConfig {
        seed: 7,
        ..Default::default()
    };
    let s = sweep.scenario(flagship::scene(), 2).unwrap();
    let mut states = States::default();
    let report = run_episode(
        flagship::scene(),
        flagship::plan(),
        &macrotree::factory::Factory::builtin(),
        &sweep.episode_config(&s),
        &mut states,
    );
    assert!(report.outcome.success);
    assert_eq!(
        report.outcome.physics_steps,
        r.physics_steps + 2,
        "run_episode ticks one period more"
    );
    let at = states.0.iter().find(|(n, _)| *n == r.physics_steps).unwrap();
    assert_eq!(at.1, env.cell().sim().state_fingerprint());
}

#[test]
fn unknown_and_ambiguous_names_are_refused_with_what_to_give() {
    let mut env = env();
    let e = env.step(&Action::Subtree("pik".into())).unwrap_err();
    assert_eq!(e.kind(), "invalid_action");
    assert!(e.to_string().contains("did you mean `pick`?"), "{e}");
    // A named condition runs as a step of its own (at once, no physics).
    let r = env.step(&Action::Subtree("holding?".into())).unwrap();
    assert_eq!((r.status, r.physics_steps), (Status::Failure, 0));
    // A guard's condition is re-checked by the guard: it cannot run alone.
    let tree = env.tree().unwrap().clone();
    let guard = tree.nodes.iter().find(|n| n.kind == "guard").unwrap();
    let check = tree.nodes[guard.children[0]].path.clone();
    let e = env.step(&Action::Subtree(check)).unwrap_err();
    assert!(e.to_string().contains("cannot run alone"), "{e}");
}
