//! The node catalog (for `macrotree nodes`) and the JSON Schema of tree files, both generated
//! from the Rust spec types.

use schemars::JsonSchema;
use schemars::generate::{SchemaGenerator, SchemaSettings};
use serde::Serialize;
use serde_json::{Map, Value, json};

use super::leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, On, OnTable, Reach, Release, Select, Wait,
};
use crate::world::query::Query;

/// One parameter of a node kind.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamDoc {
    /// Parameter name as written in YAML.
    pub name: String,
    /// Short type, e.g. `number`, `[number; 3]`, `Target`, `node`, `list of nodes`.
    pub ty: String,
    /// Whether it must be given.
    pub required: bool,
    /// Default value as compact JSON, when optional.
    pub default: Option<String>,
    /// What it means, with its unit.
    pub doc: String,
}

/// Documentation of one node kind.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeDoc {
    /// The YAML kind (`sequence`, `reach`, …).
    pub kind: &'static str,
    /// `composite`, `decorator`, `action`, `condition` or `runtime` (handled by the runtime).
    pub category: &'static str,
    /// One-line description.
    pub summary: String,
    /// Further semantics (may be empty), one paragraph per line.
    pub details: String,
    /// What happens when the node is halted.
    pub halt: &'static str,
    /// Parameters (`name` is accepted by every node and not listed).
    pub params: Vec<ParamDoc>,
    /// A YAML example.
    pub example: &'static str,
}

/// The documentation of every node kind, one Markdown file each under `docs/nodes/`: the same
/// text is the rustdoc of the node's variant or parameter struct (`#[doc = include_str!(…)]`).
/// Each file is a one-line summary paragraph, optional details, a `Halt: …` paragraph and a
/// ```` ```yaml ```` example; [`parse_node_doc`] reads them.
macro_rules! node_doc {
    ($kind:literal, $category:literal) => {
        (
            $kind,
            $category,
            include_str!(concat!("../../docs/nodes/", $kind, ".md")),
        )
    };
}

const NODE_DOCS: &[(&str, &str, &str)] = &[
    node_doc!("sequence", "composite"),
    node_doc!("fallback", "composite"),
    node_doc!("reactive_sequence", "composite"),
    node_doc!("reactive_fallback", "composite"),
    node_doc!("parallel", "composite"),
    node_doc!("race", "composite"),
    node_doc!("guard", "decorator"),
    node_doc!("retry", "decorator"),
    node_doc!("repeat", "decorator"),
    node_doc!("for_each", "decorator"),
    node_doc!("timeout", "decorator"),
    node_doc!("inverter", "decorator"),
    node_doc!("force_success", "decorator"),
    node_doc!("force_failure", "decorator"),
    node_doc!("subtree", "decorator"),
    node_doc!("reach", "action"),
    node_doc!("move_joints", "action"),
    node_doc!("home", "action"),
    node_doc!("grasp", "action"),
    node_doc!("carry", "action"),
    node_doc!("release", "action"),
    node_doc!("wait", "runtime"),
    node_doc!("select", "runtime"),
    node_doc!("grasped", "condition"),
    node_doc!("lifted", "condition"),
    node_doc!("in", "condition"),
    node_doc!("on", "condition"),
    node_doc!("on_table", "condition"),
    node_doc!("at", "condition"),
    node_doc!("goal_met", "condition"),
    node_doc!("cube_grasped", "condition"),
    node_doc!("cube_lifted", "condition"),
    node_doc!("cube_in_bowl", "condition"),
    node_doc!("cube_on_table", "condition"),
    node_doc!("cube_at", "condition"),
    node_doc!("gripper_open", "condition"),
    node_doc!("at_home", "condition"),
];

/// The parts of a node's documentation file: (summary, details, halt, example).
///
/// The summary is the first paragraph, the halt text follows `Halt: ` (without the final
/// period), the example is the body of the first ```` ```yaml ```` block, and the details are
/// the paragraphs in between. Missing parts are empty strings (a test requires all of them).
pub fn parse_node_doc(text: &'static str) -> (String, String, &'static str, &'static str) {
    let (prose, example) = match text.split_once("```yaml\n") {
        Some((prose, rest)) => (prose, rest.split("```").next().unwrap_or("").trim_end()),
        None => (text, ""),
    };
    let paragraphs: Vec<&str> = prose
        .split("\n\n")
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .collect();
    let one_line = |p: &str| p.split_whitespace().collect::<Vec<_>>().join(" ");
    let summary = paragraphs.first().map(|p| one_line(p)).unwrap_or_default();
    let mut halt = "";
    let mut details = vec![];
    for p in paragraphs.iter().skip(1) {
        match p.strip_prefix("Halt: ") {
            Some(h) => halt = h.trim_end_matches('.'),
            None => details.push(one_line(p)),
        }
    }
    (summary, details.join("\n"), halt, example)
}

