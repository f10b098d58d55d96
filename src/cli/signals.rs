//! SIGINT and SIGTERM: the process removes its temporary files and staging folders
//! ([`crate::cleanup`]) and exits with 128 + the signal's number (130, 143), as shells report a
//! process killed by it. Result files written a line at a time (`sweep --out`) keep their
//! complete lines, so the run can be resumed (`--resume`).
//!
//! The handler itself only records the signal (an atomic store, safe in a signal handler); a
//! watcher thread does the clean-up and the exit.
//!
//! SIGPIPE keeps its default action (Rust programs start with it ignored): output to a closed
//! pipe (`macrotree run … | head -0`) ends the command quietly with that signal, as the shell's
//! 141 reports, instead of a panic on the failed write. Temporary files it leaves are reclaimed
//! by the next run ([`crate::cleanup::reclaim`]).

use std::sync::atomic::{AtomicI32, Ordering};
use std::time::Duration;

static SIGNALLED: AtomicI32 = AtomicI32::new(0);

extern "C" fn on_signal(sig: libc::c_int) {
    SIGNALLED.store(sig, Ordering::SeqCst);
}

/// Installs the handlers of SIGINT and SIGTERM, gives SIGPIPE its default action and starts the
/// watcher thread.
pub(super) fn install() {
    // SAFETY: setting a signal's disposition to its default is async-signal-safe and has no
    // other effect on this process's state.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `sigaction` with a zeroed struct, an empty mask and a handler that only does
        // an atomic store (async-signal-safe); SA_RESTART keeps system calls going.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(sig, &action, std::ptr::null_mut());
        }
    }
    let _ = std::thread::Builder::new().name("signals".into()).spawn(|| {
        loop {
            std::thread::sleep(Duration::from_millis(20));
            let sig = SIGNALLED.load(Ordering::SeqCst);
            if sig != 0 {
                crate::cleanup::remove_all();
                let name = if sig == libc::SIGINT { "SIGINT" } else { "SIGTERM" };
                eprintln!(
                    "\nstopped by {name}: temporary files removed; a --out file keeps its \
                         complete lines (add --resume to continue)"
                );
                std::process::exit(128 + sig);
            }
        }
    });
}
