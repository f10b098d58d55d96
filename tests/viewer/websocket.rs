//! Websocket integration tests of the live viewer without a browser: a tungstenite client
//! plays the browser.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use macrotree::sim::{HOME_Q, Scene, Sim};
use macrotree::viewer::{
    LiveViewer, ServerLimits, TreeNodeView, ViewerError, ViewerOptions, bundle_help, load_bundle,
};
use tungstenite::{Message, WebSocket};

type Client = WebSocket<TcpStream>;

fn opts0() -> ViewerOptions {
    ViewerOptions {
        port: 0,
        ..ViewerOptions::default()
    }
}

/// Starts a viewer on a free port, or `None` (skip) when the bundle is missing outside CI.
fn start(scene: &Scene) -> Option<LiveViewer> {
    start_with(scene, ServerLimits::DEFAULT)
}

/// [`start`] with other limits.
fn start_with(scene: &Scene, limits: ServerLimits) -> Option<LiveViewer> {
    let opts = ViewerOptions { limits, ..opts0() };
    match LiveViewer::start(&scene.model, &opts) {
        Ok(v) => Some(v),
        Err(ViewerError::BundleMissing { path }) if std::env::var_os("CI").is_none() => {
            eprintln!("SKIPPED: {}", bundle_help(&path));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Connects as the live page does: from the server's own origin.
pub(crate) fn connect(addr: SocketAddr) -> Client {
    let stream = TcpStream::connect(addr).unwrap();
    stream.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    let (ws, _) = tungstenite::client(page_request(addr), stream).unwrap();
    ws
}

/// A websocket request to `addr` with the `Origin` the live page sends.
fn page_request(addr: SocketAddr) -> tungstenite::handshake::client::Request {
    use tungstenite::client::IntoClientRequest as _;
    let mut req = format!("ws://{addr}/").into_client_request().unwrap();
    req.headers_mut()
        .insert("Origin", format!("http://{addr}").parse().unwrap());
    req
}

/// A decoded server message.
#[derive(Debug)]
enum Msg {
    Cmd(Cmd),
    Text(serde_json::Value),
}

/// A decoded MeshCat command.
#[derive(Debug, PartialEq)]
struct Cmd {
    /// `type`, e.g. `set_transform`.
    ty: String,
    /// `path` (empty when the command has none).
    path: String,
    /// `matrix` of a `set_transform`: 16 column-major numbers.
    matrix: Option<Vec<f64>>,
}

/// A field of a msgpack map.
fn field<'a>(map: &'a [(rmpv::Value, rmpv::Value)], key: &str) -> Option<&'a rmpv::Value> {
    map.iter().find(|(k, _)| k.as_str() == Some(key)).map(|(_, v)| v)
}

fn recv(ws: &mut Client) -> Msg {
    loop {
        match ws.read().expect("message") {
            Message::Binary(b) => {
                let value = rmpv::decode::read_value(&mut &b[..]).unwrap();
                let map = value.as_map().expect("a command is a msgpack map");
                let text = |key| field(map, key).and_then(rmpv::Value::as_str).map(str::to_owned);
                let matrix = field(map, "matrix")
                    .and_then(rmpv::Value::as_array)
                    .map(|a| a.iter().map(|v| v.as_f64().expect("float64 entries")).collect());
                return Msg::Cmd(Cmd {
                    ty: text("type").expect("a command has a type"),
                    path: text("path").unwrap_or_default(),
                    matrix,
                });
            }
            Message::Text(t) => return Msg::Text(serde_json::from_str(t.as_str()).unwrap()),
            _ => {}
        }
    }
}

/// Reads binary commands (skipping text frames) until `n` were read.
fn recv_cmds(ws: &mut Client, n: usize) -> Vec<Cmd> {
    let mut out = Vec::new();
    while out.len() < n {
        if let Msg::Cmd(cmd) = recv(ws) {
            out.push(cmd);
        }
    }
    out
}

/// The `set_transform` a body at `xpos` with MuJoCo's row-major `xmat` must get: three.js's
/// column-major 4×4 matrix.
fn expected_transform(path: &str, xpos: [f64; 3], xmat: [f64; 9]) -> Cmd {
    let x = xmat;
    let matrix = vec![
        x[0], x[3], x[6], 0.0, x[1], x[4], x[7], 0.0, x[2], x[5], x[8], 0.0, xpos[0], xpos[1], xpos[2], 1.0,
    ];
    Cmd {
        ty: "set_transform".into(),
        path: path.into(),
        matrix: Some(matrix),
    }
}

/// Moves the arm so that every step changes the poses.
fn wiggle(sim: &mut Sim) {
    let t = sim.time();
    let mut q = HOME_Q;
    q[0] += 0.5 * (3.0 * t).sin();
    q[2] += 0.3 * (2.0 * t).sin();
    sim.set_arm_ctrl(&q);
    sim.step();
}

#[test]
fn late_joiner_gets_the_latest_snapshot_then_live_frames() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let mut sim = Sim::new(&scene);
    for _ in 0..60 {
        for _ in 0..16 {
            wiggle(&mut sim);
        }
        v.publish_poses(sim.data(), sim.time());
    }
    assert_eq!(v.frames_published(), 60);
    let layout = v.layout().clone();
    let drawn: Vec<usize> = (0..layout.body_paths.len())
        .filter(|&b| layout.body_drawn[b])
        .collect();
    // Scene settings (grid, axes, camera position, camera target) + objects + one transform per body.
    let expected = 4 + layout.geoms.len() + drawn.len();

    let mut a = connect(v.local_addr());
    let snapshot = recv_cmds(&mut a, expected);
    let count = |ty: &str, path: &str| snapshot.iter().filter(|c| c.ty == ty && c.path == path).count();
    for g in &layout.geoms {
        assert_eq!(count("set_object", &g.path), 1, "{}", g.path);
    }
    for &b in &drawn {
        // Exactly one transform per body however many frames were published: no history.
        assert_eq!(
            count("set_transform", &layout.body_paths[b]),
            1,
            "{}",
            layout.body_paths[b]
        );
    }
    // And it is the latest pose.
    let d = sim.data();
    let shoulder = layout
        .body_paths
        .iter()
        .position(|p| p == "/mujoco/ur5e_shoulder_link")
        .unwrap();
    let latest = expected_transform(
        &layout.body_paths[shoulder],
        d.xpos()[shoulder],
        d.xmat()[shoulder],
    );
    assert!(snapshot.contains(&latest));
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));

    // Live frames follow, only for bodies that moved; a second browser gets them too.
    let mut b = connect(v.local_addr());
    let _ = recv_cmds(&mut b, expected);
    assert!(v.wait_for_clients(2, Duration::from_secs(5)));
    for _ in 0..16 {
        wiggle(&mut sim);
    }
    v.publish_poses(sim.data(), sim.time());
    let d = sim.data();
    let next = expected_transform(
        &layout.body_paths[shoulder],
        d.xpos()[shoulder],
        d.xmat()[shoulder],
    );
    for ws in [&mut a, &mut b] {
        let frame = recv_cmds(ws, 1);
        assert_eq!(frame[0].ty, "set_transform");
        let mut seen = frame;
        while !seen.contains(&next) {
            seen.extend(recv_cmds(ws, 1));
            assert!(
                seen.len() <= drawn.len(),
                "one frame holds at most one transform per body"
            );
        }
        assert!(
            seen.iter()
                .all(|c| c.ty == "set_transform" && c.path != "/mujoco/world")
        );
    }

    // Closed tabs are cleaned up: a proper close, then an abrupt drop.
    a.close(None).unwrap();
    let _ = a.flush();
    drop(a);
    let deadline = Instant::now() + Duration::from_secs(5);
    while v.client_count() > 1 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(v.client_count(), 1);
    drop(b);
    // An abrupt drop is noticed at the next write at the latest.
    let deadline = Instant::now() + Duration::from_secs(5);
    while v.client_count() > 0 && Instant::now() < deadline {
        wiggle(&mut sim);
        v.publish_poses(sim.data(), sim.time());
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(v.client_count(), 0);
}

