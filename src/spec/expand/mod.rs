//! Spanned YAML values → typed [`Node`]s, expanding subtree calls with their arguments.
//!
//! Subtree bodies are kept as spanned [`Value`]s; a call substitutes `$param` scalars on a copy
//! of the body (each substituted value keeps the location of the argument, and remembers the
//! `$param` use it replaced) and then reads the copy as typed nodes. Errors therefore point at
//! the file:line:column of whatever is wrong, argument or body.
//!
//! The reader is split by what it reads: `leaf` (a leaf's parameters, every bad one reported,
//! and the objects it names), `control` (a composite's or decorator's typed parameters and its
//! nodes), `subtree` (a call: its arguments, substitution, expansion).

mod control;
mod leaf;
mod subtree;

use super::check::{ObjectUse, VarDef};
use super::confine::IncludeScope;
use super::file::{SubtreeDef, param_ref};
use super::node::{Node, NodeKind};
use crate::kinds::leaves::Leaf;
use crate::kinds::{Category, Registry};
use crate::yaml::diag::{Issue, Loc, Sources};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, ValueKind};
use std::collections::HashMap;

pub use leaf::MAX_LEAF_FILE_BYTES;
use leaf::{condition_param_help, parse_reporting_all};
pub(super) use subtree::undefined_params;

/// Deepest node nesting accepted after subtree expansion.
pub const MAX_TREE_DEPTH: usize = 64;
/// Most nodes accepted after subtree expansion.
pub const MAX_TREE_NODES: usize = 5_000;
/// Most errors reported for one leaf's parameters.
pub const MAX_LEAF_ERRORS: usize = 16;

/// Expands nodes; collects issues.
pub(crate) struct Expander<'a> {
    registry: &'a Registry,
    subtrees: &'a HashMap<String, SubtreeDef>,
    sources: &'a Sources,
    /// Problems found so far.
    pub issues: Vec<Issue>,
    /// Warnings found so far (accepted, but probably not what was meant).
    pub warnings: Vec<Issue>,
    stack: Vec<String>,
    nodes: usize,
    too_many_reported: bool,
    /// How many times each subtree was called.
    pub calls: HashMap<String, usize>,
    /// Where the loader already reported a problem (e.g. an undefined `$param`, left in place):
    /// a leaf's error at the same place is not repeated.
    pub reported: Vec<Loc>,
    /// Every object a leaf names or reads from the blackboard, located.
    pub object_uses: Vec<ObjectUse>,
    /// Every blackboard variable a `select` or `for_each` writes, located.
    pub var_defs: Vec<VarDef>,
    /// The folder the files a leaf names ([`crate::kinds::Params::FILE_PARAMS`]) are confined to.
    scope: IncludeScope,
    /// The canonical paths of the files leaves name (a `policy`'s model), in reading order.
    pub leaf_files: Vec<std::path::PathBuf>,
}

impl<'a> Expander<'a> {
    /// A new expander over the given subtree definitions, for the node kinds of `registry`.
    pub fn new(
        registry: &'a Registry,
        subtrees: &'a HashMap<String, SubtreeDef>,
        sources: &'a Sources,
    ) -> Self {
        Self {
            registry,
            subtrees,
            sources,
            issues: Vec::new(),
            warnings: Vec::new(),
            stack: Vec::new(),
            nodes: 0,
            too_many_reported: false,
            calls: HashMap::new(),
            reported: Vec::new(),
            object_uses: Vec::new(),
            var_defs: Vec::new(),
            scope: IncludeScope::default(),
            leaf_files: Vec::new(),
        }
    }

    /// Confines the files leaves name to `scope` (by default every such file is refused).
    pub fn with_scope(mut self, scope: IncludeScope) -> Self {
        self.scope = scope;
        self
    }

    fn err(&mut self, issue: Issue) {
        self.issues.push(issue);
    }

