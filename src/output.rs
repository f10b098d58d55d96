//! Safe output files: every file the command line writes (`run --record`, `run --video`,
//! `run --frames`, `sweep --out`, `schema --out`, `graph --out`) goes through [`OutputFile`];
//! `sweep --dataset` folders follow the same rules (see `crate::dataset`).
//!
//! The rule, checked by [`OutputFile::check`] before any work starts:
//!
//! - `PATH` must name a regular file or nothing yet. A symbolic link, a folder, a device, a FIFO
//!   or a socket at `PATH` is refused (never followed, never replaced, never written through).
//! - The one exception: the exact paths `/dev/stdout` and `/dev/stderr` (and `-`, for standard
//!   output) are the process's own output streams, and are written to directly.
//! - `PATH` must not be one of the command's input files (same device and inode, so a hard link
//!   or a different spelling of the same file is caught too).
//! - The folder of `PATH` must exist and accept a new file (checked by creating and removing
//!   one), so a long run is not wasted on an output that cannot be written.
//!
//! Writing never touches `PATH` until the content is complete: it goes to a new file in the same
//! folder, created exclusively (`O_CREAT | O_EXCL`, which never follows a symbolic link) under an
//! unpredictable name, flushed to disk (`fsync`), then renamed over `PATH` (an existing regular
//! file keeps its permission bits). Any error removes the temporary file and leaves `PATH` as it
//! was. Streams ([`OutputFile::stream`]) install their file the same way before the first line,
//! then append whole lines to it. A stream holds an advisory lock (`flock`) on its file for as
//! long as it is written, and on the file it replaces from the moment that is checked
//! ([`OutputFile::lock_existing`]): a second writer of the same output is refused
//! ([`OutputError::Locked`]), and [`LineFile::finish`] checks that the path still names the file
//! written ([`OutputError::Replaced`]). Files another program writes (`run --video`: ffmpeg) are
//! written to such a temporary file ([`OutputFile::pending`]) and installed the same way.

use std::collections::hash_map::RandomState;
use std::ffi::OsString;
use std::fmt;
use std::fs::{File, OpenOptions};
use std::hash::{BuildHasher, Hasher};
use std::io::{self, Write};
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// Why an output file cannot be (or was not) written. Its `Display` says what and what to do.
#[derive(Debug)]
pub enum OutputError {
    /// `PATH` exists and is not a regular file.
    NotRegular {
        /// The output path.
        path: PathBuf,
        /// What it is ("a symbolic link", "a folder", "a device", …).
        what: &'static str,
    },
    /// `PATH` is an input of the command.
    IsInput {
        /// The output path.
        path: PathBuf,
        /// The input it is.
        input: PathBuf,
    },
    /// `PATH` has no file name (`/`, `..`, an empty path or one ending in `/`).
    NotAFilePath {
        /// The output path.
        path: PathBuf,
    },
    /// The folder of `PATH` is missing or is not a folder.
    NoFolder {
        /// The output path.
        path: PathBuf,
        /// Its folder.
        dir: PathBuf,
    },
    /// Another process holds the lock of the file at `PATH`: it is writing it.
    Locked {
        /// The output path.
        path: PathBuf,
    },
    /// `PATH` no longer names the file written (another process replaced or removed it).
    Replaced {
        /// The output path.
        path: PathBuf,
    },
    /// An I/O operation failed.
    Io {
        /// The output path.
        path: PathBuf,
        /// What was being done ("create a file in", "write", …).
        action: &'static str,
        /// The error.
        source: io::Error,
    },
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotRegular { path, what } => write!(
                f,
                "refusing to write {}: it is {what}; outputs are written only to regular files or \
                 new paths (or to /dev/stdout)",
                path.display()
            ),
            Self::IsInput { path, input } => write!(
                f,
                "refusing to overwrite {}: it is an input of this command ({}); choose another output path",
                path.display(),
                input.display()
            ),
            Self::NotAFilePath { path } => write!(
                f,
                "{:?} is not a file path; give the path of the file to write, e.g. out/result.jsonl",
                path.display().to_string()
            ),
            Self::NoFolder { path, dir } => write!(
                f,
                "cannot write {}: the folder {} does not exist (create it first)",
                path.display(),
                dir.display()
            ),
            Self::Locked { path } => write!(
                f,
                "{} is being written by another process (it holds the file's lock); wait for it \
                 to finish, or choose another output path",
                path.display()
            ),
            Self::Replaced { path } => write!(
                f,
                "{} was replaced or removed by another process while this command wrote it; the \
                 results written are not at that path: run again with one writer per output",
                path.display()
            ),
            Self::Io { path, action, source } => {
                write!(f, "cannot write {}: {action}: {source}", path.display())
            }
        }
    }
}

