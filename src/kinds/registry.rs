//! The [`Registry`] of node kinds: one [`NodeType`] per kind — composites, decorators,
//! actions, conditions and the runtime leaves — with its name, [`Category`], documentation and
//! parameter type.

use std::fmt;
use std::sync::Arc;

use schemars::JsonSchema;
use schemars::generate::SchemaGenerator;
use serde::Serialize;

use super::catalog::parse_node_doc;
use super::control::{Control, ControlKind, ControlParams};
use super::leaves::{Select, Wait};
use super::objects::ObjectRole;
use super::params::{DynParams, Params};
use super::role::ActionRole;
use crate::error::Error;
use crate::yaml::de::DeError;
use crate::yaml::value::Value;

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

pub(super) type ParseParams = fn(&Value) -> Result<Arc<dyn DynParams>, DeError>;

fn parse_params<P: Params>(v: &Value) -> Result<Arc<dyn DynParams>, DeError> {
    crate::yaml::de::from_value::<P>(v).map(|p| Arc::new(p) as Arc<dyn DynParams>)
}

/// Adds `P`'s schema to the generator and answers its definition name.
fn schema_of<P: JsonSchema>(g: &mut SchemaGenerator) -> String {
    let _ = g.subschema_for::<P>();
    P::schema_name().into_owned()
}

/// How a leaf kind's parameters are read, and what they declare.
pub(crate) struct LeafImp {
    pub(super) parse: ParseParams,
    schema: fn(&mut SchemaGenerator) -> String,
    objects: &'static [(&'static str, ObjectRole)],
    files: &'static [&'static str],
    failures: &'static [&'static str],
    role: ActionRole,
}

impl LeafImp {
    fn of<P: Params>(role: ActionRole) -> Self {
        LeafImp {
            parse: parse_params::<P>,
            schema: schema_of::<P>,
            objects: P::OBJECT_PARAMS,
            files: P::FILE_PARAMS,
            failures: P::failure_kinds(),
            role,
        }
    }
}

fn parse_control<P: ControlParams>(v: &Value) -> Result<Control, DeError> {
    crate::yaml::de::from_value::<P>(v).map(Into::into)
}

/// How a composite's or decorator's parameters are read; the tree reader reads the nodes among
/// them.
pub(crate) struct ControlImp {
    kind: ControlKind,
    parse: fn(&Value) -> Result<Control, DeError>,
    schema: fn(&mut SchemaGenerator) -> String,
}

impl ControlImp {
    pub(super) fn of<P: ControlParams>(kind: ControlKind) -> Self {
        ControlImp {
            kind,
            parse: parse_control::<P>,
            schema: schema_of::<P>,
        }
    }
}

/// How a kind is read.
pub(crate) enum Imp {
    /// A composite or decorator.
    Control(ControlImp),
    /// An action leaf.
    Action(LeafImp),
    /// A condition leaf.
    Condition(LeafImp),
    Wait,
    Select,
}

/// One registered node kind.
pub struct NodeType {
    pub(super) name: &'static str,
    pub(super) category: Category,
    pub(super) doc: &'static str,
    pub(super) imp: Imp,
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

    /// The parameters that name objects of the scene, with what each must name
    /// ([`Params::OBJECT_PARAMS`] of the kind's parameter type; none for other kinds).
    pub fn object_params(&self) -> &'static [(&'static str, ObjectRole)] {
        match &self.imp {
            Imp::Action(l) | Imp::Condition(l) => l.objects,
            _ => &[],
        }
    }

    /// The parameters that name a file the leaf reads when it runs ([`Params::FILE_PARAMS`] of
    /// the kind's parameter type; none for other kinds).
    pub fn file_params(&self) -> &'static [&'static str] {
        match &self.imp {
            Imp::Action(l) | Imp::Condition(l) => l.files,
            _ => &[],
        }
    }

    /// The failure kinds of its own the kind declares ([`Params::failure_kinds`]; none for
    /// other kinds).
    pub fn failure_kinds(&self) -> &'static [&'static str] {
        match &self.imp {
            Imp::Action(l) | Imp::Condition(l) => l.failures,
            _ => &[],
        }
    }

    /// What an action kind does in the pick-and-place cycle ([`ActionRole::Other`] for every
    /// other kind).
    pub fn role(&self) -> ActionRole {
        match &self.imp {
            Imp::Action(l) => l.role,
            _ => ActionRole::Other,
        }
    }

    /// Which control node it is; `None` for leaves.
    pub fn control_kind(&self) -> Option<ControlKind> {
        match &self.imp {
            Imp::Control(c) => Some(c.kind),
            _ => None,
        }
    }

    /// Reads a composite's or decorator's parameters from its YAML body (without `name:`),
    /// with its nodes kept as located YAML; `None` for leaves.
    pub(crate) fn parse_control(&self, body: &Value) -> Option<Result<Control, DeError>> {
        match &self.imp {
            Imp::Control(c) => Some((c.parse)(body)),
            _ => None,
        }
    }

    /// The parameters that hold nodes (`child`, `children`, `condition`), read from the
    /// parameter type's schema; none for leaves.
    pub(crate) fn node_params(&self) -> Vec<String> {
        let Imp::Control(c) = &self.imp else {
            return Vec::new();
        };
        let mut g = SchemaGenerator::default();
        let name = (c.schema)(&mut g);
        let defs = g.take_definitions(true);
        super::control::node_params(defs.get(&name).unwrap_or(&serde_json::Value::Null))
    }

    /// The parameter type's schema definition name, after adding it to `g`.
    pub(crate) fn params_schema(&self, g: &mut SchemaGenerator) -> String {
        match &self.imp {
            Imp::Action(l) | Imp::Condition(l) => (l.schema)(g),
            Imp::Wait => schema_of::<Wait>(g),
            Imp::Select => schema_of::<Select>(g),
            Imp::Control(c) => (c.schema)(g),
        }
    }
}

