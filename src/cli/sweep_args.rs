//! [`SweepArgs`]: the arguments of `macrotree sweep`.

use std::path::PathBuf;

use clap::Args;

use crate::episode::Goal;
use crate::faults::FaultKind;

/// Arguments of `sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// The tree file (YAML).
    pub tree: PathBuf,
    /// Sweep this scene file instead of the tree's own `scene:` (or the built-in cube_bowl).
    #[arg(long, value_name = "FILE.yaml")]
    pub scene: Option<PathBuf>,
    /// Number of scenarios (indices 0..N, N ≤ 10 000 000); with --shard, only this shard's share
    /// of them runs.
    #[arg(long, value_name = "N", value_parser = super::limits::scenarios)]
    pub scenarios: u64,
    /// Sweep seed: scenario k of seed S is the same layout and episode seed everywhere.
    #[arg(long, default_value_t = 0, value_name = "S")]
    pub seed: u64,
    /// Worker threads, 1…1024 (default: one per core).
    #[arg(long, short = 'j', value_name = "J", value_parser = super::limits::jobs)]
    pub jobs: Option<u64>,
    /// Inject this fault through physics in every scenario (see docs/faults.md).
    #[arg(long, value_parser = super::limits::fault())]
    pub fault: Option<FaultKind>,
    /// Success means: `scene` = the tree succeeded and the scene's goal holds; `bowl` = the tree
    /// succeeded and the cube rests in the bowl; `tree` = the tree succeeded.
    #[arg(long, value_parser = super::limits::goal(), default_value = "scene")]
    pub goal: Goal,
    /// Contacts that should not happen (the arm, the fingers or the held block on a container,
    /// an obstacle or another block): `count` them (default), or `fail` the episode at the first
    /// one (failure kind `collision`).
    #[arg(long, value_parser = super::limits::collisions(), default_value = "count")]
    pub collisions: crate::episode::CollisionPolicy,
    /// Write one JSON line per scenario here, in scenario order (a regular file or a new path);
    /// the run's times go beside it, to FILE.jsonl.timing.json, for `report`.
    #[arg(long, value_name = "FILE.jsonl")]
    pub out: Option<PathBuf>,
    /// Keep the complete results already in --out (from an interrupted run of this same sweep)
    /// and run only the missing scenarios.
    #[arg(long, requires = "out")]
    pub resume: bool,
    /// Print the summary as one JSON object on stdout (the only thing on stdout; the text for people goes to stderr).
    #[arg(long)]
    pub json: bool,
    /// Run only the scenarios with index ≡ K (mod M), 0 ≤ K < M; `auto` takes K and M from a
    /// Slurm array job (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT) or a Kubernetes Indexed Job
    /// (JOB_COMPLETION_INDEX and --shard-count M); see docs/scale_out.md.
    #[arg(long, value_name = "K/M|auto")]
    pub shard: Option<crate::sweep::ShardSpec>,
    /// M for `--shard auto` in a Kubernetes Indexed Job (its `completions`); with Slurm, a check.
    #[arg(long, value_name = "M", requires = "shard", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub shard_count: Option<u64>,
    /// Replace the leaves whose path matches PATTERN (`main/**/grasp`) with a scripted outcome:
    /// success, failure, running:N or fail_first:N (repeatable; see docs/testing_trees.md).
    #[arg(long = "substitute", value_name = "PATTERN=OUTCOME")]
    pub substitute: Vec<crate::runtime::substitute::Substitution>,
    /// Stop each episode (as a failure) after this much simulated time, seconds (at most 3600).
    #[arg(long, default_value_t = crate::episode::DEFAULT_MAX_SIM_TIME_S, value_name = "S", value_parser = super::limits::max_sim_time)]
    pub max_sim_time: f64,
    /// Write the episodes, in scenario order, as a LeRobot v3.0 dataset in this folder (new or
    /// empty; see docs/datasets.md).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub dataset: Option<PathBuf>,
    /// Cameras of --dataset, comma-separated (`front`, `wrist`, `overview`), or `none` for the
    /// episode data without videos.
    #[arg(
        long,
        value_name = "LIST",
        default_value = "front,wrist",
        requires = "dataset"
    )]
    pub cameras: String,
    /// Frames per second of simulated time of --dataset: a whole number of 4 ms control periods
    /// per frame (1, 2, 5, 10, 25, 50, 125 or 250), so a policy can act at the data's rate.
    #[arg(long, value_name = "N", default_value_t = crate::dataset::DEFAULT_FRAME_RATE, requires = "dataset", value_parser = crate::dataset::parse_frame_rate)]
    pub fps: u32,
    /// Image size of --dataset's cameras, WxH pixels (even, at most 1280x960).
    #[arg(long, value_name = "WxH", default_value = "320x240", requires = "dataset")]
    pub size: crate::render::FrameSize,
    /// Write only the episodes that met the goal into --dataset.
    #[arg(long, requires = "dataset")]
    pub only_success: bool,
    /// Replace the dataset macrotree wrote earlier at --dataset DIR.
    #[arg(long, requires = "dataset")]
    pub overwrite: bool,
    /// Noise added to what --dataset's episodes execute, the recorded actions staying the clean
    /// commands (DART): `JOINT_SIGMA[,GRIPPER_SIGMA]`, radians (at most 0.2) and gripper actuator
    /// units (at most 100), redrawn every 0.1 s from the episode seed (see docs/datasets.md).
    #[arg(long, value_name = "SIGMA[,G]", requires = "dataset", conflicts_with = "out", allow_hyphen_values = true, value_parser = crate::faults::ActionNoise::parse)]
    pub noise: Option<crate::faults::ActionNoise>,
}
