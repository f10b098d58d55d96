//! `run --view` and `run --record` through the binary: the live server answers and keeps serving
//! after the episode, a taken port is a clear error (exit 2), and a replay file is written.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use crate::support::browser;

fn macrotree() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_macrotree"));
    cmd.current_dir(env!("CARGO_MANIFEST_DIR")).env_remove("RUST_LOG");
    cmd
}

/// Kills the child when dropped, so a failing assertion leaves no server behind.
struct Killed(Child);
impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A child's stderr, read line by line on a thread so that every wait has a deadline even when
/// the child prints nothing.
struct StderrLines(mpsc::Receiver<String>);

impl StderrLines {
    fn of(child: &mut Child) -> Self {
        let stderr = child.stderr.take().expect("stderr is piped");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Self(rx)
    }

    /// The lines printed within `wait` (fewer if the output ends).
    fn collect_for(&self, wait: Duration) -> Vec<String> {
        let deadline = Instant::now() + wait;
        std::iter::from_fn(|| {
            self.0
                .recv_timeout(deadline.saturating_duration_since(Instant::now()))
                .ok()
        })
        .collect()
    }

    /// The next line, or `None` at the end of the output; panics at `deadline`.
    fn next_by(&self, deadline: Instant, what: &str) -> Option<String> {
        let left = deadline.saturating_duration_since(Instant::now());
        match self.0.recv_timeout(left) {
            Ok(line) => Some(line),
            Err(mpsc::RecvTimeoutError::Disconnected) => None,
            Err(mpsc::RecvTimeoutError::Timeout) => panic!("timed out waiting for {what}"),
        }
    }
}

/// Runs `cmd` to completion like [`Command::output`], but kills it and panics after `timeout`.
fn output_within(mut cmd: Command, timeout: Duration) -> Output {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start macrotree");
    let pipe = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = r.read_to_end(&mut buf);
            buf
        })
    };
    let stdout = pipe(Box::new(child.stdout.take().unwrap()));
    let stderr = pipe(Box::new(child.stderr.take().unwrap()));
    let mut child = Killed(child);
    let deadline = Instant::now() + timeout;
    let status = loop {
        if let Some(status) = child.0.try_wait().expect("wait for macrotree") {
            break status;
        }
        assert!(
            Instant::now() < deadline,
            "macrotree did not finish within {timeout:?}"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// `GET path` with `Connection: close`; the whole exchange (connect, request, every read) must
/// finish within 10 s, even if the server sends nothing or trickles bytes: panics otherwise.
fn http_get(addr: &str, path: &str) -> String {
    let limit = Duration::from_secs(10);
    let deadline = Instant::now() + limit;
    let left = || {
        let d = deadline.saturating_duration_since(Instant::now());
        assert!(!d.is_zero(), "GET {path}: no complete answer within {limit:?}");
        d
    };
    let sock: std::net::SocketAddr = addr.parse().expect("host:port");
    let mut s = TcpStream::connect_timeout(&sock, left()).expect("connect to the live view");
    s.set_write_timeout(Some(left())).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut body = Vec::new();
    let mut buf = [0u8; 16 * 1024];
    loop {
        s.set_read_timeout(Some(left())).unwrap();
        match s.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => body.extend_from_slice(&buf[..n]),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                let _ = left();
            }
            Err(_) => break,
        }
    }
    String::from_utf8_lossy(&body).into_owned()
}

/// The `host:port` of the live view in a line of `run --view`'s output.
fn view_addr(line: &str) -> Option<String> {
    let i = line.find("http://127.0.0.1:")?;
    Some(line[i + 7..].split(['/', ' ']).next()?.to_string())
}

/// Starts `run trees/cube_to_bowl.yaml --view --port 0 EXTRA…`; returns the server, its output
/// and its `host:port`.
fn start_view(extra: &[&str]) -> (Killed, StderrLines, String) {
    start_view_of("trees/cube_to_bowl.yaml", extra)
}

