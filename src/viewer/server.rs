//! The live server: plain HTTP for the page and a websocket on the same port, on std threads.
//!
//! Threads: one acceptor, one thread per connection (an HTTP request is answered and closed; a
//! websocket connection stays and becomes a client). The simulation thread never touches a
//! socket: it updates the [`Hub`] (scene tree + per-client outboxes) under one short lock and
//! wakes the clients' threads.
//!
//! Per client, structural commands (objects, properties, deletes) go through a bounded queue;
//! body poses go into a **slot per body** that the next write empties (latest wins), so a slow
//! or stalled browser skips frames instead of growing a backlog. If its queue overflows, it is
//! cleared and the client is re-sent a snapshot of the tree.

use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use tungstenite::protocol::{Role, WebSocket};
use tungstenite::{Bytes, Message};

use super::panel::PanelState;
use super::tree::SceneTree;

/// Structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_MESSAGES: usize = 4096;
/// Bytes of structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_BYTES: usize = 64 << 20;
/// Open connections (HTTP and websocket) served at once; more are refused.
pub const MAX_CONNECTIONS: usize = 64;
/// A write that cannot progress for this long drops the client.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(30);
/// How long a client thread sleeps when it has nothing to send (it then polls for input).
const IDLE_POLL: Duration = Duration::from_millis(25);
/// Live updates (a pose batch, the sim time and the panel's statuses) are written to a client at
/// most this often (40 Hz of wall time): a sim that runs faster than real time publishes more
/// often, and the browser gets the latest state only (the panel's new events are all kept, up
/// to [`super::panel::EVENT_HISTORY`]).
pub const MIN_POSE_INTERVAL: Duration = Duration::from_millis(25);

/// Counters of one connected client.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClientStats {
    /// Client id (in connection order).
    pub id: u64,
    /// Pose frames published while this client was connected.
    pub frames_offered: u64,
    /// Pose batches actually written to it (fewer when it is slow: frames were coalesced).
    pub frames_sent: u64,
    /// Binary messages written.
    pub messages_sent: u64,
    /// Payload bytes written.
    pub bytes_sent: u64,
    /// Times its queue overflowed and it was re-sent a snapshot.
    pub resyncs: u64,
}

#[derive(Debug, Default)]
struct Outbox {
    queue: VecDeque<Bytes>,
    queued_bytes: usize,
    resync: bool,
    /// Sent after the pending poses, which are then flushed at once (capture requests: the
    /// image must show everything published before the request).
    after_poses: Vec<Bytes>,
    /// Latest pose message per slot (body id); `None` once written.
    poses: Vec<Option<Bytes>>,
    poses_pending: bool,
    /// When the client's thread may write its next live update; until then it sleeps (at most
    /// until this instant) without being woken for live updates.
    next_live_at: Option<Instant>,
    time: Option<f64>,
    tree_dirty: bool,
    status_dirty: bool,
    closed: bool,
    stats: ClientStats,
}

/// A connected websocket client as the hub sees it.
#[derive(Debug)]
pub(crate) struct Client {
    id: u64,
    out: Mutex<Outbox>,
    wake: Condvar,
}

impl Outbox {
    /// Whether live updates (poses, time, panel status) wait for the client's next write. While
    /// they do, its thread already sleeps only until that write is due, so a newer update needs
    /// no wake-up.
    fn live_pending(&self) -> bool {
        self.poses_pending || self.time.is_some() || self.status_dirty
    }

    /// Whether a live update published now must wake the client's thread: only when nothing
    /// was pending (else it is already due or timed) and the rate limit allows a write now
    /// (else the thread wakes by itself when it does). Every wake-up is a context switch that
    /// the simulation thread pays for on a busy machine.
    fn live_needs_wake(&self) -> bool {
        !self.live_pending() && self.next_live_at.is_none_or(|t| Instant::now() >= t)
    }
}

impl Client {
    fn lock(&self) -> MutexGuard<'_, Outbox> {
        self.out.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn close(&self) {
        self.lock().closed = true;
        self.wake.notify_all();
    }
}

/// What a capture request waits for: the PNG bytes, or why there are none.
pub(crate) type CaptureReply = Result<Vec<u8>, String>;

