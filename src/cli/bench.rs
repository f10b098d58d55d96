//! `macrotree bench TREE`: what all that is not physics costs.
//!
//! Runs the episode while recording every physics step's actuator commands, then replays those
//! commands on a fresh copy of the same model with nothing but `mj_step` in a loop. The ratio of
//! the two wall times is the overhead of the tree, the controllers, IK and world extraction.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use clap::Args;
use serde::Serialize;

use super::run::EpisodeArgs;
use super::{CliError, load_task};
use crate::actions::Cell;
use crate::episode::replay::{ControlRecorder, replay_controls};
use crate::episode::{NoObserver, run_in_cell};

/// Arguments of `bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The tree file (YAML).
    pub tree: PathBuf,
    #[command(flatten)]
    pub episode: EpisodeArgs,
    /// Repetitions, 1…1000; the median of each timing is reported.
    #[arg(long, default_value_t = 5, value_parser = super::limits::repeat)]
    pub repeat: usize,
    /// Print the result as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
}

/// What `bench` measures. Times in seconds.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Median wall time of the whole episode (tree, controllers, IK, physics).
    pub episode_wall_time_s: f64,
    /// Median wall time of replaying the same controls with bare mj_step.
    pub replay_wall_time_s: f64,
    /// episode / replay.
    pub ratio: f64,
    /// Simulated time of the episode.
    pub sim_time_s: f64,
    /// Physics steps of the episode.
    pub physics_steps: u64,
    /// The episode succeeded.
    pub success: bool,
    /// Mean IK solve time over 10 000 task-region targets, microseconds.
    pub ik_us_per_solve: f64,
    /// Repetitions behind each median.
    pub repeat: usize,
    /// The episode's final physics state ([`Sim::state_fingerprint`]: qpos, qvel, ctrl, time as
    /// bits), hashed with 64-bit FNV-1a over the little-endian bytes, as 16 hex digits.
    pub state_fingerprint: String,
    /// The replay of the recorded controls ended in exactly the episode's final state (bit for
    /// bit); `null` with a fault, which acts through forces and moves the controls do not hold.
    pub replay_matches_episode: Option<bool>,
}

/// 64-bit FNV-1a of `bits` (each as 8 little-endian bytes), as 16 hex digits.
fn fnv1a_hex(bits: &[u64]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bits.iter().flat_map(|v| v.to_le_bytes()) {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Runs `macrotree bench`.
pub fn bench(app: &crate::App, args: BenchArgs) -> Result<(), CliError> {
    args.episode.config()?;
    let (plan, scene) = load_task(app, &args.tree, args.episode.scene.as_deref())?;
    let plan = Arc::new(plan);
    let mut config = args.episode.config_on(&scene)?;
    config.resolved = Some(super::resolve_substitutions(&plan, &config.substitutions)?);
    let placement = config
        .placement
        .clone()
        .unwrap_or_else(|| scene.default_placement());
    let repeat = args.repeat.max(1);
    let mut episode_times = Vec::new();
    let mut replay_times = Vec::new();
    let mut last = None;
    let mut states = None;
    for _ in 0..repeat {
        let (recorder, controls) = ControlRecorder::new();
        let mut cell = Cell::new(&scene, &crate::sim::Layout::default(), config.control_period);
        // Recording costs one copy per step, which is charged to the episode (conservative).
        cell.observers.push(Box::new(recorder));
        let t = Instant::now();
        let report = run_in_cell(&mut cell, plan.clone(), app.factory(), &config, &mut NoObserver);
        episode_times.push(t.elapsed().as_secs_f64());
        let controls = controls.lock().expect("recorder lock").clone();
        let (wall, replayed) = replay_controls(&scene, &placement, &controls);
        replay_times.push(wall);
        states = Some((cell.sim().state_fingerprint(), replayed));
        last = Some(report);
    }
    let report = last.expect("repeat >= 1");
    let episode = median(episode_times);
    let replay = median(replay_times);
    let (episode_state, replay_state) = states.expect("repeat >= 1");
    let matches = config.fault.is_none().then(|| episode_state == replay_state);
    if matches == Some(false) {
        tracing::warn!(target: "macrotree::bench", "the replay of the recorded controls did not end in the episode's final state");
    }
    let result = BenchReport {
        episode_wall_time_s: episode,
        replay_wall_time_s: replay,
        ratio: episode / replay,
        sim_time_s: report.outcome.sim_time_s,
        physics_steps: report.outcome.physics_steps,
        success: report.outcome.success,
        ik_us_per_solve: crate::motion::ik_benchmark(10_000),
        repeat,
        state_fingerprint: fnv1a_hex(&episode_state),
        replay_matches_episode: matches,
    };
    use super::human::say;
    say!(
        args.json,
        "episode {:.4} s wall, replay (bare mj_step) {:.4} s wall, ratio {:.3}; {:.2} s simulated, {} steps, success {}; IK {:.2} µs/solve (median of {repeat})",
        result.episode_wall_time_s,
        result.replay_wall_time_s,
        result.ratio,
        result.sim_time_s,
        result.physics_steps,
        result.success,
        result.ik_us_per_solve
    );
    if let Some(m) = result.replay_matches_episode {
        say!(
            args.json,
            "final state {}: the replay {} the episode",
            result.state_fingerprint,
            if m {
                "ends exactly where"
            } else {
                "does NOT end where"
            }
        );
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&result).expect("bench report serializes")
        );
    }
    Ok(())
}
