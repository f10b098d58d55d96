//! Real-browser tests: headless Debian Chromium opens the live page and a recorded replay.
//!
//! The tests start Chromium themselves (fresh profile, its own process group) and kill it when
//! done. A missing `/usr/bin/chromium` (or viewer bundle) fails them, unless
//! `MACROTREE_SKIP_BROWSER_TESTS=1` asks to skip them (`.ci/run` installs the `chromium` package).
//!
//! Set `MACROTREE_VIEWER_SCREENSHOT=path.png` to also save a screenshot of the live page (used
//! for docs/images/viewer.png). `cargo test --release --test viewer -- --ignored
//! --nocapture measure_episode_overhead_with_one_browser` runs the `--view` overhead
//! measurement on the real flagship episode.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::support::browser;
use browser::*;
use macrotree::episode::{EpisodeConfig, NoObserver, run_episode};
use macrotree::plan::Plan;
use macrotree::sim::{HOME_Q, Scene, Sim};
use macrotree::viewer::{LiveViewer, Recorder, TreeNodeView, ViewObserver, ViewerOptions, load_bundle};
use mujoco_rs::prelude::*;

fn demo_tree() -> Vec<TreeNodeView> {
    let n = |path: &str, kind: &str, name: &str, parent: Option<usize>| TreeNodeView {
        path: path.into(),
        kind: kind.into(),
        name: name.into(),
        parent,
        ..TreeNodeView::default()
    };
    vec![
        n("root", "sequence", "cube_in_bowl", None),
        n("root/0", "reach", "reach_cube", Some(0)),
        n("root/1", "retry", "grasp_with_retry", Some(0)),
        n("root/1/0", "grasp", "grasp_cube", Some(2)),
        n("root/2", "carry", "carry_to_bowl", Some(0)),
    ]
}

