//! The registry of node kinds: one entry per kind — composites, decorators, actions,
//! conditions and the runtime leaves — with its name, category, documentation, parameter type
//! and, for leaves, how it runs.
//!
//! Everything that needs to know which node kinds exist reads it: parsing (and the
//! did-you-mean suggestions for misspelled kinds), the JSON Schema of tree files,
//! `macrotree nodes`, the `graph` labels, the docs and execution. The built-in leaves register
//! through the same [`Registry::register_action`] / [`Registry::register_condition`] calls a
//! crate user makes for their own leaves (see `src/registry/builtin.rs` and
//! `docs/custom_nodes.md`).
//!
//! A leaf's parameters are a type implementing [`Params`] (`Deserialize` + `JsonSchema`):
//! the YAML body of the node is read into it with located errors, its doc comments become the
//! parameter documentation, and the schema is generated from it.

mod builtin;
mod control;
mod param_error;

use std::any::Any;
use std::fmt;
use std::sync::{Arc, OnceLock, RwLock};

use schemars::JsonSchema;
use schemars::generate::SchemaGenerator;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::actions::MacroAction;
use crate::error::Error;
use crate::spec::catalog::{ParamDoc, parse_node_doc};
use crate::spec::de::DeError;
use crate::spec::leaves::{Leaf, Select, Wait};
use crate::spec::objects::ObjectRef;
use crate::spec::value::Value;
use crate::world::World;

pub(crate) use control::SchemaCtx;
pub use param_error::ParamError;

/// What a node kind is.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Category {
    /// Takes `children:` (`sequence`, `fallback`, …).
    Composite,
    /// Takes a `child:` (`retry`, `timeout`, …), or calls a subtree.
    Decorator,
    /// A macro action: runs over several ticks on the cell (`reach`, `grasp`, …).
    Action,
    /// An instantaneous check of the world (`grasped`, `in`, …).
    Condition,
    /// A leaf handled by the runtime itself (`wait`, `select`).
    Runtime,
}

impl Category {
    /// Lower-case name (`composite`, `action`, …), as `macrotree nodes` prints it.
    pub fn as_str(self) -> &'static str {
        match self {
            Category::Composite => "composite",
            Category::Decorator => "decorator",
            Category::Action => "action",
            Category::Condition => "condition",
            Category::Runtime => "runtime",
        }
    }
}

/// The parameters of a leaf kind, read from the node's YAML body.
///
/// Derive `Deserialize` (with `#[serde(deny_unknown_fields)]`, so a misspelled parameter is a
/// located error with a suggestion), `Serialize`, `JsonSchema`, `Clone`, `Debug` and
/// `PartialEq`; document every field with its unit (the doc comments become the parameter docs
/// of `macrotree nodes` and of the JSON Schema). Fields may use the crate's own parameter types
/// and unit parsers: [`ObjectRef`] (an object name or a `{variable}`),
/// [`Target`](crate::spec::Target), [`Angle`](crate::spec::units::Angle), and
/// `#[serde(deserialize_with = "macrotree::spec::units::distance")]` and friends for range-checked
/// metres, seconds and `deg(..)` angles.
///
/// Every method has a default; override the ones that apply.
pub trait Params:
    Serialize + DeserializeOwned + JsonSchema + Clone + fmt::Debug + PartialEq + Send + Sync + 'static
{
    /// Every object reference among the parameters, so that `{variables}` are resolved before
    /// each tick. Object names are checked against the scene when the tree loads, by key:
    /// `object` and `support` must name a block, `container` a container, `target` and `to` any
    /// object. Default: none.
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

/// Starts a registered action (type-erased).
pub(crate) trait ActionFactory: Send + Sync {
    fn start(&self, params: &dyn DynParams) -> Option<Box<dyn MacroAction>>;
}

struct TypedAction<P, F>(F, std::marker::PhantomData<fn(&P)>);

impl<P: Params, F: Fn(&P) -> Box<dyn MacroAction> + Send + Sync> ActionFactory for TypedAction<P, F> {
    fn start(&self, params: &dyn DynParams) -> Option<Box<dyn MacroAction>> {
        params.as_any().downcast_ref::<P>().map(&self.0)
    }
}

/// Checks a registered condition (type-erased).
pub(crate) trait ConditionCheck: Send + Sync {
    fn check(&self, world: &World, params: &dyn DynParams) -> Option<Result<bool, String>>;
}

struct TypedCondition<P, F>(F, std::marker::PhantomData<fn(&P)>);

impl<P: Params, F: Fn(&World, &P) -> Result<bool, String> + Send + Sync> ConditionCheck
    for TypedCondition<P, F>
{
    fn check(&self, world: &World, params: &dyn DynParams) -> Option<Result<bool, String>> {
        params.as_any().downcast_ref::<P>().map(|p| (self.0)(world, p))
    }
}

type ParseParams = fn(&Value) -> Result<Arc<dyn DynParams>, DeError>;

fn parse_params<P: Params>(v: &Value) -> Result<Arc<dyn DynParams>, DeError> {
    crate::spec::de::from_value::<P>(v).map(|p| Arc::new(p) as Arc<dyn DynParams>)
}

/// Adds `P`'s schema to the generator and answers its definition name.
fn schema_of<P: JsonSchema>(g: &mut SchemaGenerator) -> String {
    let _ = g.subschema_for::<P>();
    P::schema_name().into_owned()
}

/// How a kind is read and run.
pub(crate) enum Imp {
    /// A composite or decorator: parsed by the tree reader; its parameters and schema are given.
    Control {
        params: fn() -> Vec<ParamDoc>,
        schema: fn(&SchemaCtx) -> serde_json::Value,
    },
    Action {
        parse: ParseParams,
        schema: fn(&mut SchemaGenerator) -> String,
        start: Box<dyn ActionFactory>,
    },
    Condition {
        parse: ParseParams,
        schema: fn(&mut SchemaGenerator) -> String,
        check: Box<dyn ConditionCheck>,
    },
    Wait,
    Select,
}

/// One registered node kind.
pub struct NodeType {
    name: &'static str,
    category: Category,
    doc: &'static str,
    imp: Imp,
}

impl fmt::Debug for NodeType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("NodeType")
            .field("name", &self.name)
            .field("category", &self.category)
            .finish_non_exhaustive()
    }
}

