//! Camera images and `run --video`: MuJoCo's offscreen renderer (headless EGL) and the pinned
//! ffmpeg, on the real scene.

use crate::support::cli;
use crate::support::media;

use std::sync::Arc;

use cli::{macrotree, s, scratch};
use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeObserver, NoObserver, run_in_cell};
use macrotree::render::{FrameSize, with_thread_renderer};
use macrotree::runtime::TreeRunner;
use macrotree::sim::{Layout, Scene};

/// Renders the front and wrist cameras after every 8th tick and keeps a checksum of each image.
struct RenderEveryTick {
    cameras: Vec<usize>,
    sums: Vec<u64>,
    ticks: u64,
}

impl EpisodeObserver for RenderEveryTick {
    fn on_tick(&mut self, cell: &Cell, _runner: &mut TreeRunner) {
        self.ticks += 1;
        if self.ticks % 8 != 1 {
            return;
        }
        let size = FrameSize {
            width: 96,
            height: 72,
        };
        let model = &cell.sim().scene().model;
        let sums = with_thread_renderer(model, size, |r| {
            r.sync(cell.sim().data());
            self.cameras
                .iter()
                .map(|&c| r.render(c).unwrap().iter().map(|&v| v as u64).sum::<u64>())
                .collect::<Vec<_>>()
        })
        .unwrap();
        self.sums.extend(sums);
    }
}

#[test]
fn rendering_never_changes_the_physics_bits() {
    if !media::gl() {
        return;
    }
    let scene = Scene::load().unwrap();
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .load("trees/cube_to_bowl.yaml".as_ref())
            .unwrap(),
    );
    let config = EpisodeConfig::default();
    let mut plain = Cell::new(&scene, &Layout::default(), CONTROL_PERIOD);
    let a = run_in_cell(
        &mut plain,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut NoObserver,
    );
    let mut observer = RenderEveryTick {
        cameras: macrotree::render::camera_ids(&scene, &["front".into(), "wrist".into()]).unwrap(),
        sums: Vec::new(),
        ticks: 0,
    };
    let mut rendered = Cell::new(&scene, &Layout::default(), CONTROL_PERIOD);
    let b = run_in_cell(
        &mut rendered,
        plan,
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut observer,
    );
    assert!(a.outcome.success && b.outcome.success);
    // Every 8th tick rendered both cameras, and the images changed along the episode.
    let ticks = b.outcome.physics_steps / 2;
    assert_eq!(observer.ticks, ticks);
    assert_eq!(observer.sums.len() as u64, 2 * ticks.div_ceil(8));
    let distinct: std::collections::BTreeSet<_> = observer.sums.iter().collect();
    assert!(distinct.len() > 100, "only {} distinct images", distinct.len());
    // Bit-identical physics: qpos, qvel, ctrl and time.
    assert_eq!(
        plain.sim().state_fingerprint(),
        rendered.sim().state_fingerprint()
    );
    assert_eq!(a.outcome.physics_steps, b.outcome.physics_steps);
}

#[test]
fn run_video_writes_an_h264_mp4_with_one_frame_per_sample() {
    let Some(ffmpeg) = media::ffmpeg() else { return };
    if !media::gl() {
        return;
    }
    let dir = scratch("pixels-video");
    let (video, frames) = (dir.join("out.mp4"), dir.join("frames.jsonl"));
    let out = macrotree(&[
        "run",
        "trees/cube_to_bowl.yaml",
        "--video",
        s(&video),
        "--camera",
        "wrist",
        "--size",
        "320x240",
        "--fps",
        "10",
        "--frames",
        s(&frames),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let rows = std::fs::read_to_string(&frames).unwrap().lines().count();
    // 5.3 s of simulated time at 10 frames per second.
    assert!((50..=60).contains(&rows), "{rows} frames");
    let (n, size, distinct) = media::decode(&ffmpeg, &video);
    assert_eq!(n, rows);
    assert_eq!(size, (320, 240));
    assert!(distinct > rows / 2, "{distinct} distinct frames of {n}");
    assert!(
        stderr.contains(&format!("video written to {}", video.display())),
        "{stderr}"
    );
    // Nothing but the two outputs is left in the folder (no temporary file).
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["frames.jsonl", "out.mp4"]);
}

#[test]
fn the_same_episode_gives_the_same_video_bytes() {
    let Some(_) = media::ffmpeg() else { return };
    if !media::gl() {
        return;
    }
    let dir = scratch("pixels-same");
    let args = |f: &str| {
        vec![
            "run".to_string(),
            "trees/cube_to_bowl.yaml".into(),
            "--max-sim-time".into(),
            "1.5".into(),
            "--size".into(),
            "160x120".into(),
            "--video".into(),
            s(&dir.join(f)).into(),
        ]
    };
    for f in ["a.mp4", "b.mp4"] {
        let a = args(f);
        let out = macrotree(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(
            out.status.code(),
            Some(1),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(
        std::fs::read(dir.join("a.mp4")).unwrap(),
        std::fs::read(dir.join("b.mp4")).unwrap()
    );
}

#[test]
fn bad_video_options_are_refused_before_simulating() {
    let dir = scratch("pixels-bad");
    let video = dir.join("v.mp4");
    for (args, needle) in [
        (vec!["--size", "641x480"], "both even"),
        (vec!["--size", "2000x100"], "width 16…1280"),
        (vec!["--fps", "0"], "between 1 and 250"),
        (
            vec!["--camera", "nope"],
            "its cameras are: overview, front, wrist",
        ),
    ] {
        let mut all = vec!["run", "trees/cube_to_bowl.yaml", "--video", s(&video)];
        all.extend(args.iter().copied());
        let out = macrotree(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    // A folder is not a video file.
    let out = macrotree(&["run", "trees/cube_to_bowl.yaml", "--video", s(&dir)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!video.exists());
}

#[test]
fn without_opengl_run_works_and_asking_for_pixels_says_what_to_install() {
    // libglvnd finds no EGL vendor library here, as on a machine without Mesa's EGL.
    let no_egl = |args: &[&str]| {
        std::process::Command::new(cli::BIN)
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json")
            .output()
            .unwrap()
    };
    let out = no_egl(&["run", "trees/cube_to_bowl.yaml"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let Some(_) = media::ffmpeg() else { return };
    let dir = scratch("pixels-nogl");
    let video = dir.join("v.mp4");
    let out = no_egl(&["run", "trees/cube_to_bowl.yaml", "--video", s(&video)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("cannot render camera images"), "{stderr}");
    assert!(
        stderr.contains("apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri"),
        "{stderr}"
    );
    assert!(!video.exists());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "no temporary file left"
    );
}
