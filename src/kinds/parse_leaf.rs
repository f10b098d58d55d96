//! [`NodeType::parse_leaf`]: a leaf of a registered kind read from its YAML body.

use std::sync::Arc;

use super::leaf_call::LeafCall;
use super::leaves::{Leaf, Select, Wait};
use super::registry::{Imp, NodeType, ParseParams};
use crate::yaml::de::DeError;
use crate::yaml::value::Value;

impl NodeType {
    /// Reads a leaf of this kind from its YAML body (without `name:`); `None` for composites and
    /// decorators.
    pub(crate) fn parse_leaf(self: &Arc<Self>, body: &Value) -> Option<Result<Leaf, DeError>> {
        let call = |parse: ParseParams| {
            parse(body).map(|params| LeafCall {
                ty: self.clone(),
                params,
            })
        };
        Some(match &self.imp {
            Imp::Control(_) => return None,
            Imp::Action(l) => call(l.parse).map(Leaf::Action),
            Imp::Condition(l) => call(l.parse).map(Leaf::Condition),
            Imp::Wait => crate::yaml::de::from_value::<Wait>(body).map(Leaf::Wait),
            Imp::Select => crate::yaml::de::from_value::<Select>(body).map(Leaf::Select),
        })
    }
}