#[test]
fn a_stalled_reader_gets_coalesced_poses_and_never_blocks_the_sim() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let layout = v.layout().clone();
    let drawn = layout.body_drawn.iter().filter(|&&d| d).count();
    let mut ws = connect(v.local_addr());
    let _ = recv_cmds(&mut ws, 4 + layout.geoms.len());
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));

    // The client stops reading; the sim publishes far more than the socket buffers hold
    // (~4 KB per frame, 6000 frames ≈ 25 MB).
    let mut sim = Sim::new(&scene);
    let frames = 6000;
    let mut worst = Duration::ZERO;
    let started = Instant::now();
    for _ in 0..frames {
        wiggle(&mut sim);
        let t = Instant::now();
        v.publish_poses(sim.data(), sim.time());
        worst = worst.max(t.elapsed());
    }
    let publishing = started.elapsed();
    assert!(worst < Duration::from_millis(200), "a publish took {worst:?}");
    let stats = v.stats();
    assert_eq!(stats.len(), 1);
    assert_eq!(stats[0].frames_offered, frames);
    assert!(
        stats[0].frames_sent < frames / 2,
        "frames must be coalesced while the reader stalls: {stats:?}"
    );

    // Now drain: the last pose arrives, and far fewer transforms than were published.
    let shoulder = layout
        .body_paths
        .iter()
        .position(|p| p == "/mujoco/ur5e_shoulder_link")
        .unwrap();
    let d = sim.data();
    let last = expected_transform(
        &layout.body_paths[shoulder],
        d.xpos()[shoulder],
        d.xmat()[shoulder],
    );
    let mut shoulder_msgs = 0u64;
    let mut total = 0usize;
    loop {
        let cmd = recv_cmds(&mut ws, 1).remove(0);
        total += 1;
        if cmd.path == layout.body_paths[shoulder] {
            shoulder_msgs += 1;
            if cmd == last {
                break;
            }
        }
    }
    eprintln!(
        "published {frames} frames in {publishing:?} (worst call {worst:?}); the stalled reader got {shoulder_msgs} shoulder poses, {total} messages; {:?}",
        v.stats()
    );
    assert!(shoulder_msgs < frames * 3 / 4, "{shoulder_msgs}");
    assert!(total < frames as usize * drawn);
}