#[derive(Debug, Default)]
pub(crate) struct HubState {
    pub tree: SceneTree,
    pub panel: PanelState,
    clients: Vec<Arc<Client>>,
    capture: Option<(u64, mpsc::Sender<CaptureReply>)>,
    pub frames_published: u64,
    /// Sim time of the latest pose frame (sent to late joiners).
    latest_time: Option<f64>,
}

/// Shared state between the simulation thread and the server threads.
#[derive(Debug, Default)]
pub(crate) struct Hub {
    state: Mutex<HubState>,
    next_id: AtomicU64,
    connections: AtomicU64,
    pub shutdown: AtomicBool,
}

impl Hub {
    pub fn lock(&self) -> MutexGuard<'_, HubState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Applies `update` to the tree and queues `msg` to every client, under one lock so a new
    /// client's snapshot and the live stream never overlap or miss a message.
    pub fn broadcast(&self, msg: Bytes, update: impl FnOnce(&mut SceneTree, Bytes)) {
        let mut st = self.lock();
        update(&mut st.tree, msg.clone());
        for c in &st.clients {
            let mut out = c.lock();
            if out.resync {
                continue; // the snapshot it will get already holds this message
            }
            out.queued_bytes += msg.len();
            out.queue.push_back(msg.clone());
            if out.queue.len() > MAX_QUEUED_MESSAGES || out.queued_bytes > MAX_QUEUED_BYTES {
                out.queue.clear();
                out.queued_bytes = 0;
                out.resync = true;
            }
            drop(out);
            c.wake.notify_all();
        }
    }

    /// Latest-wins pose publication: stores each `(slot, path, msg)` as the path's transform and
    /// puts it in every client's slot, replacing an unsent older one.
    pub fn publish_poses(&self, poses: Vec<(usize, &str, Bytes)>, sim_time: f64) {
        let mut st = self.lock();
        st.frames_published += 1;
        st.latest_time = Some(sim_time);
        for (_, path, msg) in &poses {
            st.tree.set_transform(path, msg.clone());
        }
        for c in &st.clients {
            let mut out = c.lock();
            let wake = out.live_needs_wake();
            out.stats.frames_offered += 1;
            for (slot, _, msg) in &poses {
                if out.poses.len() <= *slot {
                    out.poses.resize(*slot + 1, None);
                }
                out.poses[*slot] = Some(msg.clone());
            }
            out.poses_pending |= !poses.is_empty();
            out.time = Some(sim_time);
            drop(out);
            if wake {
                c.wake.notify_all();
            }
        }
    }

    /// Marks the panel's tree (`tree = true`, sent at once) or status (a live update, sent with
    /// the next pose batch) as changed for every client.
    pub fn panel_changed(st: &HubState, tree: bool) {
        for c in &st.clients {
            let mut out = c.lock();
            let wake = tree || out.live_needs_wake();
            if tree {
                out.tree_dirty = true;
            }
            out.status_dirty = true;
            drop(out);
            if wake {
                c.wake.notify_all();
            }
        }
    }

    fn register(&self) -> Arc<Client> {
        let mut st = self.lock();
        let snapshot = st.tree.snapshot();
        let queued_bytes = snapshot.iter().map(|m| m.len()).sum();
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        let client = Arc::new(Client {
            id,
            out: Mutex::new(Outbox {
                queue: snapshot.into(),
                queued_bytes,
                time: st.latest_time,
                tree_dirty: st.panel.tree_message().is_some(),
                status_dirty: st.panel.tree_message().is_some(),
                stats: ClientStats {
                    id,
                    ..ClientStats::default()
                },
                ..Outbox::default()
            }),
            wake: Condvar::new(),
        });
        st.clients.push(client.clone());
        client
    }

    fn unregister(&self, id: u64) {
        let mut st = self.lock();
        st.clients.retain(|c| c.id != id);
        if st.capture.as_ref().is_some_and(|(cid, _)| *cid == id)
            && let Some((_, tx)) = st.capture.take()
        {
            let _ = tx.send(Err("the browser disconnected before answering".into()));
        }
    }

    /// Number of connected websocket clients.
    pub fn client_count(&self) -> usize {
        self.lock().clients.len()
    }

    /// Counters of every connected client.
    pub fn stats(&self) -> Vec<ClientStats> {
        self.lock().clients.iter().map(|c| c.lock().stats).collect()
    }

