//! Episode → one self-contained HTML replay: the scene as in the live view, then a single
//! `set_animation` with a position and a quaternion track per moving body, sampled at a fixed
//! rate of sim time (float32, `times` + `values` form).

use std::path::Path;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use rmpv::Value;
use serde_json::json;
use tungstenite::Bytes;

use super::panel::TreeNodeView;
use super::proto::{self, map, s};
use super::scene::SceneLayout;
use super::{initial_tree, page};
use crate::output::OutputFile;

/// Default sampling rate of a recording, frames per second of sim time.
pub const DEFAULT_FPS: f64 = 30.0;

/// One recorded sample: sim time and, per drawn body, position and xyzw quaternion.
#[derive(Debug, Clone)]
struct Sample {
    time: f64,
    poses: Vec<([f32; 3], [f32; 4])>,
}

/// Records an episode into one self-contained HTML file (viewer inlined, scene, animation with
/// play/pause/scrub, and the tree status timeline when given).
#[derive(Debug)]
pub struct Recorder {
    layout: SceneLayout,
    /// Body ids that carry drawn geoms (the recorded ones), in order.
    bodies: Vec<usize>,
    fps: f64,
    samples: Vec<Sample>,
    /// The latest frame offered, written at the end if it falls between two samples.
    last: Option<Sample>,
    next_time: f64,
    tree: Option<Vec<TreeNodeView>>,
    timeline: Vec<serde_json::Value>,
    last_statuses: Vec<&'static str>,
}

impl Recorder {
    /// A recorder sampling at `DEFAULT_FPS`.
    pub fn new(model: &MjModel) -> Self {
        Self::with_fps(model, DEFAULT_FPS)
    }

    /// A recorder sampling at `fps` frames per second of sim time.
    pub fn with_fps(model: &MjModel, fps: f64) -> Self {
        let layout = SceneLayout::new(model);
        let bodies = (0..layout.body_paths.len())
            .filter(|&b| layout.body_drawn[b])
            .collect();
        Self {
            layout,
            bodies,
            fps: if fps > 0.0 { fps } else { DEFAULT_FPS },
            samples: Vec::new(),
            last: None,
            next_time: f64::NEG_INFINITY,
            tree: None,
            timeline: Vec::new(),
            last_statuses: Vec::new(),
        }
    }

    /// Offers the state at `sim_time`; kept when it reaches the next sample time (call it every
    /// step or at any rate: it subsamples). A time going backwards starts nothing new: such
    /// frames are ignored until time passes the last sample.
    pub fn frame<M: ModelType>(&mut self, data: &MjData<M>, sim_time: f64) {
        let xpos = data.xpos();
        let xquat = data.xquat();
        let poses = self
            .bodies
            .iter()
            .map(|&b| {
                let p = xpos[b];
                let q = xquat[b];
                (
                    [p[0] as f32, p[1] as f32, p[2] as f32],
                    [q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32],
                )
            })
            .collect();
        let sample = Sample {
            time: sim_time,
            poses,
        };
        if sim_time + 1e-9 >= self.next_time {
            self.next_time = ((sim_time * self.fps).floor() + 1.0) / self.fps;
            self.samples.push(sample);
            self.last = None;
        } else if self.samples.last().is_some_and(|l| sim_time > l.time) {
            self.last = Some(sample);
        }
    }

    /// Number of samples kept so far.
    pub fn len(&self) -> usize {
        self.samples.len() + usize::from(self.last.is_some())
    }

    /// Whether no frame was recorded.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The tree's node list for the replay's side panel.
    pub fn set_tree(&mut self, nodes: Vec<TreeNodeView>) {
        self.last_statuses = vec!["idle"; nodes.len()];
        self.tree = Some(nodes);
    }

    /// Node statuses (by preorder index) and trace events at `sim_time`; only changes are kept.
    pub fn tree_status(
        &mut self,
        sim_time: f64,
        statuses: Vec<&'static str>,
        events: Vec<serde_json::Value>,
    ) {
        self.tree_status_with_attempts(sim_time, statuses, None, events);
    }

    /// Like [`tree_status`](Self::tree_status), with the loop counters (retry attempts, repeat
    /// runs, `for_each` iterations by preorder index) when they changed.
    pub fn tree_status_with_attempts(
        &mut self,
        sim_time: f64,
        statuses: Vec<&'static str>,
        attempts: Option<Vec<u32>>,
        events: Vec<serde_json::Value>,
    ) {
        if statuses == self.last_statuses && events.is_empty() && attempts.is_none() {
            return;
        }
        let mut entry = json!({ "t": sim_time, "statuses": statuses, "events": events });
        if let Some(a) = attempts {
            entry["attempts"] = json!(a);
        }
        self.timeline.push(entry);
        self.last_statuses = statuses;
    }

