//! The live server's limits: connections, sizes and waits. Every one is bounded; the defaults
//! are [`ServerLimits::DEFAULT`], and a caller (or a test) may choose others.

use std::time::Duration;

/// Largest request head (request line and headers), bytes.
pub(super) const MAX_REQUEST_HEAD: usize = 16 * 1024;

/// The limits of one live server. Durations are wall time; sizes are bytes. The defaults are
/// [`ServerLimits::DEFAULT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServerLimits {
    /// Connections (HTTP and websocket) open at once (default 64). When all are taken, a new
    /// connection closes the oldest one still sending its request head, else the oldest
    /// websocket client.
    pub max_connections: usize,
    /// Time a client has to send its whole request head, counted from the accept, however the
    /// bytes trickle in (default 10 s).
    pub request_deadline: Duration,
    /// Time to write a whole HTTP response: the page, the bundle, a `/download` of ~10 MB
    /// (default 60 s).
    pub response_deadline: Duration,
    /// Age of the oldest update a websocket client has not read at which it is dropped: data
    /// still waiting in the outbox or socket, or written before a ping it has not answered
    /// (default 30 s).
    pub max_client_lag: Duration,
    /// Interval of the pings that measure the lag of a client being sent updates (default 1 s).
    pub ping_interval: Duration,
    /// Largest message or frame a websocket client may send, bytes (default 4 KiB): the page
    /// sends nothing but close frames, pongs and the answer to a capture request.
    pub max_client_message: usize,
    /// Largest answer to a capture request (a PNG as a base64 data URL), bytes (default 32 MiB);
    /// allowed only from the client asked, while the request is pending.
    pub max_capture_reply: usize,
}

impl ServerLimits {
    /// The defaults documented on each field.
    pub const DEFAULT: Self = Self {
        max_connections: 64,
        request_deadline: Duration::from_secs(10),
        response_deadline: Duration::from_secs(60),
        max_client_lag: Duration::from_secs(30),
        ping_interval: Duration::from_secs(1),
        max_client_message: 4 * 1024,
        max_capture_reply: 32 << 20,
    };
}

impl Default for ServerLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}
