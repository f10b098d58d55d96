//! Real-browser tests: headless Debian Chromium opens the live page and a recorded replay.
//!
//! The tests start Chromium themselves (fresh profile, its own process group) and kill it when
//! done. They skip only when `/usr/bin/chromium` is absent **and** `CI` is unset; in CI they
//! must run (`.ci/run` installs the `chromium` package).
//!
//! Set `MACROTREE_VIEWER_SCREENSHOT=path.png` to also save a screenshot of the live page (used
//! for docs/images/viewer.png). `cargo test --test viewer_browser -- --ignored --nocapture`
//! runs the overhead measurement.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use macrotree::sim::{HOME_Q, Scene, Sim};
use macrotree::viewer::{LiveViewer, Recorder, TreeNodeView, ViewerOptions, page};
use tungstenite::{Message, WebSocket};

const CHROMIUM: &str = "/usr/bin/chromium";

/// Whether to run: Chromium and the bundle present; outside CI their absence skips loudly.
fn browser_available() -> bool {
    let ci = std::env::var_os("CI").is_some();
    if !Path::new(CHROMIUM).exists() {
        assert!(
            !ci,
            "{CHROMIUM} is missing: CI must install the Debian package chromium"
        );
        eprintln!("SKIPPED: {CHROMIUM} is missing (apt-get install chromium)");
        return false;
    }
    if let Err(p) = page::load_bundle() {
        assert!(!ci, "{}", page::bundle_help(&p));
        eprintln!("SKIPPED: {}", page::bundle_help(&p));
        return false;
    }
    true
}

