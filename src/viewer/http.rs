//! Just enough HTTP/1.1 for the live page: read one request head, write one response, each
//! bounded by a total deadline ([`TimedStream`]) rather than by a timeout per read or write.

use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// A TCP stream whose reads and writes fail with `TimedOut` once their deadline has passed,
/// however slowly the bytes trickle: before each call the socket's timeout is set to the time
/// left. Without a deadline a call blocks as the socket does.
#[derive(Debug)]
pub(crate) struct TimedStream {
    inner: TcpStream,
    read_deadline: Option<Instant>,
    write_deadline: Option<Instant>,
}

impl TimedStream {
    /// Wraps `inner` with no deadlines.
    pub fn new(inner: TcpStream) -> Self {
        Self {
            inner,
            read_deadline: None,
            write_deadline: None,
        }
    }

    /// The socket.
    pub fn get_ref(&self) -> &TcpStream {
        &self.inner
    }

    /// Reads after `deadline` fail (`None`: no deadline).
    pub fn set_read_deadline(&mut self, deadline: Option<Instant>) {
        self.read_deadline = deadline;
    }

    /// Writes after `deadline` fail (`None`: no deadline).
    pub fn set_write_deadline(&mut self, deadline: Option<Instant>) {
        self.write_deadline = deadline;
    }
}

/// The time left until `deadline`, or `TimedOut` when none is.
fn time_left(deadline: Instant) -> io::Result<Duration> {
    let left = deadline.saturating_duration_since(Instant::now());
    if left.is_zero() {
        Err(io::Error::new(io::ErrorKind::TimedOut, "deadline passed"))
    } else {
        Ok(left)
    }
}

impl Read for TimedStream {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if let Some(deadline) = self.read_deadline {
            self.inner.set_read_timeout(Some(time_left(deadline)?))?;
        }
        self.inner.read(buf)
    }
}

impl Write for TimedStream {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if let Some(deadline) = self.write_deadline {
            self.inner.set_write_timeout(Some(time_left(deadline)?))?;
        }
        self.inner.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// A parsed request head.
#[derive(Debug)]
pub(crate) struct Request {
    /// `GET`, `HEAD`, …
    pub method: String,
    /// The request target, query included.
    pub path: String,
    /// Header names and values, in order, trimmed.
    pub headers: Vec<(String, String)>,
    /// Bytes read past the head (the start of a websocket stream).
    pub rest: Vec<u8>,
}

impl Request {
    /// The value of the first header called `name` (any case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
}

/// Reads one request head of at most `max_head` bytes; the stream's read deadline bounds the
/// whole head.
pub(crate) fn read_request(stream: &mut TimedStream, max_head: usize) -> io::Result<Request> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1024];
    let end = loop {
        if let Some(pos) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break pos + 4;
        }
        if buf.len() > max_head {
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

/// One response: status line, content type, cache policy and body (left out for `HEAD`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Response<'a> {
    /// Status code and reason, e.g. `200 OK`.
    pub status: &'a str,
    /// `Content-Type` value.
    pub content_type: &'a str,
    /// `Cache-Control` value.
    pub cache: &'a str,
    /// The body.
    pub body: &'a [u8],
}

impl<'a> Response<'a> {
    /// A plain-text response that is never cached (errors, refusals).
    pub fn text(status: &'a str, body: &'a str) -> Self {
        Self {
            status,
            content_type: "text/plain",
            cache: "no-store",
            body: body.as_bytes(),
        }
    }

    /// Writes the response (the head only when `head_only`) and closes the connection; the
    /// stream's write deadline bounds the whole response.
    pub fn send(&self, stream: &mut TimedStream, head_only: bool) -> io::Result<()> {
        let head = format!(
            "HTTP/1.1 {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: {}\r\nConnection: close\r\n\r\n",
            self.status,
            self.content_type,
            self.body.len(),
            self.cache,
        );
        stream.write_all(head.as_bytes())?;
        if !head_only {
            stream.write_all(self.body)?;
        }
        stream.flush()
    }
}
