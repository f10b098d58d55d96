//! One websocket client's thread: takes batches from its outbox, writes them at most every
//! [`MIN_POSE_INTERVAL`](super::hub::MIN_POSE_INTERVAL), reads what the browser sends, and measures how far behind it is.

use std::collections::VecDeque;
use std::io;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use tungstenite::protocol::{WebSocket, WebSocketConfig};
use tungstenite::{Bytes, Message};

use super::hub::{Client, Hub, take_batch};
use crate::viewer::http::TimedStream;
use crate::viewer::limits::ServerLimits;

/// Messages read from a client per poll, so that a chatty client cannot starve its writes.
const MAX_READS_PER_POLL: usize = 64;
/// Time given to a refusal or a closing handshake to reach the client's socket.
pub(super) const GOODBYE_DEADLINE: Duration = Duration::from_millis(500);

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

pub(super) fn run_client(mut ws: WebSocket<TimedStream>, hub: &Hub, limits: &ServerLimits) -> io::Result<()> {
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

/// `config` accepting client messages and frames of at most `max` bytes.
pub(super) fn incoming_limits(config: WebSocketConfig, max: usize) -> WebSocketConfig {
    config.max_message_size(Some(max)).max_frame_size(Some(max))
}
