//! Real-browser tests: headless Debian Chromium opens the live page and a recorded replay.
//!
//! The tests start Chromium themselves (fresh profile, its own process group) and kill it when
//! done. They skip only when `/usr/bin/chromium` is absent **and** `CI` is unset; in CI they
//! must run (`.ci/run` installs the `chromium` package).
//!
//! Set `MACROTREE_VIEWER_SCREENSHOT=path.png` to also save a screenshot of the live page (used
//! for docs/images/viewer.png). `cargo test --test viewer_browser -- --ignored --nocapture`
//! runs the overhead measurement.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use macrotree::sim::{HOME_Q, Scene, Sim};
use macrotree::viewer::{LiveViewer, Recorder, TreeNodeView, ViewerOptions, page};
#[path = "support/browser.rs"]
mod browser;
use browser::*;

fn demo_tree() -> Vec<TreeNodeView> {
    let n = |path: &str, kind: &str, name: &str, parent: Option<usize>| TreeNodeView {
        path: path.into(),
        kind: kind.into(),
        name: name.into(),
        parent,
    };
    vec![
        n("root", "sequence", "cube_in_bowl", None),
        n("root/0", "reach", "reach_cube", Some(0)),
        n("root/1", "retry", "grasp_with_retry", Some(0)),
        n("root/1/0", "grasp", "grasp_cube", Some(2)),
        n("root/2", "carry", "carry_to_bowl", Some(0)),
    ]
}

#[test]
fn live_page_renders_the_scene_and_the_tree_panel() {
    if !browser_available() {
        return;
    }
    let scene = Scene::load().unwrap();
    let mut sim = Sim::new(&scene);
    let viewer = LiveViewer::start(
        &scene.model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .unwrap();
    viewer.set_tree(demo_tree());
    for _ in 0..200 {
        sim.step();
    }
    viewer.publish_poses(sim.data(), sim.time());
    viewer.publish_tree_status_with_attempts(
        vec!["running", "success", "running", "running", "idle"],
        vec![0, 0, 2, 0, 0],
        vec![
            serde_json::json!({"node": "root/0", "status": "success"}),
            "retry root/1 attempt 2".into(),
        ],
    );

    let browser = Chromium::open(&viewer.url(), 1000, 600);
    assert!(
        viewer.wait_for_clients(1, Duration::from_secs(60)),
        "the page did not connect"
    );
    // capture_image is queued behind the whole snapshot, so the scene is in when it renders.
    let png = viewer
        .capture_image(Duration::from_secs(120))
        .expect("capture through the viewer");
    let img = decode_png(&png);
    assert!(
        img.width > 300 && img.height > 300,
        "{}x{}",
        img.width,
        img.height
    );
    let with_scene = classify(&img);
    eprintln!("live capture {}x{}: {with_scene:?}", img.width, img.height);
    assert_scene_visible(with_scene, "live page");

    // The panel shows the tree with statuses and attempts, and the events.
    let mut dt = browser.devtools();
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let shown = dt.eval(
            "JSON.stringify([document.querySelectorAll('#tree .node').length, \
             document.querySelectorAll('#tree .node.running').length, \
             document.querySelectorAll('#tree .node.success').length, \
             document.querySelector('#tree').textContent.includes('attempt 2'), \
             document.querySelectorAll('#events li').length, \
             document.querySelector('#conn').textContent])",
        );
        if shown.as_str() == Some(r#"[5,3,1,true,2,"live"]"#) {
            break;
        }
        assert!(Instant::now() < deadline, "panel shows {shown}");
        std::thread::sleep(Duration::from_millis(100));
    }
    if let Some(path) = std::env::var_os("MACROTREE_VIEWER_SCREENSHOT") {
        std::thread::sleep(Duration::from_millis(300));
        std::fs::write(&path, dt.screenshot()).unwrap();
        eprintln!("saved {}", PathBuf::from(path).display());
    }
    // Poses move the robot in the page.
    let mut q = HOME_Q;
    q[0] += 0.9;
    sim.set_arm_ctrl(&q);
    for _ in 0..600 {
        sim.step();
    }
    viewer.publish_poses(sim.data(), sim.time());
    let moved = decode_png(&viewer.capture_image(Duration::from_secs(60)).unwrap());
    let diff = moved
        .rgb
        .iter()
        .zip(&img.rgb)
        .filter(|(a, b)| a.abs_diff(**b) > 30)
        .count();
    assert!(
        diff > 500,
        "the robot did not move in the page: {diff} bytes differ"
    );

    // Without our objects the same colours are gone: they came from the scene.
    viewer.delete("/mujoco");
    let empty = classify(&decode_png(
        &viewer.capture_image(Duration::from_secs(60)).unwrap(),
    ));
    eprintln!("empty scene: {empty:?}");
    assert!(
        empty.cube == 0 && empty.bowl == 0 && empty.robot_dark < with_scene.robot_dark / 10,
        "{empty:?}"
    );
    drop(browser);
}

