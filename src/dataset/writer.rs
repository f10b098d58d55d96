//! [`DatasetWriter`]: episodes, in scenario order, into a LeRobot v3.0 dataset folder.
//!
//! Everything is written into a new staging folder next to `DIR` (`.DIR.<random>.partial`)
//! and renamed to `DIR` when complete, so an interrupted sweep never leaves half a dataset at
//! `DIR`. `DIR` itself must be missing, an empty folder, or (with `--overwrite`) a dataset that
//! macrotree wrote (it has `meta/macrotree.json`); a symbolic link is never followed.

use std::fs::File;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::record::{FrameRecord, Recording, STATE_LEN, STATE_NAMES};
use super::stats::{QUANTILES, VecStats, image_stats_json};
use super::table::{Column, ParquetFile, Table};
use crate::episode::vectors::VALUES_PER_OBJECT;
use crate::motion::{COMMAND_LEN, COMMAND_NAMES};
use crate::render::FrameSize;
use crate::sweep::ScenarioResult;

/// The LeRobot dataset format version written.
pub const CODEBASE_VERSION: &str = "v3.0";
/// Files per chunk folder (LeRobot's default).
pub const CHUNKS_SIZE: u64 = 1000;
/// A data file is closed once its rows take about this many MiB (LeRobot's default).
pub const DATA_FILE_MB: u64 = 100;
/// `robot_type` in `meta/info.json`.
pub const ROBOT_TYPE: &str = "ur5e_robotiq_2f85";
/// The staging folder's subfolder for clips being recorded.
const CLIPS: &str = ".clips";

/// The marker file that says a folder is a dataset macrotree wrote.
pub const MARKER: &str = "meta/macrotree.json";

/// What to write.
#[derive(Debug, Clone)]
pub struct DatasetOptions {
    /// Frames per second of simulated time.
    pub fps: u32,
    /// Image size of every camera.
    pub size: FrameSize,
    /// Camera names (each becomes `observation.images.<name>`).
    pub cameras: Vec<String>,
    /// The task string (the tree's description).
    pub task: String,
    /// Names of the scene's objects, scene order (for `observation.environment_state`).
    pub objects: Vec<String>,
    /// Write only the episodes that met the goal.
    pub only_success: bool,
    /// Replace a dataset macrotree wrote at `DIR`.
    pub overwrite: bool,
    /// Provenance kept in `meta/macrotree.json` (tree, scene, sweep seed, …).
    pub provenance: Value,
}

/// Why a dataset could not be written. Its `Display` says what and what to do.
#[derive(Debug)]
pub struct DatasetError(pub String);

impl std::fmt::Display for DatasetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DatasetError {}

fn io_err(what: impl std::fmt::Display) -> impl FnOnce(std::io::Error) -> DatasetError {
    move |e| DatasetError(format!("{what}: {e}"))
}

fn pq_err(what: impl std::fmt::Display) -> impl FnOnce(parquet::errors::ParquetError) -> DatasetError {
    move |e| DatasetError(format!("{what}: {e}"))
}

/// The file `chunk-CCC/file-FFF` of `(chunk, file)`.
fn chunk_file(index: u64) -> (u64, u64) {
    (index / CHUNKS_SIZE, index % CHUNKS_SIZE)
}

fn chunk_path(prefix: &str, (chunk, file): (u64, u64), ext: &str) -> String {
    format!("{prefix}/chunk-{chunk:03}/file-{file:03}.{ext}")
}

/// The `observation.images.<camera>` key of a camera.
pub fn video_key(camera: &str) -> String {
    format!("observation.images.{camera}")
}

