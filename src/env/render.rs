//! [`MacroEnv::render`](super::MacroEnv::render): a camera image of the current state, HWC RGB
//! bytes, through MuJoCo's offscreen renderer (one renderer per thread, kept).

use serde::Serialize;

use crate::error::Error;
use crate::render::{FrameSize, MAX_HEIGHT, MAX_WIDTH, MIN_SIDE, with_thread_renderer};

/// A camera image: `height` rows of `width` RGB pixels, top row first (HWC, `u8`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `height × width × 3` bytes, row-major, RGB.
    pub pixels: Vec<u8>,
}

impl super::MacroEnv {
    /// Renders camera `camera` (a model camera name: the scene's cameras and `wrist`) at
    /// `width × height` pixels (even sizes from 16 × 16 to 1280 × 960).
    ///
    /// # Errors
    /// [`Error::Action`] for an unknown camera or a size out of range; [`Error::Simulator`]
    /// when no OpenGL (EGL) is available.
    pub fn render(&self, camera: &str, width: u32, height: u32) -> Result<Image, Error> {
        render_cell(self.cell(), camera, width, height)
    }
}

/// Renders `camera` of `cell` at `width × height` (see [`super::MacroEnv::render`]).
pub(super) fn render_cell(
    cell: &crate::actions::Cell,
    camera: &str,
    width: u32,
    height: u32,
) -> Result<Image, Error> {
    let scene = cell.sim().scene();
    let Some(id) = scene.camera_id(camera) else {
        return Err(Error::Action {
            message: format!(
                "unknown camera `{camera}`; the scene has: {}",
                scene.camera_names().join(", ")
            ),
        });
    };
    let size: FrameSize = format!("{width}x{height}").parse().map_err(|e| Error::Action {
            message: format!(
                "image size {width}x{height}: {e} (even sides, {MIN_SIDE} … {MAX_WIDTH} × {MIN_SIDE} … {MAX_HEIGHT})"
            ),
        })?;
    let model = scene.model.clone();
    let data = cell.sim().data();
    let pixels = with_thread_renderer(&model, size, |r| {
        r.sync(data);
        r.render(id).map(<[u8]>::to_vec)
    })
    .and_then(|x| x)
    .map_err(|e| Error::Simulator {
        message: format!("cannot render camera `{camera}`: {e}"),
    })?;
    Ok(Image {
        width,
        height,
        pixels,
    })
}
