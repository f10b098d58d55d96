//! Scenes: the cell's objects by name — movable blocks, containers and fixed obstacles — where
//! they start (a pose, or a seeded randomization), and the task's goal.
//!
//! A scene is a YAML file (`scenes/*.yaml`, documented in `docs/scenes.md`), read with the same
//! located diagnostics as trees. Nothing here depends on MuJoCo: [`crate::sim::Scene`] compiles
//! a [`SceneSpec`] into the MuJoCo model (objects under the [`OBJECT_PREFIX`] so user names never
//! collide with the robot's), and [`crate::world`] evaluates the goal on a world snapshot.
//!
//! ```
//! let scene = macrotree::scene::SceneSpec::from_str(
//!     "objects:\n  red: {block: {size: 0.04, color: red}, pose: [0.45, -0.1]}\n  bin: {container: {inner: [0.14, 0.14], color: red}, pose: [0.45, 0.15]}\ngoal:\n  - in: {object: red, container: bin}\n",
//!     "cell.yaml",
//! )
//! .unwrap();
//! assert_eq!(scene.objects.len(), 2);
//! assert_eq!(scene.goal.atoms[0].to_string(), "red in bin");
//! ```

mod color;
mod feasible;
mod footprint;
mod goal;
mod goal_read;
mod layout_keys;
pub mod limits;
mod load;
mod object_name;
mod placement_error;
mod sample;
mod types;

pub use color::{COLOR_NAMES, Color};
pub use footprint::Rect;
pub use goal::{
    AT_MAX_TOLERANCE, AT_MAX_YAW_TOLERANCE, AT_TOLERANCE, AT_YAW_TOLERANCE, Goal, GoalAtom, GoalPlace,
};
pub use load::{BUILTIN_CUBE_BOWL, SceneFileSchema, load_scene_file};
pub use object_name::is_object_name;
pub use sample::{MAX_DRAWS, Placement, PlacementError, placement_order, sample_placement, support_of};
pub use types::{
    CONTAINER_FLOOR, CONTAINER_WALL, ObjectKind, ObjectSpec, Pose, ROBOT_BASE_RADIUS, RandomPlacement,
    Region, RegionRole, Sampler, SceneSpec, Shape, Spot, reach_limits,
};

/// Prefix of every scene object's MuJoCo names (`obj/red`, `obj/bin/wall_px`), so that a user's
/// object name can never collide with the robot's (`ur5e/…`, `gripper/…`).
pub const OBJECT_PREFIX: &str = "obj/";
