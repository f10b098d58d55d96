//! Camera images of the simulated cell through MuJoCo's own offscreen renderer (mujoco-rs's
//! `MjRenderer`: a headless EGL context; on a machine without a GPU, Mesa's software
//! rasterizer).
//!
//! EGL and OpenGL are loaded when the first renderer is made, not linked: `macrotree run`
//! and `sweep` work on machines without them, and only asking for pixels (`run --video`,
//! `sweep --dataset --cameras …`) needs them ([`RenderError::NoGl`] says what to install).
//!
//! Rendering never changes the physics: a [`CameraRenderer`] keeps its own `MjData`, copies the
//! positions (`qpos`, mocap poses) of the simulation into it and computes the kinematics there;
//! the simulation's data is only read.
//!
//! Cameras are the model's: `front` and `overview` (declared in `assets/scene.xml`) and
//! `wrist` (on the 2F-85, added by [`crate::sim::Scene::build`]).

pub mod font;

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use mujoco_rs::prelude::*;

/// Largest image width, pixels: the offscreen buffer's width (`<visual><global offwidth>` in
/// assets/scene.xml).
pub const MAX_WIDTH: u32 = 1280;
/// Largest image height, pixels (`offheight` in assets/scene.xml).
pub const MAX_HEIGHT: u32 = 960;
/// Smallest image side, pixels.
pub const MIN_SIDE: u32 = 16;

/// The Debian packages that provide headless EGL with Mesa's software rasterizer.
pub const GL_PACKAGES: &str = "libegl1 libegl-mesa0 libgl1-mesa-dri";

/// An image size `WxH` in pixels (`--size 640x480`): both even (H.264 with 4:2:0 chroma needs
/// it), [`MIN_SIDE`] ≤ W ≤ [`MAX_WIDTH`], [`MIN_SIDE`] ≤ H ≤ [`MAX_HEIGHT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct FrameSize {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

impl FrameSize {
    /// Bytes of one RGB frame (3 bytes per pixel).
    pub fn rgb_bytes(&self) -> usize {
        self.width as usize * self.height as usize * 3
    }
}

impl fmt::Display for FrameSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

/// Checks an image's height and width (pixels) against [`MIN_SIDE`], [`MAX_WIDTH`] and
/// [`MAX_HEIGHT`] (the offscreen buffer of `assets/scene.xml`): the error says the bounds.
pub fn check_image_size(height: u32, width: u32) -> Result<(), String> {
    if (MIN_SIDE..=MAX_WIDTH).contains(&width) && (MIN_SIDE..=MAX_HEIGHT).contains(&height) {
        Ok(())
    } else {
        Err(format!(
            "an image of {height}×{width} pixels (height × width): the height must be {MIN_SIDE}…{MAX_HEIGHT} and the width {MIN_SIDE}…{MAX_WIDTH}"
        ))
    }
}

impl FromStr for FrameSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let form = format!(
            "expected WxH in pixels, both even, width {MIN_SIDE}…{MAX_WIDTH} and height {MIN_SIDE}…{MAX_HEIGHT}, e.g. 640x480"
        );
        let (w, h) = s
            .trim()
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("{s:?}: {form}"))?;
        let (Ok(width), Ok(height)) = (w.trim().parse::<u32>(), h.trim().parse::<u32>()) else {
            return Err(format!("{s:?}: {form}"));
        };
        let ok = check_image_size(height, width).is_ok() && width % 2 == 0 && height % 2 == 0;
        if !ok {
            return Err(format!("{s:?}: {form}"));
        }
        Ok(Self { width, height })
    }
}

/// Why images cannot be rendered.
#[derive(Debug)]
pub enum RenderError {
    /// This build has no renderer (built without the `render` feature).
    NotBuilt,
    /// No EGL/OpenGL could be opened.
    NoGl(String),
    /// The renderer failed.
    Failed(String),
    /// The model has no camera of that name.
    UnknownCamera {
        /// The name asked for.
        name: String,
        /// The model's cameras.
        available: Vec<String>,
    },
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotBuilt => write!(
                f,
                "this macrotree was built without the `render` feature, so it cannot render camera images; rebuild with the default features"
            ),
            Self::NoGl(why) => write!(
                f,
                "cannot render camera images: no usable EGL/OpenGL ({why}).\n  help: install headless EGL with Mesa's software rasterizer (Debian: apt-get install {GL_PACKAGES}); everything but pixels works without it"
            ),
            Self::Failed(why) => write!(f, "rendering failed: {why}"),
            Self::UnknownCamera { name, available } => write!(
                f,
                "the scene has no camera {name:?}; its cameras are: {}",
                available.join(", ")
            ),
        }
    }
}

impl std::error::Error for RenderError {}

/// The ids of camera `names` in `scene`'s model, in the order given.
pub fn camera_ids(scene: &crate::sim::Scene, names: &[String]) -> Result<Vec<usize>, RenderError> {
    names
        .iter()
        .map(|n| {
            scene.camera_id(n).ok_or_else(|| RenderError::UnknownCamera {
                name: n.clone(),
                available: scene.camera_names(),
            })
        })
        .collect()
}