/// Starts `run TREE --view --port 0 EXTRA…`; returns the server, its output and its `host:port`.
fn start_view_of(tree: &str, extra: &[&str]) -> (Killed, StderrLines, String) {
    let mut child = macrotree()
        .args(["run", tree, "--view", "--port", "0"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start macrotree");
    let lines = StderrLines::of(&mut child);
    let child = Killed(child);
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let line = lines
            .next_by(deadline, "the live view URL")
            .expect("macrotree ended without printing the URL");
        if let Some(addr) = view_addr(&line) {
            return (child, lines, addr);
        }
    }
}

#[test]
fn live_page_of_a_real_episode_shows_the_robot_and_the_tree_in_a_browser() {
    if !browser::browser_available() {
        return;
    }
    // A slowed-down episode, so the browser joins while it runs.
    let (_server, _lines, addr) = start_view(&["--speed", "0.5"]);
    let chromium = browser::Chromium::open(&format!("http://{addr}/"), 1000, 600);
    let mut dt = chromium.devtools();
    let deadline = Instant::now() + Duration::from_secs(60);
    // The tree panel lists the flagship's nodes with live statuses (some running or done).
    loop {
        let shown = dt.eval(
            "JSON.stringify([document.querySelectorAll('#tree .node').length, \
             document.querySelectorAll('#tree .node.running, #tree .node.success').length, \
             document.querySelector('#conn').textContent])",
        );
        let v: serde_json::Value = serde_json::from_str(shown.as_str().unwrap_or("[]")).unwrap_or_default();
        if v[0].as_u64().unwrap_or(0) >= 15 && v[1].as_u64().unwrap_or(0) >= 1 && v[2] == "live" {
            break;
        }
        assert!(Instant::now() < deadline, "panel shows {shown}");
        std::thread::sleep(Duration::from_millis(100));
    }
    // The scene (meshes stream in after the page loads) shows the robot, the cube and the bowl.
    let mut last = None;
    while Instant::now() < deadline {
        let png = dt.screenshot();
        let classes = browser::classify(&browser::decode_png(&png));
        if classes.robot_dark > 100 && classes.cube > 15 && classes.bowl > 60 && classes.distinct > 30 {
            if let Some(path) = std::env::var_os("MACROTREE_VIEW_SCREENSHOT") {
                std::fs::write(path, &png).unwrap();
            }
            return;
        }
        last = Some(classes);
        std::thread::sleep(Duration::from_millis(250));
    }
    panic!("the scene never showed robot, cube and bowl: {last:?}");
}

#[test]
fn view_serves_the_page_and_keeps_serving_after_the_episode() {
    let (child, lines, addr) = start_view(&[]);
    // "episode over; still serving" comes after the episode.
    let deadline = Instant::now() + Duration::from_secs(120);
    let over = std::iter::from_fn(|| lines.next_by(deadline, "the end of the episode"))
        .any(|line| line.contains("still serving"));
    assert!(over, "the episode did not finish");
    let page = http_get(&addr, "/");
    assert!(
        page.starts_with("HTTP/1.1 200"),
        "{}",
        &page[..page.len().min(200)]
    );
    assert!(page.contains("macrotree"), "not our page");
    // Still serving: a second request after the episode is answered too.
    assert!(http_get(&addr, "/").starts_with("HTTP/1.1 200"));
    drop(child);
}

/// A tree file's `breakpoints:` pause `run --view` as `--break` does: the episode holds at the
/// first `home` until the page (here a websocket client sending the page's message) resumes it,
/// then ends with the tree's result. A pattern that matches no node is refused, located at its
/// entry, by `validate` and by `run --view` before serving.
#[test]
fn breakpoints_declared_in_the_tree_file_pause_run_view_until_resumed() {
    let dir = std::env::temp_dir().join(format!("macrotree-declared-break-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let flagship =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/trees/cube_to_bowl.yaml")).unwrap();
    let tree = dir.join("paused.yaml");
    std::fs::write(&tree, format!("{flagship}\nbreakpoints: [\"main/*/home#1\"]\n")).unwrap();
    let (server, lines, addr) = start_view_of(tree.to_str().unwrap(), &[]);
    // Held at the breakpoint: no end of the episode for 3 s.
    let before = lines.collect_for(Duration::from_secs(3));
    assert!(
        !before.iter().any(|l| l.contains("still serving")),
        "the episode did not hold at its declared breakpoint: {before:?}"
    );
    let mut ws = crate::websocket::connect(addr.parse().unwrap());
    ws.send(tungstenite::Message::text(r#"{"type":"monitor","op":"resume"}"#))
        .unwrap();
    // Read what the server sends, as the page does (a client that stops reading is dropped).
    std::thread::spawn(move || while ws.read().is_ok() {});
    let deadline = Instant::now() + Duration::from_secs(120);
    let after: Vec<String> = std::iter::from_fn(|| lines.next_by(deadline, "the end of the episode"))
        .take_while(|line| !line.contains("still serving"))
        .collect();
    assert!(
        after.iter().any(|l| l.contains("success")),
        "the resumed episode did not succeed: {after:?}"
    );
    drop(server);

    // A declared pattern that matches nothing: located at its entry, before serving.
    let bad = dir.join("bad.yaml");
    std::fs::write(&bad, format!("{flagship}\nbreakpoints:\n  - \"main/**/grsap\"\n")).unwrap();
    let line = flagship.lines().count() + 3;
    for args in [
        vec!["validate", bad.to_str().unwrap()],
        vec!["run", bad.to_str().unwrap(), "--view", "--port", "0"],
    ] {
        let mut cmd = macrotree();
        cmd.args(&args);
        let out = output_within(cmd, Duration::from_secs(60));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(&format!("bad.yaml:{line}:5")),
            "{args:?}: {stderr}"
        );
        assert!(
            stderr.contains("matches no node") && stderr.contains("grasp"),
            "{stderr}"
        );
        assert!(!stderr.contains("live view:"), "refused before serving: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_taken_port_exits_2_and_says_what_to_do() {
    let blocker = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = blocker.local_addr().unwrap().port().to_string();
    let mut cmd = macrotree();
    cmd.args(["run", "trees/cube_to_bowl.yaml", "--view", "--port", &port]);
    let out = output_within(cmd, Duration::from_secs(60));
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--port"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_break_pattern_that_matches_no_node_exits_2_before_serving() {
    let mut cmd = macrotree();
    cmd.args([
        "run",
        "trees/cube_to_bowl.yaml",
        "--view",
        "--port",
        "0",
        "--break",
        "main/**/grsap",
    ]);
    let out = output_within(cmd, Duration::from_secs(60));
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("matches no node") && stderr.contains("grasp"),
        "{stderr}"
    );
    assert!(!stderr.contains("live view:"), "refused before serving: {stderr}");
    // A breakpoint needs the live page that resumes it.
    let mut cmd = macrotree();
    cmd.args(["run", "trees/cube_to_bowl.yaml", "--break", "main/**/grasp"]);
    let out = output_within(cmd, Duration::from_secs(60));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--view"));
}

#[test]
fn record_writes_a_self_contained_replay() {
    record_and_check("trees/cube_to_bowl.yaml", "scripted");
}

#[test]
fn a_policy_tree_records_a_self_contained_replay() {
    let report = record_and_check("trees/learned_pick_alone.yaml", "policy");
    let policy_ran = report["nodes"]
        .as_array()
        .expect("the report lists its nodes")
        .iter()
        .any(|n| {
            n["path"]
                .as_str()
                .is_some_and(|p| p.ends_with("policy[approach and grasp]"))
        });
    assert!(policy_ran, "the learned pick is a node of the replayed episode");
}

/// Runs `tree` with `--record`, checks the replay holds the episode ([`check_replay`]) and
/// returns the JSON report.
fn record_and_check(tree: &str, name: &str) -> serde_json::Value {
    let dir = std::env::temp_dir().join(format!("macrotree-record-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("episode.html");
    let mut cmd = macrotree();
    cmd.args(["run", tree, "--json", "--record", file.to_str().unwrap()]);
    let out = output_within(cmd, Duration::from_secs(180));
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(&file).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(html.len() < 15_000_000, "replay is {} bytes", html.len());
    assert!(
        !html.contains("<script src=\"http"),
        "the replay must not load anything from the network"
    );
    assert!(html.contains("MeshCat"), "the viewer bundle is not inlined");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value =
        serde_json::from_str(stdout.lines().last().expect("a JSON report")).expect("the report is JSON");
    check_replay(&html, &report);
    report
}

/// The replay really holds the episode: its metadata covers the episode's simulated time at its
/// frame rate, its one `set_animation` has a track of exactly that many frames for the cube, and
/// the cube's last frame is where the episode left it.
fn check_replay(html: &str, report: &serde_json::Value) {
    use base64::Engine;
    // `macrotree.replay([ "base64", … ], META);` — the page's data script.
    let start = html.find("macrotree.replay([").expect("the replay call") + "macrotree.replay(".len();
    let end = start + html[start..].find("]").expect("the command list") + 1;
    let commands: Vec<String> = serde_json::from_str(&trailing_commas_removed(&html[start..end]))
        .expect("the command list is a list of strings");
    let meta_end = start + html[start..].find(");\n</script>").expect("the end of the call");
    let meta: serde_json::Value =
        serde_json::from_str(html[end..meta_end].trim_start_matches(", ")).expect("the metadata is JSON");
    let sim_time = report["sim_time_s"].as_f64().expect("sim_time_s");
    let fps = meta["fps"].as_f64().expect("fps");
    let frames = meta["frames"].as_u64().expect("frames") as f64;
    let duration = meta["duration"].as_f64().expect("duration");
    eprintln!(
        "replay: {frames} frames at {fps} fps over {duration:.3} s; the episode simulated {sim_time:.3} s"
    );
    assert_eq!(fps, 30.0);
    assert!(
        (duration - sim_time).abs() <= 1.0 / fps + 1e-9,
        "{duration} s of {sim_time} s"
    );
    assert!(
        (frames - sim_time * fps).abs() <= 2.0,
        "{frames} frames for {sim_time} s at {fps} fps"
    );
    // Exactly one set_animation; the cube's position track has `frames` samples and ends at the
    // episode's final cube position.
    let engine = base64::engine::general_purpose::STANDARD;
    let mut animations = Vec::new();
    for c in &commands {
        let bytes = engine.decode(c).expect("base64");
        let v = rmpv::decode::read_value(&mut bytes.as_slice()).expect("msgpack");
        if field(&v, "type").and_then(|t| t.as_str()) == Some("set_animation") {
            animations.push(v);
        }
    }
    assert_eq!(animations.len(), 1, "set_animation commands");
    let animated = field(&animations[0], "animations")
        .and_then(|a| a.as_array())
        .expect("animations");
    let paths: Vec<&str> = animated
        .iter()
        .filter_map(|a| field(a, "path").and_then(|p| p.as_str()))
        .collect();
    let cube = animated
        .iter()
        .find(|a| {
            field(a, "path")
                .and_then(|p| p.as_str())
                .is_some_and(|p| p == "/mujoco/obj_cube")
        })
        .unwrap_or_else(|| panic!("the cube is not animated: {paths:?}"));
    let tracks = field(field(cube, "clip").expect("clip"), "tracks")
        .and_then(|t| t.as_array())
        .expect("tracks");
    let position = tracks
        .iter()
        .find(|t| field(t, "name").and_then(|n| n.as_str()) == Some(".position"))
        .expect("a position track");
    let floats = |name: &str| -> Vec<f32> {
        match field(position, name) {
            Some(rmpv::Value::Ext(_, b)) => b
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            other => panic!("{name}: {other:?}"),
        }
    };
    let times = floats("times");
    let values = floats("values");
    assert_eq!(times.len() as f64, frames, "cube track frames");
    assert_eq!(values.len(), times.len() * 3);
    let last = &values[values.len() - 3..];
    let end = report["cube_final"].as_array().expect("cube_final");
    for k in 0..3 {
        let want = end[k].as_f64().unwrap();
        assert!(
            (f64::from(last[k]) - want).abs() < 1e-4,
            "cube's last frame {last:?}, episode end {end:?}"
        );
    }
}

fn field<'a>(v: &'a rmpv::Value, key: &str) -> Option<&'a rmpv::Value> {
    v.as_map()?
        .iter()
        .find(|(k, _)| k.as_str() == Some(key))
        .map(|(_, v)| v)
}

fn trailing_commas_removed(list: &str) -> String {
    let mut out = list
        .trim_end_matches(']')
        .trim_end()
        .trim_end_matches(',')
        .to_string();
    out.push(']');
    out
}

/// CPU time used so far by process `pid` (`/proc/PID/stat` utime + stime, in clock ticks of
/// 1/100 s), seconds.
fn process_cpu(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).expect("the server is running");
    // Fields after the parenthesised command: state(3) … utime(14) stime(15).
    let rest = &stat[stat.rfind(')').expect("a stat line") + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f[11].parse::<u64>().unwrap() + f[12].parse::<u64>().unwrap();
    ticks as f64 / 100.0
}

/// Issue 13, item 8: when `accept` fails because the process has no file descriptor left, the
/// acceptor pauses (and says so once) instead of spinning, and serves again once descriptors
/// are free.
#[test]
fn out_of_file_descriptors_the_acceptor_backs_off_instead_of_spinning() {
    let (child, lines, addr) = start_view(&[]);
    let pid = child.0.id();
    let deadline = Instant::now() + Duration::from_secs(120);
    let over = std::iter::from_fn(|| lines.next_by(deadline, "the end of the episode"))
        .any(|line| line.contains("still serving"));
    assert!(over, "the episode did not finish");
    // Leave the server 4 descriptors: two connections take them (socket + the handle kept to
    // evict it); the next accept fails with EMFILE and stays failing while they are open.
    let open_fds = std::fs::read_dir(format!("/proc/{pid}/fd")).unwrap().count();
    let limit = open_fds + 4;
    let status = Command::new("prlimit")
        .args(["--pid", &pid.to_string(), &format!("--nofile={limit}:{limit}")])
        .status()
        .expect("run prlimit (util-linux)");
    assert!(status.success(), "prlimit failed: {status}");
    let held: Vec<TcpStream> = (0..8).map(|_| TcpStream::connect(&addr).unwrap()).collect();
    std::thread::sleep(Duration::from_millis(500));
    let window = Duration::from_secs(2);
    let before = process_cpu(pid);
    std::thread::sleep(window);
    let used = process_cpu(pid) - before;
    eprintln!(
        "out of descriptors ({open_fds} open, limit {limit}): the idle server used {used:.2} s of CPU in {window:?}"
    );
    assert!(
        used < 0.15 * window.as_secs_f64(),
        "the acceptor spins: {used:.2} s of CPU in {window:?}"
    );
    // Descriptors free again: served within the longest pause.
    drop(held);
    let served = Instant::now();
    let page = loop {
        let page = http_get(&addr, "/");
        if page.starts_with("HTTP/1.1 200") || served.elapsed() > Duration::from_secs(15) {
            break page;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(page.starts_with("HTTP/1.1 200"), "not served again: {page:.200}");
    let log = lines.collect_for(Duration::from_millis(500));
    let warnings = log
        .iter()
        .filter(|l| l.contains("cannot accept connections"))
        .count();
    assert_eq!(warnings, 1, "the failure is logged once: {log:#?}");
    assert!(
        log.iter().any(|l| l.contains("accepting connections again")),
        "{log:#?}"
    );
    drop(child);
}
