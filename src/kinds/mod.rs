//! What each node kind *is*: its name, [`Category`], documentation, parameter type (read from
//! YAML with located errors, with its JSON Schema) and the objects its parameters name. How a kind
//! *runs* — action controllers and condition checks — is bound apart, above the actions
//! (`crate::factory`), and looked up when the tree runs: a parsed tree holds a kind and its
//! parameters, never a controller.
//!
//! Everything that needs to know which node kinds exist reads the [`Registry`]: parsing (and the
//! did-you-mean suggestions for misspelled kinds), the JSON Schema of tree files,
//! `macrotree nodes`, the `graph` labels and the docs. The built-in leaves are declared through
//! the same [`Registry::declare_action`] / [`Registry::declare_condition`] calls a crate user's
//! leaves go through (`src/kinds/builtin.rs`, `docs/custom_nodes.md`).
//!
//! A leaf's parameters are a type implementing [`Params`] (`Deserialize` + `JsonSchema`): the
//! YAML body of the node is read into it with located errors, its doc comments become the
//! parameter documentation, and the schema is generated from it.

mod approach;
mod builtin;
pub mod catalog;
mod control;
mod leaf_call;
pub mod leaves;
pub mod objects;
mod param_error;
mod params;
mod parse_leaf;
mod policy;
mod registry;
mod role;
mod targets;
mod tree_file;

pub use approach::Approach;
pub use catalog::{NodeDoc, ParamDoc};
pub use control::{
    Arguments, ChildParams, CompositeParams, ConditionValue, Control, ControlKind, ForEachParams,
    GuardParams, MAX_COUNT, NodeList, NodeValue, RepeatParams, RetryParams, SubtreeParams, TimeoutParams,
};
pub use leaf_call::LeafCall;
pub use leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Leaf, Lifted, MoveJoints, On, OnTable, Place, PlanBudget, Reach, Release, Select,
    Wait,
};
pub use objects::{ObjectRef, ObjectRole};
pub use param_error::ParamError;
pub use params::Params;
pub use policy::{MAX_ACTION_STEPS, MAX_POLICY_PERIOD, POLICY_OUTPUT_INVALID, Policy, Until};
pub use registry::{Category, FileCheck, NodeType, Registry};
pub use role::ActionRole;
pub use targets::{PathKind, Target, Yaw};
pub use tree_file::{FileKey, SUBTREE_KEY_NAMES, SUBTREE_KEYS, TREE_FILE_KEY_NAMES, TREE_FILE_KEYS};
