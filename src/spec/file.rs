//! The top level of a tree file: `include:`, `subtrees:` and `main:`.

use crate::yaml::de::list;
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::is_identifier;
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, ValueKind};

/// Keys allowed at the top level of a tree file (declared with their schema in `kinds`).
pub use crate::kinds::TREE_FILE_KEY_NAMES as TOP_LEVEL_KEYS;
/// Most `breakpoints:` entries of a tree file.
pub const MAX_BREAKPOINTS: usize = 64;
/// Most characters of one `breakpoints:` entry.
pub const MAX_BREAKPOINT_CHARS: usize = 512;
/// Keys allowed in a subtree definition (declared with their schema in `kinds`).
pub use crate::kinds::SUBTREE_KEY_NAMES as SUBTREE_KEYS;

/// `keys` as `` `a:`, `b:` and `c:` ``.
fn keys_colon(keys: &[&str]) -> String {
    let shown: Vec<String> = keys.iter().map(|k| format!("`{k}:`")).collect();
    match shown.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => shown.concat(),
    }
}

/// One `include:` entry.
#[derive(Clone, Debug)]
pub struct IncludeRef {
    /// The path as written (relative to the including file's folder).
    pub path: String,
    /// Where it is written.
    pub loc: Loc,
}

/// One parameter of a subtree.
#[derive(Clone, Debug)]
pub struct ParamDef {
    /// Name without the `$`.
    pub name: String,
    /// Default value; `None` when the parameter is required (written `~`).
    pub default: Option<Value>,
    /// Where the parameter name is written.
    pub loc: Loc,
}

/// A reusable subtree with parameters.
#[derive(Clone, Debug)]
pub struct SubtreeDef {
    /// The name used in `subtree: {ref: NAME}`.
    pub name: String,
    /// Where the name is written.
    pub loc: Loc,
    /// Optional one-line description.
    pub description: Option<String>,
    /// Parameters in written order.
    pub params: Vec<ParamDef>,
    /// The body, unsubstituted.
    pub root: Value,
}

/// A parsed tree file, before subtree expansion.
#[derive(Clone, Debug, Default)]
pub struct TreeFile {
    /// `include:` entries.
    pub includes: Vec<IncludeRef>,
    /// `subtrees:` definitions.
    pub subtrees: Vec<SubtreeDef>,
    /// `main:` (the root node), if present.
    pub main: Option<Value>,
    /// Where `main:` is written.
    pub main_key: Option<Loc>,
    /// `scene:`: the default scene file (relative to this file) and where it is written.
    pub scene: Option<(String, Loc)>,
    /// `description:`: what the tree does, one line (the task string of datasets and reports).
    pub description: Option<String>,
    /// `breakpoints:` entries (text and where each is written), for the live monitor.
    pub breakpoints: Vec<(String, Loc)>,
}

/// One `breakpoints:` entry of a tree file, as written: `PATTERN`, `PATTERN@before` or
/// `PATTERN@after` (the syntax of `run --view --break`), checked against the tree's nodes by
/// the command that serves the monitor.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeclaredBreakpoint {
    /// The entry as written.
    pub text: String,
    /// The file it is written in.
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
}

/// If `s` is a parameter reference `$name`, return `name`.
pub fn param_ref(s: &str) -> Option<&str> {
    s.strip_prefix('$').filter(|n| is_identifier(n))
}

/// Read the top level of a tree file. Problems are pushed to `issues`; what could be read is
/// returned (`None` when the file is not a mapping at all).
pub fn parse_tree_file(v: &Value, issues: &mut Vec<Issue>) -> Option<TreeFile> {
    let mut out = TreeFile::default();
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                v.loc,
                format!("a tree file must be a mapping, found {}", v.describe()),
            )
            .label("expected `main:` (and optionally `include:` and `subtrees:`)")
            .help("start the file with `main:` followed by the root node"),
        );
        return None;
    };
    for (k, val) in entries {
        match k.as_str() {
            Some("include") => parse_includes(val, &mut out.includes, issues),
            Some("subtrees") => parse_subtrees(val, &mut out.subtrees, issues),
            Some("main") => {
                out.main = Some(val.clone());
                out.main_key = Some(k.loc);
            }
            Some(key @ ("scene" | "description")) => match val.as_str() {
                Some(s) if key == "scene" => out.scene = Some((s.to_string(), val.loc)),
                Some(s) => out.description = Some(s.to_string()),
                None => issues.push(
                    Issue::new(val.loc, format!("`{key}` must be text, found {}", val.describe())).label(
                        if key == "scene" {
                            "expected a scene file path, relative to this file (e.g. `../scenes/sort_three.yaml`)"
                        } else {
                            "expected one line of text"
                        },
                    ),
                ),
            },
            Some("breakpoints") => parse_breakpoints(val, &mut out.breakpoints, issues),
            Some(other) => issues.push(
                Issue::new(k.loc, format!("unknown top-level key `{other}`"))
                    .label(format!("expected {}", list(&TOP_LEVEL_KEYS)))
                    .maybe_help(did_you_mean(other, TOP_LEVEL_KEYS.iter().copied()))
                    .help_or(format!("remove it; a tree file has only {}", keys_colon(&TOP_LEVEL_KEYS))),
            ),
            None => issues.push(
                Issue::new(
                    k.loc,
                    format!("top-level keys must be names, found {}", k.describe()),
                )
                .label(format!("expected {}", list(&TOP_LEVEL_KEYS))),
            ),
        }
    }
    Some(out)
}

