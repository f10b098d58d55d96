//! The MuJoCo adapter: scene composition, layouts, stepping and world extraction.
//! Nothing outside this module (and the viewer) touches MuJoCo types.

pub mod cache;
mod cell_spec;
mod chain;
pub mod collision;
pub mod collision_model;
pub mod error;
pub mod layout;
mod margin;
pub mod mjcf;
mod pair_filter;
pub mod planning;
pub mod scene;
pub mod screen;
pub mod simulator;

pub use collision::SceneChecker;
pub use error::SimError;
pub use layout::Layout;
pub use scene::{ARM_PREFIX, ModelOrigin, ObjectIds, Scene};
pub use simulator::{HOME_Q, Sim, TIMESTEP};
