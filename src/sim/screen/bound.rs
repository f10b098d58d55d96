//! Lower bounds on the distance of two geoms through their primitives, at link frames the
//! exact checker sets.

use super::Screen;
use super::shapes::separation;
use crate::sim::chain::Frame;

impl Screen {
    /// Sets the link frames ([`ArmChain::link_poses`](crate::sim::chain::ArmChain::link_poses))
    /// at which [`Screen::geom_clearance`] bounds the distances of geoms.
    pub(crate) fn bound_at(&mut self, frames: &[Frame; 6]) {
        self.bound_frames = *frames;
        self.bound_posed.renew();
    }

    /// A lower bound on the distance between geoms `g1` and `g2` at the frames of the last
    /// [`Screen::bound_at`], metres: the clearance of their primitives, which contain them (0
    /// where they may touch); `−∞` when either has no primitive.
    pub(crate) fn geom_clearance(&mut self, g1: usize, g2: usize) -> f64 {
        let shape = |g: usize| self.shape_of.get(g).copied().flatten();
        let (Some(a), Some(b)) = (shape(g1), shape(g2)) else {
            return f64::NEG_INFINITY;
        };
        let (a, b) = (a as usize, b as usize);
        self.bound_posed.ensure(a, &self.moving, &self.bound_frames);
        self.bound_posed.ensure(b, &self.moving, &self.bound_frames);
        let at = |i: usize| &self.bound_posed.get(i, &self.fixed).shape;
        separation(at(a), at(b)).clearance()
    }
}
