//! The `Hub`: the scene tree and every client's outbox, shared between the simulation thread
//! and the client threads under one short lock.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use tungstenite::Bytes;

use crate::viewer::monitor::MonitorCommand;
use crate::viewer::panel::PanelState;
use crate::viewer::slots::Slots;
use crate::viewer::tree::SceneTree;

/// How long a client thread sleeps when it has nothing to send (it then polls for input).
pub(super) const IDLE_POLL: Duration = Duration::from_millis(25);
/// Shortest wall time between two live updates (poses, statuses) to one client: at most 40 per
/// second; a slower client gets the latest poses, never a backlog (trace events are kept up
/// to [`crate::viewer::panel::EVENT_HISTORY`]).
pub const MIN_POSE_INTERVAL: Duration = Duration::from_millis(25);
/// Structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_MESSAGES: usize = 4096;
/// Bytes of structural messages a client may have queued before it is reset to a snapshot.
pub const MAX_QUEUED_BYTES: usize = 64 << 20;

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
pub(super) struct Outbox {
    pub(super) queue: VecDeque<Bytes>,
    pub(super) queued_bytes: usize,
    pub(super) resync: bool,
    /// Sent after the pending poses, which are then flushed at once (capture requests: the
    /// image must show everything published before the request).
    pub(super) after_poses: Vec<Bytes>,
    /// Latest pose message per slot (body id); `None` once written.
    pub(super) poses: Vec<Option<Bytes>>,
    pub(super) poses_pending: bool,
    /// When the client's thread may write its next live update; until then it sleeps (at most
    /// until this instant) without being woken for live updates.
    pub(super) next_live_at: Option<Instant>,
    pub(super) time: Option<f64>,
    pub(super) tree_dirty: bool,
    pub(super) status_dirty: bool,
    pub(super) closed: bool,
    /// When the oldest update still in this outbox was queued (`None`: nothing pending).
    pub(super) pending_since: Option<Instant>,
    /// A capture request awaits this client's answer: its messages may be larger.
    pub(super) capture_pending: bool,
    pub(super) stats: ClientStats,
}

/// A connected websocket client as the hub sees it.
#[derive(Debug)]
pub(crate) struct Client {
    pub(super) id: u64,
    pub(super) out: Mutex<Outbox>,
    pub(super) wake: Condvar,
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
    pub(super) fn lock(&self) -> MutexGuard<'_, Outbox> {
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
    /// Monitor commands from the pages, oldest first (at most [`MAX_PENDING_COMMANDS`]).
    commands: Mutex<VecDeque<MonitorCommand>>,
    command_ready: Condvar,
}

/// Monitor commands kept until the simulation thread takes them; more are dropped (and logged).
pub(crate) const MAX_PENDING_COMMANDS: usize = 64;

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

    pub(super) fn register(&self) -> Arc<Client> {
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

    pub(super) fn unregister(&self, id: u64) {
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

    pub(super) fn on_text(&self, client: u64, text: &str) {
        let Ok(value) = serde_json::from_str::<serde_json::Value>(text) else {
            return;
        };
        match value.get("type").and_then(|t| t.as_str()) {
            Some("img") => self.on_capture(client, &value),
            Some("monitor") => match MonitorCommand::parse(&value) {
                Ok(cmd) => self.push_command(client, cmd),
                Err(why) => tracing::info!(client, "viewer: ignored a monitor command: {why}"),
            },
            _ => {}
        }
    }

    fn push_command(&self, client: u64, cmd: MonitorCommand) {
        let mut queue = self.commands.lock().unwrap_or_else(|e| e.into_inner());
        if queue.len() >= MAX_PENDING_COMMANDS {
            tracing::info!(
                client,
                "viewer: dropped a monitor command ({MAX_PENDING_COMMANDS} are pending)"
            );
            return;
        }
        queue.push_back(cmd);
        self.command_ready.notify_all();
    }

    /// The oldest pending monitor command, waiting up to `wait` for one.
    pub fn next_command(&self, wait: Duration) -> Option<MonitorCommand> {
        let queue = self.commands.lock().unwrap_or_else(|e| e.into_inner());
        let (mut queue, _) = self
            .command_ready
            .wait_timeout_while(queue, wait, |q| q.is_empty())
            .unwrap_or_else(|e| e.into_inner());
        queue.pop_front()
    }

    fn on_capture(&self, client: u64, value: &serde_json::Value) {
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

/// Everything a client thread takes out of its outbox in one go.
pub(super) struct Batch {
    pub(super) queue: VecDeque<Bytes>,
    pub(super) poses: Vec<Bytes>,
    pub(super) after_poses: Vec<Bytes>,
    pub(super) time: Option<f64>,
    pub(super) resync: bool,
    pub(super) tree: bool,
    pub(super) status: bool,
    pub(super) closed: bool,
    /// When the oldest update in this batch (or still pending after it) was queued.
    pub(super) since: Option<Instant>,
    /// A capture request awaits this client's answer.
    pub(super) capture_pending: bool,
}

/// Takes what is due: structural messages and the panel's node list at once, live updates
/// (poses, sim time, panel statuses) at most every [`MIN_POSE_INTERVAL`] (the newer ones
/// replace older ones meanwhile). Waits up to [`IDLE_POLL`] when nothing is due.
pub(super) fn take_batch(client: &Client) -> Batch {
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