/// Issue 13, item 14: a machine without Chromium must not pass the browser tests silently.
#[test]
fn a_missing_browser_fails_unless_skipping_is_asked_for() {
    let nowhere = Path::new("/nonexistent/macrotree-test/chromium");
    let why = browser_check(nowhere, false).expect_err("a missing browser must fail the test");
    assert!(why.contains(nowhere.to_str().unwrap()), "{why}");
    assert!(why.contains(SKIP_ENV), "the message names the opt-out: {why}");
    assert_eq!(browser_check(nowhere, true), Ok(false), "opted out: skip");
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
    eprintln!(
        "live capture {}x{} ({} bytes of PNG): {with_scene:?}",
        img.width,
        img.height,
        png.len()
    );
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
    let diff = differing_bytes(&moved, &img);
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

/// How many colour bytes of two screenshots of one size differ by more than 30 (of 255).
fn differing_bytes(a: &Image, b: &Image) -> usize {
    a.rgb
        .iter()
        .zip(&b.rgb)
        .filter(|(x, y)| x.abs_diff(**y) > 30)
        .count()
}

/// The replay bar as JSON: the clock label (`t / duration s`) and whether it plays.
const REPLAY_BAR: &str = "JSON.stringify({label: document.querySelector('#replay-time').textContent,\
  playing: document.querySelector('#play').textContent !== '▶'})";

/// Evaluates [`REPLAY_BAR`] until `done` accepts it.
fn wait_replay(dt: &mut Devtools, timeout: Duration, done: impl Fn(&str, bool) -> bool) -> serde_json::Value {
    let v = dt.wait_until(REPLAY_BAR, timeout, |v| {
        serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
            .is_ok_and(|s| done(s["label"].as_str().unwrap_or(""), s["playing"] == true))
    });
    serde_json::from_str(v.as_str().unwrap()).unwrap()
}

/// A screenshot once the page has drawn a few more frames (the scene after a seek).
fn settled_screenshot(dt: &mut Devtools) -> Image {
    std::thread::sleep(Duration::from_millis(500));
    decode_png(&dt.screenshot())
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
    // Offline: the file itself, nothing served.
    let browser = Chromium::open(&format!("file://{}", html.display()), 900, 600);
    let mut dt = browser.devtools();
    // It starts playing by itself once its first frame is drawn (and may have played its 2 s
    // to the end before the first look).
    wait_replay(&mut dt, Duration::from_secs(90), |label, playing| {
        playing || (!label.is_empty() && !label.starts_with("0.00 / "))
    });
    // Held at an early instant, it shows the scene.
    dt.eval("window.macrotree.seek(0.15)");
    wait_replay(&mut dt, Duration::from_secs(30), |label, playing| {
        !playing && label.starts_with("0.15 / ")
    });
    let early = settled_screenshot(&mut dt);
    let ce = classify(&early);
    eprintln!("replay early {ce:?}");
    assert_scene_visible(ce, "replay at 0.15 s");
    // Played from there, it ends at its last frame with the arm moved (1.2 rad about the base).
    dt.eval("document.querySelector('#play').click()");
    let end = wait_replay(&mut dt, Duration::from_secs(60), |label, playing| {
        let mut parts = label.trim_end_matches(" s").split(" / ");
        !playing && parts.next().is_some_and(|t| Some(t) == parts.next())
    });
    eprintln!("replay end {end}");
    let late = settled_screenshot(&mut dt);
    let cl = classify(&late);
    eprintln!("replay late {cl:?}");
    assert_scene_visible(cl, "replay at its end");
    let diff = differing_bytes(&early, &late);
    assert!(diff > 1000, "the replay did not animate: {diff} bytes differ");
    drop(browser);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Serves `html` for `/` (404 for anything else) on a free local port until the returned flag
/// is set; returns the port.
fn serve_page(html: String) -> (u16, Arc<std::sync::atomic::AtomicBool>) {
    use std::io::{Read, Write};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    listener.set_nonblocking(true).unwrap();
    let port = listener.local_addr().unwrap().port();
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let stopped = stop.clone();
    std::thread::spawn(move || {
        while !stopped.load(std::sync::atomic::Ordering::SeqCst) {
            let Ok((mut s, _)) = listener.accept() else {
                std::thread::sleep(Duration::from_millis(20));
                continue;
            };
            let _ = s.set_nonblocking(false);
            let _ = s.set_read_timeout(Some(Duration::from_secs(5)));
            let mut head = Vec::new();
            let mut buf = [0u8; 1024];
            while !head.windows(4).any(|w| w == b"\r\n\r\n") {
                match s.read(&mut buf) {
                    Ok(n) if n > 0 => head.extend_from_slice(&buf[..n]),
                    _ => break,
                }
            }
            let (status, body) = if head.starts_with(b"GET / ") {
                ("200 OK", html.as_str())
            } else {
                ("404 Not Found", "")
            };
            let _ = write!(
                s,
                "HTTP/1.1 {status}\r\nContent-Type: text/html\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            );
        }
    });
    (port, stop)
}

/// Issue 13, item 5: a page of another local origin (any site the user visits could do the
/// same) cannot open the viewer's websocket, by IP or by name; the viewer's own page can.
#[test]
fn a_page_from_another_local_port_cannot_open_the_websocket() {
    if !browser_available() {
        return;
    }
    let scene = Scene::load().unwrap();
    let viewer = LiveViewer::start(
        &scene.model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .unwrap();
    let port = viewer.local_addr().port();
    let attacker = format!(
        r#"<!DOCTYPE html><title>another page</title><script>
        window.results = {{}};
        function attempt(name, url) {{
          results[name] = "pending";
          var ws = new WebSocket(url);
          ws.onopen = function () {{ results[name] = "open"; }};
          ws.onmessage = function () {{ results[name] = "message"; }};
          ws.onerror = function () {{ if (results[name] === "pending") results[name] = "error"; }};
          ws.onclose = function (e) {{
            if (results[name] === "pending" || results[name] === "error") results[name] = "closed " + e.code;
          }};
        }}
        attempt("ip", "ws://127.0.0.1:{port}/");
        attempt("name", "ws://localhost:{port}/");
        </script>"#
    );
    let (other, stop) = serve_page(attacker);
    let browser = Chromium::open(&format!("http://127.0.0.1:{other}/"), 800, 500);
    let mut dt = browser.devtools();
    let results = dt.wait_until(
        "JSON.stringify(window.results || null)",
        Duration::from_secs(30),
        |v| {
            let r: serde_json::Value = serde_json::from_str(v.as_str().unwrap_or("null")).unwrap_or_default();
            ["ip", "name"]
                .iter()
                .all(|k| r[k].as_str().is_some_and(|s| s.starts_with("closed")))
        },
    );
    eprintln!("a page of 127.0.0.1:{other} opening the viewer's websocket: {results}");
    assert_eq!(viewer.client_count(), 0, "a foreign page became a client");
    // The viewer's own page connects.
    dt.call("Page.navigate", serde_json::json!({ "url": viewer.url() }));
    assert!(
        viewer.wait_for_clients(1, Duration::from_secs(60)),
        "the viewer's own page did not connect"
    );
    dt.wait_until(
        "document.querySelector('#conn') && document.querySelector('#conn').textContent",
        Duration::from_secs(30),
        |v| v == "live",
    );
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    drop(browser);
}

/// Names that would change a page if they reached its markup: each sets `window.__pwned` or
/// breaks the script that starts the replay (no `-->`: it would end the comment state that
/// `<!--<script>` opens).
const HOSTILE: [&str; 5] = [
    "<!--<script>",
    "</script><script>window.__pwned = 1</script>",
    "</SCRIPT ><img src=x onerror=\"window.__pwned = 2\">",
    "a\u{2028}b\u{2029}c",
    "&lt;b&gt; & <b>bold</b>",
];

/// A falling box whose body and geom carry hostile MuJoCo names (path segments replace `/` and
/// whitespace, so markup in a body name has no attributes; it must still not become markup).
fn hostile_model() -> MjModel {
    MjModel::from_xml_string(
        r#"<mujoco><worldbody>
             <body name="&lt;i&gt;hostile_body" pos="0.3 0 0.3">
               <freejoint/>
               <geom name="&lt;!--&lt;script&gt;" type="box" size="0.05 0.05 0.05" rgba="1 0 0 1"/>
             </body>
           </worldbody></mujoco>"#,
    )
    .expect("the hostile test model compiles")
}

fn hostile_tree() -> Vec<TreeNodeView> {
    HOSTILE
        .iter()
        .enumerate()
        .map(|(i, name)| TreeNodeView {
            path: format!("root/{name}"),
            kind: (*name).into(),
            name: (*name).into(),
            parent: (i > 0).then_some(0),
            ..TreeNodeView::default()
        })
        .collect()
}

/// The panel's node names and event texts, and whether anything set `window.__pwned`.
const PANEL_TEXT: &str = "JSON.stringify({\
    names: Array.from(document.querySelectorAll('#tree .node .name')).map(e => e.textContent),\
    events: Array.from(document.querySelectorAll('#events li')).map(e => e.textContent),\
    conn: document.querySelector('#conn').textContent,\
    pwned: window.__pwned === undefined ? null : window.__pwned,\
    italics: document.querySelectorAll('i').length,\
    time: document.querySelector('#replay-time').textContent,\
    body: document.body.textContent})";

fn panel(dt: &mut Devtools) -> serde_json::Value {
    serde_json::from_str(dt.eval(PANEL_TEXT).as_str().unwrap_or("null")).unwrap_or_default()
}

/// Issue 13, item 9: tree, event and scene names that look like markup show as text, in the
/// live page and in a replay, and the replay still starts.
#[test]
fn hostile_names_show_as_text_in_the_live_page_and_the_replay() {
    if !browser_available() {
        return;
    }
    let model = hostile_model();
    let mut data = model.make_data();
    data.forward();
    let statuses = vec!["running"; HOSTILE.len()];
    let events: Vec<serde_json::Value> = HOSTILE.iter().map(|&e| e.into()).collect();
    let names: Vec<&str> = HOSTILE.to_vec();
    let mut expected_events = names.clone();
    expected_events.reverse(); // newest first

    // Live: the names arrive as JSON text frames and the scene over the websocket.
    let viewer = LiveViewer::start(
        &model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .unwrap();
    viewer.set_tree(hostile_tree());
    viewer.publish_poses(&data, 0.0);
    viewer.publish_tree_status(statuses.clone(), events.clone());
    let browser = Chromium::open(&viewer.url(), 800, 500);
    assert!(
        viewer.wait_for_clients(1, Duration::from_secs(60)),
        "the page did not connect"
    );
    // The capture round trip means the whole scene was handled by the page.
    viewer.capture_image(Duration::from_secs(120)).expect("capture");
    let mut dt = browser.devtools();
    let live = dt.wait_until(PANEL_TEXT, Duration::from_secs(30), |v| {
        serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
            .is_ok_and(|p| p["conn"] == "live" && p["names"].as_array().is_some_and(|n| n.len() == 5))
    });
    let live: serde_json::Value = serde_json::from_str(live.as_str().unwrap()).unwrap();
    assert_eq!(live["names"], serde_json::json!(names), "{live}");
    assert_eq!(live["events"], serde_json::json!(expected_events), "{live}");
    // MeshCat's controls list the scene's names as text.
    assert_eq!(live["italics"], 0, "the body's name became markup");
    let body = live["body"].as_str().unwrap();
    assert!(body.contains("<i>hostile_body<!--<script>"), "{body}");
    std::thread::sleep(Duration::from_millis(500)); // an injected onerror would have fired
    assert_eq!(
        panel(&mut dt)["pwned"],
        serde_json::Value::Null,
        "the live page ran injected code"
    );
    drop(viewer);

    // Replay: the names are embedded in the page itself.
    let dir = temp_dir("hostile");
    let mut rec = Recorder::new(&model);
    rec.set_tree(hostile_tree());
    rec.frame(&data, data.time());
    rec.tree_status(0.0, statuses, events);
    for _ in 0..300 {
        data.step();
        rec.frame(&data, data.time());
    }
    let html = dir.join("hostile.html");
    rec.write(&html).unwrap();
    dt.call(
        "Page.navigate",
        serde_json::json!({ "url": format!("file://{}", html.display()) }),
    );
    // Started: the page fed the scene and its time label runs against the clip's duration.
    let replay = dt.wait_until(PANEL_TEXT, Duration::from_secs(60), |v| {
        serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null")).is_ok_and(|p| {
            p["conn"] == "replay"
                && p["time"]
                    .as_str()
                    .is_some_and(|t| t.contains(" / ") && !t.ends_with("/ 0.00 s"))
        })
    });
    let replay: serde_json::Value = serde_json::from_str(replay.as_str().unwrap()).unwrap();
    assert_eq!(replay["names"], serde_json::json!(names), "{replay}");
    assert_eq!(replay["events"], serde_json::json!(expected_events), "{replay}");
    assert_eq!(replay["italics"], 0, "the body's name became markup");
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(
        panel(&mut dt)["pwned"],
        serde_json::Value::Null,
        "the replay ran injected code"
    );
    drop(browser);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_default_length_episode_replay_stays_under_15_mb() {
    // Sizes only (no browser): 30 s of a moving arm at 30 fps.
    if load_bundle().is_err() {
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

/// The calling thread's scheduler counters so far (Linux `/proc/thread-self/schedstat`): time on
/// a CPU and time runnable but waiting for one, seconds.
fn thread_sched() -> (f64, f64) {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let mut f = stat
        .split_whitespace()
        .map(|v| v.parse::<f64>().unwrap_or(0.0) / 1e9);
    (f.next().unwrap_or(0.0), f.next().unwrap_or(0.0))
}

/// The 1-minute load average (`/proc/loadavg`).
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

/// One run of the real flagship episode (default layout, not paced) on this thread, with or
/// without the live viewer attached. Returns the sim thread's [`Times`] and the physics steps;
/// they cover exactly `run_episode` (and the observer's construction), the calls `macrotree
/// run` makes.
fn flagship_episode(
    scene: &Scene,
    plan: &Arc<Plan>,
    live: Option<LiveViewer>,
) -> (Times, u64, Option<LiveViewer>) {
    let config = EpisodeConfig::default();
    let (cpu, queued) = thread_sched();
    let started = Instant::now();
    let (report, live) = match live {
        None => (
            run_episode(
                scene,
                plan.clone(),
                &macrotree::factory::Factory::builtin(),
                &config,
                &mut NoObserver,
            ),
            None,
        ),
        Some(live) => {
            let mut view = ViewObserver::new(plan, Some(live), None, None);
            let report = run_episode(
                scene,
                plan.clone(),
                &macrotree::factory::Factory::builtin(),
                &config,
                &mut view,
            );
            (report, view.finish().0)
        }
    };
    let wall = started.elapsed().as_secs_f64();
    let after = thread_sched();
    assert!(report.outcome.success, "the flagship episode failed: {report:?}");
    let times = Times {
        wall,
        cpu: after.0 - cpu,
        queued: after.1 - queued,
    };
    (times, report.outcome.physics_steps, live)
}

/// What one episode cost the simulation thread, seconds.
#[derive(Debug, Clone, Copy)]
struct Times {
    /// Wall-clock time.
    wall: f64,
    /// Time on a CPU.
    cpu: f64,
    /// Time runnable but waiting for a CPU (another thread or process had it).
    queued: f64,
}

/// CPU time used so far by all processes of process group `pgid` (Chromium and its helpers),
/// seconds (`/proc/*/stat` utime + stime, in clock ticks of 1/100 s).
fn group_cpu(pgid: u32) -> f64 {
    let mut ticks = 0u64;
    for entry in std::fs::read_dir("/proc").into_iter().flatten().flatten() {
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // Fields after the parenthesised command: state ppid pgrp … utime(14) stime(15).
        let Some(rest) = stat.rfind(')').map(|i| &stat[i + 2..]) else {
            continue;
        };
        let f: Vec<&str> = rest.split_whitespace().collect();
        if f.len() > 12 && f[2].parse() == Ok(pgid) {
            ticks += f[11].parse::<u64>().unwrap_or(0) + f[12].parse::<u64>().unwrap_or(0);
        }
    }
    ticks as f64 / 100.0
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The `--view` overhead on the real flagship episode (trees/cube_to_bowl.yaml, default
/// layout, not paced) with one headless Chromium showing the live page.
///
/// Runs are interleaved A B A B … (A: `NoObserver`, what `macrotree run` does without `--view`;
/// B: `ViewObserver` streaming to a `LiveViewer` with the browser connected, what `--view`
/// does), so drift in the machine's load hits both alike, with 300 ms between runs so the
/// browser has finished drawing what the previous run sent. It prints, for each, the median
/// wall time, the sim thread's CPU time and its time runnable but waiting for a CPU, and the
/// ratios; plus baselines with no Chromium running (before it starts, after it ends),
/// Chromium's own CPU time and the load average. Nothing is asserted about time.
#[test]
#[ignore = "measurement: cargo test --release --test viewer -- --ignored --nocapture measure_episode_overhead_with_one_browser"]
fn measure_episode_overhead_with_one_browser() {
    if !browser_available() {
        return;
    }
    let reps: usize = std::env::var("MACROTREE_OVERHEAD_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(21);
    let scene = Scene::load().unwrap();
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .load(Path::new("trees/cube_to_bowl.yaml"))
            .expect("flagship tree"),
    );
    let load_before = load_average();
    for _ in 0..3 {
        flagship_episode(&scene, &plan, None); // warm-up: caches, allocator, CPU frequency
    }
    let before: Vec<Times> = (0..reps)
        .map(|_| flagship_episode(&scene, &plan, None).0)
        .collect();

    let live = LiveViewer::start(
        &scene.model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .unwrap();
    let browser = Chromium::open(&live.url(), 1000, 600);
    assert!(
        live.wait_for_clients(1, Duration::from_secs(60)),
        "the page did not connect"
    );
    live.capture_image(Duration::from_secs(120)).unwrap(); // the snapshot is loaded and drawn
    let mut live = Some(live);
    for _ in 0..2 {
        live = flagship_episode(&scene, &plan, live).2; // warm-up with the viewer
    }
    let pgid = browser.child.id();
    std::thread::sleep(Duration::from_secs(2));
    let idle_cpu = group_cpu(pgid);
    std::thread::sleep(Duration::from_secs(2));
    let idle_cpu = (group_cpu(pgid) - idle_cpu) / 2.0;
    let browser_cpu = group_cpu(pgid);
    let published_before = live.as_ref().unwrap().frames_published();
    let (mut base, mut view) = (Vec::new(), Vec::new());
    let mut steps = 0;
    // Between runs the browser catches up with what it was sent (SwiftShader draws on these same
    // cores), so that no run shares the machine with the previous run's rendering.
    let settle = Duration::from_millis(300);
    for _ in 0..reps {
        std::thread::sleep(settle);
        let (a, s, _) = flagship_episode(&scene, &plan, None);
        std::thread::sleep(settle);
        let (b, s2, l) = flagship_episode(&scene, &plan, live.take());
        assert_eq!(s, s2, "the viewer changed the episode");
        steps = s;
        live = l;
        base.push(a);
        view.push(b);
    }
    let live = live.unwrap();
    assert_eq!(live.client_count(), 1, "the browser left during the measurement");
    let frames = (live.frames_published() - published_before) / reps as u64;
    let browser_cpu = (group_cpu(pgid) - browser_cpu) / reps as f64;
    let stats = live.stats();
    drop(browser);
    drop(live);
    std::thread::sleep(Duration::from_millis(500));
    let after: Vec<Times> = (0..reps)
        .map(|_| flagship_episode(&scene, &plan, None).0)
        .collect();

    let med = |v: &[Times], f: fn(&Times) -> f64| median(&v.iter().map(f).collect::<Vec<_>>());
    let wall = |t: &Times| t.wall;
    let cpu = |t: &Times| t.cpu;
    let queued = |t: &Times| t.queued;
    let line = |v: &[Times]| {
        let walls: Vec<f64> = v.iter().map(|t| t.wall).collect();
        format!(
            "wall {:.4} s (min {:.4}, max {:.4}), sim-thread CPU {:.4} s, waiting for a CPU {:.4} s",
            median(&walls),
            walls.iter().copied().fold(f64::INFINITY, f64::min),
            walls.iter().copied().fold(0.0, f64::max),
            med(v, cpu),
            med(v, queued),
        )
    };
    let (bw, vw, bc, vc) = (
        med(&base, wall),
        med(&view, wall),
        med(&base, cpu),
        med(&view, cpu),
    );
    eprintln!(
        "flagship episode (trees/cube_to_bowl.yaml, default layout, {steps} physics steps, not paced), \
         medians of {reps} interleaved pairs:\n\
         \x20 A without --view:          {}\n\
         \x20 B --view + 1 browser:      {}\n\
         \x20 overhead B/A:              wall {:+.1} % (ratio {:.3}), sim-thread CPU {:+.1} % (ratio {:.3})\n\
         \x20 no Chromium running, before: {}\n\
         \x20 no Chromium running, after:  {}\n\
         \x20 Chromium CPU: {browser_cpu:.3} s per pair (idle: {idle_cpu:.3} s/s); {frames} pose frames published per episode\n\
         \x20 {stats:?}\n\
         \x20 load average before / after: {load_before} / {}",
        line(&base),
        line(&view),
        (vw / bw - 1.0) * 100.0,
        vw / bw,
        (vc / bc - 1.0) * 100.0,
        vc / bc,
        line(&before),
        line(&after),
        load_average(),
    );
}
