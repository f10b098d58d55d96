//! YAML → typed, spanned spec.
//!
//! The pipeline is: text → [`crate::yaml::value::Value`] (generic YAML with a location on every node, read by
//! serde-saphyr under resource limits) → [`file::TreeFile`] (`include:`, `subtrees:`, `main:`)
//! → [`node::Node`] (typed tree, subtrees expanded with their arguments, every node located).
//! Every problem is an [`Issue`] turned into a [`Diagnostic`] with file:line:column.
//!
//! The format itself is documented in `docs/tree_format.md`.

#![warn(missing_docs)]

pub mod check;
pub(crate) mod confine;
pub mod expand;
pub mod file;
pub mod load;
pub mod node;

pub use crate::yaml::{Diagnostic, Issue, Loc, Sources};
pub use load::Spec;
pub(crate) use load::{LoadOptions, Source, load};
pub use node::{Node, NodeKind};
