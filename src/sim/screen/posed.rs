//! Shapes posed in the world: the moving shapes fixed in their links' frames, posed at any link
//! frames, and the scratch that poses them once per set of link frames.

use super::local::Local;
use super::shapes::{Shape, Sphere, V3};
use crate::sim::chain::Frame;

/// A shape in the world with its bounding sphere (`None`: a half-space).
#[derive(Clone, Copy, Debug)]
pub(super) struct Posed {
    /// The primitive, world frame.
    pub(super) shape: Shape,
    /// A sphere around it; `None` for a half-space.
    pub(super) sphere: Option<Sphere>,
    /// Whether the primitive is the geom itself rather than a bound of it.
    pub(super) exact: bool,
}

/// Scratch of the moving shapes posed at one set of link frames, each when first needed: shape
/// `i` is posed while `stamp[i]` matches `call`.
#[derive(Clone, Debug)]
pub(super) struct Posing {
    posed: Vec<Posed>,
    stamp: Vec<u32>,
    call: u32,
}

impl Posing {
    /// Scratch for `n` moving shapes, none posed.
    pub(super) fn new(n: usize) -> Self {
        let none = Posed {
            shape: Shape::HalfSpace {
                normal: V3::zeros(),
                offset: 0.0,
            },
            sphere: None,
            exact: false,
        };
        Self {
            posed: vec![none; n],
            stamp: vec![0; n],
            call: 0,
        }
    }

    /// Forgets every posed shape (new link frames).
    #[inline]
    pub(super) fn renew(&mut self) {
        self.call = self.call.wrapping_add(1);
        if self.call == 0 {
            self.stamp.iter_mut().for_each(|s| *s = u32::MAX);
            self.call = 1;
        }
    }

    /// Shape `i` (moving ones first, then `fixed`), posed by [`Posing::ensure`] if moving.
    #[inline]
    pub(super) fn get<'a>(&'a self, i: usize, fixed: &'a [Posed]) -> &'a Posed {
        match self.posed.get(i) {
            Some(p) => p,
            None => &fixed[i - self.posed.len()],
        }
    }

    /// Poses moving shape `i` at `frames` unless it is posed already (`i` past the moving
    /// shapes: a fixed one, nothing to do).
    #[inline]
    pub(super) fn ensure(&mut self, i: usize, moving: &[MovingShape], frames: &[Frame; 6]) {
        if i < moving.len() && self.stamp[i] != self.call {
            self.posed[i] = moving[i].pose(frames);
            self.stamp[i] = self.call;
        }
    }
}

/// A geom the arm moves, fixed in the frame of the arm link that moves it.
#[derive(Clone, Copy, Debug)]
pub(super) struct MovingShape {
    /// The link, 0..6 (base to wrist 3).
    pub(super) link: usize,
    /// The geom's primitive in the link's frame.
    pub(super) local: Local,
    /// Whether the primitive is the geom itself rather than a bound of it.
    pub(super) exact: bool,
    /// The primitive's [`Local::reach`], metres.
    pub(super) reach: f64,
}

impl MovingShape {
    /// The shape posed at the link frames `frames`, with its bounding sphere.
    #[inline]
    pub(super) fn pose(&self, frames: &[Frame; 6]) -> Posed {
        let Frame { rot, pos } = &frames[self.link];
        let shape = self.local.posed(rot, pos);
        let centre = match &shape {
            Shape::Capsule { a, b, .. } => {
                V3::new((a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0)
            }
            Shape::Box { center, .. } => *center,
            // Never: a local primitive poses as a capsule or a box.
            Shape::HalfSpace { .. } => {
                return Posed {
                    shape,
                    sphere: None,
                    exact: self.exact,
                };
            }
        };
        Posed {
            shape,
            sphere: Some(Sphere {
                centre,
                radius: self.reach,
            }),
            exact: self.exact,
        }
    }
}
