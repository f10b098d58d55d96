//! The typed world snapshot the tree reads (the blackboard), and the condition leaves, which are
//! pure functions of it. Nothing here depends on MuJoCo: the simulator fills a [`World`] after
//! every control step, and tests build one by hand.
//!
//! # Reading the snapshot
//!
//! Frames and units: positions are in the world frame, metres, z up, the table top at z = 0;
//! orientations are unit quaternions in the world frame; angles are radians; velocities m/s and
//! rad/s; time seconds.
//!
//! - The scene's objects are [`World::objects`] (an [`ObjectState`] each: `pos`, `quat`,
//!   `linvel`, `angvel`, and whether the left or right pad touches it), in the scene's order;
//!   [`World::index_of`] finds one by name and [`crate::actions::object_index`] resolves a
//!   parameter's object (a name or a `{variable}`). [`World::spec`] and [`World::name`] give its
//!   scene description (kind, shape, colour).
//! - Shape-aware questions: [`World::yaw`] (a block's side faces, folded into [−45°, 45°)),
//!   [`World::bottom`] and [`World::top`] (above the table, exact for a block in any
//!   orientation), [`World::holds`] / [`World::held_block`] (both pads, centred),
//!   [`World::inside`] / [`World::container_of`], [`World::resting_on`], [`World::at_rest`].
//! - Contacts: [`World::touches`] lists every pair of [`Part`]s in contact right now (an object
//!   and which [`Piece`] of it — a container's floor or wall —, the fingers, the rest of the
//!   robot), contacts with the table left out; the pads' contacts with each object are also in
//!   its [`ObjectState`].
//! - The robot: [`World::arm_q`] (measured joint angles), [`World::arm_cmd`] (commanded),
//!   [`World::arm_qd`], [`World::gripper_width`] (metres between the pads),
//!   [`World::pinch_pos`] and [`World::pinch_rot`] (the tool point between the fingertips).
//!
//! A condition that reads orientation and contacts — the block rests on a face (tilted at most
//! `max_tilt` from flat) and nothing but the table touches it (the `upright` of
//! `examples/custom_leaf.rs`, registered with [`crate::App::register_condition`]):
//!
//! ```
//! use macrotree::actions::object_index;
//! use macrotree::kinds::ObjectRef;
//! use macrotree::world::{Part, World};
//!
//! fn upright(w: &World, object: &ObjectRef, max_tilt_rad: f64) -> Result<bool, macrotree::Failure> {
//!     let i = object_index(object, w)?; // "scene `cube_bowl` has no object `cbe`"
//!     let o = &w.objects[i];
//!     // The block's axis closest to world z, and its angle from it (it may rest on any face).
//!     let r = o.quat.to_rotation_matrix();
//!     let up = (0..3).map(|k| r[(2, k)].abs()).fold(0.0, f64::max);
//!     let tilt = up.clamp(-1.0, 1.0).acos();
//!     // Contacts: the pads' flags, and every other part touching it.
//!     let held = o.left_pad_contact || o.right_pad_contact;
//!     let touched = w.touches.iter().any(|&(a, b)| {
//!         let is_i = |p: Part| matches!(p, Part::Object { index, .. } if index == i);
//!         is_i(a) || is_i(b)
//!     });
//!     Ok(tilt <= max_tilt_rad && !held && !touched)
//! }
//! # let _ = upright;
//! ```

pub mod angles;
pub mod conditions;
pub mod goal;
mod legacy;
pub mod objects;
pub mod query;
pub mod snapshot;
#[cfg(test)]
pub(crate) mod tests_support;
pub mod vectors;

pub use objects::{ObjectState, Part, Piece, Touch};
pub use snapshot::World;