#[test]
fn port_in_use_is_reported_and_port_zero_picks_a_free_one() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let port = v.local_addr().port();
    assert_ne!(port, 0);
    assert!(v.url().starts_with("http://127.0.0.1:"));
    let err = LiveViewer::start(
        &scene.model,
        &ViewerOptions {
            port,
            ..ViewerOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, ViewerError::PortInUse { port: p } if p == port),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(
        text.contains(&port.to_string()) && text.contains("--port"),
        "{text}"
    );
}

fn http_get(addr: SocketAddr, path: &str) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut buf = Vec::new();
    s.read_to_end(&mut buf).unwrap();
    let split = buf.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    (
        String::from_utf8_lossy(&buf[..split]).into_owned(),
        buf[split + 4..].to_vec(),
    )
}

#[test]
fn http_serves_the_page_the_bundle_and_a_download() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let addr = v.local_addr();
    let (head, body) = http_get(addr, "/");
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    let page = String::from_utf8(body).unwrap();
    assert!(page.contains("macrotree.live()") && page.contains("/main.min.js"));
    let (head, body) = http_get(addr, "/main.min.js");
    assert!(head.starts_with("HTTP/1.1 200") && head.contains("javascript"));
    assert_eq!(body, load_bundle().unwrap().to_vec());
    let (head, body) = http_get(addr, "/viewer.js");
    assert!(head.starts_with("HTTP/1.1 200"));
    assert_eq!(body, include_bytes!("../../assets/viewer/viewer.js"));
    let (head, _) = http_get(addr, "/nope");
    assert!(head.starts_with("HTTP/1.1 404"));
    let (head, body) = http_get(addr, "/download");
    assert!(head.starts_with("HTTP/1.1 200"));
    let html = String::from_utf8(body).unwrap();
    assert!(html.contains("macrotree.replay(") && !html.contains("src=\"/main.min.js\""));
}

