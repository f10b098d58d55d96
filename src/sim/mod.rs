//! The MuJoCo adapter: scene composition, layouts, stepping and world extraction.
//! Nothing outside this module (and the viewer) touches MuJoCo types.

pub(crate) mod cache;
mod cell_spec;
mod chain;
pub(crate) mod collision;
pub(crate) mod collision_model;
pub(crate) mod error;
pub(crate) mod layout;
mod margin;
pub(crate) mod mjcf;
mod pair_filter;
pub(crate) mod planning;
pub(crate) mod scene;
pub(crate) mod screen;
pub(crate) mod simulator;

pub use cache::{MAX_MODELS, evict, model_key, model_key_stamped, model_path};
pub use collision::{DEFAULT_MARGIN, SceneChecker};
pub use error::SimError;
pub use layout::Layout;
pub use mjcf::{cell_mjcf, objects_mjcf};
pub use planning::{plan_failure, plan_in_cell};
pub use scene::{ARM_PREFIX, ModelOrigin, ObjectIds, SCENE_XML, Scene, menagerie_dir};
pub use simulator::{HOME_Q, Sim, TIMESTEP};