fn temp_dir(tag: &str) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let dir = std::env::temp_dir().join(format!("macrotree-viewer-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A headless Chromium started by this test; killed (with its process group) on drop.
struct Chromium {
    child: Child,
    profile: PathBuf,
}

impl Chromium {
    fn command(profile: &Path, width: u32, height: u32) -> Command {
        let mut cmd = Command::new(CHROMIUM);
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-extensions",
            "--no-first-run",
            "--no-default-browser-check",
            "--hide-scrollbars",
            "--mute-audio",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--window-size={width},{height}"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .process_group(0);
        cmd
    }

    /// Opens `url` and keeps running, with a DevTools port for screenshots.
    fn open(url: &str, width: u32, height: u32) -> Self {
        let profile = temp_dir("chromium");
        let child = Self::command(&profile, width, height)
            .arg("--remote-debugging-port=0")
            .arg(url)
            .spawn()
            .expect("start chromium");
        Self { child, profile }
    }

    /// The DevTools websocket of the first page.
    fn devtools(&self) -> Devtools {
        let file = self.profile.join("DevToolsActivePort");
        let deadline = Instant::now() + Duration::from_secs(30);
        let port: u16 = loop {
            if let Some(port) = std::fs::read_to_string(&file)
                .ok()
                .and_then(|s| s.lines().next().and_then(|l| l.trim().parse().ok()))
            {
                break port;
            }
            assert!(Instant::now() < deadline, "chromium wrote no DevToolsActivePort");
            std::thread::sleep(Duration::from_millis(50));
        };
        let addr = SocketAddr::from(([127, 0, 0, 1], port));
        let list = loop {
            let body = http_get(addr, "/json/list");
            let list: serde_json::Value = serde_json::from_slice(&body).unwrap_or_default();
            if list
                .as_array()
                .is_some_and(|l| l.iter().any(|t| t["type"] == "page"))
            {
                break list;
            }
            assert!(Instant::now() < deadline, "no page target");
            std::thread::sleep(Duration::from_millis(50));
        };
        let target = list
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["type"] == "page")
            .unwrap();
        let url = target["webSocketDebuggerUrl"].as_str().unwrap().to_owned();
        let stream = TcpStream::connect(addr).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let (ws, _) = tungstenite::client(url, stream).unwrap();
        Devtools { ws, next_id: 1 }
    }
}

impl Drop for Chromium {
    fn drop(&mut self) {
        let pgid = self.child.id();
        let _ = self.child.kill();
        let _ = self.child.wait();
        // Helpers (zygote, GPU, renderer) share the group we created for this browser.
        let _ = Command::new("kill")
            .args(["-KILL", "--", &format!("-{pgid}")])
            .stderr(Stdio::null())
            .status();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// A minimal DevTools protocol client.
struct Devtools {
    ws: WebSocket<TcpStream>,
    next_id: u64,
}

impl Devtools {
    fn call(&mut self, method: &str, params: serde_json::Value) -> serde_json::Value {
        let id = self.next_id;
        self.next_id += 1;
        let msg = serde_json::json!({ "id": id, "method": method, "params": params });
        self.ws.send(Message::text(msg.to_string())).unwrap();
        loop {
            if let Message::Text(t) = self.ws.read().unwrap() {
                let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
                if v["id"] == id {
                    assert!(v.get("error").is_none(), "{method}: {v}");
                    return v["result"].clone();
                }
            }
        }
    }

    fn eval(&mut self, js: &str) -> serde_json::Value {
        let r = self.call(
            "Runtime.evaluate",
            serde_json::json!({ "expression": js, "returnByValue": true }),
        );
        r["result"]["value"].clone()
    }

    fn screenshot(&mut self) -> Vec<u8> {
        use base64::Engine as _;
        let r = self.call("Page.captureScreenshot", serde_json::json!({ "format": "png" }));
        base64::engine::general_purpose::STANDARD
            .decode(r["data"].as_str().unwrap())
            .unwrap()
    }
}

fn http_get(addr: SocketAddr, path: &str) -> Vec<u8> {
    let Ok(mut s) = TcpStream::connect(addr) else {
        return Vec::new();
    };
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    );
    let mut buf = Vec::new();
    let _ = s.read_to_end(&mut buf);
    match buf.windows(4).position(|w| w == b"\r\n\r\n") {
        Some(i) => buf[i + 4..].to_vec(),
        None => Vec::new(),
    }
}

/// An RGB image.
struct Image {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

fn decode_png(bytes: &[u8]) -> Image {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let rgb = buf[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|px| {
            if channels >= 3 {
                [px[0], px[1], px[2]]
            } else {
                [px[0]; 3]
            }
        })
        .collect();
    Image {
        width: info.width as usize,
        height: info.height as usize,
        rgb,
    }
}

/// Pixel counts of the colour classes the scene should show.
#[derive(Debug, Default, Clone, Copy)]
struct Classes {
    /// The orange cube (material 0.95, 0.35, 0.15).
    cube: usize,
    /// The teal bowl (0.25, 0.65, 0.55).
    bowl: usize,
    /// The robot's near-black parts (UR5e 0.033 grey, 2F-85 0.149 grey).
    robot_dark: usize,
    /// Distinct colours (quantised), a guard against blank images.
    distinct: usize,
}

fn classify(img: &Image) -> Classes {
    let mut c = Classes::default();
    let mut seen = std::collections::HashSet::new();
    for px in img.rgb.chunks(3) {
        let (r, g, b) = (i32::from(px[0]), i32::from(px[1]), i32::from(px[2]));
        seen.insert((r >> 3, g >> 3, b >> 3));
        if r > 110 && r - g > 60 && g - b > 15 && b < 110 {
            c.cube += 1;
        }
        if g > r + 35 && g >= b && b > r + 10 {
            c.bowl += 1;
        }
        let (max, min) = (r.max(g).max(b), r.min(g).min(b));
        if max < 75 && max - min < 18 {
            c.robot_dark += 1;
        }
    }
    c.distinct = seen.len();
    c
}

fn assert_scene_visible(c: Classes, what: &str) {
    assert!(c.distinct > 30, "{what}: blank image {c:?}");
    assert!(c.cube > 15, "{what}: no cube pixels {c:?}");
    assert!(c.bowl > 60, "{what}: no bowl pixels {c:?}");
    assert!(c.robot_dark > 100, "{what}: no robot pixels {c:?}");
}

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
