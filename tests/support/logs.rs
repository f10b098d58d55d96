//! Capturing the library's `tracing` log in a test, to count what it says.
//!
//! One global INFO-level subscriber is installed for the test binary; it writes each line to the
//! emitting thread's buffer while that thread is inside [`capture`], and drops it otherwise. (A
//! per-test scoped subscriber would race with the tests running beside it on tracing's shared
//! callsite-interest cache and miss events.)

#![allow(dead_code)]

use std::cell::RefCell;
use std::io::Write;
use std::sync::Once;

thread_local! {
    static BUFFER: RefCell<Option<Vec<u8>>> = const { RefCell::new(None) };
}

struct ThreadBuffer;

impl Write for ThreadBuffer {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        BUFFER.with(|b| {
            if let Some(buf) = b.borrow_mut().as_mut() {
                buf.extend_from_slice(bytes);
            }
        });
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Runs `f` and returns its result and every line this thread logged meanwhile (INFO and up;
/// work `f` hands to other threads is not captured).
pub fn capture<R>(f: impl FnOnce() -> R) -> (R, Vec<String>) {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let subscriber = tracing_subscriber::fmt()
            .with_writer(|| ThreadBuffer)
            .with_ansi(false)
            .with_max_level(tracing::Level::INFO)
            .finish();
        tracing::subscriber::set_global_default(subscriber).expect("no other global subscriber");
    });
    BUFFER.with(|b| *b.borrow_mut() = Some(Vec::new()));
    let result = f();
    let bytes = BUFFER.with(|b| b.borrow_mut().take()).unwrap_or_default();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    (result, text.lines().map(str::to_string).collect())
}
