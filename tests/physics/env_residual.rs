//! Residual control: the environment's tree is the base controller, ticked once per step; the
//! agent's correction is added to its command. A zero residual is the scripted episode bit for
//! bit; a non-zero one changes the physics, within its bounds; other actions end the base run.

use std::sync::Arc;

use macrotree::App;
use macrotree::env::{Action, EnvConfig, MacroEnv, RESIDUAL_LEN, RESIDUAL_LIMITS, Reset, Status};
use macrotree::episode::run_episode;
use macrotree::runtime::TreeStatus;
use macrotree::sweep::SweepConfig;

use crate::support::commands::Commands;
use crate::support::flagship;

fn residual_env() -> MacroEnv {
    MacroEnv::new(
        &App::new(),
        flagship::scene().clone(),
        Some(Arc::new((*flagship::plan()).clone())),
        EnvConfig::default(),
    )
    .unwrap()
}

const ZERO: Action = Action::Residual([0.0; RESIDUAL_LEN]);

#[test]
fn a_zero_residual_runs_the_scripted_episode_bit_for_bit() {
    let sweep = SweepConfig {
        seed: 5,
        ..Default::default()
    };
    for index in [0, 3] {
        let config = sweep.episode_config(&sweep.scenario(flagship::scene(), index).unwrap());
        let mut rec = Commands::default();
        let report = run_episode(
            flagship::scene(),
            flagship::plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut rec,
        );
        assert!(report.outcome.success, "{:?}", report.failure);

        let mut env = residual_env();
        env.reset(&Reset::Scenario {
            index,
            sweep_seed: sweep.seed,
        })
        .unwrap();
        let mut last = None;
        for (k, (command, state)) in rec.commands.iter().zip(&rec.states).enumerate() {
            let r = env.step(&ZERO).unwrap();
            let base = r.base.as_ref().expect("a residual step reports its base");
            assert_eq!(base.command, command.to_vector(), "period {k}: the base command");
            assert_eq!(r.ctrl_clamped, 0);
            assert_eq!(
                &env.cell().sim().state_fingerprint(),
                state,
                "scenario {index}, period {k}: bit-identical physics"
            );
            last = Some(r);
        }
        let last = last.unwrap();
        assert_eq!(last.base.unwrap().status, TreeStatus::Success);
        assert_eq!(last.status, Status::Success);
        assert!(last.terminated && last.reward == 1.0, "the goal holds at the end");
    }
}

#[test]
fn a_residual_changes_the_command_within_its_bounds() {
    let mut env = residual_env();
    env.reset(&Reset::Default).unwrap();
    let scripted = {
        let mut twin = residual_env();
        twin.reset(&Reset::Default).unwrap();
        (0..200).map(|_| twin.step(&ZERO).unwrap()).last().unwrap()
    };
    let mut r = [0.0; RESIDUAL_LEN];
    r[0] = 0.05;
    let mut last = None;
    for _ in 0..200 {
        last = Some(env.step(&Action::Residual(r)).unwrap());
    }
    let last = last.unwrap();
    let moved = last.observation.joint_pos[0] - scripted.observation.joint_pos[0];
    assert!(
        (0.03..=RESIDUAL_LIMITS.max_joint_offset).contains(&moved),
        "the shoulder pan is {moved} rad from the scripted one's"
    );
    // Beyond the bounds: clamped and counted.
    r[0] = 1.0;
    let clamped = env.step(&Action::Residual(r)).unwrap();
    assert!(clamped.ctrl_clamped >= 1, "{}", clamped.ctrl_clamped);
    r[0] = f64::NAN;
    let e = env.step(&Action::Residual(r)).unwrap_err();
    assert!(e.to_string().contains("residual[0]"), "{e}");
}

#[test]
fn another_action_ends_the_base_run_and_the_next_residual_restarts_the_tree() {
    let mut env = residual_env();
    env.reset(&Reset::Default).unwrap();
    for _ in 0..50 {
        let r = env.step(&ZERO).unwrap();
        assert_eq!(r.base.unwrap().status, TreeStatus::Running);
    }
    let r = env.step(&Action::Leaf("home: {}".into())).unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    assert!(r.base.is_none());
    // The tree starts again from its root and runs to its end: the cube in the bowl.
    let mut last = None;
    for _ in 0..5000 {
        let r = env.step(&ZERO).unwrap();
        let done = r.base.as_ref().unwrap().status != TreeStatus::Running;
        last = Some(r);
        if done {
            break;
        }
    }
    let last = last.unwrap();
    assert_eq!(
        last.base.unwrap().status,
        TreeStatus::Success,
        "{:?}",
        last.failure
    );
    assert!(last.terminated && last.reward == 1.0);
}

#[test]
fn a_residual_without_a_tree_is_refused_before_anything_moves() {
    let mut env = MacroEnv::new(&App::new(), flagship::scene().clone(), None, EnvConfig::default()).unwrap();
    env.reset(&Reset::Default).unwrap();
    let steps = env.cell().sim().steps();
    let e = env.step(&ZERO).unwrap_err();
    assert_eq!(e.kind(), "invalid_action");
    assert!(e.to_string().contains("base tree"), "{e}");
    assert_eq!(env.cell().sim().steps(), steps);
}
