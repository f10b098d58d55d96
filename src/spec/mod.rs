//! YAML → typed, spanned spec.
//!
//! The pipeline is: text → [`crate::yaml::value::Value`] (generic YAML with a location on every node, read by
//! serde-saphyr under resource limits) → `TreeFile` (`include:`, `subtrees:`, `main:`)
//! → [`node::Node`] (typed tree, subtrees expanded with their arguments, every node located).
//! Every problem is an [`Issue`] turned into a [`Diagnostic`] with file:line:column.
//!
//! The format itself is documented in `docs/tree_format.md`.

#![warn(missing_docs)]

mod check;
pub(crate) mod confine;
mod expand;
mod file;
mod load;
mod node;

pub use crate::yaml::{Diagnostic, Issue, Loc, Sources};
pub use check::{Named, ObjectUse, VarDef, VarType};
pub use expand::{MAX_LEAF_ERRORS, MAX_LEAF_FILE_BYTES, MAX_TREE_DEPTH, MAX_TREE_NODES};
pub use file::{DeclaredBreakpoint, IncludeRef, MAX_BREAKPOINTS, ParamDef, SubtreeDef};
pub(crate) use load::{LoadOptions, Source, load};
pub use load::{MAX_FILES, MAX_INCLUDE_DEPTH, Spec, builtin_scene};
pub use node::{Node, NodeKind};