#[test]
fn tree_panel_and_capture_replies_travel_as_text_frames() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let node = |path: &str, parent: Option<usize>| TreeNodeView {
        path: path.into(),
        kind: "sequence".into(),
        name: path.into(),
        parent,
        ..TreeNodeView::default()
    };
    v.set_tree(vec![node("root", None), node("root/0", Some(0))]);
    for i in 0..250 {
        v.publish_tree_status(vec!["running", "success"], vec![serde_json::json!({ "i": i })]);
    }
    // A late joiner gets the tree, then the statuses with the bounded event history.
    let mut ws = connect(v.local_addr());
    let mut texts = Vec::new();
    while texts.len() < 2 {
        if let Msg::Text(t) = recv(&mut ws) {
            texts.push(t);
        }
    }
    assert_eq!(texts[0]["type"], "tree");
    assert_eq!(texts[0]["nodes"][1]["parent"], 0);
    assert_eq!(texts[1]["type"], "status");
    assert_eq!(texts[1]["statuses"], serde_json::json!(["running", "success"]));
    let events = texts[1]["events"].as_array().unwrap();
    assert_eq!(events.len(), macrotree::viewer::EVENT_HISTORY);
    assert_eq!(events.last().unwrap()["event"]["i"], 249);
    // New statuses follow with only the new events.
    v.publish_tree_status_with_attempts(vec!["failure", "halted"], vec![0, 3], vec!["halted".into()]);
    let status = loop {
        if let Msg::Text(t) = recv(&mut ws)
            && t["type"] == "status"
        {
            break t;
        }
    };
    assert_eq!(status["statuses"], serde_json::json!(["failure", "halted"]));
    assert_eq!(status["attempts"], serde_json::json!([0, 3]));
    assert_eq!(status["events"].as_array().unwrap().len(), 1);

    // capture_image goes to one client, whose text reply is decoded.
    let answer = std::thread::spawn(move || {
        loop {
            if let Msg::Cmd(Cmd { ty, .. }) = recv(&mut ws)
                && ty == "capture_image"
            {
                let reply = r#"{"type":"img","data":"data:image/png;base64,AAEC"}"#;
                ws.send(Message::text(reply)).unwrap();
                return ws;
            }
        }
    });
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    let png = v.capture_image(Duration::from_secs(10)).unwrap();
    assert_eq!(png, [0, 1, 2]);
    let ws = answer.join().unwrap();
    // Dropping the viewer closes the connection.
    drop(v);
    let mut ws = ws;
    let closed = (0..10_000).any(|_| match ws.read() {
        Ok(Message::Close(_)) | Err(_) => true,
        Ok(_) => false,
    });
    assert!(closed);
}

#[test]
fn capture_without_a_browser_fails_cleanly() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let err = v.capture_image(Duration::from_millis(100)).unwrap_err();
    assert!(matches!(err, ViewerError::NoClient(_)), "{err}");
}

/// Sends `head` on a fresh connection; returns the response's status line ("" if the server
/// closed without answering). Bounded: 10 s.
fn status_of(addr: SocketAddr, head: &str) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(head.as_bytes()).unwrap();
    let mut buf = Vec::new();
    let mut byte = [0u8; 1];
    while !buf.ends_with(b"\r\n") && matches!(s.read(&mut byte), Ok(1)) {
        buf.push(byte[0]);
    }
    String::from_utf8_lossy(&buf).trim_end().to_owned()
}

/// A websocket upgrade request head with `host` and, when given, `origin`.
fn upgrade_head(host: &str, origin: Option<&str>) -> String {
    let origin = origin.map_or(String::new(), |o| format!("Origin: {o}\r\n"));
    format!(
        "GET / HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n{origin}\r\n"
    )
}

/// Issue 13, item 5: only the server's own pages may open the websocket.
#[test]
fn websocket_upgrades_from_other_origins_are_refused_with_403() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let addr = v.local_addr();
    let port = addr.port();
    let host = format!("127.0.0.1:{port}");
    for origin in [
        None,
        Some("null".to_owned()),
        Some("http://evil.example".to_owned()),
        Some(format!("http://evil.example:{port}")),
        Some(format!("http://127.0.0.1:{}", port.wrapping_add(1))),
        Some(format!("https://127.0.0.1:{port}")),
        Some(format!("http://127.0.0.1.evil.example:{port}")),
    ] {
        let status = status_of(addr, &upgrade_head(&host, origin.as_deref()));
        assert!(status.starts_with("HTTP/1.1 403"), "Origin {origin:?}: {status}");
    }
    assert_eq!(v.client_count(), 0);
    for name in ["127.0.0.1", "localhost", "[::1]"] {
        let origin = format!("http://{name}:{port}");
        let status = status_of(addr, &upgrade_head(&format!("{name}:{port}"), Some(&origin)));
        assert!(status.starts_with("HTTP/1.1 101"), "Origin {origin}: {status}");
    }
}

