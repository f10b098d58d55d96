//! [`Params`]: the parameters of a leaf kind, and their type-erased form.

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use schemars::JsonSchema;
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::objects::{ObjectRef, ObjectRole};
use super::param_error::ParamError;

/// The parameters of a leaf kind, read from the node's YAML body.
///
/// Derive `Deserialize` (with `#[serde(deny_unknown_fields)]`, so a misspelled parameter is a
/// located error with a suggestion), `Serialize`, `JsonSchema`, `Clone`, `Debug` and
/// `PartialEq`; document every field with its unit (the doc comments become the parameter docs
/// of `macrotree nodes` and of the JSON Schema). Fields may use the crate's own parameter types
/// and unit parsers: [`ObjectRef`] (an object name or a `{variable}`),
/// [`Target`](crate::kinds::Target), [`Angle`](crate::yaml::units::Angle), and
/// `#[serde(deserialize_with = "macrotree::yaml::units::distance")]` and friends for range-checked
/// metres, seconds and `deg(..)` angles.
///
/// Every method has a default; override the ones that apply.
pub trait Params:
    Serialize + DeserializeOwned + JsonSchema + Clone + fmt::Debug + PartialEq + Send + Sync + 'static
{
    /// The parameters (keys of the node's body) that name objects of the scene, with what each
    /// must name: checked against the scene when the tree loads, so a misspelled name or a
    /// container where a block belongs is a located error with a suggestion. Default: none.
    ///
    /// ```ignore
    /// const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("block", ObjectRole::Block)];
    /// ```
    ///
    /// A dotted key names a value inside a nested mapping (`until.grasped.object`).
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[];

    /// The parameters (keys of the node's body, each a string) that name a file the leaf reads
    /// when it runs, relative to the tree file that names it. The loader confines each to the
    /// tree's folder (the rule of `include:`), checks it is a readable file, replaces the value
    /// with the file's canonical path, and counts the file among the tree's inputs (its digest,
    /// `--resume`). Default: none.
    const FILE_PARAMS: &'static [&'static str] = &[];

    /// Every object reference among the parameters, so that `{variables}` are resolved before
    /// each tick. Default: none.
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        Vec::new()
    }

    /// A short label with the key parameters for diagrams and logs (`push red 0.1 m`). Default:
    /// the kind, with a `?` for conditions.
    fn label(&self, _kind: &str) -> Option<String> {
        None
    }

    /// For actions: the leaf's own time limit in simulated seconds, after which the driver halts
    /// it and fails it with a `timeout:` reason. Default: none (the action must end by itself,
    /// or be bounded by a `timeout` node).
    fn timeout(&self) -> Option<f64> {
        None
    }

    /// Checks across parameters that the types alone cannot express (a range that depends on
    /// another parameter, …). An `Err` is reported at the node, with the message as given; to
    /// point at one parameter's value instead, implement [`Params::validate_fields`].
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }

    /// Like [`Params::validate`], but the error can name the parameter it is about
    /// ([`ParamError::at`]`("max_tilt", "must be between 0 and 45°, found 60.0°")`), and is then
    /// reported at that value in the file. Default: [`Params::validate`], reported at the node.
    fn validate_fields(&self) -> Result<(), ParamError> {
        self.validate().map_err(ParamError::new)
    }

    /// The failure kinds of its own this node kind may fail with, besides the built-in ones:
    /// stable `snake_case` names its controller (or check) uses as
    /// [`FailureKind::Custom`](crate::failure::FailureKind::Custom). Checked when the kind is
    /// declared; a failure of an undeclared custom kind is reported as `other`. Default: none.
    fn failure_kinds() -> &'static [&'static str] {
        &[]
    }
}

/// Type-erased [`Params`].
pub(crate) trait DynParams: Send + Sync + fmt::Debug {
    fn as_any(&self) -> &dyn Any;
    fn to_json(&self) -> serde_json::Value;
    fn dyn_eq(&self, other: &dyn DynParams) -> bool;
    fn object_refs(&self) -> Vec<ObjectRef>;
    fn map_objects(&self, f: &mut dyn FnMut(&ObjectRef) -> Option<ObjectRef>) -> Option<Arc<dyn DynParams>>;
    fn label(&self, kind: &str) -> Option<String>;
    fn timeout(&self) -> Option<f64>;
    fn validate(&self) -> Result<(), ParamError>;
}

impl<T: Params> DynParams for T {
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
    fn dyn_eq(&self, other: &dyn DynParams) -> bool {
        other.as_any().downcast_ref::<T>() == Some(self)
    }
    fn object_refs(&self) -> Vec<ObjectRef> {
        let mut copy = self.clone();
        copy.objects_mut().into_iter().map(|r| *r).collect()
    }
    fn map_objects(&self, f: &mut dyn FnMut(&ObjectRef) -> Option<ObjectRef>) -> Option<Arc<dyn DynParams>> {
        let mut out = self.clone();
        let mut changed = false;
        for r in out.objects_mut() {
            if let Some(new) = f(r) {
                *r = new;
                changed = true;
            }
        }
        changed.then(|| Arc::new(out) as Arc<dyn DynParams>)
    }
    fn label(&self, kind: &str) -> Option<String> {
        Params::label(self, kind)
    }
    fn timeout(&self) -> Option<f64> {
        Params::timeout(self)
    }
    fn validate(&self) -> Result<(), ParamError> {
        Params::validate_fields(self)
    }
}