/// Every node kind a tree may use. [`Registry::builtin`] has the crate's own; add yours with
/// [`declare_action`](Self::declare_action) and
/// [`declare_condition`](Self::declare_condition).
#[derive(Clone, Debug)]
pub struct Registry {
    types: Vec<Arc<NodeType>>,
    file_checks: std::collections::BTreeMap<&'static str, FileCheck>,
}

/// Checks the content of a file a leaf names ([`Params::FILE_PARAMS`]; e.g. that a `policy`'s
/// model fits), given its canonical path, when the tree loads: the error says what is wrong and
/// what to do, and is reported at the parameter's value.
pub type FileCheck = fn(&std::path::Path) -> Result<(), String>;

/// Longest node kind name, bytes.
const MAX_KIND_LEN: usize = 40;

impl Registry {
    pub(super) fn empty() -> Registry {
        Registry {
            types: Vec::new(),
            file_checks: std::collections::BTreeMap::new(),
        }
    }

    /// Checks the files the leaves of kind `kind` name with `check` when a tree loads (the
    /// layer that runs the kind knows what such a file must hold; without a check, the loader
    /// only confines and opens it).
    pub fn check_files_with(&mut self, kind: &'static str, check: FileCheck) {
        self.file_checks.insert(kind, check);
    }

    /// How the files the leaves of kind `kind` name are checked, if they are.
    pub fn file_check(&self, kind: &str) -> Option<FileCheck> {
        self.file_checks.get(kind).copied()
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

    /// The failure kinds the node kinds declare besides the built-in ones, in registration
    /// order (what a scenario file's `expect.failure_kind` may name besides the built-in kinds).
    pub fn failure_kinds(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        for k in self.types.iter().flat_map(|t| t.failure_kinds()) {
            if !out.contains(k) {
                out.push(k);
            }
        }
        out
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

    /// Declares an action leaf `name` whose parameters are `P`. `doc` is Markdown in the format
    /// of `docs/nodes/*.md`: a one-line summary, optional details, a `Halt: …` paragraph and a
    /// ```` ```yaml ```` example that uses the kind. How the action runs is bound apart from
    /// this declaration (`Factory::bind_action`; `App::register_action` does both).
    ///
    /// # Errors
    /// [`Error::Registry`] when the name is not a lower-case identifier, is already registered,
    /// or the doc lacks its summary, halt paragraph or example.
    pub fn declare_action<P: Params>(
        &mut self,
        name: &'static str,
        doc: &'static str,
    ) -> Result<&mut Self, Error> {
        self.declare_action_as::<P>(name, doc, ActionRole::Other)
    }

    /// Declares an action leaf like [`declare_action`](Self::declare_action) that plays `role`
    /// in the pick-and-place cycle: a custom pick declared as [`ActionRole::Grasp`] is counted
    /// in the report's grasp attempts, gets the grasp checks and arms the grasp faults, like the
    /// built-in `grasp`.
    ///
    /// # Errors
    /// As for [`declare_action`](Self::declare_action).
    pub fn declare_action_as<P: Params>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        role: ActionRole,
    ) -> Result<&mut Self, Error> {
        check_failure_kinds::<P>(name)?;
        self.add(name, Category::Action, doc, Imp::Action(LeafImp::of::<P>(role)))
    }

    /// Declares a condition leaf `name` whose parameters are `P` (an instantaneous check of the
    /// world, bound apart with `Factory::bind_condition`). `doc` as for
    /// [`declare_action`](Self::declare_action).
    ///
    /// # Errors
    /// As for [`declare_action`](Self::declare_action).
    pub fn declare_condition<P: Params>(
        &mut self,
        name: &'static str,
        doc: &'static str,
    ) -> Result<&mut Self, Error> {
        check_failure_kinds::<P>(name)?;
        self.add(
            name,
            Category::Condition,
            doc,
            Imp::Condition(LeafImp::of::<P>(ActionRole::Other)),
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
}

/// Checks the failure kinds `P` declares for the node kind `name`
/// ([`Params::failure_kinds`]): each a valid custom name, none twice.
fn check_failure_kinds<P: Params>(name: &str) -> Result<(), Error> {
    let kinds = P::failure_kinds();
    for (i, k) in kinds.iter().enumerate() {
        let why = crate::failure::FailureKind::check_custom_name(k)
            .err()
            .or_else(|| {
                kinds[..i]
                    .contains(k)
                    .then(|| format!("failure kind `{k}` is declared twice"))
            });
        if let Some(message) = why {
            return Err(Error::Registry {
                kind: name.to_string(),
                message,
            });
        }
    }
    Ok(())
}
