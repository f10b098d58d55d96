//! The keys of a tree file's top level and of a subtree definition, each declared once with its
//! JSON Schema: the tree reader (`spec::file`) takes exactly these keys, and the tree schema
//! ([`Registry::json_schema`](super::Registry::json_schema)) lists exactly these.

use serde_json::{Value, json};

/// One key of a tree file's top level or of a subtree definition.
pub struct FileKey {
    /// The key as written.
    pub name: &'static str,
    /// Its JSON Schema (nodes refer to the schema's `$defs`).
    pub schema: fn() -> Value,
}

/// The keys of a tree file's top level, in the order the docs list them.
pub const TREE_FILE_KEYS: &[FileKey] = &[
    FileKey {
        name: "description",
        schema: || {
            json!({"description": "What the tree does, one line (the task string of reports and datasets).",
                   "type": "string"})
        },
    },
    FileKey {
        name: "scene",
        schema: || {
            json!({"description": "The scene file the tree runs on by default, relative to this file (`--scene` overrides it). Without it: the built-in cube_bowl scene.",
                   "type": "string"})
        },
    },
    FileKey {
        name: "include",
        schema: || {
            json!({"description": "Files with subtrees to load, relative to this file.",
                   "anyOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}}]})
        },
    },
    FileKey {
        name: "subtrees",
        schema: || {
            json!({
                "description": "Reusable subtrees by name.",
                "type": "object",
                "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"},
                "additionalProperties": {
                    "type": "object",
                    "properties": properties(SUBTREE_KEYS),
                    "required": ["root"],
                    "additionalProperties": false
                }
            })
        },
    },
    FileKey {
        name: "main",
        schema: || json!({"$ref": "#/$defs/Node"}),
    },
    FileKey {
        name: "breakpoints",
        schema: || {
            json!({"description": "Where a live monitor (`run --view`) pauses, as `--break` does: node path globs, each optionally ending in `@before` (the default) or `@after`.",
                   "type": "array",
                   "items": {"type": "string", "minLength": 1}})
        },
    },
];

/// The keys of a subtree definition (an entry of `subtrees:`).
pub const SUBTREE_KEYS: &[FileKey] = &[
    FileKey {
        name: "params",
        schema: || {
            json!({"description": "Parameter names with default values (`~` = required).",
                   "type": "object", "propertyNames": {"pattern": "^[A-Za-z_][A-Za-z0-9_]*$"}})
        },
    },
    FileKey {
        name: "root",
        schema: || json!({"$ref": "#/$defs/NodeTemplate"}),
    },
    FileKey {
        name: "description",
        schema: || json!({"type": "string"}),
    },
];

/// The names of `keys`, in order (`N` must be `keys.len()`).
pub const fn key_names<const N: usize>(keys: &[FileKey]) -> [&'static str; N] {
    let mut out = [""; N];
    let mut i = 0;
    while i < N {
        out[i] = keys[i].name;
        i += 1;
    }
    out
}

/// The names of the keys of a tree file's top level.
pub const TREE_FILE_KEY_NAMES: [&str; TREE_FILE_KEYS.len()] = key_names(TREE_FILE_KEYS);

/// The names of the keys of a subtree definition.
pub const SUBTREE_KEY_NAMES: [&str; SUBTREE_KEYS.len()] = key_names(SUBTREE_KEYS);

/// The schema's `properties` of `keys`.
pub fn properties(keys: &[FileKey]) -> Value {
    Value::Object(keys.iter().map(|k| (k.name.to_string(), (k.schema)())).collect())
}

#[cfg(test)]
mod tests {
    use super::{SUBTREE_KEY_NAMES, SUBTREE_KEYS, TREE_FILE_KEY_NAMES, TREE_FILE_KEYS};

    #[test]
    fn the_key_names_are_the_declared_keys_in_order() {
        let names = |keys: &[super::FileKey]| keys.iter().map(|k| k.name).collect::<Vec<_>>();
        assert_eq!(TREE_FILE_KEY_NAMES.to_vec(), names(TREE_FILE_KEYS));
        assert_eq!(SUBTREE_KEY_NAMES.to_vec(), names(SUBTREE_KEYS));
    }
}
