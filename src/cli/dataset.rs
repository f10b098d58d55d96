//! `sweep --dataset DIR`: the sweep's episodes as a LeRobot v3.0 dataset (see
//! [`crate::dataset`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use super::CliError;
use super::sweep_args::SweepArgs;
use crate::actions::Cell;
use crate::dataset::{EpisodeRecorder, Recording};
use crate::plan::Plan;
use crate::render::FrameSize;
use crate::sim::Scene;
use crate::sweep::{ScenarioResult, SweepConfig, run_scenario};

/// What each worker needs to record an episode (shared by the workers).
pub(super) struct DatasetRecorder {
    plan: Arc<Plan>,
    fps: u32,
    size: FrameSize,
    cameras: Vec<usize>,
    clips: PathBuf,
}

impl DatasetRecorder {
    /// Runs scenario `index` in `cell` while recording it.
    pub(super) fn run(
        &self,
        cell: &mut Cell,
        plan: &Arc<Plan>,
        factory: &crate::factory::Factory,
        config: &SweepConfig,
        index: u64,
    ) -> (ScenarioResult, Result<Recording, String>) {
        let mut rec = EpisodeRecorder::new(self.plan.clone(), self.fps);
        let mut start_error = None;
        for (k, &cam) in self.cameras.iter().enumerate() {
            let path = self.clips.join(format!("scenario-{index}-camera-{k}.mp4"));
            match rec.with_camera(cam, self.size, path) {
                Ok(r) => rec = r,
                Err(e) => {
                    start_error = Some(e);
                    rec = EpisodeRecorder::new(self.plan.clone(), self.fps);
                    break;
                }
            }
        }
        let result = run_scenario(cell, plan, factory, config, index, &mut rec);
        let recording = match start_error {
            Some(e) => Err(e),
            None => rec.finish(),
        };
        (result, recording)
    }
}

/// A dataset being written by a sweep.
#[cfg_attr(not(feature = "dataset"), allow(dead_code))]
pub(super) struct SweepDataset {
    #[cfg(feature = "dataset")]
    writer: crate::dataset::DatasetWriter,
    dir: PathBuf,
    fps: u32,
    size: FrameSize,
    cameras: Vec<usize>,
    camera_names: Vec<String>,
    plan: Arc<Plan>,
    renders: u64,
    render_time: Duration,
}