impl std::error::Error for OutputError {}

/// A checked output path: see the [module docs](self) for the rule.
#[derive(Debug, Clone)]
pub struct OutputFile {
    path: PathBuf,
    /// `Some(1)` or `Some(2)` for standard output or error, written directly.
    stream_fd: Option<u8>,
    dir: PathBuf,
    name: OsString,
    /// Permission bits of the regular file at `path`, when there is one.
    existing_mode: Option<u32>,
    /// The file at `path`, open and locked ([`Self::lock_existing`]).
    held: Option<std::sync::Arc<File>>,
}

impl OutputFile {
    /// Checks that `path` can be written and is none of `inputs` (files the command reads;
    /// missing ones are ignored), before the work that produces the output starts.
    pub fn check(path: &Path, inputs: &[&Path]) -> Result<Self, OutputError> {
        let stream_fd = match path.as_os_str().as_encoded_bytes() {
            b"-" | b"/dev/stdout" => Some(1),
            b"/dev/stderr" => Some(2),
            _ => None,
        };
        if stream_fd.is_some() {
            return Ok(Self {
                path: path.to_path_buf(),
                stream_fd,
                dir: PathBuf::new(),
                name: OsString::new(),
                existing_mode: None,
                held: None,
            });
        }
        let name = match path.file_name() {
            Some(n) if !path.as_os_str().as_encoded_bytes().ends_with(b"/") => n.to_owned(),
            _ => {
                return Err(OutputError::NotAFilePath {
                    path: path.to_path_buf(),
                });
            }
        };
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !std::fs::metadata(&dir).is_ok_and(|m| m.is_dir()) {
            return Err(OutputError::NoFolder {
                path: path.to_path_buf(),
                dir,
            });
        }
        let existing_mode = match std::fs::symlink_metadata(path) {
            Ok(meta) => {
                refuse_non_regular(path, &meta)?;
                for input in inputs {
                    if std::fs::metadata(input).is_ok_and(|m| same_file(&m, &meta)) {
                        return Err(OutputError::IsInput {
                            path: path.to_path_buf(),
                            input: input.to_path_buf(),
                        });
                    }
                }
                Some(meta.permissions().mode())
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(source) => {
                return Err(OutputError::Io {
                    path: path.to_path_buf(),
                    action: "cannot inspect it",
                    source,
                });
            }
        };
        let out = Self {
            path: path.to_path_buf(),
            stream_fd: None,
            dir,
            name,
            existing_mode,
            held: None,
        };
        // The folder accepts a new file: try one (and remove it).
        let (probe, _, _registered) = out.create_temp()?;
        let _ = std::fs::remove_file(probe);
        // Temporary files of this output left by a process that is gone.
        let mut prefix = OsString::from(".");
        prefix.push(&out.name);
        prefix.push(".");
        crate::cleanup::reclaim(&out.dir, &prefix, ".tmp", false);
        Ok(out)
    }

    /// The output path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Opens the regular file now at the path (without following a link) and takes its
    /// advisory lock, held until this value and its streams are dropped: refused with
    /// [`OutputError::Locked`] when another process holds it. Returns the open file (to read
    /// what it holds), `None` when nothing is at the path or it is an output stream.
    pub fn lock_existing(&mut self) -> Result<Option<std::sync::Arc<File>>, OutputError> {
        if self.stream_fd.is_some() {
            return Ok(None);
        }
        let file = match OpenOptions::new()
            .read(true)
            .custom_flags(O_NOFOLLOW)
            .open(&self.path)
        {
            Ok(f) => f,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(self.io("cannot open it")(e)),
        };
        let meta = file.metadata().map_err(self.io("cannot inspect it"))?;
        refuse_non_regular(&self.path, &meta)?;
        try_lock(&file, &self.path)?;
        let file = std::sync::Arc::new(file);
        self.held = Some(file.clone());
        Ok(Some(file))
    }

    /// A regular file was at the path when it was checked (writing will replace it).
    pub fn replaces_existing(&self) -> bool {
        self.existing_mode.is_some()
    }

    /// The path is standard output or standard error, written directly (nothing to resume from).
    pub fn is_stream(&self) -> bool {
        self.stream_fd.is_some()
    }

    /// Writes `bytes` as the whole content of the file (temporary file, `fsync`, rename).
    pub fn write_all(&self, bytes: &[u8]) -> Result<(), OutputError> {
        if let Some(mut file) = self.open_stream()? {
            return file.write_all(bytes).map_err(self.io("write error"));
        }
        let (tmp, file, _registered) = self.create_temp()?;
        let result = self.fill_and_install(&tmp, file, bytes);
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result.map(|_| ())
    }

    /// Installs a file holding the first `len` bytes of `src` at the path (as
    /// [`stream`](Self::stream) does, copying in bounded memory) and returns it open, and
    /// locked, for appending whole lines.
    pub fn stream_from(&self, src: &File, len: u64) -> Result<LineFile, OutputError> {
        if self.stream_fd.is_some() {
            return self.stream(&[]);
        }
        let (tmp, mut file, _registered) = self.create_temp()?;
        let copied = (|| -> Result<(), OutputError> {
            use std::io::{Read, Seek};
            let mut src = src;
            src.seek(io::SeekFrom::Start(0))
                .map_err(self.io("cannot read it"))?;
            let n = io::copy(&mut src.take(len), &mut file).map_err(self.io("cannot copy it"))?;
            if n != len {
                return Err(self.io("cannot copy it")(io::Error::other(
                    "the file became shorter while it was read",
                )));
            }
            Ok(())
        })();
        let installed = copied.and_then(|()| self.install_stream(&tmp, file, &[]));
        match installed {
            Ok(file) => self.line_file(file, len),
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                Err(e)
            }
        }
    }

