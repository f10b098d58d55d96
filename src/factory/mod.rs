//! How each node kind *runs*: the controller an action leaf starts and the check a condition
//! leaf answers, bound to the kind's name and looked up when the tree runs.
//!
//! What a kind *is* (name, category, doc, parameter type) is declared apart, in
//! [`crate::kinds::Registry`]; a parsed tree holds a kind and its parameters and nothing that
//! runs. [`Factory::builtin`] binds the built-in leaves; [`crate::App::register_action`] and
//! [`crate::App::register_condition`] declare a user's kind and bind it in one call.
//!
//! This sits above [`crate::actions`] (the controllers) and needs the `sim` feature.

mod builtin;

use std::collections::BTreeMap;
use std::fmt;
use std::sync::{Arc, OnceLock};

use crate::actions::{Cell, MacroAction, Progress};
use crate::failure::{Failure, FailureKind};
use crate::kinds::{Category, LeafCall, Params, Registry};
use crate::world::World;

type StartFn = dyn Fn(&LeafCall) -> Option<Box<dyn MacroAction>> + Send + Sync;
type CheckFn = dyn Fn(&World, &LeafCall) -> Option<Result<bool, Failure>> + Send + Sync;

/// The bindings of action and condition kinds to how they run, by kind name.
#[derive(Clone, Default)]
pub struct Factory {
    actions: BTreeMap<&'static str, Arc<StartFn>>,
    conditions: BTreeMap<&'static str, Arc<CheckFn>>,
}

impl fmt::Debug for Factory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Factory")
            .field("actions", &self.actions.keys().collect::<Vec<_>>())
            .field("conditions", &self.conditions.keys().collect::<Vec<_>>())
            .finish()
    }
}

/// A kind bound twice, or bound with no declaration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BindError(pub String);

impl fmt::Display for BindError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl Factory {
    /// The built-in actions' controllers and conditions' checks (shared, cheap to clone).
    pub fn builtin() -> Arc<Factory> {
        static BUILTIN: OnceLock<Arc<Factory>> = OnceLock::new();
        BUILTIN.get_or_init(|| Arc::new(builtin::factory())).clone()
    }

    /// Binds the action kind `name` (declared with parameters `P`) to `start`, which makes a new
    /// controller from the parameters each time the leaf starts. Its failures may be of the
    /// built-in kinds or of the custom kinds `P` declares ([`Params::failure_kinds`]); one of
    /// another custom kind is reported as `other`.
    ///
    /// # Errors
    /// When `name` is already bound.
    pub fn bind_action<P, F>(&mut self, name: &'static str, start: F) -> Result<&mut Self, BindError>
    where
        P: Params,
        F: Fn(&P) -> Box<dyn MacroAction> + Send + Sync + 'static,
    {
        if self.actions.contains_key(name) || self.conditions.contains_key(name) {
            return Err(BindError(format!("node kind `{name}` is already bound")));
        }
        let f = move |call: &LeafCall| {
            call.params::<P>().map(|p| {
                Box::new(Declared {
                    inner: start(p),
                    kinds: P::failure_kinds(),
                    node_kind: name,
                }) as Box<dyn MacroAction>
            })
        };
        self.actions.insert(name, Arc::new(f));
        Ok(self)
    }

    /// Binds the condition kind `name` (declared with parameters `P`) to `check`, a pure
    /// function of the world snapshot. Its failures' kinds are checked as for
    /// [`bind_action`](Self::bind_action).
    ///
    /// # Errors
    /// When `name` is already bound.
    pub fn bind_condition<P, F>(&mut self, name: &'static str, check: F) -> Result<&mut Self, BindError>
    where
        P: Params,
        F: Fn(&World, &P) -> Result<bool, Failure> + Send + Sync + 'static,
    {
        if self.actions.contains_key(name) || self.conditions.contains_key(name) {
            return Err(BindError(format!("node kind `{name}` is already bound")));
        }
        let f = move |w: &World, call: &LeafCall| {
            call.params::<P>()
                .map(|p| check(w, p).map_err(|e| declared(e, P::failure_kinds(), name)))
        };
        self.conditions.insert(name, Arc::new(f));
        Ok(self)
    }

    /// A new controller for the action leaf `call`; `None` when its kind has no controller here
    /// (not an action, or declared but never bound).
    pub fn start(&self, call: &LeafCall) -> Option<Box<dyn MacroAction>> {
        self.actions.get(call.kind()).and_then(|f| f(call))
    }

    /// The answer of the condition leaf `call` in `world`; `None` when its kind has no check
    /// here.
    pub fn check(&self, call: &LeafCall, world: &World) -> Option<Result<bool, Failure>> {
        self.conditions.get(call.kind()).and_then(|f| f(world, call))
    }

    /// The action and condition kinds of `registry` that have nothing bound here, in
    /// registration order (a tree using one of them cannot run).
    pub fn unbound<'r>(&self, registry: &'r Registry) -> Vec<&'r str> {
        registry
            .types()
            .filter(|t| match t.category() {
                Category::Action => !self.actions.contains_key(t.name()),
                Category::Condition => !self.conditions.contains_key(t.name()),
                _ => false,
            })
            .map(|t| t.name())
            .collect()
    }
}

/// `failure` as its node kind `node_kind` may report it: a custom kind it did not declare in
/// `kinds` becomes `other` (and is logged), with the message saying so.
fn declared(failure: Failure, kinds: &[&str], node_kind: &str) -> Failure {
    match failure.kind {
        FailureKind::Custom(k) if !kinds.contains(&k) => {
            tracing::error!(target: "macrotree::actions", "`{node_kind}` failed with the failure kind `{k}`, which it does not declare (Params::failure_kinds); reported as `other`");
            let message = format!("{} (undeclared failure kind `{k}`)", failure.message);
            Failure {
                kind: FailureKind::Other,
                message,
                ..failure
            }
        }
        _ => failure,
    }
}

/// A controller whose failures are checked against the custom kinds its node kind declares.
struct Declared {
    inner: Box<dyn MacroAction>,
    kinds: &'static [&'static str],
    node_kind: &'static str,
}

impl MacroAction for Declared {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        self.inner
            .start(cell)
            .map_err(|e| declared(e, self.kinds, self.node_kind))
    }
    fn update(&mut self, cell: &mut Cell) -> Progress {
        match self.inner.update(cell) {
            Progress::Failed(e) => Progress::Failed(declared(e, self.kinds, self.node_kind)),
            p => p,
        }
    }
    fn halt(&mut self, cell: &mut Cell) {
        self.inner.halt(cell);
    }
    fn waiting_for(&self, cell: &Cell) -> String {
        self.inner.waiting_for(cell)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_action_and_condition_is_bound_and_nothing_else() {
        let registry = Registry::builtin();
        let factory = Factory::builtin();
        assert_eq!(factory.unbound(&registry), Vec::<&str>::new());
        let declared: Vec<&str> = registry
            .types()
            .filter(|t| matches!(t.category(), Category::Action | Category::Condition))
            .map(|t| t.name())
            .collect();
        let bound = factory.actions.len() + factory.conditions.len();
        assert_eq!(bound, declared.len(), "bound {:?}", factory);
    }

    #[test]
    fn a_kind_is_bound_once() {
        let mut f = Factory::default();
        f.bind_condition("near", |_: &World, _: &crate::kinds::GripperOpen| Ok(true))
            .unwrap();
        let again = f.bind_condition("near", |_: &World, _: &crate::kinds::GripperOpen| Ok(true));
        assert!(again.unwrap_err().0.contains("already bound"));
    }
}