fn p(name: &str, ty: &str, required: bool, default: Option<&str>, doc: &str) -> ParamDoc {
    ParamDoc {
        name: name.into(),
        ty: ty.into(),
        required,
        default: default.map(str::to_string),
        doc: doc.into(),
    }
}

fn generator() -> SchemaGenerator {
    SchemaSettings::draft2020_12().for_deserialize().into_generator()
}

/// Leaf parameter struct schemas by kind: (kind, definition name).
fn leaf_schemas(g: &mut SchemaGenerator) -> Vec<(&'static str, String)> {
    fn one<T: JsonSchema>(g: &mut SchemaGenerator, kind: &'static str) -> (&'static str, String) {
        let _ = g.subschema_for::<T>();
        (kind, T::schema_name().into_owned())
    }
    vec![
        one::<Reach>(g, "reach"),
        one::<MoveJoints>(g, "move_joints"),
        one::<Home>(g, "home"),
        one::<Grasp>(g, "grasp"),
        one::<Carry>(g, "carry"),
        one::<Release>(g, "release"),
        one::<Wait>(g, "wait"),
        one::<Select>(g, "select"),
        one::<Grasped>(g, "grasped"),
        one::<Lifted>(g, "lifted"),
        one::<In>(g, "in"),
        one::<On>(g, "on"),
        one::<OnTable>(g, "on_table"),
        one::<At>(g, "at"),
        one::<GoalMet>(g, "goal_met"),
        one::<CubeGrasped>(g, "cube_grasped"),
        one::<CubeLifted>(g, "cube_lifted"),
        one::<CubeInBowl>(g, "cube_in_bowl"),
        one::<CubeOnTable>(g, "cube_on_table"),
        one::<CubeAt>(g, "cube_at"),
        one::<GripperOpen>(g, "gripper_open"),
        one::<AtHome>(g, "at_home"),
    ]
}

fn short_type(s: &Value) -> String {
    if let Some(r) = s.get("$ref").and_then(Value::as_str) {
        return r.rsplit('/').next().unwrap_or(r).to_string();
    }
    match s.get("type") {
        Some(Value::String(t)) if t == "array" => {
            let item = s.get("items").map_or("any".into(), short_type);
            match s.get("minItems").and_then(Value::as_u64) {
                Some(n) if s.get("maxItems").and_then(Value::as_u64) == Some(n) => {
                    format!("[{item}; {n}]")
                }
                _ => format!("list of {item}"),
            }
        }
        Some(Value::String(t)) => t.clone(),
        Some(Value::Array(ts)) => ts
            .iter()
            .filter_map(Value::as_str)
            .filter(|t| *t != "null")
            .collect::<Vec<_>>()
            .join(" | "),
        _ => "value".into(),
    }
}

