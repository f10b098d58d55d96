//! The blackboard: run-time variables (object names) that `select` and `for_each` write and
//! leaves read as `{name}` wherever an object is expected. Names and types are checked when the
//! tree is compiled; at run time a variable read before it was written fails the leaf that reads
//! it.

use std::borrow::Cow;
use std::collections::BTreeMap;

use crate::kinds::{Leaf, ObjectRef};

/// Variable values by name. A variable is unset until written (and a `goal_as` variable is
/// unset again when the selected object has no goal).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Blackboard {
    values: BTreeMap<String, Option<String>>,
}

impl Blackboard {
    /// The value of `var`, if set.
    pub fn get(&self, var: &str) -> Option<&str> {
        self.values.get(var).and_then(|v| v.as_deref())
    }

    /// Sets (`Some`) or unsets (`None`) `var`.
    pub fn set(&mut self, var: &str, value: Option<String>) {
        self.values.insert(var.to_string(), value);
    }

    /// Every variable written so far, by name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, Option<&str>)> {
        self.values.iter().map(|(k, v)| (k.as_str(), v.as_deref()))
    }

    /// `leaf` with every `{var}` replaced by the variable's value (borrowed when it reads none),
    /// or why it cannot run: the first variable it reads that is unset.
    pub fn resolve<'l>(&self, leaf: &'l Leaf) -> Result<Cow<'l, Leaf>, String> {
        let mut unset = None;
        let resolved = leaf.map_objects(&mut |r: &ObjectRef| match r {
            ObjectRef::Var(v) => match self.get(v).and_then(ObjectRef::name) {
                Some(named) => Some(named),
                None => {
                    unset.get_or_insert_with(|| v.to_string());
                    None
                }
            },
            ObjectRef::Name(_) => None,
        });
        if let Some(v) = unset {
            return Err(format!(
                "the variable `{{{v}}}` is not set (no `select` or `for_each` has written it yet)"
            ));
        }
        Ok(match resolved {
            Some(l) => Cow::Owned(l),
            None => Cow::Borrowed(leaf),
        })
    }
}
