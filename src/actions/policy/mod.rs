//! The `policy` leaf's controller: an ONNX model run through ONNX Runtime, closed loop on the
//! cell. The kind itself (its parameters, `until:`) is [`crate::kinds::Policy`].
//!
//! - `runtime`: the ONNX Runtime library, opened once per process at run time;
//! - `metadata`: what a model declares beside its graph (action kind, period, normalisation);
//! - `features`: the model inputs a leaf can feed, by name;
//! - `layout`: the two actions a model may return (set points, or the full command);
//! - `model`: a checked model, loaded once per process and shared by every leaf and worker;
//! - `controller`: the leaf's [`crate::actions::MacroAction`].

mod controller;
mod features;
mod layout;
mod metadata;
mod model;
mod runtime;

pub use controller::{ConditionCheck, PolicyAction};
pub use features::Feature;
pub use layout::{ActionLayout, ModelAction};
pub use metadata::{ActionMode, Normalization};
pub use model::{ModelInfo, PolicyModel, check_model_file};
pub use runtime::{LIBRARY_VAR, library_path, set_library_path};
