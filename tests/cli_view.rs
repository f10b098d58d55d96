//! `run --view` and `run --record` through the binary: the live server answers and keeps serving
//! after the episode, a taken port is a clear error (exit 2), and a replay file is written.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

#[path = "support/browser.rs"]
mod browser;

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

fn http_get(addr: &str, path: &str) -> String {
    let mut s = TcpStream::connect(addr).expect("connect to the live view");
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut body = Vec::new();
    let _ = s.read_to_end(&mut body);
    String::from_utf8_lossy(&body).into_owned()
}

/// The `host:port` of the live view in a line of `run --view`'s output.
fn view_addr(line: &str) -> Option<String> {
    let i = line.find("http://127.0.0.1:")?;
    Some(line[i + 7..].split(['/', ' ']).next()?.to_string())
}

/// Starts `run TREE --view --port 0 EXTRA…`; returns the server, its output and its `host:port`.
fn start_view(extra: &[&str]) -> (Killed, StderrLines, String) {
    let mut child = macrotree()
        .args(["run", "trees/cube_to_bowl.yaml", "--view", "--port", "0"])
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
fn record_writes_a_self_contained_replay() {
    let dir = std::env::temp_dir().join(format!("macrotree-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("episode.html");
    let mut cmd = macrotree();
    cmd.args([
        "run",
        "trees/cube_to_bowl.yaml",
        "--record",
        file.to_str().unwrap(),
    ]);
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
    assert!(
        html.contains("set_animation") || html.contains("animation"),
        "no animation in the replay"
    );
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