/// Checks the options of `sweep --dataset DIR` (folder, cameras, OpenGL, ffmpeg) and starts the
/// dataset, before any episode runs.
#[cfg_attr(not(feature = "dataset"), allow(unused_variables))]
pub(super) fn start(
    args: &SweepArgs,
    dir: &Path,
    scene: &Scene,
    plan: &Arc<Plan>,
    config: &SweepConfig,
) -> Result<SweepDataset, CliError> {
    #[cfg(not(feature = "dataset"))]
    {
        Err(CliError::Input(
            "error: this macrotree was built without the `dataset` feature; rebuild with the default features to write datasets".into(),
        ))
    }
    #[cfg(feature = "dataset")]
    {
        let input = |e: &dyn std::fmt::Display| CliError::Input(format!("error: {e}"));
        crate::dataset::check_dir(dir, args.overwrite).map_err(|e| input(&e))?;
        let camera_names: Vec<String> = match args.cameras.trim() {
            "none" | "" => Vec::new(),
            list => list.split(',').map(|c| c.trim().to_string()).collect(),
        };
        let mut seen = std::collections::HashSet::new();
        if let Some(dup) = camera_names.iter().find(|c| !seen.insert(c.as_str())) {
            return Err(CliError::Input(format!("error: --cameras names {dup:?} twice")));
        }
        let cameras = crate::render::camera_ids(scene, &camera_names)
            .map_err(|e| CliError::Input(format!("error: --cameras: {e}")))?;
        if !cameras.is_empty() {
            crate::video::find_ffmpeg().map_err(|e| input(&e))?;
            // Fail before simulating when there is no OpenGL.
            crate::render::with_thread_renderer(&scene.model, args.size, |_| ()).map_err(|e| input(&e))?;
        }
        let task = plan
            .description
            .clone()
            .filter(|d| !d.trim().is_empty())
            .unwrap_or_else(|| {
                let name = args
                    .tree
                    .file_stem()
                    .map_or_else(|| plan.file.clone(), |s| s.to_string_lossy().into_owned());
                format!("run the behavior tree {name}")
            });
        let provenance = serde_json::json!({
            "written_by": format!("macrotree {}", env!("CARGO_PKG_VERSION")),
            "tree": args.tree.display().to_string(),
            "scene": scene.spec.name,
            "scene_file": config.scene_file,
            "sweep_seed": config.seed,
            "scenarios": config.scenarios,
            "shard": config.shard.map(|s| s.to_string()),
            "fault": config.fault,
            "action_noise": config.noise.map(|n| serde_json::json!({
                "joint_sigma_rad": n.joint_sigma,
                "gripper_sigma": n.gripper_sigma,
                "hold_s": crate::faults::NOISE_HOLD_S,
                "labels": "the clean commands; the noise is in what was executed",
            })),
            "goal": config.goal,
            "max_sim_time_s": config.max_sim_time,
            "fps": args.fps,
            "size": args.size,
            "cameras": camera_names,
            "only_success": args.only_success,
        });
        let opts = crate::dataset::DatasetOptions {
            fps: args.fps,
            size: args.size,
            cameras: camera_names.clone(),
            task,
            objects: scene.spec.objects.iter().map(|o| o.name.clone()).collect(),
            only_success: args.only_success,
            overwrite: args.overwrite,
            provenance,
        };
        let writer = crate::dataset::DatasetWriter::create(dir, opts).map_err(|e| input(&e))?;
        Ok(SweepDataset {
            writer,
            dir: dir.to_path_buf(),
            fps: args.fps,
            size: args.size,
            cameras,
            camera_names,
            plan: plan.clone(),
            renders: 0,
            render_time: Duration::ZERO,
        })
    }
}

impl SweepDataset {
    /// The recorder the workers use.
    pub(super) fn recorder(&self) -> DatasetRecorder {
        #[cfg(feature = "dataset")]
        let clips = self.writer.clips_dir();
        #[cfg(not(feature = "dataset"))]
        let clips = PathBuf::new();
        DatasetRecorder {
            plan: self.plan.clone(),
            fps: self.fps,
            size: self.size,
            cameras: self.cameras.clone(),
            clips,
        }
    }

    /// Adds the next episode (in scenario order); `None` when the episode panicked.
    #[cfg_attr(not(feature = "dataset"), allow(unused_variables))]
    pub(super) fn add(
        &mut self,
        result: &ScenarioResult,
        recording: Option<Result<Recording, String>>,
    ) -> Result<(), String> {
        let recording = match recording {
            Some(Ok(r)) => r,
            Some(Err(e)) => return Err(format!("scenario {}: recording failed: {e}", result.index)),
            // A panicked episode has no recording; it is left out (the sweep's results show it).
            None => return Ok(()),
        };
        self.renders += recording.renders;
        self.render_time += recording.render_time;
        #[cfg(feature = "dataset")]
        self.writer.add(result, recording).map_err(|e| e.to_string())?;
        Ok(())
    }

    /// Writes the metadata and installs the dataset.
    pub(super) fn finish(self) -> Result<(), CliError> {
        #[cfg(feature = "dataset")]
        {
            let (episodes, frames) = self
                .writer
                .finish()
                .map_err(|e| CliError::Input(format!("error: {e}")))?;
            let cams = if self.camera_names.is_empty() {
                "no cameras".to_string()
            } else {
                format!("cameras {} at {}", self.camera_names.join(", "), self.size)
            };
            let per = self.render_time.as_secs_f64() * 1e3 / self.renders.max(1) as f64;
            eprintln!(
                "dataset written to {}: {episodes} episodes, {frames} frames at {} fps, {cams}{}",
                self.dir.display(),
                self.fps,
                if self.renders > 0 {
                    format!(" ({} images, {per:.1} ms wall each)", self.renders)
                } else {
                    String::new()
                }
            );
        }
        Ok(())
    }
}