    /// Locks the new file `file` (at `tmp`), fills it with `prefix` and installs it.
    fn install_stream(&self, tmp: &Path, file: File, prefix: &[u8]) -> Result<File, OutputError> {
        try_lock(&file, &self.path)?;
        // A file another writer put at the path since the check is not replaced under it.
        if let Ok(other) = OpenOptions::new()
            .read(true)
            .custom_flags(O_NOFOLLOW)
            .open(&self.path)
        {
            let held = self.held.as_ref().and_then(|h| h.metadata().ok());
            let same = match (other.metadata(), held) {
                (Ok(a), Some(b)) => same_file(&a, &b),
                _ => false,
            };
            if !same {
                try_lock(&other, &self.path)?;
            }
        }
        self.fill_and_install(tmp, file, prefix)
    }

    fn line_file(&self, file: File, len: u64) -> Result<LineFile, OutputError> {
        let meta = file.metadata().map_err(self.io("cannot inspect it"))?;
        Ok(LineFile {
            file,
            path: self.path.clone(),
            len,
            lines: 0,
            regular: true,
            ident: Some((meta.dev(), meta.ino())),
        })
    }

    /// Installs a file holding `prefix` at the path (as [`write_all`](Self::write_all) does) and
    /// returns it open, and locked, for appending whole lines.
    pub fn stream(&self, prefix: &[u8]) -> Result<LineFile, OutputError> {
        if let Some(mut file) = self.open_stream()? {
            file.write_all(prefix).map_err(self.io("write error"))?;
            return Ok(LineFile {
                file,
                path: self.path.clone(),
                len: prefix.len() as u64,
                lines: 0,
                regular: false,
                ident: None,
            });
        }
        let (tmp, file, _registered) = self.create_temp()?;
        match self.install_stream(&tmp, file, prefix) {
            Ok(file) => self.line_file(file, prefix.len() as u64),
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                Err(e)
            }
        }
    }

    /// A new, empty temporary file next to the path for another program to fill (see
    /// [`PendingFile`]); refused for standard output and error.
    pub fn pending(&self) -> Result<PendingFile<'_>, OutputError> {
        if self.stream_fd.is_some() {
            return Err(OutputError::NotRegular {
                path: self.path.clone(),
                what: "an output stream (this output needs a file it can seek in)",
            });
        }
        let (tmp, file, registered) = self.create_temp()?;
        Ok(PendingFile {
            out: self,
            tmp,
            installed: false,
            _lock: file,
            _registered: registered,
        })
    }

    fn io(&self, action: &'static str) -> impl FnOnce(io::Error) -> OutputError + '_ {
        move |source| OutputError::Io {
            path: self.path.clone(),
            action,
            source,
        }
    }

    /// A handle on standard output or error (a duplicate of the descriptor), for stream paths.
    fn open_stream(&self) -> Result<Option<File>, OutputError> {
        use std::os::fd::AsFd;
        let fd = match self.stream_fd {
            Some(1) => io::stdout().as_fd().try_clone_to_owned(),
            Some(_) => io::stderr().as_fd().try_clone_to_owned(),
            None => return Ok(None),
        };
        fd.map(|fd| Some(File::from(fd)))
            .map_err(self.io("cannot open it"))
    }

    /// A new, empty file next to the path, created exclusively under an unpredictable name,
    /// locked (its owner is alive while the lock is held) and registered for removal on a
    /// signal ([`crate::cleanup`]).
    fn create_temp(&self) -> Result<(PathBuf, File, crate::cleanup::Registered), OutputError> {
        let (tmp, file) = self.create_temp_unregistered()?;
        let _ = file.try_lock();
        let registered = crate::cleanup::register(&tmp, false);
        Ok((tmp, file, registered))
    }

    fn create_temp_unregistered(&self) -> Result<(PathBuf, File), OutputError> {
        let mut last = None;
        for _ in 0..16 {
            let mut name = OsString::from(".");
            name.push(&self.name);
            name.push(format!(".{:016x}.tmp", random_u64()));
            let tmp = self.dir.join(name);
            let opened = OpenOptions::new()
                .write(true)
                .create_new(true)
                .mode(0o666)
                .open(&tmp);
            match opened {
                Ok(file) => return Ok((tmp, file)),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
                Err(e) => return Err(self.io("cannot create a file in its folder")(e)),
            }
        }
        Err(self.io("cannot create a file in its folder")(
            last.unwrap_or_else(|| io::Error::other("no free temporary name")),
        ))
    }

    /// Writes `bytes` to the temporary file, syncs it and renames it over the path.
    fn fill_and_install(&self, tmp: &Path, mut file: File, bytes: &[u8]) -> Result<File, OutputError> {
        file.write_all(bytes).map_err(self.io("write error"))?;
        if let Some(mode) = self.existing_mode {
            file.set_permissions(std::fs::Permissions::from_mode(mode & 0o7777))
                .map_err(self.io("cannot set permissions"))?;
        }
        file.sync_all().map_err(self.io("cannot flush it to disk"))?;
        // Whatever appeared at the path since the check must still be replaceable.
        match std::fs::symlink_metadata(&self.path) {
            Ok(meta) => refuse_non_regular(&self.path, &meta)?,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(self.io("cannot inspect it")(e)),
        }
        std::fs::rename(tmp, &self.path).map_err(self.io("cannot rename the new file over it"))?;
        if let Ok(d) = File::open(&self.dir) {
            let _ = d.sync_all();
        }
        Ok(file)
    }
}

