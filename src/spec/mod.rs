//! YAML → typed, spanned spec.
//!
//! The pipeline is: text → [`value::Value`] (generic YAML with a location on every node, read by
//! serde-saphyr under resource limits) → [`file::TreeFile`] (`include:`, `subtrees:`, `main:`)
//! → [`node::Node`] (typed tree, subtrees expanded with their arguments, every node located).
//! Every problem is an [`Issue`] turned into a [`Diagnostic`] with file:line:column.
//!
//! The format itself is documented in `docs/tree_format.md`.

#![warn(missing_docs)]

pub mod catalog;
pub mod check;
pub(crate) mod confine;
pub mod de;
pub mod diag;
pub mod expand;
pub mod file;
pub mod leaves;
pub mod load;
pub mod node;
pub mod objects;
pub mod suggest;
pub mod units;
pub mod value;

pub use catalog::{NodeDoc, ParamDoc, catalog, json_schema};
pub use confine::{includes_anywhere, set_includes_anywhere};
pub use diag::{Diagnostic, Issue, Loc, Sources};
pub use leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Leaf, LeafCall, Lifted, MoveJoints, On, OnTable, Params, Reach, Release, Select,
    Wait,
};
pub use load::{Spec, load_bytes, load_file, load_str};
pub use node::{Node, NodeKind};
pub use objects::ObjectRef;
pub use units::{PathKind, Target, Yaw};