    /// Read one node (and its descendants). `None` when it is too broken to build; the
    /// problems are in [`Self::issues`].
    pub fn node(&mut self, v: &Value, depth: usize) -> Option<Node> {
        if depth > MAX_TREE_DEPTH {
            self.err(
                Issue::new(
                    v.loc,
                    format!("the tree is nested more than {MAX_TREE_DEPTH} levels deep"),
                )
                .help("flatten the tree or split it into subtrees"),
            );
            return None;
        }
        self.nodes += 1;
        if self.nodes > MAX_TREE_NODES {
            if !self.too_many_reported {
                self.too_many_reported = true;
                self.err(
                    Issue::new(
                        v.loc,
                        format!("the tree has more than {MAX_TREE_NODES} nodes after subtree expansion"),
                    )
                    .help("check for subtrees that call each other many times"),
                );
            }
            return None;
        }
        let (key, body) = match &v.kind {
            ValueKind::Map(entries) if entries.len() == 1 => (&entries[0].0, &entries[0].1),
            ValueKind::Map(entries) if entries.is_empty() => {
                self.err(
                    Issue::new(v.loc, "empty node `{}`")
                        .label("expected a node like `sequence: {children: [...]}` or `home: {}`"),
                );
                return None;
            }
            ValueKind::Map(entries) => {
                let keys: Vec<String> = entries
                    .iter()
                    .map(|(k, _)| format!("`{}`", k.as_str().unwrap_or("?")))
                    .collect();
                let has_name = entries.iter().any(|(k, _)| k.as_str() == Some("name"));
                let help = if has_name {
                    "put `name:` inside the node's mapping, e.g. `sequence: {name: pick, children: [...]}`"
                } else {
                    "a node is a mapping with exactly one key, its kind; start a new list item (`- `) for each node"
                };
                self.err(
                    Issue::new(
                        v.loc,
                        format!("a node must have exactly one kind, found {}", keys.join(", ")),
                    )
                    .label("expected one key such as `sequence:` or `reach:`")
                    .help(help),
                );
                return None;
            }
            ValueKind::Str(s) => {
                let mut issue =
                    Issue::new(v.loc, format!("a node must be a mapping, found {}", v.describe()))
                        .label("expected `kind: {parameters}`");
                if let Some(r) = param_ref(s) {
                    issue = issue.help(format!(
                        "`${r}` stands for a value, not a node; pass nodes as subtrees"
                    ));
                } else if self.registry.get(s).is_some() {
                    issue = issue.help(format!("write `{s}: {{}}`"));
                } else if let Some(h) = did_you_mean(s, self.registry.names()) {
                    issue = issue.help(h);
                }
                self.err(issue);
                return None;
            }
            _ => {
                self.err(
                    Issue::new(v.loc, format!("a node must be a mapping, found {}", v.describe()))
                        .label("expected `kind: {parameters}`, e.g. `home: {}`"),
                );
                return None;
            }
        };
        let Some(kind) = key.as_str() else {
            self.err(Issue::new(key.loc, "a node kind must be a name").label("expected e.g. `sequence`"));
            return None;
        };
        let kind = kind.to_string();
        // Node bodies: a mapping, or nothing (`home:` = `home: {}`).
        let empty;
        let body = match &body.kind {
            ValueKind::Map(_) => body,
            ValueKind::Null => {
                empty = Value::new(ValueKind::Map(vec![]), body.loc);
                &empty
            }
            _ => {
                let mut issue = Issue::new(
                    body.loc,
                    format!(
                        "the body of `{kind}` must be a mapping, found {}",
                        body.describe()
                    ),
                )
                .label("expected `{...}`");
                let composite = self
                    .registry
                    .get(&kind)
                    .is_some_and(|t| t.category() == Category::Composite);
                if composite && body.as_seq().is_some() {
                    issue = issue.help(format!("write `{kind}: {{children: [...]}}`"));
                } else {
                    issue = issue.help(format!(
                        "write `{kind}: {{}}` for defaults, or `{kind}: {{param: value}}`"
                    ));
                }
                self.err(issue);
                return None;
            }
        };
        let name = self.take_name(body);
        let loc = key.loc;
        let k = kind.as_str();
        let ty = self.registry.entry(k).cloned();
        let category = ty.as_ref().map(|t| t.category());
        let node_kind = if let Some(t) = ty.as_ref().filter(|t| t.control_kind().is_some()) {
            self.control(t, loc, body, depth)?
        } else if let (Some(parsed), warnings) = {
            let read = match &ty {
                Some(t) => self.resolve_files(t, without_name(body))?,
                None => without_name(body),
            };
            crate::yaml::de::collect_warnings(|| {
                ty.as_ref()
                    .and_then(|t| parse_reporting_all(read, |v| t.parse_leaf(v)))
            })
        } {
            for w in warnings {
                let mut issue = Issue::new(w.loc, format!("{} in `{k}`", w.message)).maybe_help(w.help);
                if let Some(via) = w.via {
                    issue = issue.note(format!(
                        "this value is a subtree argument, used at {}",
                        self.sources.describe(via)
                    ));
                }
                self.warnings.push(issue);
            }
            if let Some(t) = &ty {
                self.record_objects(t, body);
            }
            match parsed {
                Ok(leaf) => {
                    if let Some(Err(why)) = leaf.call().map(|c| c.validate()) {
                        // At the value of the parameter the error names, when the body writes it.
                        let at = why.field().and_then(|f| body.get(f));
                        let (at, label) = match at {
                            Some(v) => (v.loc, "this value"),
                            None => (loc, "the parameters do not fit together"),
                        };
                        self.err(
                            Issue::new(at, format!("invalid parameters in `{k}`: {why}"))
                                .label(label)
                                .help(format!("see `macrotree nodes {k}` for its parameters and units")),
                        );
                        return None;
                    }
                    if let Leaf::Select(s) = &leaf {
                        let at = |key: &str| body.get(key).map_or(body.loc, |v| v.loc);
                        self.var_defs.extend(VarDef::from_select(
                            s,
                            at("as"),
                            body.get("goal_as").map(|v| v.loc),
                        ));
                    }
                    NodeKind::Leaf(leaf)
                }
                Err(errors) => {
                    for e in errors {
                        let mut issue = e.into_issue(body.loc, |l| self.sources.describe(l));
                        if let Some(help) = (category == Some(Category::Condition))
                            .then(|| condition_param_help(k, &issue.message))
                            .flatten()
                        {
                            issue.help = Some(help);
                        }
                        self.param_error(k, issue);
                    }
                    return None;
                }
            }
        } else {
            let mut issue =
                Issue::new(key.loc, format!("unknown node kind `{k}`")).label("expected a node kind");
            if self.subtrees.contains_key(k) {
                issue = issue.help(format!(
                    "`{k}` is a subtree: call it with `subtree: {{ref: {k}}}`"
                ));
            } else if let Some(h) = did_you_mean(k, self.registry.names()) {
                issue = issue.help(h);
            } else {
                issue = issue
                    .help("see docs/tree_format.md (or `macrotree nodes`) for the node kinds")
                    .note(
                        "a node kind registered by your own program (docs/custom_nodes.md) is validated with that program (`your_program validate FILE`), not the stock `macrotree`",
                    );
            }
            self.err(issue);
            return None;
        };
        Some(Node {
            kind: node_kind,
            name,
            loc,
        })
    }