/// A temporary file next to an [`OutputFile`]'s path, filled by someone else (an ffmpeg
/// process), then [`install`](Self::install)ed over the path; removed if dropped before.
#[derive(Debug)]
pub struct PendingFile<'a> {
    out: &'a OutputFile,
    tmp: PathBuf,
    installed: bool,
    /// The temporary file, open and locked while it is pending.
    _lock: File,
    _registered: crate::cleanup::Registered,
}

impl PendingFile<'_> {
    /// The temporary file to fill.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Syncs the filled temporary file and renames it over the output path.
    pub fn install(mut self) -> Result<(), OutputError> {
        let file = File::open(&self.tmp).map_err(self.out.io("cannot reopen the new file"))?;
        if let Some(mode) = self.out.existing_mode {
            file.set_permissions(std::fs::Permissions::from_mode(mode & 0o7777))
                .map_err(self.out.io("cannot set permissions"))?;
        }
        file.sync_all().map_err(self.out.io("cannot flush it to disk"))?;
        match std::fs::symlink_metadata(&self.out.path) {
            Ok(meta) => refuse_non_regular(&self.out.path, &meta)?,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(self.out.io("cannot inspect it")(e)),
        }
        std::fs::rename(&self.tmp, &self.out.path)
            .map_err(self.out.io("cannot rename the new file over it"))?;
        self.installed = true;
        if let Ok(d) = File::open(&self.out.dir) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

impl Drop for PendingFile<'_> {
    fn drop(&mut self) {
        if !self.installed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// An output file being written one whole line at a time (a JSONL stream). Each line is
/// written with its newline and handed to the system before [`write_line`](Self::write_line)
/// returns; after a failed write the file is cut back to its last complete line.
#[derive(Debug)]
pub struct LineFile {
    file: File,
    path: PathBuf,
    len: u64,
    lines: u64,
    /// A regular file (not standard output or error): can be cut back and synced.
    regular: bool,
    /// (device, inode) of the file, checked against the path by [`Self::finish`].
    ident: Option<(u64, u64)>,
}

impl LineFile {
    /// Appends `line` and a newline.
    pub fn write_line(&mut self, line: &str) -> Result<(), OutputError> {
        let mut buf = Vec::with_capacity(line.len() + 1);
        buf.extend_from_slice(line.as_bytes());
        buf.push(b'\n');
        match self.file.write_all(&buf) {
            Ok(()) => {
                self.len += buf.len() as u64;
                self.lines += 1;
                Ok(())
            }
            Err(source) => {
                if self.regular {
                    let _ = self.file.set_len(self.len);
                }
                Err(OutputError::Io {
                    path: self.path.clone(),
                    action: "write error",
                    source,
                })
            }
        }
    }

    /// Lines written through this stream (not counting the prefix).
    pub fn lines(&self) -> u64 {
        self.lines
    }

    /// The path of the file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the file to disk and checks that the path still names it
    /// ([`OutputError::Replaced`] when another process replaced or removed it).
    pub fn finish(self) -> Result<(), OutputError> {
        if !self.regular {
            return Ok(());
        }
        self.file.sync_all().map_err(|source| OutputError::Io {
            path: self.path.clone(),
            action: "cannot flush it to disk",
            source,
        })?;
        let now = std::fs::symlink_metadata(&self.path)
            .ok()
            .filter(|m| m.file_type().is_file())
            .map(|m| (m.dev(), m.ino()));
        if self.ident.is_some() && now != self.ident {
            return Err(OutputError::Replaced { path: self.path });
        }
        Ok(())
    }
}

/// Refuses anything but a regular file, naming what it is.
fn refuse_non_regular(path: &Path, meta: &std::fs::Metadata) -> Result<(), OutputError> {
    let t = meta.file_type();
    let what = if t.is_file() {
        return Ok(());
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a folder"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    };
    Err(OutputError::NotRegular {
        path: path.to_path_buf(),
        what,
    })
}

/// `open(2)`'s flag: fail on a symbolic link instead of following it.
const O_NOFOLLOW: i32 = libc::O_NOFOLLOW;

/// Takes `file`'s advisory lock (`flock`, exclusive, without waiting).
fn try_lock(file: &File, path: &Path) -> Result<(), OutputError> {
    match file.try_lock() {
        Ok(()) => Ok(()),
        Err(std::fs::TryLockError::WouldBlock) => Err(OutputError::Locked {
            path: path.to_path_buf(),
        }),
        Err(std::fs::TryLockError::Error(source)) => Err(OutputError::Io {
            path: path.to_path_buf(),
            action: "cannot lock it",
            source,
        }),
    }
}

fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// 64 unpredictable bits: the standard library seeds every `RandomState` from the operating
/// system's random source; the time and process id are mixed in on top.
fn random_u64() -> u64 {
    let mut h = RandomState::new().build_hasher();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    h.write_u128(now);
    h.write_u32(std::process::id());
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("macrotree-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_replace_a_regular_file_and_keep_its_mode_without_leftovers() {
        let dir = scratch("replace");
        let path = dir.join("a.txt");
        std::fs::write(&path, "old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        let out = OutputFile::check(&path, &[]).unwrap();
        assert!(out.replaces_existing());
        out.write_all(b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(
            std::fs::metadata(&path).unwrap().permissions().mode() & 0o777,
            0o600
        );
        assert_eq!(entries(&dir), ["a.txt"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn temporary_names_differ() {
        assert_ne!(random_u64(), random_u64());
    }

    #[test]
    fn a_path_without_a_file_name_is_refused() {
        for p in ["", "/", "..", "some/dir/"] {
            assert!(
                matches!(
                    OutputFile::check(Path::new(p), &[]),
                    Err(OutputError::NotAFilePath { .. })
                ),
                "{p:?}"
            );
        }
    }

    #[test]
    fn a_stream_cut_back_to_whole_lines_on_error_keeps_the_prefix() {
        let dir = scratch("stream");
        let path = dir.join("r.jsonl");
        let out = OutputFile::check(&path, &[]).unwrap();
        let mut s = out.stream(b"{\"a\":1}\n").unwrap();
        s.write_line("{\"b\":2}").unwrap();
        assert_eq!(s.lines(), 1);
        s.finish().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\"a\":1}\n{\"b\":2}\n");
        assert_eq!(entries(&dir), ["r.jsonl"]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
