//! One action everywhere: the command the leaves give each control period is what the
//! environment's `ctrl` action takes and what a dataset's `action` column records, so a recorded
//! episode replays — bit for bit at the control period, and to the same outcome from a dataset
//! at its own frame rate.

use macrotree::App;
use macrotree::actions::CONTROL_PERIOD;
use macrotree::dataset::{DEFAULT_FRAME_RATE, EpisodeRecorder};
use macrotree::env::{Action, EnvConfig, MacroEnv, Reset};
use macrotree::episode::{EpisodeConfig, run_episode};
use macrotree::sweep::SweepConfig;

use crate::support::commands::Commands;
use crate::support::flagship;

fn env(control_period: f64) -> MacroEnv {
    MacroEnv::new(
        &App::new(),
        flagship::scene().clone(),
        None,
        EnvConfig {
            control_period,
            ..EnvConfig::default()
        },
    )
    .unwrap()
}

/// The goal holds at the end (the cube at rest in the bowl, released).
fn goal_holds(env: &mut MacroEnv) -> bool {
    env.step(&Action::Leaf("goal_met: {}".into())).unwrap().success()
}

#[test]
fn an_episodes_commands_replayed_through_ctrl_give_its_physics_bit_for_bit() {
    for (reset, index) in [
        (Reset::Default, None),
        (
            Reset::Scenario {
                index: 7,
                sweep_seed: 3,
            },
            Some(7),
        ),
    ] {
        let sweep = SweepConfig {
            seed: 3,
            ..Default::default()
        };
        let config = match index {
            Some(k) => sweep.episode_config(&sweep.scenario(flagship::scene(), k).unwrap()),
            None => EpisodeConfig::default(),
        };
        let mut rec = Commands::default();
        let report = run_episode(
            flagship::scene(),
            flagship::plan(),
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut rec,
        );
        assert!(report.outcome.success, "{:?}", report.failure);
        assert!(
            rec.commands
                .iter()
                .any(|c| c.arm.qd.iter().any(|v| v.abs() > 0.5))
        );
        assert!(
            rec.commands
                .iter()
                .any(|c| c.arm.qdd.iter().any(|v| v.abs() > 1.0))
        );

        let mut env = env(CONTROL_PERIOD);
        env.reset(&reset).unwrap();
        for (k, (command, state)) in rec.commands.iter().zip(&rec.states).enumerate() {
            let r = env.step(&Action::Ctrl(command.to_vector())).unwrap();
            assert_eq!(
                r.ctrl_clamped, 0,
                "period {k}: a leaf's command is within the ctrl limits"
            );
            assert_eq!(
                &env.cell().sim().state_fingerprint(),
                state,
                "period {k}: bit-identical physics"
            );
        }
        assert!(goal_holds(&mut env));
    }
}

#[test]
fn a_dataset_at_its_frame_rate_replays_through_ctrl_to_the_same_outcome() {
    let scene = flagship::scene();
    let sweep = SweepConfig {
        seed: 11,
        ..Default::default()
    };
    let fps = DEFAULT_FRAME_RATE;
    let mut env = env(1.0 / fps as f64);
    let (mut same, mut successes) = (0, 0);
    let scenarios = 50;
    for index in 0..scenarios {
        let s = sweep.scenario(scene, index).unwrap();
        let mut rec = EpisodeRecorder::new(flagship::plan(), fps);
        let report = run_episode(
            scene,
            flagship::plan(),
            &macrotree::factory::Factory::builtin(),
            &sweep.episode_config(&s),
            &mut rec,
        );
        let frames = rec.finish().unwrap().frames;
        assert_eq!(frames[0].sim_time, 0.0, "frame 0 is the state at reset");
        env.reset(&Reset::Scenario {
            index,
            sweep_seed: sweep.seed,
        })
        .unwrap();
        let start = env.observe().state();
        assert_eq!(
            start, frames[0].state,
            "scenario {index}: the replay starts where the episode did"
        );
        for f in &frames {
            let action = f.action.map(f64::from);
            env.step(&Action::Ctrl(action)).unwrap();
        }
        let replayed = goal_holds(&mut env);
        successes += report.outcome.success as u32;
        same += (replayed == report.outcome.success) as u32;
    }
    assert_eq!(successes, scenarios as u32, "every recorded episode succeeded");
    assert_eq!(same, scenarios as u32, "every replay ends as its episode did");
}