/// Records a short episode in which the arm swings; returns the HTML path.
fn record_episode(dir: &Path, seconds: f64) -> PathBuf {
    let scene = Scene::load().unwrap();
    let mut sim = Sim::new(&scene);
    let mut rec = Recorder::new(&scene.model);
    rec.set_tree(demo_tree());
    rec.frame(sim.data(), sim.time());
    let mut q = HOME_Q;
    q[0] += 1.2;
    q[1] += 0.4;
    sim.set_arm_ctrl(&q);
    rec.tree_status(
        0.0,
        vec!["running", "running", "idle", "idle", "idle"],
        vec!["start".into()],
    );
    let steps = (seconds / macrotree::sim::TIMESTEP).round() as usize;
    for i in 0..steps {
        sim.step();
        rec.frame(sim.data(), sim.time());
        if i == steps / 2 {
            rec.tree_status(
                sim.time(),
                vec!["running", "success", "running", "running", "idle"],
                vec![],
            );
        }
    }
    let path = dir.join("replay.html");
    rec.write(&path).unwrap();
    path
}

fn screenshot_file(html: &Path, virtual_ms: u32, out: &Path) -> Image {
    let profile = temp_dir("shot");
    let status = Chromium::command(&profile, 900, 600)
        .arg(format!("--virtual-time-budget={virtual_ms}"))
        .arg(format!("--screenshot={}", out.display()))
        .arg(format!("file://{}", html.display()))
        .status()
        .expect("run chromium");
    let _ = std::fs::remove_dir_all(&profile);
    assert!(status.success(), "chromium --screenshot failed: {status}");
    decode_png(&std::fs::read(out).unwrap())
}