/// Issue 13, item 5: DNS rebinding. A page whose own name resolves to 127.0.0.1 still sends
/// that name in `Host`; such requests are refused.
#[test]
fn requests_with_a_foreign_host_are_refused_with_403() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let addr = v.local_addr();
    let port = addr.port();
    let get = |host: Option<&str>| {
        let host = host.map_or(String::new(), |h| format!("Host: {h}\r\n"));
        status_of(
            addr,
            &format!("GET / HTTP/1.1\r\n{host}Connection: close\r\n\r\n"),
        )
    };
    for host in [
        None,
        Some(format!("evil.example:{port}")),
        Some(format!("127.0.0.1:{}", port.wrapping_add(1))),
        Some("127.0.0.1".to_owned()),
        Some(format!("localhost.evil.example:{port}")),
    ] {
        let status = get(host.as_deref());
        assert!(status.starts_with("HTTP/1.1 403"), "Host {host:?}: {status}");
    }
    // A same-host request from a foreign page (it carries that page's Origin) is refused too.
    let foreign = status_of(
        addr,
        &format!("GET /download HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: http://evil.example\r\n\r\n"),
    );
    assert!(foreign.starts_with("HTTP/1.1 403"), "{foreign}");
    for name in ["127.0.0.1", "localhost", "LocalHost", "[::1]"] {
        let status = get(Some(&format!("{name}:{port}")));
        assert!(status.starts_with("HTTP/1.1 200"), "Host {name}: {status}");
    }
}

/// The resident set size of this process (`/proc/self/status`), bytes.
fn rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .unwrap_or(0)
        * 1024
}

/// Waits up to `timeout` for `cond`; whether it held.
fn eventually(timeout: Duration, mut cond: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + timeout;
    loop {
        if cond() {
            return true;
        }
        if Instant::now() >= deadline {
            return false;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Issue 13, item 6: client messages are capped at a few KiB.
#[test]
fn a_client_sending_a_large_message_is_dropped_and_the_server_stays_healthy() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let addr = v.local_addr();
    let limit = ServerLimits::DEFAULT.max_client_message;
    let mut ws = connect(addr);
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    // The client reads the scene first: its thread polls input between writes.
    ws.get_ref()
        .set_read_timeout(Some(Duration::from_millis(300)))
        .unwrap();
    while ws.read().is_ok() {}
    // A message within the limit is read (and ignored): the client stays.
    ws.send(Message::text(format!(
        "{{\"pad\":\"{}\"}}",
        "x".repeat(limit - 16)
    )))
    .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        v.client_count(),
        1,
        "a message within the limit dropped the client"
    );
    // One byte over: dropped, with a close frame or a reset.
    let _ = ws.send(Message::Binary(vec![0u8; limit + 1].into()));
    let deadline = Instant::now() + Duration::from_secs(10);
    let ended = loop {
        match ws.read() {
            Ok(Message::Close(_)) => break true,
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                if Instant::now() >= deadline {
                    break false;
                }
            }
            Err(_) => break true,
        }
    };
    assert!(ended, "a client sending {} bytes is still served", limit + 1);
    assert!(eventually(Duration::from_secs(5), || v.client_count() == 0));

    // A frame that announces 60 MiB is refused at its header: the server closes the
    // connection instead of reading (and buffering) the payload.
    let before = rss();
    let announced: u64 = 60 << 20;
    let mut raw = TcpStream::connect(addr).unwrap();
    raw.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    raw.set_write_timeout(Some(Duration::from_secs(10))).unwrap();
    raw.write_all(upgrade_head(&addr.to_string(), Some(&format!("http://{addr}"))).as_bytes())
        .unwrap();
    let mut header = vec![0x82, 0xff]; // binary, masked, 64-bit length
    header.extend_from_slice(&announced.to_be_bytes());
    header.extend_from_slice(&[1, 2, 3, 4]); // mask
    raw.write_all(&header).unwrap();
    // Read what the server sends (the scene) meanwhile, so that it gets to read our frame.
    let drain = raw.try_clone().unwrap();
    let drainer = std::thread::spawn(move || std::io::copy(&mut &drain, &mut std::io::sink()));
    let chunk = vec![0u8; 64 << 10];
    let mut written = 0u64;
    let error = loop {
        if written >= announced {
            break None;
        }
        match raw.write(&chunk) {
            Ok(n) => written += n as u64,
            Err(e) => break Some(e.kind()),
        }
    };
    let grown = rss().saturating_sub(before);
    eprintln!(
        "a 60 MiB frame: the connection was closed after {:.1} MiB had been written to the socket ({error:?}); this process grew by {:.1} MiB",
        written as f64 / f64::from(1 << 20),
        grown as f64 / f64::from(1 << 20)
    );
    use std::io::ErrorKind::{BrokenPipe, ConnectionAborted, ConnectionReset};
    assert!(
        matches!(error, Some(BrokenPipe | ConnectionReset | ConnectionAborted)),
        "the server did not close the connection: {error:?} after {written} bytes"
    );
    let _ = drainer.join();
    assert!(eventually(Duration::from_secs(5), || v.client_count() == 0));

    // Still healthy: the page is served and a new client gets the scene.
    let (head, _) = http_get(addr, "/");
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    let mut fresh = connect(addr);
    assert!(!recv_cmds(&mut fresh, 4).is_empty());
}

