//! The open connections and what each is doing, so that a full server makes room for a new
//! connection (the user's) instead of refusing it: slow or idle clients cannot lock it out.

use std::net::{Shutdown, TcpStream};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Instant;

/// What a connection is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stage {
    /// Still sending its request head.
    Head,
    /// Being answered (an HTTP response, bounded by the response deadline).
    Response,
    /// A websocket client.
    WebSocket,
}

#[derive(Debug)]
struct Slot {
    id: u64,
    opened: Instant,
    stage: Stage,
    /// A handle on the same socket, to shut it down from the acceptor.
    socket: TcpStream,
}

/// The open connections, at most `max` (plus, briefly, evicted ones whose threads are ending).
#[derive(Debug, Default)]
pub(crate) struct Slots {
    open: Mutex<Vec<Slot>>,
    next_id: std::sync::atomic::AtomicU64,
}

/// Why a connection was not admitted.
#[derive(Debug)]
pub(crate) enum Refused {
    /// Every slot is answering an HTTP request: none may be evicted.
    Full,
    /// The socket could not be duplicated (out of file descriptors).
    Io(std::io::Error),
}

impl Slots {
    fn lock(&self) -> MutexGuard<'_, Vec<Slot>> {
        self.open.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Number of open connections.
    pub fn len(&self) -> usize {
        self.lock().len()
    }

    /// Registers `stream` in a slot. When all `max` slots are taken it first shuts down the
    /// oldest connection still sending its head, else the oldest websocket client; the
    /// returned guard frees the slot when dropped.
    pub fn admit(self: &Arc<Self>, stream: &TcpStream, max: usize) -> Result<SlotGuard, Refused> {
        let socket = stream.try_clone().map_err(Refused::Io)?;
        let mut open = self.lock();
        if open.len() >= max.max(1) {
            let victim = oldest(&open, Stage::Head).or_else(|| oldest(&open, Stage::WebSocket));
            let Some(i) = victim else {
                return Err(Refused::Full);
            };
            let evicted = open.swap_remove(i);
            let _ = evicted.socket.shutdown(Shutdown::Both);
            tracing::debug!(stage = ?evicted.stage, "viewer: all connections taken; closed the oldest idle one");
        }
        let id = self.next_id.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        open.push(Slot {
            id,
            opened: Instant::now(),
            stage: Stage::Head,
            socket,
        });
        Ok(SlotGuard {
            slots: self.clone(),
            id,
        })
    }
}

/// Index of the oldest slot at `stage`.
fn oldest(open: &[Slot], stage: Stage) -> Option<usize> {
    open.iter()
        .enumerate()
        .filter(|(_, s)| s.stage == stage)
        .min_by_key(|(_, s)| s.opened)
        .map(|(i, _)| i)
}

/// A connection's slot; freed on drop.
#[derive(Debug)]
pub(crate) struct SlotGuard {
    slots: Arc<Slots>,
    id: u64,
}

impl SlotGuard {
    /// Records what the connection now does (an evicted connection has no slot to update).
    pub fn set_stage(&self, stage: Stage) {
        if let Some(slot) = self.slots.lock().iter_mut().find(|s| s.id == self.id) {
            slot.stage = stage;
        }
    }
}

impl Drop for SlotGuard {
    fn drop(&mut self) {
        self.slots.lock().retain(|s| s.id != self.id);
    }
}