    /// Sends `capture_image` to the oldest client; the reply arrives on the returned channel.
    pub fn request_capture(&self, msg: Bytes) -> Option<mpsc::Receiver<CaptureReply>> {
        let mut st = self.lock();
        let client = st.clients.first()?.clone();
        let (tx, rx) = mpsc::channel();
        st.capture = Some((client.id, tx));
        client.lock().after_poses.push(msg);
        client.wake.notify_all();
        Some(rx)
    }

    /// Closes every client (their threads send a close frame and exit).
    pub fn close_all(&self) {
        self.shutdown.store(true, Ordering::SeqCst);
        for c in &self.lock().clients {
            c.close();
        }
    }

    fn on_text(&self, client: u64, text: &str) {
        let Ok(value) = serde_json::from_str::<serde_json::Value>(text) else {
            return;
        };
        if value.get("type").and_then(|t| t.as_str()) != Some("img") {
            return;
        }
        let mut st = self.lock();
        if st.capture.as_ref().is_none_or(|(cid, _)| *cid != client) {
            return;
        }
        let Some((_, tx)) = st.capture.take() else {
            return;
        };
        let data = value.get("data").and_then(|d| d.as_str()).unwrap_or("");
        let reply = match data.split_once(";base64,") {
            Some((_, b64)) => {
                use base64::Engine as _;
                base64::engine::general_purpose::STANDARD
                    .decode(b64)
                    .map_err(|e| format!("the image is not valid base64: {e}"))
            }
            None => Err("the browser answered without a data: URL".into()),
        };
        let _ = tx.send(reply);
    }
}

/// Static content served over HTTP.
#[derive(Debug)]
pub(crate) struct Site {
    pub page: Bytes,
    pub bundle: Bytes,
    pub script: Bytes,
    pub style: Bytes,
}

/// Starts the acceptor thread on `listener`.
pub(crate) fn spawn_acceptor(listener: TcpListener, hub: Arc<Hub>, site: Arc<Site>) -> io::Result<()> {
    std::thread::Builder::new()
        .name("macrotree-viewer-accept".into())
        .spawn(move || {
            for stream in listener.incoming() {
                if hub.shutdown.load(Ordering::SeqCst) {
                    break;
                }
                let Ok(stream) = stream else { continue };
                if hub.connections.load(Ordering::SeqCst) >= MAX_CONNECTIONS as u64 {
                    let _ = respond(
                        &stream,
                        "503 Service Unavailable",
                        "text/plain",
                        "no-store",
                        b"too many connections\n",
                        false,
                    );
                    continue;
                }
                hub.connections.fetch_add(1, Ordering::SeqCst);
                let (hub2, site2) = (hub.clone(), site.clone());
                let spawned = std::thread::Builder::new()
                    .name("macrotree-viewer-conn".into())
                    .spawn(move || {
                        let _ = serve_connection(stream, &hub2, &site2);
                        hub2.connections.fetch_sub(1, Ordering::SeqCst);
                    });
                if spawned.is_err() {
                    hub.connections.fetch_sub(1, Ordering::SeqCst);
                }
            }
        })?;
    Ok(())
}

/// Wakes the acceptor (blocked in `accept`) so it sees the shutdown flag.
pub(crate) fn wake_acceptor(addr: SocketAddr) {
    let target = if addr.ip().is_unspecified() {
        SocketAddr::new(std::net::Ipv4Addr::LOCALHOST.into(), addr.port())
    } else {
        addr
    };
    let _ = TcpStream::connect_timeout(&target, Duration::from_millis(200));
}

struct Request {
    method: String,
    path: String,
    headers: Vec<(String, String)>,
    rest: Vec<u8>,
}

impl Request {
    fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
}

fn read_request(stream: &mut TcpStream) -> io::Result<Request> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1024];
    let end = loop {
        if let Some(pos) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break pos + 4;
        }
        if buf.len() > 16 * 1024 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                "request head too large",
            ));
        }
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        buf.extend_from_slice(&chunk[..n]);
    };
    let head = String::from_utf8_lossy(&buf[..end]).into_owned();
    let mut lines = head.split("\r\n");
    let mut first = lines.next().unwrap_or("").split_whitespace();
    let method = first.next().unwrap_or("").to_owned();
    let path = first.next().unwrap_or("/").to_owned();
    let headers = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
        .collect();
    Ok(Request {
        method,
        path,
        headers,
        rest: buf[end..].to_vec(),
    })
}