fn params_from_schema(def: &Value) -> Vec<ParamDoc> {
    let required: Vec<&str> = def
        .get("required")
        .and_then(Value::as_array)
        .map(|r| r.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let Some(props) = def.get("properties").and_then(Value::as_object) else {
        return vec![];
    };
    // Required parameters first, then alphabetical (the schema's property order).
    let mut out: Vec<ParamDoc> = props
        .iter()
        .map(|(name, s)| ParamDoc {
            name: name.clone(),
            ty: short_type(s),
            required: required.contains(&name.as_str()),
            default: s.get("default").map(|d| d.to_string()),
            doc: s
                .get("description")
                .and_then(Value::as_str)
                .unwrap_or("")
                .replace('\n', " "),
        })
        .collect();
    out.sort_by_key(|p| !p.required);
    out
}

/// Every node kind with its parameters (units, defaults), one-line description, halt behaviour
/// and a YAML example; generated from the Rust types (for `macrotree nodes`).
pub fn catalog() -> Vec<NodeDoc> {
    let mut g = generator();
    let leaves = leaf_schemas(&mut g);
    let defs = g.take_definitions(true);
    NODE_DOCS
        .iter()
        .map(|&(kind, category, text)| {
            let params = match kind {
                "sequence" | "fallback" | "reactive_sequence" | "reactive_fallback" | "parallel" | "race" => {
                    vec![p(
                        "children",
                        "list of nodes",
                        true,
                        None,
                        "the children, at least one",
                    )]
                }
                "guard" => vec![
                    p(
                        "condition",
                        "condition node",
                        true,
                        None,
                        "a condition leaf (or an `inverter` of one), checked every tick",
                    ),
                    p("child", "node", true, None, "the guarded node"),
                ],
                "retry" => vec![
                    p("attempts", "integer", true, None, "total runs allowed, 1 to 1000"),
                    p("child", "node", true, None, "the node to retry"),
                ],
                "repeat" => vec![
                    p(
                        "times",
                        "integer",
                        true,
                        None,
                        "successful runs required, 1 to 1000",
                    ),
                    p("child", "node", true, None, "the node to repeat"),
                ],
                "for_each" => vec![
                    p("as", "string", true, None, "the variable each selected object is written to; read it as `{name}`"),
                    p("max_iterations", "integer", true, None, "most iterations, 1 to 1000"),
                    p("child", "node", true, None, "the node run once per selected object"),
                    p(
                        "select",
                        "Query",
                        false,
                        Some("{}"),
                        "the query: `kind` (block), `color`, `where` (pending, done, on_table, free), `order` (nearest, name, scene)",
                    ),
                    p("goal_as", "string", false, None, "also write where the object's goal sends it"),
                ],
                "timeout" => vec![
                    p("seconds", "number", true, None, "simulated seconds (> 0)"),
                    p("child", "node", true, None, "the node to time-limit"),
                ],
                "inverter" | "force_success" | "force_failure" => {
                    vec![p("child", "node", true, None, "the decorated node")]
                }
                "subtree" => vec![
                    p(
                        "ref",
                        "string",
                        true,
                        None,
                        "name of a subtree under `subtrees:` (here or in an included file)",
                    ),
                    p(
                        "args",
                        "mapping",
                        false,
                        Some("{}"),
                        "argument values by parameter name; omitted ones take their defaults",
                    ),
                ],
                kind => leaves
                    .iter()
                    .find(|(k, _)| *k == kind)
                    .and_then(|(_, name)| defs.get(name))
                    .map(params_from_schema)
                    .unwrap_or_default(),
            };
            let (summary, details, halt, example) = parse_node_doc(text);
            NodeDoc {
                kind,
                category,
                summary,
                details,
                halt,
                params,
                example,
            }
        })
        .collect()
}

/// Wrap a value schema so that a `$param` reference is also accepted (inside subtree bodies).
fn templated(s: &Value) -> Value {
    let mut inner = s.clone();
    let mut out = Map::new();
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
    Value::Object(out)
}

/// The JSON Schema (draft 2020-12) of a tree file, generated from the Rust spec types.
///
/// Committed as `schema/tree.schema.json` (editors use it through a
/// `# yaml-language-server: $schema=…` first line). Regenerate with
/// `UPDATE_SCHEMA=1 cargo test --test tree_schema`. Inside `subtrees:` bodies every parameter
/// value may also be a `$param` reference.
pub fn json_schema() -> Value {
    let mut g = generator();
    let leaves = leaf_schemas(&mut g);
    let _ = g.subschema_for::<Query>();
    let mut defs = g.take_definitions(true);

    defs.insert(
        "NodeName".into(),
        json!({"type": "string", "minLength": 1, "maxLength": 80, "pattern": "^[^/\\[\\]#\\n\\r]+$",
               "description": "Optional label used in node paths, logs and diagrams."}),
    );
    defs.insert(
        "ParamRef".into(),
        json!({"type": "string", "pattern": "^\\$[A-Za-z_][A-Za-z0-9_]*$",
               "description": "A subtree parameter, `$name`, replaced by the call's argument or the default."}),
    );

    for template in [false, true] {
        let suffix = if template { "Template" } else { "" };
        let node_ref = json!({"$ref": format!("#/$defs/Node{suffix}")});
        let cond_ref = json!({"$ref": format!("#/$defs/Condition{suffix}")});
        let scalar = |s: Value| if template { templated(&s) } else { s };
        let mut variants = Vec::new();
        let mut cond_variants = Vec::new();
        let body = |props: Value, required: &[&str]| {
            let mut props = props;
            props["name"] = json!({"$ref": "#/$defs/NodeName"});
            json!({"type": "object", "properties": props, "required": required, "additionalProperties": false})
        };
        for &(kind, category, text) in NODE_DOCS {
            let (summary, details, halt, example) = parse_node_doc(text);
            let b = match kind {
                "sequence" | "fallback" | "reactive_sequence" | "reactive_fallback" | "parallel" | "race" => {
                    body(
                        json!({"children": {"type": "array", "items": node_ref, "minItems": 1}}),
                        &["children"],
                    )
                }
                "guard" => body(
                    json!({"condition": cond_ref, "child": node_ref}),
                    &["condition", "child"],
                ),
                "retry" => body(
                    json!({"attempts": scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})), "child": node_ref}),
                    &["attempts", "child"],
                ),
                "repeat" => body(
                    json!({"times": scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})), "child": node_ref}),
                    &["times", "child"],
                ),
                "timeout" => body(
                    json!({"seconds": scalar(json!({"type": "number", "exclusiveMinimum": 0})), "child": node_ref}),
                    &["seconds", "child"],
                ),
                "for_each" => body(
                    json!({"select": {"$ref": "#/$defs/Query"},
                           "as": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                           "goal_as": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                           "max_iterations": scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})),
                           "child": node_ref}),
                    &["as", "max_iterations", "child"],
                ),
                "inverter" | "force_success" | "force_failure" => {
                    body(json!({"child": node_ref}), &["child"])
                }
                "subtree" => body(
                    json!({"ref": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                           "args": {"type": "object", "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"}}}),
                    &["ref"],
                ),
                kind => {
                    let def_name = leaves
                        .iter()
                        .find(|(k, _)| *k == kind)
                        .map(|(_, n)| n.clone())
                        .unwrap_or_default();
                    let def = defs.get(&def_name).cloned().unwrap_or(json!({}));
                    let mut props = def.get("properties").cloned().unwrap_or(json!({}));
                    if let Some(obj) = props.as_object_mut() {
                        for v in obj.values_mut() {
                            *v = scalar(v.clone());
                        }
                    }
                    let required: Vec<&str> = def
                        .get("required")
                        .and_then(Value::as_array)
                        .map(|r| r.iter().filter_map(Value::as_str).collect())
                        .unwrap_or_default();
                    let b = body(props, &required);
                    if required.is_empty() {
                        json!({"anyOf": [b, {"type": "null"}]})
                    } else {
                        b
                    }
                }
            };
            let description = [summary, details.replace('\n', " "), format!("Halt: {halt}.")]
                .into_iter()
                .filter(|part| !part.is_empty())
                .chain([format!("Example: `{example}`")])
                .collect::<Vec<_>>()
                .join(" ");
            let variant = json!({
                "type": "object",
                "description": description,
                "properties": {kind: b},
                "required": [kind],
                "additionalProperties": false,
            });
            if category == "condition" {
                cond_variants.push(variant.clone());
            }
            variants.push(variant);
        }
        // A check is a condition leaf or an inverter of one.
        let inv = json!({
            "type": "object",
            "properties": {"inverter": {"type": "object", "properties": {"child": cond_ref, "name": {"$ref": "#/$defs/NodeName"}},
                                         "required": ["child"], "additionalProperties": false}},
            "required": ["inverter"], "additionalProperties": false
        });
        cond_variants.push(inv);
        defs.insert(
            format!("Node{suffix}"),
            json!({"description": "A behavior-tree node: a mapping with exactly one key, its kind.", "oneOf": variants}),
        );
        defs.insert(
            format!("Condition{suffix}"),
            json!({"description": "A condition leaf, or an `inverter` of one.", "oneOf": cond_variants}),
        );
    }
    // Leaf parameter structs are inlined into the node variants; drop their standalone copies.
    for (_, name) in &leaves {
        defs.remove(name);
    }

    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://macrotree.invalid/schema/tree.schema.json",
        "title": "macrotree behavior tree file",
        "description": "A behavior tree in YAML for the UR5e + Robotiq gripper. See docs/tree_format.md. Units: m, s, m/s, rad (or deg(..)).",
        "type": "object",
        "properties": {
            "description": {"description": "What the tree does, one line (the task string of reports and datasets).",
                            "type": "string"},
            "scene": {"description": "The scene file the tree runs on by default, relative to this file (`--scene` overrides it). Without it: the built-in cube_bowl scene.",
                      "type": "string"},
            "include": {"description": "Files with subtrees to load, relative to this file.",
                        "anyOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}}]},
            "subtrees": {
                "description": "Reusable subtrees by name.",
                "type": "object",
                "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                "additionalProperties": {
                    "type": "object",
                    "properties": {
                        "description": {"type": "string"},
                        "params": {"description": "Parameter names with default values (`~` = required).",
                                   "type": "object", "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"}},
                        "root": {"$ref": "#/$defs/NodeTemplate"}
                    },
                    "required": ["root"],
                    "additionalProperties": false
                }
            },
            "main": {"$ref": "#/$defs/Node"}
        },
        "additionalProperties": false,
        "$defs": Value::Object(defs),
    })
}