/// Checks that `dir` may receive a dataset (see the module docs), before any episode runs.
pub fn check_dir(dir: &Path, overwrite: bool) -> Result<(), DatasetError> {
    let name = dir
        .file_name()
        .filter(|_| !dir.as_os_str().as_encoded_bytes().ends_with(b"/.."));
    if name.is_none() {
        return Err(DatasetError(format!(
            "{:?} is not a folder path a dataset can be written to; name the folder, e.g. ds/",
            dir.display().to_string()
        )));
    }
    let parent = parent_of(dir);
    if !std::fs::metadata(&parent).is_ok_and(|m| m.is_dir()) {
        return Err(DatasetError(format!(
            "cannot write the dataset {}: the folder {} does not exist (create it first)",
            dir.display(),
            parent.display()
        )));
    }
    match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(DatasetError(format!("cannot inspect {}: {e}", dir.display()))),
        Ok(m) if m.file_type().is_symlink() => Err(DatasetError(format!(
            "refusing to write the dataset {}: it is a symbolic link (never followed); name a new folder",
            dir.display()
        ))),
        Ok(m) if !m.is_dir() => Err(DatasetError(format!(
            "refusing to write the dataset {}: it exists and is not a folder",
            dir.display()
        ))),
        Ok(_) => {
            let empty = std::fs::read_dir(dir)
                .map_err(io_err(format!("cannot list {}", dir.display())))?
                .next()
                .is_none();
            let ours = std::fs::symlink_metadata(dir.join(MARKER)).is_ok_and(|m| m.is_file())
                && std::fs::symlink_metadata(dir.join("meta")).is_ok_and(|m| m.is_dir());
            if empty || (ours && overwrite) {
                Ok(())
            } else if ours {
                Err(DatasetError(format!(
                    "the folder {} already holds a dataset; add --overwrite to replace it, or name a new folder",
                    dir.display()
                )))
            } else {
                Err(DatasetError(format!(
                    "refusing to write the dataset into {}: the folder is not empty and is not a dataset macrotree wrote; name a new or empty folder",
                    dir.display()
                )))
            }
        }
    }
}