fn respond(
    mut stream: &TcpStream,
    status: &str,
    content_type: &str,
    cache: &str,
    body: &[u8],
    head_only: bool,
) -> io::Result<()> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: {cache}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    if !head_only {
        stream.write_all(body)?;
    }
    stream.flush()
}

fn serve_connection(mut stream: TcpStream, hub: &Hub, site: &Site) -> io::Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(10)))?;
    stream.set_write_timeout(Some(WRITE_TIMEOUT))?;
    let req = read_request(&mut stream)?;
    let upgrade = req
        .header("Upgrade")
        .is_some_and(|v| v.eq_ignore_ascii_case("websocket"));
    if upgrade {
        let Some(key) = req.header("Sec-WebSocket-Key") else {
            return respond(
                &stream,
                "400 Bad Request",
                "text/plain",
                "no-store",
                b"missing Sec-WebSocket-Key\n",
                false,
            );
        };
        let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
        let head = format!(
            "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
        );
        stream.write_all(head.as_bytes())?;
        stream.flush()?;
        let ws = WebSocket::from_partially_read(stream, req.rest, Role::Server, None);
        return run_client(ws, hub);
    }
    let head_only = req.method == "HEAD";
    if req.method != "GET" && !head_only {
        return respond(
            &stream,
            "405 Method Not Allowed",
            "text/plain",
            "no-store",
            b"only GET\n",
            false,
        );
    }
    let path = req.path.split('?').next().unwrap_or("/");
    match path {
        "/" | "/index.html" => respond(
            &stream,
            "200 OK",
            "text/html; charset=utf-8",
            "no-cache",
            &site.page,
            head_only,
        ),
        "/main.min.js" => respond(
            &stream,
            "200 OK",
            "text/javascript; charset=utf-8",
            "public, max-age=3600",
            &site.bundle,
            head_only,
        ),
        "/viewer.js" => respond(
            &stream,
            "200 OK",
            "text/javascript; charset=utf-8",
            "no-cache",
            &site.script,
            head_only,
        ),
        "/viewer.css" => respond(
            &stream,
            "200 OK",
            "text/css; charset=utf-8",
            "no-cache",
            &site.style,
            head_only,
        ),
        "/favicon.ico" => respond(
            &stream,
            "204 No Content",
            "image/x-icon",
            "public, max-age=86400",
            b"",
            head_only,
        ),
        "/download" => {
            let commands = hub.lock().tree.snapshot();
            let html = super::page::standalone_html(&site.bundle, &commands, None);
            respond(
                &stream,
                "200 OK",
                "text/html; charset=utf-8",
                "no-store",
                html.as_bytes(),
                head_only,
            )
        }
        _ => respond(
            &stream,
            "404 Not Found",
            "text/plain",
            "no-store",
            b"not found\n",
            head_only,
        ),
    }
}

/// Everything a client thread takes out of its outbox in one go.
struct Batch {
    queue: VecDeque<Bytes>,
    poses: Vec<Bytes>,
    after_poses: Vec<Bytes>,
    time: Option<f64>,
    resync: bool,
    tree: bool,
    status: bool,
    closed: bool,
}

