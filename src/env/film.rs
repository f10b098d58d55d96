//! Filming steps: camera frames sampled at a fixed rate of simulated time while actions run,
//! collected until taken ([`MacroEnv::take_frames`](super::MacroEnv::take_frames)). Macros last
//! seconds, so one image per step would not show them; this is Gymnasium's `rgb_array_list`.

use crate::actions::Cell;
use crate::error::Error;

use super::render::{Image, render_cell};

/// Most frames held before they are taken (about 3.7 GB at 1280 × 960, 24 MB at 320 × 240
/// ... per 100 frames: the caller takes them after every step).
pub const MAX_HELD_FRAMES: usize = 10_000;

/// Highest frame rate, frames per simulated second.
pub const MAX_FRAME_RATE: f64 = 250.0;

/// A camera filming the cell.
pub(super) struct Film {
    camera: String,
    width: u32,
    height: u32,
    period: f64,
    next: f64,
    frames: Vec<Image>,
    dropped: u64,
}

impl Film {
    /// Frames of `camera` at `width × height` pixels, `rate` per simulated second.
    pub fn new(camera: String, width: u32, height: u32, rate: f64) -> Result<Self, Error> {
        if !(rate.is_finite() && rate > 0.0 && rate <= MAX_FRAME_RATE) {
            return Err(Error::Action {
                message: format!(
                    "frame rate {rate}; expected more than 0 and at most {MAX_FRAME_RATE} per second"
                ),
            });
        }
        Ok(Self {
            camera,
            width,
            height,
            period: 1.0 / rate,
            next: 0.0,
            frames: Vec::new(),
            dropped: 0,
        })
    }

    /// Starts over at time `t` (a reset): the next frame is taken at once.
    pub fn restart(&mut self, t: f64) {
        self.next = t;
    }

    /// Takes a frame if one is due at the cell's time.
    pub fn tick(&mut self, cell: &Cell) -> Result<(), Error> {
        let t = cell.world().time;
        if t + 1e-9 < self.next {
            return Ok(());
        }
        while self.next <= t + 1e-9 {
            self.next += self.period;
        }
        if self.frames.len() >= MAX_HELD_FRAMES {
            self.dropped += 1;
            return Ok(());
        }
        self.frames
            .push(render_cell(cell, &self.camera, self.width, self.height)?);
        Ok(())
    }

    /// The frames taken since the last call, and how many were dropped (more than
    /// [`MAX_HELD_FRAMES`] held).
    pub fn take(&mut self) -> (Vec<Image>, u64) {
        (
            std::mem::take(&mut self.frames),
            std::mem::take(&mut self.dropped),
        )
    }
}

impl super::MacroEnv {
    /// Films the steps from now on: frames of `camera` at `width × height`, one now (and one at
    /// every reset), then one every `1 / rate` simulated seconds, held until
    /// [`take_frames`](Self::take_frames).
    ///
    /// # Errors
    /// As [`render`](Self::render), and [`Error::Action`] for a rate out of range.
    pub fn film(&mut self, camera: &str, width: u32, height: u32, rate: f64) -> Result<(), Error> {
        let mut film = Film::new(camera.to_string(), width, height, rate)?;
        film.restart(self.cell().world().time);
        film.tick(self.cell())?;
        self.film = Some(film);
        Ok(())
    }

    /// The frames filmed since the last call (empty when not filming), oldest first.
    pub fn take_frames(&mut self) -> Vec<Image> {
        self.film.as_mut().map(|f| f.take().0).unwrap_or_default()
    }
}
