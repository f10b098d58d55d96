//! H.264 MP4 video through a pinned ffmpeg: raw RGB frames are piped to its standard input.
//!
//! The ffmpeg used is `$MACROTREE_FFMPEG`, else `third_party/ffmpeg/ffmpeg` of this source tree
//! (the static build inside the PyPI wheel `imageio-ffmpeg==0.8.1`, fetched and checked by
//! `tools/bootstrap`). Nothing is fetched at run time.
//!
//! Encoding is deterministic: libx264 on one thread, no B-frames, bit-exact flags and no
//! metadata, so the same frames give the same file on every run and for any `--jobs`.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};

use crate::render::FrameSize;

/// Environment variable naming the ffmpeg binary to use.
pub const FFMPEG_ENV: &str = "MACROTREE_FFMPEG";

/// Lowest `--fps`, frames per second of simulated time.
pub const MIN_FPS: u32 = 1;
/// Highest `--fps` (the tree ticks every 4 ms: 250 ticks per second).
pub const MAX_FPS: u32 = 250;

/// Why a video could not be written.
#[derive(Debug)]
pub enum VideoError {
    /// The ffmpeg binary is missing.
    NoFfmpeg {
        /// Where it was looked for.
        path: PathBuf,
    },
    /// ffmpeg could not be started, fed or finished.
    Ffmpeg(String),
}

impl std::fmt::Display for VideoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NoFfmpeg { path } => write!(
                f,
                "ffmpeg not found at {}\n  help: run tools/bootstrap (it fetches the pinned ffmpeg from the PyPI wheel imageio-ffmpeg), or point {FFMPEG_ENV} at an ffmpeg with libx264",
                path.display()
            ),
            Self::Ffmpeg(why) => write!(f, "ffmpeg: {why}"),
        }
    }
}

impl std::error::Error for VideoError {}

/// The ffmpeg binary: `$MACROTREE_FFMPEG`, else `third_party/ffmpeg/ffmpeg` of this source tree.
pub fn ffmpeg_path() -> PathBuf {
    match std::env::var_os(FFMPEG_ENV) {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("third_party/ffmpeg/ffmpeg"),
    }
}

/// [`ffmpeg_path`] if it names a file, else [`VideoError::NoFfmpeg`].
pub fn find_ffmpeg() -> Result<PathBuf, VideoError> {
    let path = ffmpeg_path();
    if path.is_file() {
        Ok(path)
    } else {
        Err(VideoError::NoFfmpeg { path })
    }
}

/// `--fps N`: [`MIN_FPS`] ≤ N ≤ [`MAX_FPS`].
pub fn parse_fps(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (MIN_FPS..=MAX_FPS).contains(&n) => Ok(n),
        _ => Err(format!(
            "must be a whole number of frames per second between {MIN_FPS} and {MAX_FPS}, got {s}"
        )),
    }
}

/// Opens the file a clip is written to (see [`VideoEncoder::start`]).
fn open_clip(path: &Path) -> Result<std::fs::File, VideoError> {
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    let open = |create_new: bool| {
        let mut o = std::fs::OpenOptions::new();
        o.read(true).write(true).custom_flags(libc::O_NOFOLLOW);
        if create_new {
            o.create_new(true).mode(0o644);
        }
        o.open(path)
    };
    let refused = |why: String| VideoError::Ffmpeg(format!("cannot write {}: {why}", path.display()));
    let file = match open(true) {
        Ok(f) => return Ok(f),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            open(false).map_err(|e| refused(format!("{e} (a link is never followed)")))?
        }
        Err(e) => return Err(refused(e.to_string())),
    };
    let meta = file.metadata().map_err(|e| refused(e.to_string()))?;
    if !meta.is_file() || meta.nlink() != 1 || meta.len() != 0 {
        return Err(refused(
            "something is already there (only a new file is written)".into(),
        ));
    }
    Ok(file)
}

/// An ffmpeg process encoding the frames it is given into an MP4 file.
pub struct VideoEncoder {
    child: Child,
    stdin: Option<ChildStdin>,
    stderr: Option<std::thread::JoinHandle<String>>,
    size: FrameSize,
    frames: u64,
    path: PathBuf,
}