/// The answer to a capture request is the one client message that may be large.
#[test]
fn a_capture_answer_may_exceed_the_message_limit() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let mut ws = connect(v.local_addr());
    let png: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
    let answer = {
        use base64::Engine as _;
        let b64 = base64::engine::general_purpose::STANDARD.encode(&png);
        format!(r#"{{"type":"img","data":"data:image/png;base64,{b64}"}}"#)
    };
    assert!(answer.len() > 10 * ServerLimits::DEFAULT.max_client_message);
    let replier = std::thread::spawn(move || {
        loop {
            if let Msg::Cmd(Cmd { ty, .. }) = recv(&mut ws)
                && ty == "capture_image"
            {
                ws.send(Message::text(answer)).unwrap();
                return ws;
            }
        }
    });
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    assert_eq!(v.capture_image(Duration::from_secs(20)).unwrap(), png);
    let _ws = replier.join().unwrap();
    assert_eq!(v.client_count(), 1);
}

/// Issue 13, item 7: a request head must arrive whole within the request deadline, however
/// steadily its bytes trickle in.
#[test]
fn a_slow_loris_request_is_closed_at_the_request_deadline() {
    let scene = Scene::load().unwrap();
    let deadline = Duration::from_millis(500);
    let limits = ServerLimits {
        request_deadline: deadline,
        ..ServerLimits::DEFAULT
    };
    let Some(v) = start_with(&scene, limits) else {
        return;
    };
    let addr = v.local_addr();
    let started = Instant::now();
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_millis(50))).unwrap();
    let head = format!("GET / HTTP/1.1\r\nHost: {addr}\r\nX-Pad: {}", "a".repeat(10_000));
    // One byte every 50 ms: each read of the server gets data long before any per-read
    // timeout; only a deadline on the whole head ends it.
    let mut response = Vec::new();
    let mut sent = 0;
    let closed = loop {
        if started.elapsed() > Duration::from_secs(20) {
            break None;
        }
        if s.write_all(&head.as_bytes()[sent..=sent]).is_err() {
            break Some(started.elapsed());
        }
        sent += 1;
        match s.read_to_end(&mut response) {
            Ok(_) => break Some(started.elapsed()),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(_) => break Some(started.elapsed()),
        }
    };
    let closed = closed.expect("a client sending a byte every 50 ms was held for 20 s");
    eprintln!(
        "slow loris: closed after {closed:?} ({sent} bytes sent), deadline {deadline:?}; answer {:?}",
        String::from_utf8_lossy(&response).lines().next()
    );
    assert!(closed >= deadline, "closed before the deadline: {closed:?}");
    assert!(closed < deadline * 10, "held for {closed:?}");
    assert!(eventually(Duration::from_secs(5), || v.connection_count() == 0));
}

/// Issue 13, item 7: when every slot is taken, idle connections make room for a new request
/// (the user's); the connected browser keeps its place.
#[test]
fn a_full_server_makes_room_for_a_new_request() {
    let scene = Scene::load().unwrap();
    let limits = ServerLimits {
        max_connections: 4,
        request_deadline: Duration::from_secs(60),
        ..ServerLimits::DEFAULT
    };
    let Some(v) = start_with(&scene, limits) else {
        return;
    };
    let addr = v.local_addr();
    let mut browser = connect(addr);
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    // Three connections that send half a request head and wait.
    let idle: Vec<TcpStream> = (0..3)
        .map(|_| {
            let mut s = TcpStream::connect(addr).unwrap();
            s.write_all(b"GET / HT").unwrap();
            s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
            std::thread::sleep(Duration::from_millis(20)); // distinct ages
            s
        })
        .collect();
    assert!(
        eventually(Duration::from_secs(5), || v.connection_count() == 4),
        "{} connections",
        v.connection_count()
    );
    // Full: a new request is still answered.
    let (head, _) = http_get(addr, "/");
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    // The oldest idle connection made room; the browser and the younger ones stay.
    let mut first = &idle[0];
    let mut buf = [0u8; 64];
    assert_eq!(
        first.read(&mut buf).unwrap_or(0),
        0,
        "the oldest idle connection was not closed"
    );
    assert_eq!(v.client_count(), 1);
    assert!(v.connection_count() <= 4);
    let _ = recv(&mut browser); // still served
}

