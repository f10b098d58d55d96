//! The composites and decorators: one typed parameter struct per shape of body (serde +
//! schemars, documented like a leaf's), declared in the [`Registry`](super::Registry) like every
//! other kind so that parsing, the catalog, the schema and the suggestions all read it. The node
//! fields (`child`, `children`, `condition`) are kept as located YAML for the tree reader
//! (`spec::expand`), which reads them as nodes and expands subtree calls.

use std::borrow::Cow;

use schemars::generate::SchemaGenerator;
use schemars::{JsonSchema, Schema, json_schema};
use serde::{Deserialize, Deserializer};
use serde_json::{Value as Json, json};

use super::leaves::Select;
use super::objects::{opt_var_name, var_name};
use crate::world::query::Query;
use crate::yaml::de::RawValue;
use crate::yaml::units;
use crate::yaml::value::Value;

/// Largest `attempts`, `times` and `max_iterations`.
pub const MAX_COUNT: u32 = 1_000;

/// Which control node a kind is: what the tree reader builds from its parameters.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ControlKind {
    /// `sequence`.
    Sequence,
    /// `fallback`.
    Fallback,
    /// `reactive_sequence`.
    ReactiveSequence,
    /// `reactive_fallback`.
    ReactiveFallback,
    /// `parallel`.
    Parallel,
    /// `race`.
    Race,
    /// `guard`.
    Guard,
    /// `retry`.
    Retry,
    /// `repeat`.
    Repeat,
    /// `for_each`.
    ForEach,
    /// `timeout`.
    Timeout,
    /// `inverter`.
    Inverter,
    /// `force_success`.
    ForceSuccess,
    /// `force_failure`.
    ForceFailure,
    /// `subtree`.
    Subtree,
}

/// A control node's parameters, read from its body (without `name:`).
#[derive(Clone, Debug)]
pub enum Control {
    /// A composite's.
    Composite(CompositeParams),
    /// A guard's.
    Guard(GuardParams),
    /// A retry's.
    Retry(RetryParams),
    /// A repeat's.
    Repeat(RepeatParams),
    /// A for_each's.
    ForEach(ForEachParams),
    /// A timeout's.
    Timeout(TimeoutParams),
    /// An inverter's or a force_*'s.
    Decorated(ChildParams),
    /// A subtree call's.
    Subtree(SubtreeParams),
}

macro_rules! into_control {
    ($($ty:ident => $variant:ident),* $(,)?) => {
        $(impl From<$ty> for Control {
            fn from(p: $ty) -> Control {
                Control::$variant(p)
            }
        })*
    };
}

into_control!(
    CompositeParams => Composite,
    GuardParams => Guard,
    RetryParams => Retry,
    RepeatParams => Repeat,
    ForEachParams => ForEach,
    TimeoutParams => Timeout,
    ChildParams => Decorated,
    SubtreeParams => Subtree,
);

/// The parameter types of control kinds.
pub(crate) trait ControlParams: serde::de::DeserializeOwned + JsonSchema + Into<Control> {}

impl<T: serde::de::DeserializeOwned + JsonSchema + Into<Control>> ControlParams for T {}

/// Where a node field's schema refers to (`#/$defs/Node`, made `NodeTemplate` inside subtree
/// bodies by [`template_refs`]).
const NODE_REF: &str = "#/$defs/Node";
/// Likewise for a condition (`#/$defs/Condition`).
const CONDITION_REF: &str = "#/$defs/Condition";

/// One node, kept as located YAML until the tree reader reads it.
#[derive(Clone, Debug)]
pub struct NodeValue(pub Value);

/// A condition leaf (or an `inverter` of one), kept as located YAML.
#[derive(Clone, Debug)]
pub struct ConditionValue(pub Value);

/// A list of nodes, kept as located YAML (the reader checks it is a non-empty list).
#[derive(Clone, Debug)]
pub struct NodeList(pub Value);

/// A subtree call's arguments, kept as located YAML (the reader matches them with the
/// subtree's parameters).
#[derive(Clone, Debug)]
pub struct Arguments(pub Value);

macro_rules! raw_yaml {
    ($($ty:ident: $name:literal => $schema:expr),* $(,)?) => {
        $(impl<'de> Deserialize<'de> for $ty {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                RawValue::deserialize(d).map(|r| $ty(r.0))
            }
        }

        impl JsonSchema for $ty {
            fn inline_schema() -> bool {
                true
            }
            fn schema_name() -> Cow<'static, str> {
                $name.into()
            }
            fn json_schema(_: &mut SchemaGenerator) -> Schema {
                $schema
            }
        })*
    };
}

