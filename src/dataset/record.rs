//! [`EpisodeRecorder`]: an episode observer that samples the episode at a fixed frame rate —
//! robot state, commanded action, object poses, the running leaf — and renders camera images
//! into video encoders. `run --video`, `run --frames` and `sweep --dataset` use it.
//!
//! Frame k is taken at the start of the first control period at or after `k / fps` seconds:
//! its state is the period's first (frame 0 is the state at reset) and its action the command
//! the cell holds over that period (LeRobot's convention: the action of frame k acts from
//! frame k to frame k + 1). At a frame rate that is a whole number of control periods
//! ([`FRAME_RATES`]) the frames fall on period starts exactly, and a policy acting at that rate
//! in the step-wise environment (`control_period = 1 / fps`) takes the dataset's actions.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::actions::Cell;
use crate::episode::{EpisodeObserver, vectors};
use crate::motion::CellCommand;
use crate::plan::Plan;
use crate::render::{FrameSize, font, with_thread_renderer};
use crate::runtime::TreeRunner;
use crate::video::VideoEncoder;

/// Names of the values of `observation.state`: joint angles, gripper closure, joint
/// velocities, pinch pose. One definition with the environment's observation
/// ([`crate::episode::vectors`]).
pub use crate::episode::vectors::{STATE_LEN, STATE_NAMES};

/// The control rate of every tree, frames per second: one frame per control period.
pub const CONTROL_RATE: u32 = 250;
const _: () = assert!((1.0 / crate::actions::CONTROL_PERIOD) as u32 == CONTROL_RATE);

/// The frame rates a dataset may have: the whole fractions of the [`CONTROL_RATE`], so that a
/// frame is a whole number of control periods (1, 2, 5, 10, 25, 50, 125 and 250 frames per
/// second).
pub const FRAME_RATES: [u32; 8] = [1, 2, 5, 10, 25, 50, 125, 250];
const _: () = {
    let mut i = 0;
    while i < FRAME_RATES.len() {
        assert!(CONTROL_RATE.is_multiple_of(FRAME_RATES[i]));
        i += 1;
    }
};

/// The default frame rate of a dataset, frames per second (20 ms frames: 5 control periods).
pub const DEFAULT_FRAME_RATE: u32 = 50;

/// Parses a dataset's frame rate: one of [`FRAME_RATES`].
pub fn parse_frame_rate(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if FRAME_RATES.contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of 4 ms control periods per frame: one of {} frames per second, got {}",
            FRAME_RATES.map(|r| r.to_string()).join(", "),
            s.chars().take(40).collect::<String>()
        )),
    }
}

/// One sampled frame of an episode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameRecord {
    /// Frame number in the episode, from 0.
    pub frame_index: u64,
    /// The frame's nominal time, `frame_index / fps`, seconds.
    pub timestamp: f64,
    /// Simulated time when it was sampled (the first control tick at or after `timestamp`),
    /// seconds.
    pub sim_time: f64,
    /// The robot's state ([`crate::episode::vectors::state_vector`]): measured arm joint angles
    /// (radians), the gripper's closure (radians), joint velocities (rad/s), the pinch point
    /// (metres) and orientation (qw, qx, qy, qz); names [`STATE_NAMES`].
    #[serde(rename = "observation.state")]
    pub state: [f32; STATE_LEN],
    /// The command held from this frame to the next: joint set points (radians), velocities
    /// (rad/s), accelerations (rad/s²) and the gripper command (0 open … 255 closed)
    /// ([`crate::motion::CellCommand::to_vector`]; names [`crate::motion::COMMAND_NAMES`]).
    pub action: [f32; crate::motion::COMMAND_LEN],
    /// Every scene object's pose, scene order: x, y, z (metres), qw, qx, qy, qz.
    #[serde(rename = "observation.environment_state")]
    pub environment: Vec<f32>,
    /// Path of the running leaf (several joined by ` | `; empty when none runs); the
    /// dataset's `tree.active_leaf` column.
    #[serde(rename = "tree.active_leaf")]
    pub active_leaf: String,
    /// Node kind of the running leaf (`reach`, `grasp`, …; same joining); the dataset's
    /// `tree.active_kind` column.
    #[serde(rename = "tree.active_kind")]
    pub active_kind: String,
}