/// `breakpoints: [PATTERN, PATTERN@after, …]`: text entries, at most [`MAX_BREAKPOINTS`] of
/// at most [`MAX_BREAKPOINT_CHARS`] characters each.
fn parse_breakpoints(v: &Value, out: &mut Vec<(String, Loc)>, issues: &mut Vec<Issue>) {
    let expected = "expected a list of node path globs, each optionally ending in `@before` or `@after`, e.g. `[\"main/**/grasp\", \"main/**/carry@after\"]`";
    let Some(items) = v.as_seq() else {
        issues.push(
            Issue::new(
                v.loc,
                format!("`breakpoints` must be a list, found {}", v.describe()),
            )
            .label(expected),
        );
        return;
    };
    if items.len() > MAX_BREAKPOINTS {
        issues.push(Issue::new(
            v.loc,
            format!("at most {MAX_BREAKPOINTS} breakpoints, found {}", items.len()),
        ));
        return;
    }
    for item in items {
        match item.as_str() {
            Some(s) if !s.is_empty() && s.chars().count() <= MAX_BREAKPOINT_CHARS => {
                out.push((s.to_string(), item.loc));
            }
            Some(_) => issues.push(Issue::new(
                item.loc,
                format!("a breakpoint is 1 to {MAX_BREAKPOINT_CHARS} characters"),
            )),
            None => issues.push(
                Issue::new(
                    item.loc,
                    format!("a breakpoint must be text, found {}", item.describe()),
                )
                .label(expected),
            ),
        }
    }
}

impl Issue {
    /// Set help text unless one is already set.
    #[must_use]
    pub fn help_or(mut self, help: impl Into<String>) -> Self {
        if self.help.is_none() {
            self.help = Some(help.into());
        }
        self
    }
}

fn parse_includes(v: &Value, out: &mut Vec<IncludeRef>, issues: &mut Vec<Issue>) {
    let items: Vec<&Value> = match &v.kind {
        ValueKind::Seq(s) => s.iter().collect(),
        ValueKind::Str(_) => vec![v],
        ValueKind::Null => vec![],
        _ => {
            issues.push(
                Issue::new(
                    v.loc,
                    format!("`include` must be a list of file paths, found {}", v.describe()),
                )
                .label("expected e.g. `[lib/pick_place.yaml]`"),
            );
            return;
        }
    };
    for item in items {
        match item.as_str() {
            Some(p) if !p.trim().is_empty() => out.push(IncludeRef {
                path: p.to_string(),
                loc: item.loc,
            }),
            _ => issues.push(
                Issue::new(
                    item.loc,
                    format!("an include must be a file path, found {}", item.describe()),
                )
                .label("expected a path relative to this file, e.g. `lib/pick_place.yaml`"),
            ),
        }
    }
}

fn parse_subtrees(v: &Value, out: &mut Vec<SubtreeDef>, issues: &mut Vec<Issue>) {
    let entries = match &v.kind {
        ValueKind::Map(m) => m,
        ValueKind::Null => return,
        _ => {
            issues.push(
                Issue::new(
                    v.loc,
                    format!(
                        "`subtrees` must be a mapping of names to subtrees, found {}",
                        v.describe()
                    ),
                )
                .label("expected `NAME: {params: {...}, root: <node>}`"),
            );
            return;
        }
    };
    for (k, def) in entries {
        let Some(name) = k.as_str().filter(|n| is_identifier(n)) else {
            issues.push(
                Issue::new(k.loc, format!("invalid subtree name {}", k.describe()))
                    .label("expected a name made of letters, digits and `_`"),
            );
            continue;
        };
        if let Some(d) = parse_subtree_def(name, k.loc, def, issues) {
            out.push(d);
        }
    }
}