raw_yaml!(
    NodeValue: "NodeValue" => json_schema!({"$ref": NODE_REF}),
    ConditionValue: "ConditionValue" => json_schema!({"$ref": CONDITION_REF}),
    NodeList: "NodeList" => json_schema!({"type": "array", "items": {"$ref": NODE_REF}, "minItems": 1}),
    Arguments: "Arguments" => json_schema!({"type": "object", "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"}}),
);

/// `sequence`, `fallback`, `reactive_*`, `parallel`, `race`: `{children}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CompositeParams {
    /// The children, at least one, ticked in order.
    pub children: NodeList,
}

/// `guard: {condition, child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GuardParams {
    /// A condition leaf (or an `inverter` of one), checked every tick.
    pub condition: ConditionValue,
    /// The guarded node.
    pub child: NodeValue,
}

/// `retry: {attempts, child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RetryParams {
    /// Total runs allowed, 1 to 1000.
    #[serde(deserialize_with = "attempts")]
    #[schemars(range(min = 1, max = MAX_COUNT))]
    pub attempts: u32,
    /// The node to retry.
    pub child: NodeValue,
}

/// `repeat: {times, child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RepeatParams {
    /// Successful runs required, 1 to 1000.
    #[serde(deserialize_with = "times")]
    #[schemars(range(min = 1, max = MAX_COUNT))]
    pub times: u32,
    /// The node to repeat.
    pub child: NodeValue,
}

/// `for_each: {select, as, goal_as, max_iterations, child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ForEachParams {
    /// The query: `kind` (block), `color`, `where` (pending, done, on_table, free), `order`
    /// (nearest, name, scene). Default: every block, nearest first.
    #[serde(default, deserialize_with = "query")]
    #[schemars(extend("default" = {}))]
    pub select: Query,
    /// The variable each selected object is written to; read it as `{name}`.
    #[serde(rename = "as", deserialize_with = "var_name")]
    #[schemars(regex(pattern = r"^[A-Za-z_][A-Za-z0-9_]*$"))]
    pub var: String,
    /// Also write where the object's goal sends it (a container or a block) to this variable.
    #[serde(
        default,
        rename = "goal_as",
        deserialize_with = "opt_var_name",
        skip_serializing_if = "Option::is_none"
    )]
    #[schemars(with = "String", regex(pattern = r"^[A-Za-z_][A-Za-z0-9_]*$"))]
    pub goal_var: Option<String>,
    /// Most iterations, 1 to 1000; more matches after that fail the loop.
    #[serde(deserialize_with = "max_iterations")]
    #[schemars(range(min = 1, max = MAX_COUNT))]
    pub max_iterations: u32,
    /// The node run once per selected object.
    pub child: NodeValue,
}

impl ForEachParams {
    /// What each iteration selects, and the variables it writes.
    pub fn select(&self) -> Select {
        Select {
            var: self.var.clone(),
            goal_var: self.goal_var.clone(),
            kind: self.select.kind,
            color: self.select.color.clone(),
            filters: self.select.filters.clone(),
            order: self.select.order,
        }
    }
}

/// `timeout: {seconds, child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeoutParams {
    /// Simulated seconds (> 0).
    #[serde(deserialize_with = "units::time_limit")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub seconds: f64,
    /// The node to time-limit.
    pub child: NodeValue,
}

/// `inverter`, `force_success`, `force_failure`: `{child}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ChildParams {
    /// The decorated node.
    pub child: NodeValue,
}

/// `subtree: {ref, args}`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SubtreeParams {
    /// Name of a subtree under `subtrees:` (here or in an included file).
    #[serde(rename = "ref", deserialize_with = "subtree_name")]
    #[schemars(regex(pattern = r"^[A-Za-z_][A-Za-z0-9_]*$"))]
    pub reference: String,
    /// Argument values by parameter name; omitted ones take their defaults.
    #[serde(default)]
    pub args: Option<Arguments>,
}

/// `select:` may be written empty (`select:` or `select: ~`): every block, nearest first.
fn query<'de, D: Deserializer<'de>>(d: D) -> Result<Query, D::Error> {
    Ok(Option::<Query>::deserialize(d)?.unwrap_or_default())
}

