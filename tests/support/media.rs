//! What the pixel and dataset tests need besides the binary: the pinned ffmpeg, OpenGL (EGL)
//! and pyarrow. Outside CI a missing piece skips the test (with a note); in CI (`CI` set) it
//! fails it, since `.ci/run` installs them.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn missing(what: &str) -> Option<PathBuf> {
    assert!(std::env::var_os("CI").is_none(), "{what} is missing in CI");
    eprintln!("skipped: {what} is missing (run tools/bootstrap; see README)");
    None
}

/// The pinned ffmpeg, if present.
pub fn ffmpeg() -> Option<PathBuf> {
    let p = macrotree::video::ffmpeg_path();
    if p.is_file() {
        Some(p)
    } else {
        missing(&format!("ffmpeg ({})", p.display()))
    }
}

/// Whether an offscreen OpenGL context can be made here.
pub fn gl() -> bool {
    let scene = macrotree::sim::Scene::load().expect("scene loads");
    let size = macrotree::render::FrameSize {
        width: 64,
        height: 48,
    };
    match macrotree::render::CameraRenderer::new(&scene.model, size) {
        Ok(_) => true,
        Err(e) => missing(&format!("OpenGL/EGL ({e})")).is_some(),
    }
}

/// The folder holding the pinned pyarrow (`PYTHONPATH`), if present.
pub fn pyarrow() -> Option<PathBuf> {
    let p = match std::env::var_os("MACROTREE_PYARROW") {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("third_party/pyarrow"),
    };
    if p.join("pyarrow/parquet/__init__.py").is_file() {
        Some(p)
    } else {
        missing(&format!("pyarrow ({})", p.display()))
    }
}

/// Decodes `video` to the end with ffmpeg: (frames, (width, height), distinct frames).
pub fn decode(ffmpeg: &Path, video: &Path) -> (usize, (u32, u32), usize) {
    let out = Command::new(ffmpeg)
        .args(["-hide_banner", "-nostdin", "-i"])
        .arg(video)
        .args(["-map", "0:v:0", "-f", "framemd5", "-"])
        .output()
        .expect("ffmpeg runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "ffmpeg cannot decode {}: {err}",
        video.display()
    );
    let line = err
        .lines()
        .find(|l| l.contains("Video: h264"))
        .unwrap_or_else(|| panic!("not H.264: {err}"));
    let size = line
        .split([',', ' '])
        .find_map(|w| {
            let (a, b) = w.split_once('x')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .expect("a WxH in the stream line");
    let hashes: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| l.rsplit(',').next().unwrap().trim().to_string())
        .collect();
    let distinct = hashes.iter().collect::<std::collections::BTreeSet<_>>().len();
    (hashes.len(), size, distinct)
}
