//! `write_mp4`: frames to an H.264 MP4 through the library's `VideoEncoder`, written through an
//! exclusive temporary file and installed at the path when complete.

use std::path::Path;

use macrotree::output::OutputFile;
use macrotree::render::FrameSize;
use macrotree::video::VideoEncoder;
use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::error::value;

/// Writes `frames` (H×W×3 uint8, one size) at `fps` to `path`; returns the number of frames.
#[pyfunction]
#[pyo3(signature = (path, frames: "list[NDArray[np.uint8]]", fps))]
pub fn write_mp4(
    py: Python<'_>,
    path: String,
    frames: Vec<PyReadonlyArray3<'_, u8>>,
    fps: u32,
) -> PyResult<u64> {
    let first = frames.first().ok_or_else(|| value("no frames to write"))?;
    let shape = first.shape().to_vec();
    let size: FrameSize = format!("{}x{}", shape[1], shape[0]).parse().map_err(value)?;
    if !(macrotree::video::MIN_FPS..=macrotree::video::MAX_FPS).contains(&fps) {
        return Err(value(format!(
            "fps is {fps}; expected {} … {}",
            macrotree::video::MIN_FPS,
            macrotree::video::MAX_FPS
        )));
    }
    let mut bytes = Vec::with_capacity(frames.len());
    for f in &frames {
        if f.shape() != shape.as_slice() {
            return Err(value(format!(
                "every frame must have shape {shape:?}, got {:?}",
                f.shape()
            )));
        }
        bytes.push(f.as_slice()?.to_vec());
    }
    let out = OutputFile::check(Path::new(&path), &[]).map_err(|e| value(e.to_string()))?;
    py.detach(|| {
        let pending = out.pending().map_err(|e| e.to_string())?;
        let mut enc = VideoEncoder::start(pending.path(), size, fps).map_err(|e| e.to_string())?;
        for b in &bytes {
            enc.push(b).map_err(|e| e.to_string())?;
        }
        let n = enc.finish().map_err(|e| e.to_string())?;
        pending.install().map_err(|e| e.to_string())?;
        Ok::<u64, String>(n)
    })
    .map_err(value)
}
