//! Temporary files and staging folders this process owns, removed when it is stopped by
//! SIGINT or SIGTERM, and reclaimed by a later run when their owner is gone.
//!
//! Every temporary file of [`crate::output`] and every dataset staging folder is
//! [`register`]ed while it exists; the command line's signal handler ([`remove_all`]) removes
//! them before the process exits. Each one is also held open with its advisory lock (`flock`)
//! by its owner, so a later run tells a leftover of a process that is gone (the lock is free:
//! the system drops a process's locks when it ends, however it ends, `kill -9` included) from
//! one still being written (locked), and [`reclaim`] removes only the former.

use std::collections::HashMap;
use std::ffi::OsStr;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT: AtomicU64 = AtomicU64::new(1);
static LIVE: Mutex<Option<HashMap<u64, (PathBuf, bool)>>> = Mutex::new(None);

/// A registered path: deregistered when dropped (the path itself is left as it is).
#[derive(Debug)]
pub struct Registered(u64);

impl Drop for Registered {
    fn drop(&mut self) {
        if let Ok(mut live) = LIVE.lock()
            && let Some(map) = live.as_mut()
        {
            map.remove(&self.0);
        }
    }
}

/// Registers `path` (a file, or a folder when `dir`) to be removed by [`remove_all`].
pub fn register(path: &Path, dir: bool) -> Registered {
    let id = NEXT.fetch_add(1, Ordering::Relaxed);
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    if let Ok(mut live) = LIVE.lock() {
        live.get_or_insert_with(HashMap::new).insert(id, (abs, dir));
    }
    Registered(id)
}

/// Removes every registered path (the signal handler's clean-up before the process exits).
#[cfg(feature = "cli")]
pub fn remove_all() {
    let taken = match LIVE.lock() {
        Ok(mut live) => live.take().unwrap_or_default(),
        Err(_) => return,
    };
    for (path, dir) in taken.into_values() {
        let _ = if dir {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
    }
}

/// Takes the advisory lock of `file` without waiting: `true` when taken.
pub fn try_lock(file: &File) -> bool {
    file.try_lock().is_ok()
}

/// A leftover younger than this is never reclaimed: its owner may have created it and not yet
/// taken its lock.
pub const MIN_AGE: std::time::Duration = std::time::Duration::from_secs(10);

/// Removes the leftovers in `dir` whose names start with `prefix` and end with `suffix`
/// (temporary files, or staging folders when `dirs`) whose owner is gone: nobody holds their
/// lock, and they are at least [`MIN_AGE`] old. Links and other kinds of entries are left
/// alone. Returns how many were removed.
pub fn reclaim(dir: &Path, prefix: &OsStr, suffix: &str, dirs: bool) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten().take(100_000) {
        let name = entry.file_name();
        let bytes = name.as_encoded_bytes();
        if !bytes.starts_with(prefix.as_encoded_bytes()) || !bytes.ends_with(suffix.as_bytes()) {
            continue;
        }
        let path = entry.path();
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if meta.file_type().is_symlink() || meta.is_dir() != dirs || !(meta.is_dir() || meta.is_file()) {
            continue;
        }
        let fresh = meta
            .modified()
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_none_or(|age| age < MIN_AGE);
        if fresh {
            continue;
        }
        let Ok(f) = File::open(&path) else {
            continue;
        };
        // Locked: its owner is still writing it.
        if !try_lock(&f) {
            continue;
        }
        let gone = if dirs {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        if gone.is_ok() {
            removed += 1;
        }
    }
    removed
}