/// Takes what is due: structural messages and the panel's node list at once, live updates
/// (poses, sim time, panel statuses) at most every [`MIN_POSE_INTERVAL`] (the newer ones
/// replace older ones meanwhile). Waits up to [`IDLE_POLL`] when nothing is due.
fn take_batch(client: &Client) -> Batch {
    let mut out = client.lock();
    let deadline = Instant::now() + IDLE_POLL;
    loop {
        let now = Instant::now();
        let other = !out.queue.is_empty()
            || !out.after_poses.is_empty()
            || out.resync
            || out.tree_dirty
            || out.closed;
        let live_allowed = out.next_live_at.is_none_or(|t| now >= t);
        if other || (out.live_pending() && live_allowed) || now >= deadline {
            break;
        }
        // Publishers do not wake a rate-limited thread (see `live_needs_wake`): sleep at most
        // until the next live write is allowed, whether or not anything is pending yet.
        let mut wait = deadline - now;
        if let Some(t) = out.next_live_at.filter(|_| !live_allowed) {
            wait = wait.min(t - now);
        }
        out = client
            .wake
            .wait_timeout(out, wait)
            .unwrap_or_else(|e| e.into_inner())
            .0;
    }
    let now = Instant::now();
    let mut poses = Vec::new();
    let mut time = None;
    let mut status = false;
    let flush = !out.after_poses.is_empty();
    if (out.next_live_at.is_none_or(|t| now >= t) || flush) && out.live_pending() {
        if out.poses_pending {
            poses = out.poses.iter_mut().filter_map(Option::take).collect();
            out.stats.frames_sent += 1;
            out.poses_pending = false;
        }
        time = out.time.take();
        status = std::mem::take(&mut out.status_dirty);
        out.next_live_at = Some(now + MIN_POSE_INTERVAL);
    }
    // A new node list goes with the statuses it resets.
    let tree = std::mem::take(&mut out.tree_dirty);
    status |= tree && std::mem::take(&mut out.status_dirty);
    out.queued_bytes = 0;
    Batch {
        queue: std::mem::take(&mut out.queue),
        poses,
        after_poses: std::mem::take(&mut out.after_poses),
        time,
        resync: std::mem::take(&mut out.resync),
        tree,
        status,
        closed: out.closed,
    }
}

fn run_client(mut ws: WebSocket<TcpStream>, hub: &Hub) -> io::Result<()> {
    ws.get_ref().set_nodelay(true)?;
    let client = hub.register();
    let result = client_loop(&mut ws, hub, &client);
    hub.unregister(client.id);
    let _ = ws.close(None);
    let _ = ws.flush();
    result
}

fn ws_err(e: tungstenite::Error) -> io::Error {
    match e {
        tungstenite::Error::Io(e) => e,
        other => io::Error::other(other.to_string()),
    }
}

fn client_loop(ws: &mut WebSocket<TcpStream>, hub: &Hub, client: &Client) -> io::Result<()> {
    let mut events_seen = 0u64;
    loop {
        let mut batch = take_batch(client);
        if batch.closed || hub.shutdown.load(Ordering::SeqCst) {
            return Ok(());
        }
        if batch.resync {
            // Overflowed: drop what was queued and replay the current tree instead.
            let st = hub.lock();
            let mut out = client.lock();
            out.queue.clear();
            out.queued_bytes = 0;
            out.resync = false;
            out.stats.resyncs += 1;
            drop(out);
            batch.queue = st.tree.snapshot().into();
        }
        let mut messages = 0u64;
        let mut bytes = 0u64;
        let ordered = batch
            .queue
            .drain(..)
            .chain(batch.poses.drain(..))
            .chain(batch.after_poses.drain(..));
        for msg in ordered {
            messages += 1;
            bytes += msg.len() as u64;
            ws.write(Message::Binary(msg)).map_err(ws_err)?;
        }
        if batch.tree || batch.status {
            let (tree, status) = {
                let st = hub.lock();
                let tree = batch
                    .tree
                    .then(|| st.panel.tree_message().map(str::to_owned))
                    .flatten();
                let (status, seen) = st.panel.status_message(events_seen);
                events_seen = seen;
                (tree, status)
            };
            if let Some(tree) = tree {
                ws.write(Message::text(tree)).map_err(ws_err)?;
            }
            ws.write(Message::text(status)).map_err(ws_err)?;
        }
        if let Some(t) = batch.time {
            ws.write(Message::text(format!("{{\"type\":\"time\",\"t\":{t}}}")))
                .map_err(ws_err)?;
        }
        ws.flush().map_err(ws_err)?;
        if messages > 0 {
            let mut out = client.lock();
            out.stats.messages_sent += messages;
            out.stats.bytes_sent += bytes;
        }
        // Poll for input without blocking (capture replies, close frames).
        ws.get_ref().set_nonblocking(true)?;
        let read = loop {
            match ws.read() {
                Ok(Message::Text(text)) => hub.on_text(client.id, text.as_str()),
                Ok(Message::Close(_)) => break Err(io::ErrorKind::ConnectionAborted.into()),
                Ok(_) => {}
                Err(tungstenite::Error::Io(e)) if e.kind() == io::ErrorKind::WouldBlock => break Ok(()),
                Err(e) => break Err(ws_err(e)),
            }
        };
        ws.get_ref().set_nonblocking(false)?;
        read?;
    }
}