impl NodeType {
    /// The YAML kind (`reach`, `push`, …).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// What it is.
    pub fn category(&self) -> Category {
        self.category
    }

    /// Its documentation: a one-line summary paragraph, optional details, a `Halt: …`
    /// paragraph and a ```` ```yaml ```` example (the format of `docs/nodes/*.md`).
    pub fn doc(&self) -> &'static str {
        self.doc
    }

    pub(crate) fn imp(&self) -> &Imp {
        &self.imp
    }

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
            Imp::Control { .. } => return None,
            Imp::Action { parse, .. } => call(*parse).map(Leaf::Action),
            Imp::Condition { parse, .. } => call(*parse).map(Leaf::Condition),
            Imp::Wait => crate::spec::de::from_value::<Wait>(body).map(Leaf::Wait),
            Imp::Select => crate::spec::de::from_value::<Select>(body).map(Leaf::Select),
        })
    }

    /// The parameter type's schema definition name, after adding it to `g` (leaves only).
    pub(crate) fn leaf_schema(&self, g: &mut SchemaGenerator) -> Option<String> {
        match &self.imp {
            Imp::Action { schema, .. } | Imp::Condition { schema, .. } => Some(schema(g)),
            Imp::Wait => Some(schema_of::<Wait>(g)),
            Imp::Select => Some(schema_of::<Select>(g)),
            Imp::Control { .. } => None,
        }
    }
}

/// An action or condition leaf of a tree: its registered kind and its parameters.
#[derive(Clone)]
pub struct LeafCall {
    ty: Arc<NodeType>,
    params: Arc<dyn DynParams>,
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

    /// Starts the action (a new controller); `None` for conditions.
    pub fn start_action(&self) -> Option<Box<dyn MacroAction>> {
        match &self.ty.imp {
            Imp::Action { start, .. } => start.start(&*self.params),
            _ => None,
        }
    }

    /// Checks the condition against `world`; `None` for actions.
    pub fn check(&self, world: &World) -> Option<Result<bool, String>> {
        match &self.ty.imp {
            Imp::Condition { check, .. } => check.check(world, &*self.params),
            _ => None,
        }
    }
}

/// Every node kind a tree may use. [`Registry::builtin`] has the crate's own; add yours with
/// [`register_action`](Self::register_action) and
/// [`register_condition`](Self::register_condition).
#[derive(Clone, Debug)]
pub struct Registry {
    types: Vec<Arc<NodeType>>,
}

impl Default for Registry {
    /// The built-in node kinds.
    fn default() -> Self {
        Self::builtin()
    }
}

/// Longest node kind name, bytes.
const MAX_KIND_LEN: usize = 40;

impl Registry {
    /// The built-in node kinds (composites, decorators, actions, conditions, `wait`, `select`).
    pub fn builtin() -> Registry {
        static BUILTIN: OnceLock<Registry> = OnceLock::new();
        BUILTIN.get_or_init(builtin::registry).clone()
    }

    fn empty() -> Registry {
        Registry { types: Vec::new() }
    }

    /// The kind called `name`.
    pub fn get(&self, name: &str) -> Option<&NodeType> {
        self.entry(name).map(|t| &**t)
    }

    pub(crate) fn entry(&self, name: &str) -> Option<&Arc<NodeType>> {
        self.types.iter().find(|t| t.name == name)
    }

