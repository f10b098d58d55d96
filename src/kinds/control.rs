//! The composites and decorators: their parameters (for `macrotree nodes`) and the schema of
//! their bodies. The tree reader (`spec::expand`) builds them; they are registered here like
//! every other kind so that the catalog, the schema and the suggestions know them.

use serde_json::{Value, json};

use crate::kinds::catalog::ParamDoc;

/// What the schema of a control node's body refers to.
pub(crate) struct SchemaCtx {
    /// `{"$ref": "#/$defs/Node"}` (or `NodeTemplate` inside subtree bodies).
    pub node_ref: Value,
    /// `{"$ref": "#/$defs/Condition"}` (or `ConditionTemplate`).
    pub cond_ref: Value,
    /// Inside subtree bodies: scalar values may also be `$param` references.
    pub template: bool,
}

impl SchemaCtx {
    /// A scalar value's schema, which may also be a `$param` inside subtree bodies.
    pub fn scalar(&self, s: Value) -> Value {
        if self.template { templated(&s) } else { s }
    }

    /// The body of a node: `props` plus `name`, `required`, nothing else.
    pub fn body(&self, props: Value, required: &[&str]) -> Value {
        let mut props = props;
        props["name"] = json!({"$ref": "#/$defs/NodeName"});
        json!({"type": "object", "properties": props, "required": required, "additionalProperties": false})
    }
}

/// Wrap a value schema so that a `$param` reference is also accepted (inside subtree bodies).
pub(crate) fn templated(s: &Value) -> Value {
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
    Value::Object(out)
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

pub(super) fn composite_params() -> Vec<ParamDoc> {
    vec![p(
        "children",
        "list of nodes",
        true,
        None,
        "the children, at least one",
    )]
}

pub(super) fn composite_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"children": {"type": "array", "items": c.node_ref, "minItems": 1}}),
        &["children"],
    )
}

pub(super) fn guard_params() -> Vec<ParamDoc> {
    vec![
        p(
            "condition",
            "condition node",
            true,
            None,
            "a condition leaf (or an `inverter` of one), checked every tick",
        ),
        p("child", "node", true, None, "the guarded node"),
    ]
}

pub(super) fn guard_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"condition": c.cond_ref, "child": c.node_ref}),
        &["condition", "child"],
    )
}

pub(super) fn retry_params() -> Vec<ParamDoc> {
    vec![
        p("attempts", "integer", true, None, "total runs allowed, 1 to 1000"),
        p("child", "node", true, None, "the node to retry"),
    ]
}

pub(super) fn retry_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"attempts": c.scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})), "child": c.node_ref}),
        &["attempts", "child"],
    )
}

pub(super) fn repeat_params() -> Vec<ParamDoc> {
    vec![
        p(
            "times",
            "integer",
            true,
            None,
            "successful runs required, 1 to 1000",
        ),
        p("child", "node", true, None, "the node to repeat"),
    ]
}

pub(super) fn repeat_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"times": c.scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})), "child": c.node_ref}),
        &["times", "child"],
    )
}

pub(super) fn for_each_params() -> Vec<ParamDoc> {
    vec![
        p(
            "as",
            "string",
            true,
            None,
            "the variable each selected object is written to; read it as `{name}`",
        ),
        p(
            "max_iterations",
            "integer",
            true,
            None,
            "most iterations, 1 to 1000",
        ),
        p(
            "child",
            "node",
            true,
            None,
            "the node run once per selected object",
        ),
        p(
            "select",
            "Query",
            false,
            Some("{}"),
            "the query: `kind` (block), `color`, `where` (pending, done, on_table, free), `order` (nearest, name, scene)",
        ),
        p(
            "goal_as",
            "string",
            false,
            None,
            "also write where the object's goal sends it",
        ),
    ]
}

pub(super) fn for_each_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"select": {"$ref": "#/$defs/Query"},
               "as": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
               "goal_as": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
               "max_iterations": c.scalar(json!({"type": "integer", "minimum": 1, "maximum": 1000})),
               "child": c.node_ref}),
        &["as", "max_iterations", "child"],
    )
}

pub(super) fn timeout_params() -> Vec<ParamDoc> {
    vec![
        p("seconds", "number", true, None, "simulated seconds (> 0)"),
        p("child", "node", true, None, "the node to time-limit"),
    ]
}

pub(super) fn timeout_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"seconds": c.scalar(json!({"type": "number", "exclusiveMinimum": 0})), "child": c.node_ref}),
        &["seconds", "child"],
    )
}

pub(super) fn child_params() -> Vec<ParamDoc> {
    vec![p("child", "node", true, None, "the decorated node")]
}

pub(super) fn child_schema(c: &SchemaCtx) -> Value {
    c.body(json!({"child": c.node_ref}), &["child"])
}

pub(super) fn subtree_params() -> Vec<ParamDoc> {
    vec![
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
    ]
}

pub(super) fn subtree_schema(c: &SchemaCtx) -> Value {
    c.body(
        json!({"ref": {"type": "string", "pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
               "args": {"type": "object", "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"}}}),
        &["ref"],
    )
}
