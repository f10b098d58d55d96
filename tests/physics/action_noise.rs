//! Demonstrations with recoveries: noise injected into what the arm executes moves the episode
//! off the clean path, the recorded action stays the clean command, and the same seed gives the
//! same noisy episode bit for bit.

use macrotree::dataset::{DEFAULT_FRAME_RATE, EpisodeRecorder, FrameRecord};
use macrotree::episode::{EpisodeConfig, EpisodeReport, run_episode};
use macrotree::faults::ActionNoise;
use macrotree::sweep::SweepConfig;

use crate::support::flagship;

fn record(config: &EpisodeConfig) -> (EpisodeReport, Vec<FrameRecord>) {
    let mut rec = EpisodeRecorder::new(flagship::plan(), DEFAULT_FRAME_RATE);
    let report = run_episode(
        flagship::scene(),
        flagship::plan(),
        &macrotree::factory::Factory::builtin(),
        config,
        &mut rec,
    );
    (report, rec.finish().unwrap().frames)
}

#[test]
fn noise_moves_the_executed_path_while_the_labels_stay_clean_commands() {
    let noise = ActionNoise {
        joint_sigma: 0.02,
        gripper_sigma: 10.0,
    };
    let clean = EpisodeConfig::default();
    let noisy = EpisodeConfig {
        noise: Some(noise),
        ..EpisodeConfig::default()
    };
    let (clean_report, clean_frames) = record(&clean);
    let (noisy_report, noisy_frames) = record(&noisy);
    assert!(
        clean_report.outcome.success && noisy_report.outcome.success,
        "{:?}",
        noisy_report.failure
    );
    assert_eq!(
        noisy_frames[0].state, clean_frames[0].state,
        "both start at reset"
    );
    // The arm left the clean path: its measured joints differ by more than the servos' lag.
    let off_path = noisy_frames
        .iter()
        .zip(&clean_frames)
        .flat_map(|(n, c)| n.state[..6].iter().zip(&c.state[..6]).map(|(a, b)| (a - b).abs()))
        .fold(0f32, f32::max);
    assert!(
        off_path > 0.01,
        "the noisy episode stays within {off_path} rad of the clean one"
    );
    // A label is the clean command the leaves gave, never the noisy one the servos got: while
    // the arm holds still at home (the first frames), the label is exactly home at rest.
    let home = macrotree::motion::HOME_Q.map(|q| q as f32);
    assert_eq!(noisy_frames[0].action[..6], home);
    assert!(noisy_frames[0].action[6..18].iter().all(|v| *v == 0.0));
    // The same seed: the same noisy episode, bit for bit.
    let (_, again) = record(&noisy);
    assert_eq!(again, noisy_frames);
    // Another seed: other noise.
    let (_, other) = record(&EpisodeConfig { seed: 1, ..noisy });
    assert_ne!(other, noisy_frames);
}

#[test]
fn noisy_demonstrations_of_the_flagship_still_succeed() {
    let scene = flagship::scene();
    let sweep = SweepConfig {
        seed: 4,
        noise: Some(ActionNoise {
            joint_sigma: 0.02,
            gripper_sigma: 10.0,
        }),
        ..Default::default()
    };
    let scenarios = 20;
    let successes = (0..scenarios)
        .filter(|&k| {
            let s = sweep.scenario(scene, k).unwrap();
            let (report, _) = record(&sweep.episode_config(&s));
            report.outcome.success
        })
        .count();
    assert_eq!(
        successes, scenarios as usize,
        "the flagship's retries absorb σ = 0.02 rad"
    );
}