    /// Every kind, in registration order (built-ins first, in documentation order).
    pub fn types(&self) -> impl Iterator<Item = &NodeType> {
        self.types.iter().map(|t| &**t)
    }

    /// Every kind's name, in registration order.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.types.iter().map(|t| t.name)
    }

    /// The names of the kinds of `category`, in registration order.
    pub fn names_of(&self, category: Category) -> Vec<&'static str> {
        self.types
            .iter()
            .filter(|t| t.category == category)
            .map(|t| t.name)
            .collect()
    }

    /// Registers an action leaf: `start` makes a new controller from the parameters each time the
    /// leaf starts (its `start` runs on the first tick, `update` on every tick after, `halt` when
    /// the tree preempts it). `doc` is Markdown in the format of `docs/nodes/*.md`: a one-line
    /// summary, optional details, a `Halt: …` paragraph and a ```` ```yaml ```` example that uses
    /// the kind.
    ///
    /// # Errors
    /// [`Error::Registry`] when the name is not a lower-case identifier, is already registered,
    /// or the doc lacks its summary, halt paragraph or example.
    pub fn register_action<P, F>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        start: F,
    ) -> Result<&mut Self, Error>
    where
        P: Params,
        F: Fn(&P) -> Box<dyn MacroAction> + Send + Sync + 'static,
    {
        self.add(
            name,
            Category::Action,
            doc,
            Imp::Action {
                parse: parse_params::<P>,
                schema: schema_of::<P>,
                start: Box::new(TypedAction(start, std::marker::PhantomData)),
            },
        )
    }

    /// Registers a condition leaf: `check` answers from the world snapshot alone (a pure
    /// function: called every tick the condition is checked, it must not keep state). `Ok(false)`
    /// fails the leaf with `not satisfied`, `Err(reason)` fails it with the reason (e.g. an
    /// unknown object). `doc` as for [`register_action`](Self::register_action).
    ///
    /// # Errors
    /// As for [`register_action`](Self::register_action).
    pub fn register_condition<P, F>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        check: F,
    ) -> Result<&mut Self, Error>
    where
        P: Params,
        F: Fn(&World, &P) -> Result<bool, String> + Send + Sync + 'static,
    {
        self.add(
            name,
            Category::Condition,
            doc,
            Imp::Condition {
                parse: parse_params::<P>,
                schema: schema_of::<P>,
                check: Box::new(TypedCondition(check, std::marker::PhantomData)),
            },
        )
    }

    pub(crate) fn add(
        &mut self,
        name: &'static str,
        category: Category,
        doc: &'static str,
        imp: Imp,
    ) -> Result<&mut Self, Error> {
        let bad = |why: String| {
            Err(Error::Registry {
                kind: name.to_string(),
                message: why,
            })
        };
        let valid = !name.is_empty()
            && name.len() <= MAX_KIND_LEN
            && name.starts_with(|c: char| c.is_ascii_lowercase())
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !valid {
            return bad(format!(
                "`{name}` is not a valid node kind: use 1–{MAX_KIND_LEN} lower-case letters, digits and `_`, starting with a letter"
            ));
        }
        if name == "name" {
            return bad("`name` is reserved (every node accepts `name:`)".into());
        }
        if self.entry(name).is_some() {
            return bad(format!("node kind `{name}` is already registered"));
        }
        let (summary, _, halt, example) = parse_node_doc(doc);
        if summary.is_empty() {
            return bad("its doc has no summary (a first paragraph of one line)".into());
        }
        if halt.is_empty() {
            return bad("its doc has no `Halt: …` paragraph (what halting it does)".into());
        }
        if !example.contains(&format!("{name}:")) {
            return bad(format!(
                "its doc has no ```yaml example that uses `{name}:` (e.g. `{name}: {{…}}`)"
            ));
        }
        self.types.push(Arc::new(NodeType {
            name,
            category,
            doc,
            imp,
        }));
        Ok(self)
    }

    /// Makes this registry the one the command line and the path-based entry points
    /// ([`crate::plan::load_plan`], [`crate::plan::compile_str`], `macrotree nodes`, …) use, for
    /// the rest of the process.
    pub fn install(self) {
        let mut slot = INSTALLED.write().unwrap_or_else(|e| e.into_inner());
        *slot = Some(Arc::new(self));
    }
}

static INSTALLED: RwLock<Option<Arc<Registry>>> = RwLock::new(None);

/// The registry the path-based entry points use: the one last [`Registry::install`]ed, else the
/// built-in one.
pub fn installed() -> Arc<Registry> {
    static DEFAULT: OnceLock<Arc<Registry>> = OnceLock::new();
    let slot = INSTALLED.read().unwrap_or_else(|e| e.into_inner());
    match &*slot {
        Some(r) => r.clone(),
        None => DEFAULT.get_or_init(|| Arc::new(Registry::builtin())).clone(),
    }
}