/// Issue 13, item 7: a browser that stops reading is dropped once the oldest update it has not
/// read is older than the lag limit, whatever the kernel buffers; a reading one stays.
#[test]
fn a_websocket_client_that_stops_reading_is_dropped_at_the_lag_limit() {
    let scene = Scene::load().unwrap();
    let max_lag = Duration::from_secs(2);
    let limits = ServerLimits {
        max_client_lag: max_lag,
        ping_interval: Duration::from_millis(100),
        ..ServerLimits::DEFAULT
    };
    let Some(v) = start_with(&scene, limits) else {
        return;
    };
    let addr = v.local_addr();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let mut reader_ws = connect(addr);
    let reader_stop = stop.clone();
    let reader = std::thread::spawn(move || {
        let mut n = 0u64;
        while !reader_stop.load(std::sync::atomic::Ordering::SeqCst) {
            reader_ws.read().expect("the reading client was dropped");
            n += 1;
        }
        n
    });
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    // The clock starts before the stalled client connects: the oldest update it leaves unread
    // (its snapshot or the first ping) cannot be older than this instant, so a drop measured
    // from here is never early, while one measured after the join could be early by the join.
    let joined = Instant::now();
    let _stalled = connect(addr); // reads nothing after its handshake
    assert!(v.wait_for_clients(2, Duration::from_secs(5)));
    let mut sim = Sim::new(&scene);
    let mut dropped = None;
    while joined.elapsed() < Duration::from_secs(30) {
        for _ in 0..8 {
            wiggle(&mut sim);
        }
        v.publish_poses(sim.data(), sim.time());
        std::thread::sleep(Duration::from_millis(16));
        if v.client_count() < 2 {
            dropped = Some(joined.elapsed());
            break;
        }
    }
    let dropped = dropped.expect("a client that reads nothing was still connected after 30 s");
    // Keep publishing a little: the reading client must stay.
    for _ in 0..30 {
        wiggle(&mut sim);
        v.publish_poses(sim.data(), sim.time());
        std::thread::sleep(Duration::from_millis(16));
    }
    assert_eq!(v.client_count(), 1, "the reading client was dropped too");
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    v.publish_poses(sim.data(), sim.time() + 1.0);
    let read = reader.join().expect("the reading client kept its connection");
    eprintln!(
        "a client that stopped reading was dropped {dropped:?} after it began to connect (lag limit {max_lag:?}); the reader got {read} messages"
    );
    assert!(dropped >= max_lag, "dropped before the lag limit: {dropped:?}");
    assert!(dropped < max_lag * 5, "held for {dropped:?}");
}

/// How long a browser that stops reading holds its connection with the default limits, on the
/// pose stream of a real episode (30 Hz). Nothing is asserted about time.
#[test]
#[ignore = "measurement (~35 s): cargo test --release --test viewer -- --ignored --nocapture measure_how_long_a_stalled_reader_is_held"]
fn measure_how_long_a_stalled_reader_is_held() {
    let scene = Scene::load().unwrap();
    let Some(v) = start(&scene) else { return };
    let mut ws = connect(v.local_addr());
    let _ = recv_cmds(&mut ws, 4); // the page starts reading, then stalls
    assert!(v.wait_for_clients(1, Duration::from_secs(5)));
    let stalled = Instant::now();
    let mut sim = Sim::new(&scene);
    while v.client_count() > 0 && stalled.elapsed() < Duration::from_secs(300) {
        for _ in 0..16 {
            wiggle(&mut sim);
        }
        v.publish_poses(sim.data(), sim.time());
        std::thread::sleep(Duration::from_millis(33));
    }
    eprintln!(
        "a reader that stalled after 4 messages was dropped after {:?} (limit {:?}, still connected: {})",
        stalled.elapsed(),
        ServerLimits::DEFAULT.max_client_lag,
        v.client_count()
    );
}