/// An offscreen renderer of one model at one image size, with its own `MjData` (so rendering
/// never writes to the simulation's). Not `Send`: its OpenGL context belongs to the thread that
/// made it.
pub struct CameraRenderer {
    #[cfg(feature = "render")]
    renderer: mujoco_rs::renderer::MjRenderer,
    data: MjData<Arc<MjModel>>,
    size: FrameSize,
}

impl CameraRenderer {
    /// A renderer of `model` making `size` images.
    pub fn new(model: &Arc<MjModel>, size: FrameSize) -> Result<Self, RenderError> {
        #[cfg(feature = "render")]
        {
            let global = &model.vis().global;
            if size.width > global.offwidth as u32 || size.height > global.offheight as u32 {
                return Err(RenderError::Failed(format!(
                    "{size} is larger than the model's offscreen buffer {}x{}",
                    global.offwidth, global.offheight
                )));
            }
            let renderer = mujoco_rs::renderer::MjRenderer::builder()
                .width(size.width)
                .height(size.height)
                .build(model)
                .map_err(|e| match e {
                    mujoco_rs::renderer::RendererError::GlutinError(g) => RenderError::NoGl(g.to_string()),
                    other => RenderError::Failed(other.to_string()),
                })?;
            Ok(Self {
                renderer,
                data: MjData::new(model.clone()),
                size,
            })
        }
        #[cfg(not(feature = "render"))]
        {
            let _ = (model, size);
            Err(RenderError::NotBuilt)
        }
    }

    /// The image size.
    pub fn size(&self) -> FrameSize {
        self.size
    }

    /// Copies the pose of everything in `sim` (joint positions, mocap poses) into this
    /// renderer's own data and computes its kinematics; `sim` is only read.
    pub fn sync(&mut self, sim: &MjData<Arc<MjModel>>) {
        self.data.qpos_mut().copy_from_slice(sim.qpos());
        self.data.mocap_pos_mut().copy_from_slice(sim.mocap_pos());
        self.data.mocap_quat_mut().copy_from_slice(sim.mocap_quat());
        self.data.forward_kinematics();
    }

    /// Renders camera `camera` (a model camera id) of the pose last [`sync`](Self::sync)ed, as
    /// `height` rows of `width` RGB pixels, top row first.
    pub fn render(&mut self, camera: usize) -> Result<&[u8], RenderError> {
        #[cfg(feature = "render")]
        {
            self.renderer.set_camera(MjvCamera::new_fixed(camera));
            self.renderer
                .sync_data(&mut self.data)
                .map_err(|e| RenderError::Failed(e.to_string()))?;
            self.renderer
                .render()
                .map_err(|e| RenderError::Failed(e.to_string()))?;
            self.renderer
                .rgb_flat()
                .ok_or_else(|| RenderError::Failed("no RGB image".into()))
        }
        #[cfg(not(feature = "render"))]
        {
            let _ = camera;
            Err(RenderError::NotBuilt)
        }
    }
}

/// CPU time of the whole process (every thread, including the software rasterizer's), seconds.
pub fn process_cpu_time() -> f64 {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    unsafe extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `t` is a valid, writable timespec; the clock id is Linux's process CPU clock.
    if unsafe { clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &mut t) } != 0 {
        return 0.0;
    }
    t.sec as f64 + t.nsec as f64 * 1e-9
}

thread_local! {
    static THREAD_RENDERER: std::cell::RefCell<Option<(usize, CameraRenderer)>> =
        const { std::cell::RefCell::new(None) };
}

/// Calls `f` with this thread's renderer of `model` at `size`, made on first use (and remade
/// when the model or the size changes). Sweep workers keep one OpenGL context each this way.
pub fn with_thread_renderer<T>(
    model: &Arc<MjModel>,
    size: FrameSize,
    f: impl FnOnce(&mut CameraRenderer) -> T,
) -> Result<T, RenderError> {
    let key = Arc::as_ptr(model) as usize;
    THREAD_RENDERER.with(|cell| {
        let mut slot = cell.borrow_mut();
        let reuse = matches!(&*slot, Some((k, r)) if *k == key && r.size() == size);
        if !reuse {
            *slot = None;
            *slot = Some((key, CameraRenderer::new(model, size)?));
        }
        let (_, r) = slot.as_mut().expect("set above");
        Ok(f(r))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_are_range_checked() {
        assert_eq!(
            "480x360".parse::<FrameSize>(),
            Ok(FrameSize {
                width: 480,
                height: 360
            })
        );
        for bad in [
            "", "480", "481x360", "480x361", "0x0", "1282x960", "1280x962", "8x8", "ax4", "-2x4",
        ] {
            assert!(bad.parse::<FrameSize>().is_err(), "{bad}");
        }
        assert!("1280x960".parse::<FrameSize>().is_ok());
    }
}