fn parent_of(dir: &Path) -> PathBuf {
    match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Per-episode bookkeeping for `meta/episodes`.
struct EpisodeMeta {
    length: u64,
    from: u64,
    data_file: (u64, u64),
    videos: Vec<((u64, u64), f64)>,
    stats: Vec<(String, VecStats)>,
    scenario: u64,
    seed: u64,
    success: bool,
}

/// Writes a LeRobot v3.0 dataset (see the module docs).
pub struct DatasetWriter {
    dir: PathBuf,
    stage: PathBuf,
    opts: DatasetOptions,
    data: Option<(ParquetFile, u64)>,
    data_index: u64,
    data_rows: u64,
    row_bytes: u64,
    episodes: Vec<EpisodeMeta>,
    frames: u64,
    histograms: Vec<[[u64; 256]; 3]>,
    finished: bool,
    /// The staging folder, open and locked while this writer lives (a later run reclaims it
    /// only when the lock is free), and registered for removal on a signal.
    _stage_lock: Option<std::fs::File>,
    _registered: crate::cleanup::Registered,
}

impl DatasetWriter {
    /// Starts a dataset for `dir` (checked with [`check_dir`]) in a new staging folder.
    pub fn create(dir: &Path, opts: DatasetOptions) -> Result<Self, DatasetError> {
        check_dir(dir, opts.overwrite)?;
        let parent = parent_of(dir);
        let name = dir.file_name().expect("checked").to_string_lossy().into_owned();
        // Staging folders of this dataset left by a process that is gone.
        crate::cleanup::reclaim(
            &parent,
            std::ffi::OsStr::new(&format!(".{name}.")),
            ".partial",
            true,
        );
        let stage = parent.join(format!(".{name}.{:016x}.partial", random_u64()));
        std::fs::create_dir(&stage).map_err(io_err(format!("cannot create {}", stage.display())))?;
        let registered = crate::cleanup::register(&stage, true);
        let stage_lock = std::fs::File::open(&stage).ok().filter(crate::cleanup::try_lock);
        std::fs::create_dir(stage.join(CLIPS))
            .map_err(io_err(format!("cannot create a folder in {}", stage.display())))?;
        let row_bytes = 8 * 5
            + 4 * ((STATE_LEN + COMMAND_LEN) as u64 + (VALUES_PER_OBJECT * opts.objects.len()) as u64)
            + 64;
        let cams = opts.cameras.len();
        Ok(Self {
            dir: dir.to_path_buf(),
            stage,
            opts,
            data: None,
            data_index: 0,
            data_rows: 0,
            row_bytes,
            episodes: Vec::new(),
            frames: 0,
            histograms: vec![[[0; 256]; 3]; cams],
            finished: false,
            _stage_lock: stage_lock,
            _registered: registered,
        })
    }

    /// The folder where recorders write their clips ([`add`](Self::add) moves them into the
    /// dataset; it is removed before the dataset is installed).
    pub fn clips_dir(&self) -> PathBuf {
        self.stage.join(CLIPS)
    }

    /// Episodes written so far.
    pub fn episodes(&self) -> u64 {
        self.episodes.len() as u64
    }

    /// Adds the episode of `result` (the next scenario in order) from its `recording`; returns
    /// whether it was written (with `only_success`, failed episodes are not). Its clips are moved
    /// into the dataset or removed.
    pub fn add(&mut self, result: &ScenarioResult, recording: Recording) -> Result<bool, DatasetError> {
        let keep = !self.opts.only_success || result.outcome.success;
        if !keep || recording.frames.is_empty() {
            for clip in &recording.clips {
                let _ = std::fs::remove_file(&clip.path);
            }
            return Ok(false);
        }
        let episode = self.episodes.len() as u64;
        let frames = &recording.frames;
        let n = frames.len() as u64;
        if recording.clips.len() != self.opts.cameras.len() || recording.clips.iter().any(|c| c.frames != n) {
            return Err(DatasetError(format!(
                "episode of scenario {}: {} frames but the videos have {:?} (cameras {:?})",
                result.index,
                n,
                recording.clips.iter().map(|c| c.frames).collect::<Vec<_>>(),
                self.opts.cameras
            )));
        }
        // Data rows.
        let table = self.data_table(frames, episode);
        if self.data.is_some() && self.data_rows * self.row_bytes > DATA_FILE_MB << 20 {
            self.close_data()?;
            self.data_index += 1;
        }
        let data_file = chunk_file(self.data_index);
        if self.data.is_none() {
            let rel = chunk_path("data", data_file, "parquet");
            let file = self.create_file(&rel)?;
            let pq = ParquetFile::create(file, &table, vec![("huggingface".into(), self.hf_metadata())])
                .map_err(pq_err(format!("writing {rel}")))?;
            self.data = Some((pq, self.data_index));
            self.data_rows = 0;
        }
        let (pq, _) = self.data.as_mut().expect("opened above");
        pq.write(&table).map_err(pq_err("writing the data rows"))?;
        self.data_rows += n;
        // Videos: one file per episode and camera.
        let mut videos = Vec::new();
        for (k, clip) in recording.clips.iter().enumerate() {
            let rel = chunk_path(
                &format!("videos/{}", video_key(&self.opts.cameras[k])),
                chunk_file(episode),
                "mp4",
            );
            let dest = self.stage.join(&rel);
            std::fs::create_dir_all(dest.parent().expect("has a folder"))
                .map_err(io_err(format!("cannot create the folder of {rel}")))?;
            // Only the file the encoder created goes in: never a link planted in its place.
            let planted = std::fs::symlink_metadata(&clip.path)
                .map(|m| !m.file_type().is_file() || std::os::unix::fs::MetadataExt::nlink(&m) != 1)
                .unwrap_or(true);
            if planted {
                return Err(DatasetError(format!(
                    "the clip {} is not the regular file the encoder wrote (a link or another \
                     file was put in its place); the dataset was not written",
                    clip.path.display()
                )));
            }
            std::fs::rename(&clip.path, &dest)
                .map_err(io_err(format!("cannot move the video into {rel}")))?;
            for c in 0..3 {
                for v in 0..256 {
                    self.histograms[k][c][v] += clip.histogram[c][v];
                }
            }
            videos.push((chunk_file(episode), n as f64 / self.opts.fps as f64));
        }
        // Statistics of this episode.
        let col = |f: &dyn Fn(&FrameRecord) -> Vec<f64>| frames.iter().map(f).collect::<Vec<_>>();
        let mut stats = vec![
            (
                "observation.state".to_string(),
                VecStats::of(&col(&|r| r.state.iter().map(|&v| v as f64).collect())),
            ),
            (
                "action".to_string(),
                VecStats::of(&col(&|r| r.action.iter().map(|&v| v as f64).collect())),
            ),
        ];
        if !self.opts.objects.is_empty() {
            stats.push((
                "observation.environment_state".to_string(),
                VecStats::of(&col(&|r| r.environment.iter().map(|&v| v as f64).collect())),
            ));
        }
        let from = self.frames;
        stats.extend([
            (
                "timestamp".to_string(),
                VecStats::of(&col(&|r| vec![(r.timestamp as f32) as f64])),
            ),
            (
                "frame_index".to_string(),
                VecStats::of(&col(&|r| vec![r.frame_index as f64])),
            ),
            (
                "episode_index".to_string(),
                VecStats::of(&col(&|_| vec![episode as f64])),
            ),
            (
                "index".to_string(),
                VecStats::of(&col(&|r| vec![(from + r.frame_index) as f64])),
            ),
            ("task_index".to_string(), VecStats::of(&col(&|_| vec![0.0]))),
        ]);
        self.episodes.push(EpisodeMeta {
            length: n,
            from,
            data_file,
            videos,
            stats,
            scenario: result.index,
            seed: result.seed,
            success: result.outcome.success,
        });
        self.frames += n;
        Ok(true)
    }

    fn data_table(&self, frames: &[FrameRecord], episode: u64) -> Table {
        let mut t = Table::default();
        let flat =
            |f: &dyn Fn(&FrameRecord) -> &[f32]| frames.iter().flat_map(|r| f(r).iter().copied()).collect();
        t.push(
            "observation.state",
            Column::ListF32 {
                values: flat(&|r| &r.state),
                width: STATE_LEN,
            },
        );
        t.push(
            "action",
            Column::ListF32 {
                values: flat(&|r| &r.action),
                width: COMMAND_LEN,
            },
        );
        if !self.opts.objects.is_empty() {
            t.push(
                "observation.environment_state",
                Column::ListF32 {
                    values: flat(&|r| &r.environment),
                    width: VALUES_PER_OBJECT * self.opts.objects.len(),
                },
            );
        }
        t.push(
            "tree.active_leaf",
            Column::Str(frames.iter().map(|r| r.active_leaf.clone()).collect()),
        );
        t.push(
            "tree.active_kind",
            Column::Str(frames.iter().map(|r| r.active_kind.clone()).collect()),
        );
        t.push(
            "timestamp",
            Column::F32(frames.iter().map(|r| r.timestamp as f32).collect()),
        );
        t.push(
            "frame_index",
            Column::I64(frames.iter().map(|r| r.frame_index as i64).collect()),
        );
        t.push("episode_index", Column::I64(vec![episode as i64; frames.len()]));
        t.push(
            "index",
            Column::I64(
                frames
                    .iter()
                    .map(|r| (self.frames + r.frame_index) as i64)
                    .collect(),
            ),
        );
        t.push("task_index", Column::I64(vec![0; frames.len()]));
        t
    }

    /// `meta/info.json`'s `features`.
    fn features(&self) -> Value {
        let mut f = serde_json::Map::new();
        let names: Vec<&str> = STATE_NAMES.to_vec();
        f.insert(
            "observation.state".into(),
            json!({"dtype": "float32", "shape": [STATE_LEN], "names": names}),
        );
        f.insert(
            "action".into(),
            json!({"dtype": "float32", "shape": [COMMAND_LEN], "names": COMMAND_NAMES.to_vec()}),
        );
        if !self.opts.objects.is_empty() {
            let env: Vec<String> = self
                .opts
                .objects
                .iter()
                .flat_map(|o| ["x", "y", "z", "qw", "qx", "qy", "qz"].map(|c| format!("{o}.{c}")))
                .collect();
            f.insert(
                "observation.environment_state".into(),
                json!({"dtype": "float32", "shape": [env.len()], "names": env}),
            );
        }
        let s = self.opts.size;
        for cam in &self.opts.cameras {
            f.insert(
                video_key(cam),
                json!({
                    "dtype": "video",
                    "shape": [s.height, s.width, 3],
                    "names": ["height", "width", "channels"],
                    "info": {
                        "video.height": s.height,
                        "video.width": s.width,
                        "video.codec": "h264",
                        "video.pix_fmt": "yuv420p",
                        "video.fps": self.opts.fps,
                        "video.channels": 3,
                        "has_audio": false,
                        "video.g": 2 * self.opts.fps,
                        "video.crf": 23,
                        "video.preset": "veryfast",
                        "is_depth_map": false
                    }
                }),
            );
        }
        f.insert(
            "tree.active_leaf".into(),
            json!({"dtype": "string", "shape": [1], "names": null}),
        );
        f.insert(
            "tree.active_kind".into(),
            json!({"dtype": "string", "shape": [1], "names": null}),
        );
        f.insert(
            "timestamp".into(),
            json!({"dtype": "float32", "shape": [1], "names": null}),
        );
        for k in ["frame_index", "episode_index", "index", "task_index"] {
            f.insert(k.into(), json!({"dtype": "int64", "shape": [1], "names": null}));
        }
        Value::Object(f)
    }

    /// The `huggingface` key–value metadata of the data files: the columns as `datasets`
    /// features.
    fn hf_metadata(&self) -> String {
        let list = |n: usize| json!({"feature": {"dtype": "float32", "_type": "Value"}, "length": n, "_type": "List"});
        let value = |d: &str| json!({"dtype": d, "_type": "Value"});
        let mut f = serde_json::Map::new();
        f.insert("observation.state".into(), list(STATE_LEN));
        f.insert("action".into(), list(COMMAND_LEN));
        if !self.opts.objects.is_empty() {
            f.insert(
                "observation.environment_state".into(),
                list(VALUES_PER_OBJECT * self.opts.objects.len()),
            );
        }
        f.insert("tree.active_leaf".into(), value("string"));
        f.insert("tree.active_kind".into(), value("string"));
        f.insert("timestamp".into(), value("float32"));
        for k in ["frame_index", "episode_index", "index", "task_index"] {
            f.insert(k.into(), value("int64"));
        }
        json!({"info": {"features": f}}).to_string()
    }

    fn create_file(&self, rel: &str) -> Result<File, DatasetError> {
        let path = self.stage.join(rel);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(io_err(format!("cannot create the folder of {rel}")))?;
        }
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(io_err(format!("cannot create {rel}")))
    }

    fn write_json(&self, rel: &str, v: &Value) -> Result<(), DatasetError> {
        let mut f = self.create_file(rel)?;
        let mut text = serde_json::to_string_pretty(v).expect("JSON serializes");
        text.push('\n');
        f.write_all(text.as_bytes())
            .and_then(|_| f.sync_all())
            .map_err(io_err(format!("writing {rel}")))
    }

    fn close_data(&mut self) -> Result<(), DatasetError> {
        if let Some((pq, _)) = self.data.take() {
            let f = pq.finish().map_err(pq_err("finishing a data file"))?;
            f.sync_all().map_err(io_err("flushing a data file"))?;
        }
        Ok(())
    }

    /// Writes the metadata and installs the dataset at `DIR`; returns the number of episodes
    /// and frames.
    pub fn finish(mut self) -> Result<(u64, u64), DatasetError> {
        if self.episodes.is_empty() {
            return Err(DatasetError(
                "no episode to write (with --only-success: none succeeded); the dataset was not written"
                    .into(),
            ));
        }
        self.close_data()?;
        self.write_episodes()?;
        self.write_tasks()?;
        self.write_json("meta/stats.json", &self.stats_json())?;
        let total = self.episodes.len() as u64;
        let info = json!({
            "codebase_version": CODEBASE_VERSION,
            "robot_type": ROBOT_TYPE,
            "total_episodes": total,
            "total_frames": self.frames,
            "total_tasks": 1,
            "chunks_size": CHUNKS_SIZE,
            "data_files_size_in_mb": DATA_FILE_MB,
            "video_files_size_in_mb": 200,
            "fps": self.opts.fps,
            "splits": {"train": format!("0:{total}")},
            "data_path": "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet",
            "video_path": if self.opts.cameras.is_empty() { Value::Null } else {
                json!("videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4")
            },
            "features": self.features(),
        });
        self.write_json("meta/info.json", &info)?;
        let episodes: Vec<Value> = self
            .episodes
            .iter()
            .enumerate()
            .map(|(i, e)| json!({"episode_index": i, "scenario": e.scenario, "seed": e.seed, "success": e.success, "length": e.length}))
            .collect();
        let mut provenance = self.opts.provenance.clone();
        provenance["episodes"] = Value::Array(episodes);
        self.write_json(MARKER, &provenance)?;
        std::fs::remove_dir_all(self.stage.join(CLIPS)).map_err(io_err("cannot remove the clips folder"))?;
        self.install()?;
        self.finished = true;
        Ok((self.episodes.len() as u64, self.frames))
    }

    fn write_episodes(&self) -> Result<(), DatasetError> {
        let eps = &self.episodes;
        let i64s = |f: &dyn Fn(usize, &EpisodeMeta) -> i64| {
            Column::I64(eps.iter().enumerate().map(|(i, e)| f(i, e)).collect())
        };
        let mut t = Table::default();
        t.push("episode_index", i64s(&|i, _| i as i64));
        t.push(
            "tasks",
            Column::ListStr {
                values: vec![self.opts.task.clone(); eps.len()],
                width: 1,
            },
        );
        t.push("length", i64s(&|_, e| e.length as i64));
        t.push("data/chunk_index", i64s(&|_, e| e.data_file.0 as i64));
        t.push("data/file_index", i64s(&|_, e| e.data_file.1 as i64));
        t.push("dataset_from_index", i64s(&|_, e| e.from as i64));
        t.push("dataset_to_index", i64s(&|_, e| (e.from + e.length) as i64));
        for (k, cam) in self.opts.cameras.iter().enumerate() {
            let key = video_key(cam);
            t.push(
                &format!("videos/{key}/chunk_index"),
                i64s(&|_, e| e.videos[k].0.0 as i64),
            );
            t.push(
                &format!("videos/{key}/file_index"),
                i64s(&|_, e| e.videos[k].0.1 as i64),
            );
            t.push(
                &format!("videos/{key}/from_timestamp"),
                Column::F64(vec![0.0; eps.len()]),
            );
            t.push(
                &format!("videos/{key}/to_timestamp"),
                Column::F64(eps.iter().map(|e| e.videos[k].1).collect()),
            );
        }
        let names: Vec<String> = eps[0].stats.iter().map(|(n, _)| n.clone()).collect();
        for (s, name) in names.iter().enumerate() {
            let width = eps[0].stats[s].1.mean.len();
            let list = |f: &dyn Fn(&VecStats) -> &Vec<f64>| Column::ListF64 {
                values: eps
                    .iter()
                    .flat_map(|e| f(&e.stats[s].1).iter().copied())
                    .collect(),
                width,
            };
            t.push(&format!("stats/{name}/min"), list(&|v| &v.min));
            t.push(&format!("stats/{name}/max"), list(&|v| &v.max));
            t.push(&format!("stats/{name}/mean"), list(&|v| &v.mean));
            t.push(&format!("stats/{name}/std"), list(&|v| &v.std));
            t.push(
                &format!("stats/{name}/count"),
                Column::ListI64 {
                    values: eps.iter().map(|e| e.stats[s].1.count as i64).collect(),
                    width: 1,
                },
            );
            for (k, (q, _)) in QUANTILES.iter().enumerate() {
                t.push(&format!("stats/{name}/{q}"), list(&|v| &v.quantiles[k]));
            }
        }
        t.push("meta/episodes/chunk_index", Column::I64(vec![0; eps.len()]));
        t.push("meta/episodes/file_index", Column::I64(vec![0; eps.len()]));
        t.push("macrotree/scenario_index", i64s(&|_, e| e.scenario as i64));
        t.push("macrotree/seed", i64s(&|_, e| e.seed as i64));
        t.push("macrotree/success", i64s(&|_, e| e.success as i64));
        let rel = chunk_path("meta/episodes", (0, 0), "parquet");
        let mut pq = ParquetFile::create(self.create_file(&rel)?, &t, Vec::new())
            .map_err(pq_err(format!("writing {rel}")))?;
        pq.write(&t).map_err(pq_err(format!("writing {rel}")))?;
        pq.finish()
            .map_err(pq_err(format!("writing {rel}")))?
            .sync_all()
            .map_err(io_err(format!("writing {rel}")))
    }

    fn write_tasks(&self) -> Result<(), DatasetError> {
        let mut t = Table::default();
        t.push("task_index", Column::I64(vec![0]));
        t.push("task", Column::Str(vec![self.opts.task.clone()]));
        // pandas reads the `task` column back as the frame's index, as LeRobot expects.
        let pandas = json!({
            "index_columns": ["task"],
            "column_indexes": [{"name": null, "field_name": null, "pandas_type": "unicode", "numpy_type": "object", "metadata": {"encoding": "UTF-8"}}],
            "columns": [
                {"name": "task_index", "field_name": "task_index", "pandas_type": "int64", "numpy_type": "int64", "metadata": null},
                {"name": "task", "field_name": "task", "pandas_type": "unicode", "numpy_type": "object", "metadata": null}
            ],
            "attributes": {},
            "creator": {"library": "macrotree", "version": env!("CARGO_PKG_VERSION")},
            "pandas_version": "2.3.3"
        });
        let rel = "meta/tasks.parquet";
        let mut pq = ParquetFile::create(
            self.create_file(rel)?,
            &t,
            vec![("pandas".into(), pandas.to_string())],
        )
        .map_err(pq_err(rel))?;
        pq.write(&t).map_err(pq_err(rel))?;
        pq.finish().map_err(pq_err(rel))?.sync_all().map_err(io_err(rel))
    }

    fn stats_json(&self) -> Value {
        let mut m = serde_json::Map::new();
        let names: Vec<String> = self.episodes[0].stats.iter().map(|(n, _)| n.clone()).collect();
        for (s, name) in names.iter().enumerate() {
            let parts: Vec<&VecStats> = self.episodes.iter().map(|e| &e.stats[s].1).collect();
            if let Some(all) = VecStats::combine(&parts) {
                m.insert(name.clone(), all.to_json());
            }
        }
        for (k, cam) in self.opts.cameras.iter().enumerate() {
            m.insert(video_key(cam), image_stats_json(&self.histograms[k], self.frames));
        }
        Value::Object(m)
    }

    /// Renames the staging folder to `DIR` (replacing the dataset there when allowed).
    fn install(&self) -> Result<(), DatasetError> {
        if let Ok(d) = File::open(&self.stage) {
            let _ = d.sync_all();
        }
        check_dir(&self.dir, self.opts.overwrite)?;
        if std::fs::symlink_metadata(&self.dir).is_ok() {
            // An empty folder, or (checked just now) a dataset of ours with --overwrite.
            let old = parent_of(&self.dir).join(format!(".{:016x}.old", random_u64()));
            std::fs::rename(&self.dir, &old).map_err(io_err(format!(
                "cannot move the old {} aside",
                self.dir.display()
            )))?;
            if let Err(e) = std::fs::rename(&self.stage, &self.dir) {
                let _ = std::fs::rename(&old, &self.dir);
                return Err(DatasetError(format!(
                    "cannot install {}: {e}",
                    self.dir.display()
                )));
            }
            std::fs::remove_dir_all(&old).map_err(io_err(format!(
                "cannot remove the old dataset at {}",
                old.display()
            )))?;
        } else {
            std::fs::rename(&self.stage, &self.dir)
                .map_err(io_err(format!("cannot install {}", self.dir.display())))?;
        }
        if let Ok(d) = File::open(parent_of(&self.dir)) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

impl Drop for DatasetWriter {
    fn drop(&mut self) {
        if !self.finished {
            let _ = std::fs::remove_dir_all(&self.stage);
        }
    }
}

fn random_u64() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    h.write_u32(std::process::id());
    h.finish()
}
