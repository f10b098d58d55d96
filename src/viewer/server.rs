//! The live server: plain HTTP for the page and a websocket on the same port, on std threads.
//!
//! Threads: one acceptor, one thread per connection (an HTTP request is answered and closed; a
//! websocket connection stays and becomes a client). The simulation thread never touches a
//! socket: it updates the `Hub` (scene tree + per-client outboxes) under one short lock and
//! wakes the clients' threads.
//!
//! Per client, structural commands (objects, properties, deletes) go through a bounded queue;
//! body poses go into a **slot per body** that the next write empties (latest wins), so a slow
//! or stalled browser skips frames instead of growing a backlog. If its queue overflows, it is
//! cleared and the client is re-sent a snapshot of the tree.
//!
//! Who may connect and for how long: requests must name this server in `Host` and websocket
//! upgrades must come from its own pages (`Origin`), see `guard.rs`; every size and wait
//! is bounded by [`ServerLimits`], and a full server evicts an idle connection rather than
//! refusing the user (see `docs/security.md`).

use std::collections::VecDeque;
use std::io::{self, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use tungstenite::protocol::{Role, WebSocket, WebSocketConfig};
use tungstenite::{Bytes, Message};

use super::guard::Authority;
use super::http::{Request, Response, TimedStream, read_request};
use super::limits::{MAX_REQUEST_HEAD, ServerLimits};
use super::panel::PanelState;
use super::slots::{Refused, SlotGuard, Slots, Stage};
use super::tree::SceneTree;

pub use super::limits::{MAX_CLIENT_LAG, MAX_CONNECTIONS};

/// Structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_MESSAGES: usize = 4096;
/// Bytes of structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_BYTES: usize = 64 << 20;
/// First pause of the acceptor after a failed `accept` (e.g. out of file descriptors).
pub const ACCEPT_BACKOFF_MIN: Duration = Duration::from_millis(10);
/// Longest pause of the acceptor between failed `accept`s (the pause doubles up to it).
pub const ACCEPT_BACKOFF_MAX: Duration = Duration::from_secs(1);
/// Least time between two warnings about failed `accept`s.
pub const ACCEPT_WARN_INTERVAL: Duration = Duration::from_secs(60);
/// Time given to a refusal or a closing handshake to reach the client's socket.
const GOODBYE_DEADLINE: Duration = Duration::from_millis(500);
/// Messages read from a client per poll, so that a chatty client cannot starve its writes.
const MAX_READS_PER_POLL: usize = 64;
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
    /// When the oldest update still in this outbox was queued (`None`: nothing pending).
    pending_since: Option<Instant>,
    /// A capture request awaits this client's answer: its messages may be larger.
    capture_pending: bool,
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

    /// Records that an update queued at `now` waits here (the oldest one counts).
    fn mark_pending(&mut self, now: Instant) {
        self.pending_since.get_or_insert(now);
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
    /// The open connections (HTTP and websocket).
    pub slots: Arc<Slots>,
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
        let now = Instant::now();
        for c in &st.clients {
            let mut out = c.lock();
            if out.resync {
                continue; // the snapshot it will get already holds this message
            }
            out.mark_pending(now);
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
        let now = Instant::now();
        for c in &st.clients {
            let mut out = c.lock();
            let wake = out.live_needs_wake();
            out.mark_pending(now);
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
        let now = Instant::now();
        for c in &st.clients {
            let mut out = c.lock();
            let wake = tree || out.live_needs_wake();
            out.mark_pending(now);
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
                pending_since: Some(Instant::now()),
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
        if let Some((old, _)) = st.capture.take()
            && let Some(c) = st.clients.iter().find(|c| c.id == old)
        {
            c.lock().capture_pending = false; // a newer request replaces an unanswered one
        }
        let (tx, rx) = mpsc::channel();
        st.capture = Some((client.id, tx));
        let mut out = client.lock();
        out.after_poses.push(msg);
        out.capture_pending = true;
        out.mark_pending(Instant::now());
        drop(out);
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
        if let Some(c) = st.clients.iter().find(|c| c.id == client) {
            c.lock().capture_pending = false;
        }
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

/// What the server serves (the page, scripts and style) and the rules it serves by.
#[derive(Debug)]
pub(crate) struct Site {
    pub page: Bytes,
    pub bundle: Bytes,
    pub script: Bytes,
    pub style: Bytes,
    /// The names requests must use (`Host`, `Origin`).
    pub authority: Authority,
    /// Connections, sizes and waits.
    pub limits: ServerLimits,
}

/// Pauses between failed `accept`s: a connection the acceptor cannot take (no file descriptor
/// left) stays queued, so retrying at once would spin a core. The pause doubles from
/// [`ACCEPT_BACKOFF_MIN`] to [`ACCEPT_BACKOFF_MAX`]; a successful accept resets it. Also decides
/// when to log: a warning at the first failure and then at most once per
/// [`ACCEPT_WARN_INTERVAL`] (near the descriptor limit accepts fail and succeed in turns), and
/// one line when accepting works again after a warning.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct AcceptBackoff {
    /// Failed accepts in a row.
    failures: u32,
    /// When the last warning was logged.
    warned_at: Option<Instant>,
    /// A warning was logged and the recovery not yet.
    recovery_unlogged: bool,
}

impl AcceptBackoff {
    /// Counts one more failure; returns the pause before the next `accept`.
    pub fn failed(&mut self) -> Duration {
        self.failures = self.failures.saturating_add(1);
        let doublings = (self.failures - 1).min(16);
        ACCEPT_BACKOFF_MIN
            .saturating_mul(1 << doublings)
            .min(ACCEPT_BACKOFF_MAX)
    }

    /// Failed accepts in a row so far.
    pub fn failures(&self) -> u32 {
        self.failures
    }

    /// Whether to log a warning about a failure at `now`: yes for the first one, then at most
    /// once per [`ACCEPT_WARN_INTERVAL`].
    pub fn warn_now(&mut self, now: Instant) -> bool {
        if self
            .warned_at
            .is_some_and(|t| now.duration_since(t) < ACCEPT_WARN_INTERVAL)
        {
            return false;
        }
        self.warned_at = Some(now);
        self.recovery_unlogged = true;
        true
    }

    /// Resets the pause after a successful accept; returns whether to log the recovery (once
    /// after each warning).
    pub fn succeeded(&mut self) -> bool {
        self.failures = 0;
        std::mem::take(&mut self.recovery_unlogged)
    }
}

/// Whether a failed `accept` may be retried at once: the failure consumed nothing that is
/// still queued (the peer gave up, or a signal interrupted the call).
fn retry_at_once(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::ConnectionAborted | io::ErrorKind::Interrupted
    )
}

/// Starts the acceptor thread on `listener`.
pub(crate) fn spawn_acceptor(listener: TcpListener, hub: Arc<Hub>, site: Arc<Site>) -> io::Result<()> {
    std::thread::Builder::new()
        .name("macrotree-viewer-accept".into())
        .spawn(move || accept_loop(&listener, &hub, &site))?;
    Ok(())
}

/// Accepts connections until the hub shuts down, pausing after failures and logging them
/// sparingly ([`AcceptBackoff`]).
fn accept_loop(listener: &TcpListener, hub: &Arc<Hub>, site: &Arc<Site>) {
    let mut backoff = AcceptBackoff::default();
    loop {
        let accepted = listener.accept();
        if hub.shutdown.load(Ordering::SeqCst) {
            break;
        }
        match accepted {
            Ok((stream, _)) => {
                if backoff.succeeded() {
                    tracing::info!("viewer: accepting connections again");
                }
                admit(stream, hub, site);
            }
            Err(e) if retry_at_once(&e) => {}
            Err(e) => {
                let pause = backoff.failed();
                if backoff.warn_now(Instant::now()) {
                    tracing::warn!(error = %e, "viewer: cannot accept connections; retrying with pauses of up to {ACCEPT_BACKOFF_MAX:?}");
                }
                std::thread::sleep(pause);
            }
        }
    }
}

/// Gives `stream` a slot and a thread, or answers 503 when no slot can be freed.
fn admit(stream: TcpStream, hub: &Arc<Hub>, site: &Arc<Site>) {
    let accepted = Instant::now();
    let slot = match hub.slots.admit(&stream, site.limits.max_connections) {
        Ok(slot) => slot,
        Err(Refused::Full) => {
            let mut stream = TimedStream::new(stream);
            stream.set_write_deadline(Some(accepted + GOODBYE_DEADLINE));
            let _ =
                Response::text("503 Service Unavailable", "too many connections\n").send(&mut stream, false);
            return;
        }
        Err(Refused::Io(e)) => {
            // Out of descriptors: dropping the connection frees one.
            tracing::debug!(error = %e, "viewer: dropped a connection it could not track");
            return;
        }
    };
    let (hub, site) = (hub.clone(), site.clone());
    let _ = std::thread::Builder::new()
        .name("macrotree-viewer-conn".into())
        .spawn(move || {
            let _ = serve_connection(stream, &hub, &site, &slot, accepted);
        });
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

/// Why `req` is refused (403), if it is: a `Host` that does not name this server, an `Origin`
/// that is not one of its pages, or a websocket upgrade without `Origin`.
fn refusal(req: &Request, authority: &Authority, upgrade: bool) -> Option<&'static str> {
    if !req.header("Host").is_some_and(|h| authority.host_allowed(h)) {
        return Some("Host must name this server: 127.0.0.1, localhost or [::1] with its port\n");
    }
    match req.header("Origin") {
        Some(origin) if !authority.origin_allowed(origin) => {
            Some("only this server's own pages may connect (Origin)\n")
        }
        None if upgrade => Some("a websocket upgrade must carry Origin\n"),
        _ => None,
    }
}

/// The answer to a request head that did not arrive whole, if any is worth sending.
fn head_error_response(e: &io::Error) -> Option<Response<'static>> {
    match e.kind() {
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock => {
            Some(Response::text("408 Request Timeout", "request head too slow\n"))
        }
        io::ErrorKind::InvalidData => Some(Response::text(
            "431 Request Header Fields Too Large",
            "request head too large\n",
        )),
        _ => None,
    }
}

fn serve_connection(
    stream: TcpStream,
    hub: &Hub,
    site: &Site,
    slot: &SlotGuard,
    accepted: Instant,
) -> io::Result<()> {
    let limits = &site.limits;
    let mut stream = TimedStream::new(stream);
    stream.set_read_deadline(Some(accepted + limits.request_deadline));
    let req = match read_request(&mut stream, MAX_REQUEST_HEAD) {
        Ok(req) => req,
        Err(e) => {
            if let Some(response) = head_error_response(&e) {
                stream.set_write_deadline(Some(Instant::now() + GOODBYE_DEADLINE));
                let _ = response.send(&mut stream, false);
            }
            return Err(e);
        }
    };
    slot.set_stage(Stage::Response);
    stream.set_read_deadline(None);
    stream.set_write_deadline(Some(Instant::now() + limits.response_deadline));
    let upgrade = req
        .header("Upgrade")
        .is_some_and(|v| v.eq_ignore_ascii_case("websocket"));
    if let Some(why) = refusal(&req, &site.authority, upgrade) {
        return Response::text("403 Forbidden", why).send(&mut stream, false);
    }
    if upgrade {
        return upgrade_to_websocket(stream, req, hub, site, slot);
    }
    let head_only = req.method == "HEAD";
    if req.method != "GET" && !head_only {
        return Response::text("405 Method Not Allowed", "only GET\n").send(&mut stream, false);
    }
    let path = req.path.split('?').next().unwrap_or("/");
    let file = |content_type, cache, body| Response {
        status: "200 OK",
        content_type,
        cache,
        body,
    };
    let download;
    let response = match path {
        "/" | "/index.html" => file("text/html; charset=utf-8", "no-cache", &site.page[..]),
        "/main.min.js" => file(
            "text/javascript; charset=utf-8",
            "public, max-age=3600",
            &site.bundle[..],
        ),
        "/viewer.js" => file("text/javascript; charset=utf-8", "no-cache", &site.script[..]),
        "/viewer.css" => file("text/css; charset=utf-8", "no-cache", &site.style[..]),
        "/favicon.ico" => Response {
            status: "204 No Content",
            content_type: "image/x-icon",
            cache: "public, max-age=86400",
            body: b"",
        },
        "/download" => {
            let commands = hub.lock().tree.snapshot();
            download = super::page::standalone_html(&site.bundle, &commands, None);
            file("text/html; charset=utf-8", "no-store", download.as_bytes())
        }
        _ => Response::text("404 Not Found", "not found\n"),
    };
    response.send(&mut stream, head_only)
}

/// Completes the websocket handshake and serves the client until it leaves or lags.
fn upgrade_to_websocket(
    mut stream: TimedStream,
    req: Request,
    hub: &Hub,
    site: &Site,
    slot: &SlotGuard,
) -> io::Result<()> {
    let Some(key) = req.header("Sec-WebSocket-Key") else {
        return Response::text("400 Bad Request", "missing Sec-WebSocket-Key\n").send(&mut stream, false);
    };
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    let head = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    stream.write_all(head.as_bytes())?;
    stream.flush()?;
    stream.set_write_deadline(None);
    slot.set_stage(Stage::WebSocket);
    let config = incoming_limits(WebSocketConfig::default(), site.limits.max_client_message);
    let ws = WebSocket::from_partially_read(stream, req.rest, Role::Server, Some(config));
    run_client(ws, hub, &site.limits)
}

/// `config` accepting client messages and frames of at most `max` bytes.
fn incoming_limits(config: WebSocketConfig, max: usize) -> WebSocketConfig {
    config.max_message_size(Some(max)).max_frame_size(Some(max))
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
    /// When the oldest update in this batch (or still pending after it) was queued.
    since: Option<Instant>,
    /// A capture request awaits this client's answer.
    capture_pending: bool,
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
    let since = out.pending_since;
    if !out.live_pending() {
        out.pending_since = None; // all taken; rate-limited live updates keep their age
    }
    Batch {
        since,
        capture_pending: out.capture_pending,
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

/// How far behind a client is. After written data the client is pinged (at most every
/// [`ServerLimits::ping_interval`]); each ping is stamped with when the oldest data before it
/// was queued, and a pong answers every ping up to its sequence number. This measures what the
/// client has actually read, whatever the kernel buffers in between.
#[derive(Debug, Default)]
struct Lag {
    /// Pings not answered yet: (sequence number, when the oldest data before it was queued).
    unanswered: VecDeque<(u64, Instant)>,
    /// When the oldest data written since the last ping was queued.
    unpinged: Option<Instant>,
    last_ping: Option<Instant>,
    next_seq: u64,
}

impl Lag {
    /// Data queued at `since` was written to the socket.
    fn wrote(&mut self, since: Instant) {
        self.unpinged = Some(self.unpinged.map_or(since, |u| u.min(since)));
    }

    /// The payload of a ping to send now, if data was written since the last ping and the
    /// interval has passed.
    fn ping_due(&mut self, now: Instant, interval: Duration) -> Option<Bytes> {
        let since = self.unpinged?;
        if self.last_ping.is_some_and(|t| now.duration_since(t) < interval) {
            return None;
        }
        let seq = self.next_seq;
        self.next_seq += 1;
        self.unanswered.push_back((seq, since));
        self.unpinged = None;
        self.last_ping = Some(now);
        Some(Bytes::copy_from_slice(&seq.to_be_bytes()))
    }

    /// A pong arrived: every ping up to its sequence number is answered.
    fn answered(&mut self, payload: &[u8]) {
        let Ok(seq) = <[u8; 8]>::try_from(payload).map(u64::from_be_bytes) else {
            return; // not one of ours (an unsolicited pong)
        };
        while self.unanswered.front().is_some_and(|&(s, _)| s <= seq) {
            self.unanswered.pop_front();
        }
    }

    /// When the oldest data the client is not known to have read was queued.
    fn oldest(&self) -> Option<Instant> {
        let pinged = self.unanswered.front().map(|&(_, t)| t);
        pinged.into_iter().chain(self.unpinged).min()
    }
}

fn run_client(mut ws: WebSocket<TimedStream>, hub: &Hub, limits: &ServerLimits) -> io::Result<()> {
    ws.get_ref().get_ref().set_nodelay(true)?;
    let client = hub.register();
    let result = client_loop(&mut ws, hub, &client, limits);
    hub.unregister(client.id);
    ws.get_mut()
        .set_write_deadline(Some(Instant::now() + GOODBYE_DEADLINE));
    let _ = ws.close(None);
    let _ = ws.flush();
    if let Err(e) = &result
        && e.kind() == io::ErrorKind::TimedOut
    {
        tracing::info!(
            client = client.id,
            "viewer: dropped a browser that fell {:?} behind",
            limits.max_client_lag
        );
    }
    result
}

fn ws_err(e: tungstenite::Error) -> io::Error {
    match e {
        tungstenite::Error::Io(e) => e,
        other => io::Error::other(other.to_string()),
    }
}

fn client_loop(
    ws: &mut WebSocket<TimedStream>,
    hub: &Hub,
    client: &Client,
    limits: &ServerLimits,
) -> io::Result<()> {
    let mut events_seen = 0u64;
    let mut lag = Lag::default();
    let mut capture_mode = false;
    loop {
        let mut batch = take_batch(client);
        if batch.closed || hub.shutdown.load(Ordering::SeqCst) {
            return Ok(());
        }
        // Writes may block only until the oldest unread update is `max_client_lag` old.
        let now = Instant::now();
        let oldest = batch.since.into_iter().chain(lag.oldest()).min().unwrap_or(now);
        let deadline = oldest + limits.max_client_lag;
        if now >= deadline {
            return Err(io::Error::new(io::ErrorKind::TimedOut, "the client lags"));
        }
        ws.get_mut().set_write_deadline(Some(deadline));
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
        if let Some(since) = batch.since {
            lag.wrote(since);
        }
        if let Some(ping) = lag.ping_due(now, limits.ping_interval) {
            ws.write(Message::Ping(ping)).map_err(ws_err)?;
        }
        ws.flush().map_err(ws_err)?;
        if messages > 0 {
            let mut out = client.lock();
            out.stats.messages_sent += messages;
            out.stats.bytes_sent += bytes;
        }
        if batch.capture_pending != capture_mode {
            // Only the answer to a capture request may be large.
            capture_mode = batch.capture_pending;
            let max = if capture_mode {
                limits.max_capture_reply
            } else {
                limits.max_client_message
            };
            ws.set_config(|c| *c = incoming_limits(*c, max));
        }
        poll_input(ws, hub, client.id, &mut lag)?;
    }
}

/// Reads what the client sent without blocking (capture answers, pongs, close frames), at
/// most [`MAX_READS_PER_POLL`] messages. A message over the size limit is an error.
fn poll_input(ws: &mut WebSocket<TimedStream>, hub: &Hub, client: u64, lag: &mut Lag) -> io::Result<()> {
    ws.get_ref().get_ref().set_nonblocking(true)?;
    let mut read = Ok(());
    for _ in 0..MAX_READS_PER_POLL {
        match ws.read() {
            Ok(Message::Text(text)) => hub.on_text(client, text.as_str()),
            Ok(Message::Pong(payload)) => lag.answered(&payload),
            Ok(Message::Close(_)) => {
                read = Err(io::ErrorKind::ConnectionAborted.into());
                break;
            }
            Ok(_) => {}
            Err(tungstenite::Error::Io(e)) if e.kind() == io::ErrorKind::WouldBlock => break,
            Err(e) => {
                read = Err(ws_err(e));
                break;
            }
        }
    }
    ws.get_ref().get_ref().set_nonblocking(false)?;
    read
}
