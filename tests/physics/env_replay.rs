//! Stepping a tree's leaves one by one through the environment gives `run_episode`'s physics
//! bit for bit: the flagship tree is run once while an observer records the action leaves it
//! starts (as the mappings the environment takes) and the physics state after every control
//! period; the recorded leaves are then stepped in a fresh environment and the state compared.

use std::sync::Arc;

use macrotree::App;
use macrotree::actions::Cell;
use macrotree::env::{Action, EnvConfig, MacroEnv, Reset, Status};
use macrotree::episode::{EpisodeConfig, EpisodeObserver, run_episode};
use macrotree::kinds::Leaf;
use macrotree::runtime::{NodeStatus, TreeRunner};

use crate::support::flagship;

/// The action leaves the tree started, as JSON mappings, and the physics state after every
/// control period (physics steps so far, state fingerprint).
#[derive(Default)]
struct Recorder {
    started: Vec<String>,
    states: Vec<(u64, Vec<u64>)>,
}

impl EpisodeObserver for Recorder {
    fn on_tick(&mut self, cell: &Cell, runner: &mut TreeRunner) {
        let plan = runner.plan().clone();
        for t in runner.drain_transitions() {
            let starts = t.from != NodeStatus::Running
                && matches!(
                    t.to,
                    NodeStatus::Running | NodeStatus::Failure | NodeStatus::Success
                );
            let leaf = plan.nodes[t.node].leaf.and_then(|id| plan.leaf(id));
            if let (true, Some(info)) = (starts, leaf)
                && let Leaf::Action(call) = &info.kind
            {
                self.started.push(serde_json::to_string(call).unwrap());
            }
        }
        self.states
            .push((cell.sim().steps(), cell.sim().state_fingerprint()));
    }
}

fn replay(reset: Reset, config: EpisodeConfig) {
    let scene = flagship::scene();
    let plan = flagship::plan();
    let mut rec = Recorder::default();
    let report = run_episode(
        scene,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut rec,
    );
    assert!(report.outcome.success, "{:?}", report.failure);
    assert_eq!(
        report.outcome.halts, 0,
        "no leaf was halted, so the replay applies"
    );
    let kinds: Vec<&str> = rec.started.iter().map(|s| s.split('"').nth(1).unwrap()).collect();
    assert_eq!(
        kinds,
        [
            "home", "release", "reach", "reach", "grasp", "carry", "release", "home"
        ],
        "one attempt"
    );

    let mut env = MacroEnv::new(
        &App::new(),
        scene.clone(),
        Some(Arc::new((*plan).clone())),
        EnvConfig::default(),
    )
    .unwrap();
    env.reset(&reset).unwrap();
    let mut steps = 0;
    for text in &rec.started {
        let r = env.step(&Action::Leaf(text.clone())).unwrap();
        assert_eq!(r.status, Status::Success, "{text}: {:?}", r.failure);
        steps += r.physics_steps;
    }
    assert_eq!(env.cell().sim().steps(), steps);
    // run_episode simulates one more control period after the tree has finished.
    let (last_steps, _) = rec.states.last().unwrap();
    assert_eq!(*last_steps, steps + 2);
    assert_eq!(report.outcome.physics_steps, steps + 2);
    let (_, episode_state) = rec
        .states
        .iter()
        .find(|(s, _)| *s == steps)
        .expect("the episode passed the replay's step count");
    assert_eq!(
        &env.cell().sim().state_fingerprint(),
        episode_state,
        "bit-identical physics after {steps} steps"
    );
    let last = env.observe();
    assert!(
        env.step(&Action::Leaf("cube_in_bowl: {}".into()))
            .unwrap()
            .success(),
        "the cube is in the bowl: {:?}",
        last.object("cube")
    );
}

#[test]
fn stepping_the_flagship_trees_leaves_gives_run_episodes_physics_bit_for_bit() {
    replay(Reset::Default, EpisodeConfig::default());
}

#[test]
fn the_replay_holds_on_a_swept_scenario_too() {
    let scene = flagship::scene();
    let sweep = macrotree::sweep::SweepConfig {
        seed: 1,
        ..Default::default()
    };
    let s = sweep.scenario(scene, 5).unwrap();
    replay(
        Reset::Scenario {
            index: 5,
            sweep_seed: 1,
        },
        sweep.episode_config(&s),
    );
}