    fn all_samples(&self) -> Vec<&Sample> {
        self.samples.iter().chain(self.last.iter()).collect()
    }

    /// The MeshCat commands of the replay: scene, initial body poses, then the animation.
    pub fn commands(&self) -> Vec<Bytes> {
        let mut tree = initial_tree(&self.layout);
        let samples = self.all_samples();
        let Some(first) = samples.first() else {
            return tree.snapshot();
        };
        let mut animations = Vec::new();
        for (i, &body) in self.bodies.iter().enumerate() {
            let path = &self.layout.body_paths[body];
            let (p0, q0) = first.poses[i];
            let quat_wxyz = [
                f64::from(q0[3]),
                f64::from(q0[0]),
                f64::from(q0[1]),
                f64::from(q0[2]),
            ];
            let pos = [f64::from(p0[0]), f64::from(p0[1]), f64::from(p0[2])];
            let m = proto::mat_from_pos_quat(pos, quat_wxyz);
            tree.set_transform(path, proto::encode(&proto::set_transform(path, &m)));
            let moves = samples.iter().any(|smp| smp.poses[i] != first.poses[i]);
            if !moves || samples.len() < 2 {
                continue;
            }
            let mut times = Vec::with_capacity(samples.len());
            let mut positions = Vec::with_capacity(samples.len() * 3);
            let mut quats = Vec::with_capacity(samples.len() * 4);
            let mut prev: Option<[f32; 4]> = None;
            for smp in &samples {
                let (p, mut q) = smp.poses[i];
                if let Some(pq) = prev {
                    let dot: f32 = (0..4).map(|k| pq[k] * q[k]).sum();
                    if dot < 0.0 {
                        q = q.map(|v| -v);
                    }
                }
                prev = Some(q);
                times.push(((smp.time - first.time) * self.fps) as f32);
                positions.extend_from_slice(&p);
                quats.extend_from_slice(&q);
            }
            let track = |name: &str, ty: &str, values: &[f32]| {
                map(vec![
                    ("name", s(name)),
                    ("type", s(ty)),
                    ("times", proto::f32_ext(&times)),
                    ("values", proto::f32_ext(values)),
                ])
            };
            animations.push(map(vec![
                ("path", s(path)),
                (
                    "clip",
                    map(vec![
                        ("fps", Value::F64(self.fps)),
                        ("name", s("default")),
                        (
                            "tracks",
                            Value::Array(vec![
                                track(".position", "vector3", &positions),
                                track(".quaternion", "quaternion", &quats),
                            ]),
                        ),
                    ]),
                ),
            ]));
        }
        if !animations.is_empty() {
            let options = map(vec![
                ("play", Value::Boolean(true)),
                ("loopMode", Value::from(2200)),
                ("repetitions", Value::from(1)),
                ("clampWhenFinished", Value::Boolean(true)),
            ]);
            tree.set_animation(proto::encode(&proto::set_animation(animations, options)));
        }
        tree.snapshot()
    }

    /// Metadata handed to the replay page: duration, fps, tree and status timeline.
    fn meta(&self) -> serde_json::Value {
        let samples = self.all_samples();
        let (t0, t1) = match (samples.first(), samples.last()) {
            (Some(a), Some(b)) => (a.time, b.time),
            _ => (0.0, 0.0),
        };
        json!({
            "fps": self.fps,
            "start": t0,
            "duration": t1 - t0,
            "frames": samples.len(),
            "tree": self.tree,
            "timeline": self.timeline,
        })
    }

    /// The replay page as a string.
    pub fn html(&self, bundle: &[u8]) -> String {
        page::standalone_html(bundle, &self.commands(), Some(&self.meta()))
    }

    /// Writes the replay HTML to `path` (checked, then written safely and atomically, see
    /// [`crate::output`]). Fails with `NotFound` and a message naming tools/bootstrap when the
    /// viewer bundle is missing; any other error's message is complete (it names the file).
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        self.write_to(&OutputFile::check(path, &[]).map_err(std::io::Error::other)?)
    }

    /// Writes the replay HTML to an output checked earlier, like [`write`](Self::write).
    pub fn write_to(&self, out: &OutputFile) -> std::io::Result<()> {
        let bundle = page::load_bundle()
            .map_err(|p| std::io::Error::new(std::io::ErrorKind::NotFound, page::bundle_help(&p)))?;
        out.write_all(self.html(&bundle).as_bytes())
            .map_err(std::io::Error::other)
    }
}
