//! Websocket integration tests of the live viewer without a browser: a tungstenite client
//! plays the browser.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use macrotree::sim::{HOME_Q, Scene, Sim};
use macrotree::viewer::proto;
use macrotree::viewer::{LiveViewer, TreeNodeView, ViewerError, ViewerOptions, page};
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
    match LiveViewer::start(&scene.model, &opts0()) {
        Ok(v) => Some(v),
        Err(ViewerError::BundleMissing { path }) if std::env::var_os("CI").is_none() => {
            eprintln!("SKIPPED: {}", page::bundle_help(&path));
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// Connects as the live page does: from the server's own origin.
fn connect(addr: SocketAddr) -> Client {
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
    Cmd { ty: String, path: String, raw: Vec<u8> },
    Text(serde_json::Value),
}

fn recv(ws: &mut Client) -> Msg {
    loop {
        match ws.read().expect("message") {
            Message::Binary(b) => {
                let value = rmpv::decode::read_value(&mut &b[..]).unwrap();
                let (ty, path) = proto::peek_type_path(&value);
                return Msg::Cmd {
                    ty: ty.unwrap().to_owned(),
                    path: path.unwrap_or("").to_owned(),
                    raw: b.to_vec(),
                };
            }
            Message::Text(t) => return Msg::Text(serde_json::from_str(t.as_str()).unwrap()),
            _ => {}
        }
    }
}

/// Reads binary commands (skipping text frames) until `n` were read.
fn recv_cmds(ws: &mut Client, n: usize) -> Vec<(String, String, Vec<u8>)> {
    let mut out = Vec::new();
    while out.len() < n {
        if let Msg::Cmd { ty, path, raw, .. } = recv(ws) {
            out.push((ty, path, raw));
        }
    }
    out
}

fn expected_transform(path: &str, data_xpos: [f64; 3], xmat: [f64; 9]) -> Vec<u8> {
    proto::encode(&proto::set_transform(
        path,
        &proto::mat_from_pos_xmat(data_xpos, xmat),
    ))
    .to_vec()
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
    let count = |ty: &str, path: &str| snapshot.iter().filter(|(t, p, _)| t == ty && p == path).count();
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
    assert!(snapshot.iter().any(|(_, _, raw)| raw == &latest));
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
        assert_eq!(frame[0].0, "set_transform");
        let mut seen = frame;
        while !seen.iter().any(|(_, _, raw)| raw == &next) {
            seen.extend(recv_cmds(ws, 1));
            assert!(
                seen.len() <= drawn.len(),
                "one frame holds at most one transform per body"
            );
        }
        assert!(
            seen.iter()
                .all(|(t, p, _)| t == "set_transform" && p != "/mujoco/world")
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
        let (_, path, raw) = recv_cmds(&mut ws, 1).remove(0);
        total += 1;
        if path == layout.body_paths[shoulder] {
            shoulder_msgs += 1;
            if raw == last {
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
    assert_eq!(body, page::load_bundle().unwrap().to_vec());
    let (head, body) = http_get(addr, "/viewer.js");
    assert!(head.starts_with("HTTP/1.1 200"));
    assert_eq!(body, page::PAGE_JS.as_bytes());
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
    assert_eq!(events.len(), macrotree::viewer::panel::EVENT_HISTORY);
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
            if let Msg::Cmd { ty, .. } = recv(&mut ws)
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