/// Per-channel histograms of pixel values (R, G, B), for image statistics.
pub type Histogram = Box<[[u64; 256]; 3]>;

/// One camera being recorded.
struct CameraTrack {
    camera: usize,
    encoder: Option<VideoEncoder>,
    path: PathBuf,
    histogram: Histogram,
}

/// A recorded camera: its video file and pixel histogram.
#[derive(Debug)]
pub struct CameraClip {
    /// Model camera id.
    pub camera: usize,
    /// The MP4 written.
    pub path: PathBuf,
    /// Frames in it.
    pub frames: u64,
    /// Per-channel histogram of the pixel values of every other pixel of every other row.
    pub histogram: Histogram,
}

/// Samples an episode at `fps` frames per second of simulated time (see the module docs).
pub struct EpisodeRecorder {
    plan: Arc<Plan>,
    fps: u32,
    next: u64,
    frames: Vec<FrameRecord>,
    size: FrameSize,
    cameras: Vec<CameraTrack>,
    overlay: bool,
    error: Option<String>,
    render_time: Duration,
    render_cpu: f64,
    renders: u64,
}

/// What an [`EpisodeRecorder`] recorded.
#[derive(Debug)]
pub struct Recording {
    /// The sampled frames.
    pub frames: Vec<FrameRecord>,
    /// One clip per camera, in the order asked for.
    pub clips: Vec<CameraClip>,
    /// Wall time spent rendering (copying the pose, drawing, reading pixels back).
    pub render_time: Duration,
    /// CPU time of the whole process while rendering (every thread, including the software
    /// rasterizer's), seconds; the cost of rendering when nothing else runs in the process.
    pub render_cpu_s: f64,
    /// Images rendered.
    pub renders: u64,
}

impl EpisodeRecorder {
    /// A recorder of frames only (no images).
    pub fn new(plan: Arc<Plan>, fps: u32) -> Self {
        Self {
            plan,
            fps: fps.max(1),
            next: 0,
            frames: Vec::new(),
            size: FrameSize {
                width: 16,
                height: 16,
            },
            cameras: Vec::new(),
            overlay: false,
            error: None,
            render_time: Duration::ZERO,
            render_cpu: 0.0,
            renders: 0,
        }
    }

    /// Also renders camera `camera` (model id) at `size` into an H.264 MP4 at `path` (every
    /// camera at the same size).
    pub fn with_camera(mut self, camera: usize, size: FrameSize, path: PathBuf) -> Result<Self, String> {
        self.size = size;
        let encoder = VideoEncoder::start(&path, size, self.fps).map_err(|e| e.to_string())?;
        self.cameras.push(CameraTrack {
            camera,
            encoder: Some(encoder),
            path,
            histogram: Box::new([[0; 256]; 3]),
        });
        Ok(self)
    }

    /// Draws the simulated time and the running leaf on the images.
    pub fn with_overlay(mut self, on: bool) -> Self {
        self.overlay = on;
        self
    }

    /// Finishes the videos; the first error of the episode (rendering, encoding) if any.
    pub fn finish(mut self) -> Result<Recording, String> {
        let mut clips = Vec::new();
        for track in &mut self.cameras {
            let Some(encoder) = track.encoder.take() else {
                continue;
            };
            match encoder.finish() {
                Ok(frames) => clips.push(CameraClip {
                    camera: track.camera,
                    path: track.path.clone(),
                    frames,
                    histogram: std::mem::replace(&mut track.histogram, Box::new([[0; 256]; 3])),
                }),
                Err(e) => {
                    self.error.get_or_insert(e.to_string());
                }
            }
        }
        if let Some(e) = self.error {
            return Err(e);
        }
        Ok(Recording {
            frames: self.frames,
            clips,
            render_time: self.render_time,
            render_cpu_s: self.render_cpu,
            renders: self.renders,
        })
    }

