//! The acceptor: takes connections (pausing after failed accepts), checks `Host` and `Origin`,
//! answers HTTP requests and hands websocket upgrades to a client thread.

use std::io::{self, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use tungstenite::Bytes;
use tungstenite::protocol::{Role, WebSocket, WebSocketConfig};

use super::client::{GOODBYE_DEADLINE, incoming_limits, run_client};
use super::hub::Hub;
use crate::viewer::guard::Authority;
use crate::viewer::http::{Request, Response, TimedStream, read_request};
use crate::viewer::limits::{MAX_REQUEST_HEAD, ServerLimits};
use crate::viewer::slots::{Refused, SlotGuard, Stage};

/// First pause of the acceptor after a failed `accept` (e.g. out of file descriptors).
const ACCEPT_BACKOFF_MIN: Duration = Duration::from_millis(10);
/// Longest pause of the acceptor between failed `accept`s (the pause doubles up to it).
const ACCEPT_BACKOFF_MAX: Duration = Duration::from_secs(1);
/// Least time between two warnings about failed `accept`s.
const ACCEPT_WARN_INTERVAL: Duration = Duration::from_secs(60);

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
pub(super) struct AcceptBackoff {
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

    #[cfg(test)]
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
            download = crate::viewer::page::standalone_html(&site.bundle, &commands, None);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The acceptor's pauses after failed accepts double up to a bound and reset on success; it
    /// warns at the first failure, then at most once per interval, and logs one recovery per warning.
    #[test]
    fn accept_backoff_doubles_up_to_its_bound_and_warns_sparingly() {
        let mut b = AcceptBackoff::default();
        let pauses: Vec<_> = (0..12).map(|_| b.failed()).collect();
        assert_eq!(pauses[0], ACCEPT_BACKOFF_MIN);
        assert_eq!(pauses[1], ACCEPT_BACKOFF_MIN * 2);
        assert!(pauses.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(*pauses.last().unwrap(), ACCEPT_BACKOFF_MAX);
        assert_eq!(b.failures(), 12);
        for _ in 0..100_000 {
            assert!(b.failed() <= ACCEPT_BACKOFF_MAX);
        }
        // Logging: failures and successes in turns (near the descriptor limit).
        let t0 = Instant::now();
        let mut b = AcceptBackoff::default();
        assert!(!b.succeeded(), "nothing to recover from");
        b.failed();
        assert!(b.warn_now(t0), "the first failure is logged");
        assert!(b.succeeded(), "and so is the recovery");
        assert_eq!(b.failed(), ACCEPT_BACKOFF_MIN, "a success starts the pauses over");
        assert!(
            !b.warn_now(t0 + ACCEPT_WARN_INTERVAL / 2),
            "not again within the interval"
        );
        assert!(!b.succeeded(), "no recovery line without a warning");
        b.failed();
        assert!(b.warn_now(t0 + ACCEPT_WARN_INTERVAL), "again after the interval");
    }
}