fn parse_subtree_def(name: &str, loc: Loc, v: &Value, issues: &mut Vec<Issue>) -> Option<SubtreeDef> {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                v.loc,
                format!("subtree `{name}` must be a mapping, found {}", v.describe()),
            )
            .label("expected `{params: {...}, root: <node>}`"),
        );
        return None;
    };
    let mut def = SubtreeDef {
        name: name.to_string(),
        loc,
        description: None,
        params: Vec::new(),
        root: Value::new(ValueKind::Null, v.loc),
    };
    let mut has_root = false;
    for (k, val) in entries {
        match k.as_str() {
            Some("root") => {
                def.root = val.clone();
                has_root = true;
            }
            Some("description") => match val.as_str() {
                Some(s) => def.description = Some(s.to_string()),
                None => issues.push(
                    Issue::new(
                        val.loc,
                        format!("`description` must be text, found {}", val.describe()),
                    )
                    .label("expected a one-line description"),
                ),
            },
            Some("params") => {
                match &val.kind {
                    ValueKind::Null => {}
                    ValueKind::Map(ps) => {
                        for (pk, pv) in ps {
                            match pk.as_str().filter(|n| is_identifier(n)) {
                            Some(pname) => def.params.push(ParamDef {
                                name: pname.to_string(),
                                default: (pv.kind != ValueKind::Null).then(|| pv.clone()),
                                loc: pk.loc,
                            }),
                            None => issues.push(
                                Issue::new(pk.loc, format!("invalid parameter name {}", pk.describe()))
                                    .label("expected a name made of letters, digits and `_` (used as `$name`)")
                                    .help("write parameters without the `$`, e.g. `params: {approach: 0.15}`"),
                            ),
                        }
                        }
                    }
                    _ => issues.push(
                        Issue::new(
                            val.loc,
                            format!("`params` must be a mapping, found {}", val.describe()),
                        )
                        .label("expected `{name: default, other: ~}` (`~` = required)"),
                    ),
                }
            }
            Some(other) => issues.push(
                Issue::new(k.loc, format!("unknown key `{other}` in subtree `{name}`"))
                    .label(format!("expected {}", list(&SUBTREE_KEYS)))
                    .maybe_help(did_you_mean(other, SUBTREE_KEYS.iter().copied()))
                    .help_or(format!(
                        "a subtree has {}; only `root:` is required",
                        keys_colon(&SUBTREE_KEYS)
                    )),
            ),
            None => issues.push(
                Issue::new(k.loc, "keys must be names").label(format!("expected {}", list(&SUBTREE_KEYS))),
            ),
        }
    }
    if !has_root {
        issues.push(
            Issue::new(loc, format!("subtree `{name}` has no `root:`"))
                .label("expected `root: <node>`")
                .help("add `root:` with the subtree's top node, e.g. `root: {sequence: {children: [...]}}`"),
        );
        return None;
    }
    Some(def)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::{SUBTREE_KEYS, TOP_LEVEL_KEYS};
    use crate::kinds::Registry;

    fn keys(properties: &serde_json::Value) -> BTreeSet<&str> {
        properties
            .as_object()
            .map(|m| m.keys().map(String::as_str).collect())
            .unwrap_or_default()
    }

    #[test]
    fn the_tree_schema_declares_exactly_the_keys_the_reader_takes() {
        let schema = Registry::builtin().json_schema();
        assert_eq!(
            keys(&schema["properties"]),
            TOP_LEVEL_KEYS.iter().copied().collect()
        );
        let subtree = &schema["properties"]["subtrees"]["additionalProperties"]["properties"];
        assert_eq!(keys(subtree), SUBTREE_KEYS.iter().copied().collect());
    }

    #[test]
    fn the_reader_takes_every_declared_key_and_names_them_all_for_an_unknown_one() {
        let text = "description: d\nscene: s.yaml\ninclude: [lib.yaml]\nbreakpoints: [main]\n\
                    subtrees:\n  t:\n    description: d\n    params: {x: 1}\n    root: {wait: {seconds: $x}}\n\
                    main: {t: {}}\n";
        let v = crate::yaml::value::parse_yaml(text, 0).unwrap();
        let mut issues = Vec::new();
        assert!(super::parse_tree_file(&v, &mut issues).is_some());
        assert!(issues.is_empty(), "{issues:?}");
        let v = crate::yaml::value::parse_yaml("mian: {wait: {}}\nsubtrees: {t: {rot: {wait: {}}}}\n", 0)
            .unwrap();
        super::parse_tree_file(&v, &mut issues);
        let shown = format!("{issues:?}");
        for key in TOP_LEVEL_KEYS.iter().chain(&SUBTREE_KEYS) {
            assert!(shown.contains(&format!("`{key}`")), "{key}: {shown}");
        }
    }
}