    fn take_name(&mut self, body: &Value) -> Option<String> {
        let v = body.get("name")?;
        match v.as_str() {
            Some(s) if valid_name(s) => Some(s.to_string()),
            Some(s) => {
                self.err(
                    Issue::new(v.loc, format!("invalid node name `{s}`"))
                        .label("expected 1–80 characters without `/`, `[`, `]`, `#`, `|` or line breaks")
                        .help(
                            "names appear in node paths like `main/sequence[pick]/reach`, and a dataset joins the paths of leaves running at once with ` | `; keep them simple",
                        ),
                );
                None
            }
            None => {
                self.err(
                    Issue::new(v.loc, format!("`name` must be text, found {}", v.describe()))
                        .label("expected a short label"),
                );
                None
            }
        }
    }

    /// Reports a parameter error of node kind `k` (unless its value was already reported: an
    /// undefined `$param` left in place needs no second error for its type).
    fn param_error(&mut self, k: &str, mut issue: Issue) {
        if self.reported.contains(&issue.loc) || self.issues.iter().any(|i| i.loc == issue.loc) {
            return;
        }
        issue.message = format!("{} in `{k}`", issue.message);
        if issue.help.is_none() {
            issue.help = Some(format!(
                "see `macrotree nodes {k}` (or docs/nodes/{k}.md) for its parameters and units"
            ));
        }
        self.err(issue);
    }
}

/// A node name: 1–80 characters, none of them a node path's separators (`/`, `[`, `]`, `#`), the
/// separator of several running leaves in a dataset's labels (`|`), or a line break.
fn valid_name(s: &str) -> bool {
    !s.trim().is_empty() && s.chars().count() <= 80 && !s.contains(['/', '[', ']', '#', '|', '\n', '\r'])
}

fn without_name(body: &Value) -> Value {
    match &body.kind {
        ValueKind::Map(m) => Value {
            kind: ValueKind::Map(
                m.iter()
                    .filter(|(k, _)| k.as_str() != Some("name"))
                    .cloned()
                    .collect(),
            ),
            loc: body.loc,
            via: body.via,
        },
        _ => body.clone(),
    }
}
