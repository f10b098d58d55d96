//! The node catalog (for `macrotree nodes`) and the JSON Schema of tree files, both generated
//! from the Rust spec types.

use schemars::generate::{SchemaGenerator, SchemaSettings};
use serde::Serialize;
use serde_json::{Value, json};

use super::control::body_schema;
use super::{Category, Registry};
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

fn generator() -> SchemaGenerator {
    SchemaSettings::draft2020_12().for_deserialize().into_generator()
}

fn short_type(s: &Value) -> String {
    if let Some(r) = s.get("$ref").and_then(Value::as_str) {
        return match r.rsplit('/').next().unwrap_or(r) {
            "Node" => "node".into(),
            "Condition" => "condition node".into(),
            name => name.to_string(),
        };
    }
    match s.get("type") {
        Some(Value::String(t)) if t == "array" => {
            let item = s.get("items").map_or("any".into(), short_type);
            match s.get("minItems").and_then(Value::as_u64) {
                Some(n) if s.get("maxItems").and_then(Value::as_u64) == Some(n) => {
                    format!("[{item}; {n}]")
                }
                _ if item == "node" => "list of nodes".into(),
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

/// A default as users write it: an angle (a parameter of type `Angle`) as `deg(10)`, not its
/// radians; anything else as JSON.
fn show_default(param: &Value, default: &Value) -> String {
    match default.as_f64() {
        Some(rad) if short_type(param) == "Angle" => {
            let deg = rad.to_degrees();
            // Up to 6 decimals, trailing zeros dropped: 0.17453292519943295 rad is `deg(10)`.
            let text = format!("{:.6}", deg);
            let text = text.trim_end_matches('0').trim_end_matches('.');
            format!("deg({})", if text == "-0" { "0" } else { text })
        }
        _ => default.to_string(),
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
            default: s.get("default").map(|d| show_default(s, d)),
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

impl Registry {
    /// Every node kind with its parameters (units, defaults), one-line description, halt
    /// behaviour and a YAML example, generated from the Rust types and the kinds' docs.
    pub fn catalog(&self) -> Vec<NodeDoc> {
        let mut g = generator();
        let bodies: Vec<String> = self.types().map(|t| t.params_schema(&mut g)).collect();
        let defs = g.take_definitions(true);
        self.types()
            .zip(bodies)
            .map(|(t, body)| {
                let params = defs.get(&body).map(params_from_schema).unwrap_or_default();
                let (summary, details, halt, example) = parse_node_doc(t.doc());
                NodeDoc {
                    kind: t.name(),
                    category: t.category().as_str(),
                    summary,
                    details,
                    halt,
                    params,
                    example,
                }
            })
            .collect()
    }
}

impl Registry {
    /// The JSON Schema (draft 2020-12) of a tree file using this registry's node kinds (what
    /// `macrotree schema` prints; `schema/tree.schema.json` for the built-in kinds).
    pub fn json_schema(&self) -> Value {
        let mut g = generator();
        let bodies: Vec<String> = self.types().map(|t| t.params_schema(&mut g)).collect();
        let _ = g.subschema_for::<Query>();
        let mut defs = g.take_definitions(true);

        defs.insert(
            "NodeName".into(),
            json!({"type": "string", "minLength": 1, "maxLength": 80, "pattern": "^[^/\\[\\]#|\\n\\r]+$",
               "description": "Optional label used in node paths, logs and diagrams."}),
        );
        defs.insert(
        "ParamRef".into(),
        json!({"type": "string", "pattern": "^\\$[A-Za-z_][A-Za-z0-9_]*$",
               "description": "A subtree parameter, `$name`, replaced by the call's argument or the default."}),
    );

        for template in [false, true] {
            let suffix = if template { "Template" } else { "" };
            let cond_ref = json!({"$ref": format!("#/$defs/Condition{suffix}")});
            let mut variants = Vec::new();
            let mut cond_variants = Vec::new();
            for (t, def_name) in self.types().zip(&bodies) {
                let kind = t.name();
                let (summary, details, halt, example) = parse_node_doc(t.doc());
                let def = defs.get(def_name).cloned().unwrap_or(json!({}));
                let (mut props, required) = body_schema(&def, template);
                props["name"] = json!({"$ref": "#/$defs/NodeName"});
                let b = json!({"type": "object", "properties": props, "required": required, "additionalProperties": false});
                let b = if required.is_empty() {
                    json!({"anyOf": [b, {"type": "null"}]})
                } else {
                    b
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
                if t.category() == Category::Condition {
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
        // Parameter structs are inlined into the node variants; drop their standalone copies,
        // unless another definition still refers to one (a `policy`'s `until:` is a condition's
        // parameters).
        let referenced = serde_json::to_string(&defs).unwrap_or_default();
        for name in &bodies {
            if !referenced.contains(&format!("\"#/$defs/{name}\"")) {
                defs.remove(name);
            }
        }

        json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": "https://macrotree.invalid/schema/tree.schema.json",
            "title": "macrotree behavior tree file",
            "description": "A behavior tree in YAML for the UR5e + Robotiq gripper. See docs/tree_format.md. Units: m, s, m/s, rad (or deg(..)).",
            "type": "object",
            "properties": super::tree_file::properties(super::tree_file::TREE_FILE_KEYS),
            "additionalProperties": false,
            "$defs": Value::Object(defs),
        })
    }
}