impl VideoEncoder {
    /// Starts encoding `size` RGB frames at `fps` frames per second into `path`: a new file,
    /// created exclusively without following a link, or the empty regular file a caller created
    /// so (an [`crate::output::PendingFile`]); anything else is refused. ffmpeg never sees the
    /// path: the file is opened here and handed to it as its standard output
    /// (`file:/dev/stdout`), so no folder name can become an ffmpeg option and no path that
    /// looks like a URL makes it open a connection.
    pub fn start(path: &Path, size: FrameSize, fps: u32) -> Result<Self, VideoError> {
        let ffmpeg = find_ffmpeg()?;
        let out = open_clip(path)?;
        let mut child = Command::new(&ffmpeg)
            .args(["-nostdin", "-hide_banner", "-loglevel", "error"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
            .args(["-video_size", &size.to_string(), "-framerate", &fps.to_string()])
            .args(["-i", "pipe:0", "-an"])
            .args([
                "-c:v", "libx264", "-preset", "veryfast", "-crf", "23", "-pix_fmt", "yuv420p",
            ])
            .args(["-threads", "1", "-bf", "0", "-g", &(2 * fps).to_string()])
            .args([
                "-fflags",
                "+bitexact",
                "-flags:v",
                "+bitexact",
                "-map_metadata",
                "-1",
            ])
            .args(["-movflags", "+faststart", "-f", "mp4", "-y", "file:/dev/stdout"])
            .stdin(Stdio::piped())
            .stdout(Stdio::from(out))
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| VideoError::Ffmpeg(format!("cannot start {}: {e}", ffmpeg.display())))?;
        let stdin = child.stdin.take();
        let mut err = child.stderr.take().expect("stderr is piped");
        // Read ffmpeg's messages as they come, so it never blocks on a full pipe.
        let stderr = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            s
        });
        Ok(Self {
            child,
            stdin,
            stderr: Some(stderr),
            size,
            frames: 0,
            path: path.to_path_buf(),
        })
    }

    /// Appends one frame: `height` rows of `width` RGB pixels, top row first.
    pub fn push(&mut self, rgb: &[u8]) -> Result<(), VideoError> {
        if rgb.len() != self.size.rgb_bytes() {
            return Err(VideoError::Ffmpeg(format!(
                "a {} frame has {} bytes, got {}",
                self.size,
                self.size.rgb_bytes(),
                rgb.len()
            )));
        }
        let stdin = self.stdin.as_mut().expect("open until finish");
        if let Err(e) = stdin.write_all(rgb) {
            let why = self.abort();
            return Err(VideoError::Ffmpeg(format!("writing a frame failed ({e}): {why}")));
        }
        self.frames += 1;
        Ok(())
    }

    /// Frames pushed so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Closes the input and waits for ffmpeg to write the file; returns the number of frames.
    pub fn finish(mut self) -> Result<u64, VideoError> {
        drop(self.stdin.take());
        let status = self
            .child
            .wait()
            .map_err(|e| VideoError::Ffmpeg(format!("waiting for ffmpeg: {e}")))?;
        let messages = self.stderr.take().and_then(|h| h.join().ok()).unwrap_or_default();
        if !status.success() {
            return Err(VideoError::Ffmpeg(format!(
                "encoding {} failed ({status}): {}",
                self.path.display(),
                messages.trim()
            )));
        }
        Ok(self.frames)
    }

    /// Stops ffmpeg and returns what it said.
    fn abort(&mut self) -> String {
        drop(self.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default()
            .trim()
            .to_string()
    }
}

impl Drop for VideoEncoder {
    fn drop(&mut self) {
        if self.stdin.is_some() {
            self.abort();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fps_bounds() {
        assert_eq!(parse_fps("30"), Ok(30));
        for bad in ["0", "251", "-1", "2.5", "x", ""] {
            assert!(parse_fps(bad).is_err(), "{bad}");
        }
    }
}
