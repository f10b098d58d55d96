//! [`Screen`]: a conservative fast collision model of the cell, asked before MuJoCo
//! ([`SceneChecker::certainly_free`](super::collision::SceneChecker)).
//!
//! Each collidable geom is bounded by one convex primitive (`Shape`): capsules and spheres
//! exactly, a cylinder by the capsule of its radius and half-height, a box exactly, a plane as
//! its half-space, and a mesh or an ellipsoid by MuJoCo's bounding box of it (`geom_aabb`, which
//! contains its convex hull, what MuJoCo collides). Robot geoms are fixed in the frame of the
//! arm link that moves them (the gripper at its snapshot opening, a held block in the wrist-3
//! frame); the six link frames are computed from the model's own body offsets and joint axes
//! (the same products as `mj_kinematics`). The pairs tested are exactly the pairs MuJoCo tests
//! in the checker's private model: its contact bitmasks, its body filters (same weld body,
//! weld parent and child unless disabled, `<exclude>`), plus explicit `<pair>`s. A configuration
//! is certainly free when every pair's primitives are at least the pair's margin plus
//! [`PAD`] apart: the geoms inside them are then farther apart than the margin, so MuJoCo
//! reports no contact. `tests/physics/motion_screen.rs` checks this against MuJoCo over thousands of
//! configurations near obstacles.

mod bound;
mod build;
mod lever;
mod link_capsule;
mod local;
mod pairs;
mod posed;
#[cfg(test)]
mod probes;
pub(crate) mod shapes;
mod sphere;
#[cfg(test)]
mod tests;
mod turned;
mod verdict;

pub(crate) use build::Build;
pub use pairs::JointRange;
#[cfg(test)]
pub(crate) use probes::{PairMove, TurnedBound};
pub use verdict::GeomPair;

use local::Local;
use pairs::{Group, Pair};
use posed::{MovingShape, Posed, Posing};
use shapes::Sphere;

use super::chain::{ArmChain, Frame};

/// Extra distance every pair must keep beyond its margin for the screen to vouch, metres: room
/// for MuJoCo's own tolerances (its convex-hull distances converge to about 1e-6 m).
pub const PAD: f64 = 5e-4;

/// The conservative model of one snapshot of the cell (see the module docs).
#[derive(Clone, Debug)]
pub struct Screen {
    /// The arm's link frames at any joints.
    chain: ArmChain,
    /// The shapes the arm moves, each in its link's frame.
    moving: Vec<MovingShape>,
    /// Fixed shapes, world frame.
    fixed: Vec<Posed>,
    /// The pairs tested, in groups ([`Screen::groups`]).
    pairs: Vec<Pair>,
    /// The pairs in groups of one arm link against one partner (a fixed shape or another
    /// link), each group tested first with bounding spheres ([`Group`]).
    groups: Vec<Group>,
    /// Bounding sphere of each link's moving shapes in the link's frame; `None` for a link
    /// without shapes.
    link_spheres: [Option<Sphere>; 6],
    /// A capsule around each link's moving shapes in the link's frame
    /// ([`link_capsule`](link_capsule::link_capsule); `None` for a link without shapes):
    /// tighter than the sphere around a long link (the forearm) or the gripper, it culls a group
    /// the spheres cannot.
    link_capsules: [Option<Local>; 6],
    /// Geom id of each shape (moving ones, then fixed ones).
    geoms: Vec<usize>,
    /// The pairs the last [`Screen::free_spare`] could not decide.
    undecided: Vec<Undecided>,
    /// The moving shapes posed for the verdicts ([`Screen::free_spare`]).
    posed: Posing,
    /// Index of each geom's shape (`None`: the geom has none), for [`Screen::geom_clearance`].
    shape_of: Vec<Option<u32>>,
    /// The moving shapes posed for [`Screen::geom_clearance`], at `bound_frames`.
    bound_posed: Posing,
    /// The link frames of [`Screen::bound_at`].
    bound_frames: [Frame; 6],
}

/// A pair whose primitives come within its margin plus [`PAD`] but that the screen cannot call
/// blocked: only the geoms' exact distance decides it ([`Screen::undecided`]).
#[derive(Clone, Copy, Debug)]
pub struct Undecided {
    /// The two geom ids.
    pub geoms: GeomPair,
    /// The distance the geoms must keep beyond the margin for the screen's vouching, metres:
    /// the pair's margin plus [`PAD`].
    pub gap: f64,
    /// The pair's lever-arm ratio, in (0, 1].
    pub kappa: f64,
    /// The joints that move the pair's parts relative to each other; `None`: none does.
    pub range: Option<JointRange>,
}
