//! The live server's limits: connections, sizes and waits. Every one is bounded; the defaults
//! are the constants below, and [`ServerLimits`] lets a caller (or a test) choose others.

use std::time::Duration;

/// Connections (HTTP and websocket) open at once. When all are taken, a new connection closes
/// the oldest one still sending its request head, else the oldest websocket client.
pub const MAX_CONNECTIONS: usize = 64;
/// Time a client has to send its whole request head, counted from the accept, however the
/// bytes trickle in.
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(10);
/// Largest request head (request line and headers), bytes.
pub const MAX_REQUEST_HEAD: usize = 16 * 1024;
/// Time to write a whole HTTP response (the page, the bundle, a `/download` of ~10 MB).
pub const RESPONSE_DEADLINE: Duration = Duration::from_secs(60);
/// A websocket client is dropped when the oldest update it has not yet read is this old: data
/// still waiting in our outbox or socket, or data written before a ping it has not answered.
pub const MAX_CLIENT_LAG: Duration = Duration::from_secs(30);
/// How often a websocket client that is being sent updates is pinged to measure its lag.
pub const PING_INTERVAL: Duration = Duration::from_secs(1);
/// Largest message (and frame) a websocket client may send, bytes: the page sends nothing but
/// close frames, pongs and the answer to a capture request.
pub const MAX_CLIENT_MESSAGE: usize = 4 * 1024;
/// Largest answer to a capture request (a PNG as a base64 data URL), bytes; allowed only from
/// the client asked, while the request is pending.
pub const MAX_CAPTURE_REPLY: usize = 32 << 20;

/// The limits of one live server (see the constants for what each means). Durations are wall
/// time; sizes are bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServerLimits {
    /// Connections open at once ([`MAX_CONNECTIONS`]).
    pub max_connections: usize,
    /// Time to send a whole request head ([`REQUEST_DEADLINE`]).
    pub request_deadline: Duration,
    /// Time to write a whole HTTP response ([`RESPONSE_DEADLINE`]).
    pub response_deadline: Duration,
    /// Age of the oldest unread update at which a websocket client is dropped
    /// ([`MAX_CLIENT_LAG`]).
    pub max_client_lag: Duration,
    /// Interval of the pings that measure a client's lag ([`PING_INTERVAL`]).
    pub ping_interval: Duration,
    /// Largest message or frame from a websocket client, bytes ([`MAX_CLIENT_MESSAGE`]).
    pub max_client_message: usize,
    /// Largest answer to a capture request, bytes ([`MAX_CAPTURE_REPLY`]).
    pub max_capture_reply: usize,
}

impl ServerLimits {
    /// The documented defaults (the constants of this module).
    pub const DEFAULT: Self = Self {
        max_connections: MAX_CONNECTIONS,
        request_deadline: REQUEST_DEADLINE,
        response_deadline: RESPONSE_DEADLINE,
        max_client_lag: MAX_CLIENT_LAG,
        ping_interval: PING_INTERVAL,
        max_client_message: MAX_CLIENT_MESSAGE,
        max_capture_reply: MAX_CAPTURE_REPLY,
    };
}

impl Default for ServerLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}