fn subtree_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    use serde::de::{self, Visitor};
    struct Name;
    impl Visitor<'_> for Name {
        type Value = String;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a subtree name")
        }
        fn visit_str<E: de::Error>(self, s: &str) -> Result<String, E> {
            Ok(s.to_string())
        }
    }
    d.deserialize_str(Name)
}

/// A count of 1 to [`MAX_COUNT`] for the parameter `key`.
fn count<'de, D: Deserializer<'de>>(d: D, key: &str) -> Result<u32, D::Error> {
    use serde::de::{self, Unexpected, Visitor};
    struct Count<'k>(&'k str);
    impl Visitor<'_> for Count<'_> {
        type Value = u32;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an integer ≥ 1")
        }
        fn visit_i64<E: de::Error>(self, n: i64) -> Result<u32, E> {
            if (1..=i64::from(MAX_COUNT)).contains(&n) {
                Ok(n as u32)
            } else {
                Err(E::custom(format!(
                    "`{}` must be between 1 and {MAX_COUNT}, found {n}",
                    self.0
                )))
            }
        }
        fn visit_u64<E: de::Error>(self, n: u64) -> Result<u32, E> {
            self.visit_i64(i64::try_from(n).unwrap_or(i64::MAX))
        }
        fn visit_f64<E: de::Error>(self, x: f64) -> Result<u32, E> {
            Err(E::custom(format!("`{}` must be an integer, found {x}", self.0)))
        }
        fn visit_str<E: de::Error>(self, s: &str) -> Result<u32, E> {
            Err(E::invalid_type(Unexpected::Str(s), &self))
        }
    }
    d.deserialize_i64(Count(key))
}

fn attempts<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    count(d, "attempts")
}
fn times<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    count(d, "times")
}
fn max_iterations<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    count(d, "max_iterations")
}

/// The properties and required keys of a node body (any kind's) from its parameter struct's
/// schema `def`, for a tree's `main:` (`template` false) or a subtree body (true): inside subtree
/// bodies the node fields refer to the template forms, and every other value may also be a
/// `$param`.
pub(crate) fn body_schema(def: &Json, template: bool) -> (Json, Vec<String>) {
    let mut props = def.get("properties").cloned().unwrap_or(json!({}));
    if let Some(obj) = props.as_object_mut() {
        for v in obj.values_mut() {
            if holds_nodes(v) {
                if template {
                    template_refs(v);
                }
            } else if template {
                *v = templated(v);
            }
        }
    }
    let required = def
        .get("required")
        .and_then(Json::as_array)
        .map(|r| r.iter().filter_map(Json::as_str).map(str::to_string).collect())
        .unwrap_or_default();
    (props, required)
}

/// The parameters of the schema `def` that hold nodes.
pub(crate) fn node_params(def: &Json) -> Vec<String> {
    def.get("properties")
        .and_then(Json::as_object)
        .map(|props| {
            props
                .iter()
                .filter(|(_, s)| holds_nodes(s))
                .map(|(k, _)| k.clone())
                .collect()
        })
        .unwrap_or_default()
}

/// Whether a parameter's schema holds nodes (a node, a condition or a list of nodes).
fn holds_nodes(s: &Json) -> bool {
    match s {
        Json::String(r) => r == NODE_REF || r == CONDITION_REF,
        Json::Object(m) => m.values().any(holds_nodes),
        Json::Array(items) => items.iter().any(holds_nodes),
        _ => false,
    }
}

/// Points node references at their template forms.
fn template_refs(s: &mut Json) {
    match s {
        Json::Object(m) => {
            for (k, v) in m.iter_mut() {
                match v {
                    Json::String(r) if k == "$ref" && (r == NODE_REF || r == CONDITION_REF) => {
                        r.push_str("Template");
                    }
                    _ => template_refs(v),
                }
            }
        }
        Json::Array(items) => items.iter_mut().for_each(template_refs),
        _ => {}
    }
}

/// Wrap a value schema so that a `$param` reference is also accepted (inside subtree bodies).
pub(crate) fn templated(s: &Json) -> Json {
    let mut inner = s.clone();
    let mut out = serde_json::Map::new();
    // Keep documentation at the outer level so editors still show it.
    if let Some(obj) = inner.as_object_mut() {
        for k in ["description", "default"] {
            if let Some(v) = obj.remove(k) {
                out.insert(k.into(), v);
            }
        }
        if let Some(items) = obj.get("items").cloned() {
            obj.insert("items".into(), templated(&items));
        }
    }
    out.insert("anyOf".into(), json!([inner, {"$ref": "#/$defs/ParamRef"}]));
    Json::Object(out)
}