#[test]
fn recorded_replay_plays_offline_and_animates() {
    if !browser_available() {
        return;
    }
    let dir = temp_dir("replay");
    let html = record_episode(&dir, 2.0);
    let size = std::fs::metadata(&html).unwrap().len();
    eprintln!("replay of 2 s: {size} bytes");
    assert!(size < 15 << 20, "{size}");
    let early = screenshot_file(&html, 150, &dir.join("early.png"));
    let late = screenshot_file(&html, 3000, &dir.join("late.png"));
    let (ce, cl) = (classify(&early), classify(&late));
    eprintln!("replay early {ce:?}\nreplay late {cl:?}");
    assert_scene_visible(ce, "replay at 0.15 s");
    assert_scene_visible(cl, "replay at 3 s");
    let diff = early
        .rgb
        .iter()
        .zip(&late.rgb)
        .filter(|(a, b)| a.abs_diff(**b) > 30)
        .count();
    assert!(diff > 1000, "the replay did not animate: {diff} bytes differ");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_default_length_episode_replay_stays_under_15_mb() {
    // Sizes only (no browser): 30 s of a moving arm at 30 fps.
    if page::load_bundle().is_err() {
        assert!(std::env::var_os("CI").is_none(), "bundle missing in CI");
        return;
    }
    let dir = temp_dir("size");
    let html = record_episode(&dir, 30.0);
    let size = std::fs::metadata(&html).unwrap().len();
    eprintln!("replay of 30 s: {size} bytes");
    assert!(size < 15 << 20, "{size}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// CPU time of the calling thread so far (Linux `schedstat`), seconds.
fn thread_cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    stat.split_whitespace()
        .next()
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(0.0)
        / 1e9
}

/// Runs an episode-like loop: `steps` physics steps, poses published at 30 Hz of sim time.
/// Returns (wall seconds, sim-thread CPU seconds).
fn episode(sim: &mut Sim, viewer: Option<&LiveViewer>, steps: usize) -> (f64, f64) {
    sim.reset(&macrotree::sim::Layout::default());
    let started = Instant::now();
    let cpu = thread_cpu();
    let mut next_publish = 0.0;
    for i in 0..steps {
        let t = sim.time();
        let mut q = HOME_Q;
        q[0] += 0.8 * (t * 1.5).sin();
        q[2] += 0.4 * (t * 1.1).sin();
        sim.set_arm_ctrl(&q);
        sim.set_gripper_ctrl(if i % 1000 < 500 { 0.0 } else { 255.0 });
        sim.step();
        if let Some(v) = viewer
            && sim.time() >= next_publish
        {
            next_publish += 1.0 / 30.0;
            v.publish_poses(sim.data(), sim.time());
        }
    }
    (started.elapsed().as_secs_f64(), thread_cpu() - cpu)
}

/// Median wall and CPU seconds of `rounds` episodes.
fn measure(sim: &mut Sim, viewer: Option<&LiveViewer>, steps: usize, rounds: usize) -> (f64, f64) {
    let (mut wall, mut cpu): (Vec<f64>, Vec<f64>) = (0..rounds).map(|_| episode(sim, viewer, steps)).unzip();
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (median(&mut wall), median(&mut cpu))
}

#[test]
#[ignore = "measurement: cargo test --release --test viewer_browser -- --ignored --nocapture"]
fn measure_overhead_with_one_browser() {
    if !browser_available() {
        return;
    }
    let scene = Scene::load().unwrap();
    let mut sim = Sim::new(&scene);
    // 60 s of sim time (30 000 steps), poses published at 30 Hz of sim time: 1800 frames.
    let steps: usize = std::env::var("MACROTREE_OVERHEAD_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30_000);
    let rounds = 7;
    episode(&mut sim, None, steps); // warm-up
    let base = measure(&mut sim, None, steps, rounds);
    let viewer = LiveViewer::start(
        &scene.model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .unwrap();
    let no_client = measure(&mut sim, Some(&viewer), steps, rounds);
    let browser = Chromium::open(&viewer.url(), 1000, 600);
    assert!(viewer.wait_for_clients(1, Duration::from_secs(60)));
    viewer.capture_image(Duration::from_secs(120)).unwrap(); // the snapshot is loaded
    let with_browser = measure(&mut sim, Some(&viewer), steps, rounds);
    let stats = viewer.stats();
    drop(browser);
    drop(viewer);
    std::thread::sleep(Duration::from_millis(500));
    let base2 = measure(&mut sim, None, steps, rounds);
    let pct = |x: f64, b: f64| (x / b - 1.0) * 100.0;
    let (bw, bc) = (base.0.min(base2.0), base.1.min(base2.1));
    eprintln!(
        "{steps} steps ({:.0} s of sim time), poses published at 30 Hz of sim time, median of {rounds}:\n\
         \x20 no viewer:            wall {:.3} s / {:.3} s (before / after), sim-thread CPU {:.3} s / {:.3} s\n\
         \x20 viewer, no browser:   wall {:.3} s ({:+.1} %), sim-thread CPU {:.3} s ({:+.1} %)\n\
         \x20 viewer + 1 browser:   wall {:.3} s ({:+.1} %), sim-thread CPU {:.3} s ({:+.1} %)\n\
         \x20 {stats:?}",
        steps as f64 * macrotree::sim::TIMESTEP,
        base.0,
        base2.0,
        base.1,
        base2.1,
        no_client.0,
        pct(no_client.0, bw),
        no_client.1,
        pct(no_client.1, bc),
        with_browser.0,
        pct(with_browser.0, bw),
        with_browser.1,
        pct(with_browser.1, bc),
    );
}
