//! [`LeafCall`]: an action or condition leaf of a parsed tree — its kind and its parameters.

use std::fmt;
use std::sync::Arc;

use serde::Serialize;

use super::objects::ObjectRef;
use super::param_error::ParamError;
use super::params::{DynParams, Params};
use super::registry::{Category, NodeType};

/// An action or condition leaf of a tree: its registered kind and its parameters.
#[derive(Clone)]
pub struct LeafCall {
    pub(super) ty: Arc<NodeType>,
    pub(super) params: Arc<dyn DynParams>,
}

impl fmt::Debug for LeafCall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple(self.ty.name).field(&self.params).finish()
    }
}

impl PartialEq for LeafCall {
    fn eq(&self, other: &Self) -> bool {
        self.ty.name == other.ty.name && self.params.dyn_eq(&*other.params)
    }
}

impl Serialize for LeafCall {
    /// `{kind: {parameters}}`.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(1))?;
        m.serialize_entry(self.ty.name, &self.params.to_json())?;
        m.end()
    }
}

impl LeafCall {
    /// The YAML kind (`reach`, `push`, …).
    pub fn kind(&self) -> &'static str {
        self.ty.name
    }

    /// What the action does in the pick-and-place cycle, as its kind declares
    /// ([`ActionRole::Other`](super::ActionRole::Other) for conditions).
    pub fn role(&self) -> super::ActionRole {
        self.ty.role()
    }

    /// The registered kind.
    pub fn node_type(&self) -> &NodeType {
        &self.ty
    }

    /// The parameters, if they are of type `P` (the type the kind was registered with).
    pub fn params<P: Params>(&self) -> Option<&P> {
        self.params.as_any().downcast_ref::<P>()
    }

    /// The parameters as JSON (compact, for logs).
    pub fn params_json(&self) -> serde_json::Value {
        self.params.to_json()
    }

    /// The action's own time limit, simulated seconds (`None`: none).
    pub fn timeout(&self) -> Option<f64> {
        self.params.timeout()
    }

    /// Every object reference among the parameters.
    pub fn object_refs(&self) -> Vec<ObjectRef> {
        self.params.object_refs()
    }

    /// The call with object references replaced where `f` answers `Some`; `None` when nothing
    /// was replaced.
    pub fn map_objects(&self, f: &mut dyn FnMut(&ObjectRef) -> Option<ObjectRef>) -> Option<LeafCall> {
        self.params.map_objects(f).map(|params| LeafCall {
            ty: self.ty.clone(),
            params,
        })
    }

    /// Short label with the key parameters (for diagrams and logs).
    pub fn label(&self) -> String {
        self.params
            .label(self.ty.name)
            .unwrap_or_else(|| match self.ty.category {
                Category::Condition => format!("{}?", self.ty.name),
                _ => self.ty.name.to_string(),
            })
    }

    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        self.params.validate()
    }
}
