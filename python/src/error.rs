//! Errors across the boundary: every `macrotree::Error` becomes a `MacrotreeError` carrying the
//! library's located message (`file:line:column: …`) and its stable kind.

use pyo3::create_exception;
use pyo3::prelude::*;

// Named under `macrotree`, where the class is exported, so that an instance pickles: a Gymnasium
// `AsyncVectorEnv` worker sends its exception to the caller that way (under `_native` the pickling
// failed, the worker died and the caller waited for ever).
create_exception!(
    macrotree,
    MacrotreeError,
    pyo3::exceptions::PyException,
    "Invalid input (a tree, scene or leaf mapping that does not check, a number out of range): the message is located and says what to do."
);

/// Most characters of an exception's message: several located diagnostics, each bounded by
/// the library; input quoted anywhere else (a 1 MB layout name) is cut to fit.
const MAX_MESSAGE_CHARS: usize = 8 * macrotree::yaml::MAX_FIELD_CHARS;

/// `message` cut to [`MAX_MESSAGE_CHARS`].
fn bounded(message: &str) -> String {
    macrotree::yaml::cut_text(message, MAX_MESSAGE_CHARS)
}

/// A library error as a Python exception; `kind` (e.g. `invalid_tree`) is kept as an attribute.
pub fn to_py(e: macrotree::Error) -> PyErr {
    let err = MacrotreeError::new_err(bounded(&e.to_string()));
    Python::attach(|py| {
        let _ = err.value(py).setattr("kind", e.kind());
    });
    err
}

/// A `ValueError` for a malformed argument caught on this side.
pub fn value(message: impl Into<String>) -> PyErr {
    pyo3::exceptions::PyValueError::new_err(bounded(&message.into()))
}

/// `mutex` locked, or a `RuntimeError` when another thread holds it: an environment serves one
/// thread at a time. Waiting would deadlock: this thread holds the GIL, which the other thread
/// needs to finish its call.
pub fn try_lock<T>(mutex: &std::sync::Mutex<T>) -> PyResult<std::sync::MutexGuard<'_, T>> {
    match mutex.try_lock() {
        Ok(guard) => Ok(guard),
        Err(std::sync::TryLockError::Poisoned(e)) => Ok(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => Err(pyo3::exceptions::PyRuntimeError::new_err(
            "this environment is in use by another thread (a call on it is still running); an environment serves one thread at a time: give each thread its own, or serialise the calls",
        )),
    }
}

/// How often a long call looks for Ctrl-C (Python's signal handlers run on the main thread).
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// Python's pending signals, looked at from Rust code running with the GIL released: the
/// closure [`SignalPoll::poll`] gives a stepping loop says to stop once a handler raised (Ctrl-C:
/// `KeyboardInterrupt`), which [`SignalPoll::raised`] then hands back.
#[derive(Default)]
pub struct SignalPoll {
    raised: std::sync::Mutex<Option<PyErr>>,
}

impl SignalPoll {
    /// A closure for `step_with` and the like: every [`SIGNAL_POLL`] it takes the GIL and runs
    /// Python's signal handlers; true once one raised.
    pub fn poll(&self) -> impl FnMut() -> bool + '_ {
        let mut last = std::time::Instant::now();
        move || {
            if last.elapsed() < SIGNAL_POLL {
                return false;
            }
            last = std::time::Instant::now();
            Python::attach(|py| match py.check_signals() {
                Ok(()) => false,
                Err(e) => {
                    *self.raised.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
                    true
                }
            })
        }
    }

    /// `e` as a Python exception: the signal handler's own (`KeyboardInterrupt`) when one
    /// raised, else the library error.
    pub fn error(&self, e: macrotree::Error) -> PyErr {
        match self.raised.lock().unwrap_or_else(|e| e.into_inner()).take() {
            Some(raised) => raised,
            None => to_py(e),
        }
    }
}
