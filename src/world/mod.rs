//! The typed world snapshot the tree reads (the blackboard), and the condition leaves, which are
//! pure functions of it. Nothing here depends on MuJoCo: the simulator fills a [`World`] after
//! every control step, and tests build one by hand.

pub mod conditions;
pub mod goal;
mod legacy;
pub mod objects;
pub mod query;
pub mod snapshot;

pub use objects::{ObjectState, Part, Piece, Touch};
pub use snapshot::World;