    fn sample(&self, cell: &Cell, command: &CellCommand, runner: &TreeRunner, sim_time: f64) -> FrameRecord {
        // The flat vectors are the environment's observation's: one definition for both.
        let world = cell.world();
        let sim = cell.sim();
        let gripper_joint = sim.gripper_joint();
        let state = vectors::state_vector(&vectors::RobotState::of(world, gripper_joint));
        let action = vectors::command_vector(&command.to_vector());
        let environment = vectors::environment_vector(world);
        let (mut paths, mut kinds) = (Vec::new(), Vec::new());
        for id in runner.running_leaves() {
            if let Some(leaf) = self.plan.leaf(id) {
                paths.push(leaf.path.as_str());
                kinds.push(self.plan.nodes[leaf.node].kind);
            }
        }
        FrameRecord {
            frame_index: self.next,
            timestamp: self.next as f64 / self.fps as f64,
            sim_time,
            state,
            action,
            environment,
            active_leaf: paths.join(" | "),
            active_kind: kinds.join(" | "),
        }
    }

    fn render(&mut self, cell: &Cell, record: &FrameRecord) -> Result<(), String> {
        let start = Instant::now();
        let cpu = crate::render::process_cpu_time();
        let model = &cell.sim().scene().model;
        let size = self.size;
        let scale = if size.width >= 640 { 2 } else { 1 };
        let overlay = self.overlay.then(|| {
            let leaf = if record.active_leaf.is_empty() {
                "(no leaf running)".to_string()
            } else {
                font::fit_tail(&record.active_leaf, size.width as usize, scale)
            };
            vec![
                format!("t = {:.2} s  {}", record.sim_time, record.active_kind),
                leaf,
            ]
        });
        let tracks = &mut self.cameras;
        let renders = &mut self.renders;
        with_thread_renderer(model, size, |r| -> Result<(), String> {
            r.sync(cell.sim().data());
            for track in tracks.iter_mut() {
                let rgb = r.render(track.camera).map_err(|e| e.to_string())?;
                *renders += 1;
                let (w, h) = (size.width as usize, size.height as usize);
                for y in (0..h).step_by(2) {
                    for px in rgb[y * w * 3..(y + 1) * w * 3].chunks_exact(6) {
                        track.histogram[0][px[0] as usize] += 1;
                        track.histogram[1][px[1] as usize] += 1;
                        track.histogram[2][px[2] as usize] += 1;
                    }
                }
                let encoder = track.encoder.as_mut().expect("open while recording");
                match &overlay {
                    Some(lines) => {
                        let mut img = rgb.to_vec();
                        font::draw_banner(&mut img, w, h, lines, scale);
                        encoder.push(&img)
                    }
                    None => encoder.push(rgb),
                }
                .map_err(|e| e.to_string())?;
            }
            Ok(())
        })
        .map_err(|e| e.to_string())??;
        self.render_time += start.elapsed();
        self.render_cpu += crate::render::process_cpu_time() - cpu;
        Ok(())
    }
}

impl EpisodeObserver for EpisodeRecorder {
    fn on_period_start(&mut self, cell: &Cell, command: &CellCommand, runner: &mut TreeRunner) {
        if self.error.is_some() {
            return;
        }
        let t = cell.world().time;
        // Frame k is sampled at the start of the first control period at or after k / fps.
        if t + 1e-9 < self.next as f64 / self.fps as f64 {
            return;
        }
        let record = self.sample(cell, command, runner, t);
        if !self.cameras.is_empty()
            && let Err(e) = self.render(cell, &record)
        {
            self.error = Some(e);
            return;
        }
        self.frames.push(record);
        self.next += 1;
    }
}
