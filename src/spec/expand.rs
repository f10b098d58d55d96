//! Spanned YAML values → typed [`Node`]s, expanding subtree calls with their arguments.
//!
//! Subtree bodies are kept as spanned [`Value`]s; a call substitutes `$param` scalars on a copy
//! of the body (each substituted value keeps the location of the argument, and remembers the
//! `$param` use it replaced) and then reads the copy as typed nodes. Errors therefore point at
//! the file:line:column of whatever is wrong, argument or body.

use std::collections::HashMap;

use super::check::{ObjectUse, VarDef};
use super::file::{SubtreeDef, param_ref};
use super::node::{Node, NodeKind};
use crate::kinds::ObjectRole;
use crate::kinds::control::{Control, ControlKind, NodeList, NodeValue, SubtreeParams};
use crate::kinds::leaves::Leaf;
use crate::kinds::{Category, NodeType, Registry};
use crate::yaml::de::DeError;
use crate::yaml::diag::{Issue, Loc, Sources};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, ValueKind};

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
        }
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
        } else if let (Some(parsed), warnings) = crate::yaml::de::collect_warnings(|| {
            ty.as_ref()
                .and_then(|t| parse_reporting_all(without_name(body), |v| t.parse_leaf(v)))
        }) {
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

    /// Notes where leaf `kind` names objects or variables (for the scene and blackboard checks),
    /// even when the leaf has other errors, so that every mistake is reported at once.
    /// The parameters that name objects are the ones the kind declares
    /// ([`crate::kinds::Params::OBJECT_PARAMS`]).
    fn record_objects(&mut self, ty: &NodeType, body: &Value) {
        let kind = ty.name();
        for &(key, role) in ty.object_params() {
            let Some(v) = body.get(key) else { continue };
            let reference = match &v.kind {
                // `cube` and `bowl` are legacy names only where a `Target` is read (any object):
                // an `ObjectRef` parameter resolves them as plain names when the tree runs.
                ValueKind::Str(s) if s == "cube" && role == ObjectRole::Any => {
                    Some(super::check::Named::LegacyCube)
                }
                ValueKind::Str(s) if s == "bowl" && role == ObjectRole::Any => {
                    Some(super::check::Named::LegacyBowl)
                }
                ValueKind::Str(s) => crate::kinds::objects::ObjectRef::parse(s)
                    .ok()
                    .map(super::check::Named::Ref),
                ValueKind::Map(m) if m.len() == 1 => m[0]
                    .0
                    .as_str()
                    .and_then(crate::kinds::objects::Ident::new)
                    .map(|k| super::check::Named::Ref(crate::kinds::objects::ObjectRef::Var(k))),
                _ => None,
            };
            if let Some(reference) = reference {
                self.object_uses.push(ObjectUse {
                    reference,
                    role,
                    loc: v.loc,
                    via: v.via,
                    leaf: kind.to_string(),
                });
            }
        }
        // A `grasp` without `object:` and the `cube_*` conditions act on the legacy cube.
        if kind.starts_with("cube_") {
            self.object_uses.push(ObjectUse {
                reference: super::check::Named::LegacyCube,
                role: ObjectRole::Block,
                loc: body.loc,
                via: body.via,
                leaf: kind.to_string(),
            });
        }
        if kind == "cube_in_bowl" {
            self.object_uses.push(ObjectUse {
                reference: super::check::Named::LegacyBowl,
                role: ObjectRole::Container,
                loc: body.loc,
                via: body.via,
                leaf: kind.to_string(),
            });
        }
    }

    fn take_name(&mut self, body: &Value) -> Option<String> {
        let v = body.get("name")?;
        match v.as_str() {
            Some(s) if valid_name(s) => Some(s.to_string()),
            Some(s) => {
                self.err(
                    Issue::new(v.loc, format!("invalid node name `{s}`"))
                        .label("expected 1–80 characters without `/`, `[`, `]`, `#` or line breaks")
                        .help(
                            "names appear in node paths like `main/sequence[pick]/reach`; keep them simple",
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

    /// Reads a composite or decorator of kind `ty`: its parameters through the registry (its
    /// typed parameter struct; every bad parameter reported at once), then its nodes. After bad
    /// parameters, the nodes the body holds (in the parameters whose type holds nodes) are still
    /// read, so that their mistakes are reported too.
    fn control(&mut self, ty: &NodeType, loc: Loc, body: &Value, depth: usize) -> Option<NodeKind> {
        let k = ty.name();
        let kind = ty.control_kind()?;
        let errors = match parse_reporting_all(without_name(body), |v| ty.parse_control(v))? {
            Ok(params) => return self.control_nodes(k, kind, params, loc, body, depth),
            Err(errors) => errors,
        };
        let example = crate::kinds::catalog::parse_node_doc(ty.doc()).3;
        for e in errors {
            let missing = e.missing_parameter().is_some();
            let mut issue = e.into_issue(body.loc, |l| self.sources.describe(l));
            if missing && !example.contains('\n') {
                issue.help = Some(format!("e.g. `{example}`"));
            }
            self.param_error(k, issue);
        }
        for key in ty.node_params() {
            match body.get(&key) {
                Some(v) if v.as_seq().is_some() => {
                    for item in v.as_seq().unwrap_or_default() {
                        self.node(item, depth + 1);
                    }
                }
                Some(v) => {
                    self.node(v, depth + 1);
                }
                None => {}
            }
        }
        None
    }

    /// Reads the nodes of a control node of kind `kind` with parameters `params`.
    fn control_nodes(
        &mut self,
        k: &str,
        kind: ControlKind,
        params: Control,
        loc: Loc,
        body: &Value,
        depth: usize,
    ) -> Option<NodeKind> {
        use ControlKind as C;
        let child = |this: &mut Self, v: &NodeValue| this.node(&v.0, depth + 1).map(Box::new);
        match params {
            Control::Composite(p) => {
                let children = self.children(k, kind, &p.children, depth)?;
                Some(match kind {
                    C::Sequence => NodeKind::Sequence(children),
                    C::Fallback => NodeKind::Fallback(children),
                    C::ReactiveSequence => NodeKind::ReactiveSequence(children),
                    C::ReactiveFallback => NodeKind::ReactiveFallback(children),
                    C::Parallel => NodeKind::Parallel(children),
                    _ => NodeKind::Race(children),
                })
            }
            Control::Guard(p) => {
                let condition = self.node(&p.condition.0, depth + 1).map(Box::new);
                let child = child(self, &p.child);
                let condition = condition?;
                if condition.as_check().is_none() {
                    self.err(
                        Issue::new(
                            condition.loc,
                            format!(
                                "a guard's condition must be a condition leaf, found `{}`",
                                condition.kind.kind_name()
                            ),
                        )
                        .label(format!(
                            "expected one of {}",
                            self.registry.names_of(Category::Condition).join(", ")
                        ))
                        .help("conditions are checked every tick and never run; put actions in `child:`"),
                    );
                    return None;
                }
                Some(NodeKind::Guard {
                    condition,
                    child: child?,
                })
            }
            Control::Retry(p) => Some(NodeKind::Retry {
                attempts: p.attempts,
                child: child(self, &p.child)?,
            }),
            Control::Repeat(p) => Some(NodeKind::Repeat {
                times: p.times,
                child: child(self, &p.child)?,
            }),
            Control::ForEach(p) => {
                let select = p.select();
                let at = |key: &str| body.get(key).map(|v| v.loc);
                self.var_defs.extend(VarDef::from_select(
                    &select,
                    at("as").unwrap_or(loc),
                    at("goal_as"),
                ));
                Some(NodeKind::ForEach {
                    select,
                    max_iterations: p.max_iterations,
                    child: child(self, &p.child)?,
                })
            }
            Control::Timeout(p) => Some(NodeKind::Timeout {
                seconds: p.seconds,
                child: child(self, &p.child)?,
            }),
            Control::Decorated(p) => {
                let c = child(self, &p.child)?;
                Some(match kind {
                    C::Inverter => NodeKind::Inverter(c),
                    C::ForceSuccess => NodeKind::ForceSuccess(c),
                    _ => NodeKind::ForceFailure(c),
                })
            }
            Control::Subtree(p) => self.subtree_call(loc, body, &p, depth),
        }
    }

    /// A composite's `children:`: a non-empty list of nodes; before the last, a reactive
    /// composite takes only checks.
    fn children(&mut self, k: &str, kind: ControlKind, list: &NodeList, depth: usize) -> Option<Vec<Node>> {
        let children_v = &list.0;
        let Some(items) = children_v.as_seq() else {
            self.err(
                Issue::new(
                    children_v.loc,
                    format!(
                        "`children` must be a list of nodes, found {}",
                        children_v.describe()
                    ),
                )
                .label("expected `[...]` or a `- ` list"),
            );
            return None;
        };
        if items.is_empty() {
            self.err(
                Issue::new(children_v.loc, format!("`{k}` has no children"))
                    .label("expected at least one node")
                    .help(format!("add a child node, or remove the empty `{k}`")),
            );
            return None;
        }
        let mut children = Vec::with_capacity(items.len());
        let mut ok = true;
        for item in items {
            match self.node(item, depth + 1) {
                Some(n) => children.push(n),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let reactive = match kind {
            ControlKind::ReactiveSequence => Some("holds"),
            ControlKind::ReactiveFallback => Some("fails"),
            _ => None,
        };
        if let Some(what) = reactive {
            let last = children.len() - 1;
            for c in &children[..last] {
                if c.as_check().is_none() {
                    self.err(
                        Issue::new(c.loc, format!("in `{k}`, only the last child may be `{}`", c.kind.kind_name()))
                            .label("expected a condition leaf (or an `inverter` of one), re-checked every tick")
                            .help(format!(
                                "the children before the last are conditions re-checked every tick while the last one runs \
                                 (as long as each {what}); use `sequence`/`fallback` for steps that run one after another"
                            )),
                    );
                    ok = false;
                }
            }
            if !ok {
                return None;
            }
        }
        Some(children)
    }

    fn subtree_call(
        &mut self,
        loc: Loc,
        body: &Value,
        call: &SubtreeParams,
        depth: usize,
    ) -> Option<NodeKind> {
        let reference = call.reference.as_str();
        let ref_loc = body.get("ref").map_or(loc, |v| v.loc);
        let Some(def) = self.subtrees.get(reference) else {
            let mut names: Vec<&str> = self.subtrees.keys().map(String::as_str).collect();
            names.sort_unstable();
            let label = if names.is_empty() {
                "no subtrees are defined (add `subtrees:` or `include:` a library)".to_string()
            } else {
                format!(
                    "expected one of {}",
                    names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            self.err(
                Issue::new(ref_loc, format!("undefined subtree `{reference}`"))
                    .label(label)
                    .maybe_help(did_you_mean(reference, names.iter().copied()))
                    .help_or("define it under `subtrees:` or include the file that defines it"),
            );
            return None;
        };
        if self.stack.iter().any(|s| s == reference) {
            let mut chain = self.stack.clone();
            chain.push(reference.to_string());
            let start = chain.iter().position(|s| s == reference).unwrap_or(0);
            self.err(
                Issue::new(ref_loc, format!("recursive subtree: {}", chain[start..].join(" → ")))
                    .label("this call leads back to itself")
                    .help("subtrees are expanded in place, so they cannot call themselves; use `retry`/`repeat` for loops"),
            );
            return None;
        }
        // Arguments.
        let mut env: HashMap<String, Value> = HashMap::new();
        let mut arg_texts = Vec::new();
        let mut ok = true;
        if let Some(av) = call.args.as_ref().map(|a| &a.0) {
            match &av.kind {
                ValueKind::Null => {}
                ValueKind::Map(entries) => {
                    for (k, v) in entries {
                        let Some(pname) = k.as_str() else {
                            self.err(Issue::new(k.loc, "argument names must be text"));
                            ok = false;
                            continue;
                        };
                        let pname = pname.strip_prefix('$').unwrap_or(pname);
                        if def.params.iter().any(|p| p.name == pname) {
                            env.insert(pname.to_string(), v.clone());
                            arg_texts.push((pname.to_string(), render_value(v)));
                        } else {
                            let params: Vec<String> =
                                def.params.iter().map(|p| format!("`{}`", p.name)).collect();
                            let label = if params.is_empty() {
                                format!("subtree `{reference}` takes no parameters")
                            } else {
                                format!("expected one of {}", params.join(", "))
                            };
                            self.err(
                                Issue::new(k.loc, format!("unknown argument `{pname}` for subtree `{reference}`"))
                                    .label(label)
                                    .maybe_help(did_you_mean(pname, def.params.iter().map(|p| p.name.as_str())))
                                    .help_or(format!(
                                        "declare it in `subtrees: {{{reference}: {{params: {{{pname}: <default>}}}}}}` or remove it"
                                    )),
                            );
                            ok = false;
                        }
                    }
                }
                _ => {
                    self.err(
                        Issue::new(
                            av.loc,
                            format!("`args` must be a mapping, found {}", av.describe()),
                        )
                        .label("expected `{param: value, ...}`"),
                    );
                    ok = false;
                }
            }
        }
        for p in &def.params {
            if env.contains_key(&p.name) {
                continue;
            }
            match &p.default {
                Some(d) => {
                    env.insert(p.name.clone(), d.clone());
                }
                None => {
                    self.err(
                        Issue::new(
                            loc,
                            format!("missing argument `{}` for subtree `{reference}`", p.name),
                        )
                        .label(format!(
                            "`{}` is required (declared at {})",
                            p.name,
                            self.sources.describe(p.loc)
                        ))
                        .help(format!("add `args: {{{}: <value>}}`", p.name)),
                    );
                    ok = false;
                }
            }
        }
        if !ok {
            return None;
        }
        let body_v = substitute(&def.root, &env);
        let reference = reference.to_string();
        *self.calls.entry(reference.clone()).or_default() += 1;
        self.stack.push(reference.clone());
        let body = self.node(&body_v, depth + 1);
        self.stack.pop();
        Some(NodeKind::Subtree {
            reference,
            args: arg_texts,
            body: Box::new(body?),
        })
    }
}

fn valid_name(s: &str) -> bool {
    !s.trim().is_empty() && s.chars().count() <= 80 && !s.contains(['/', '[', ']', '#', '\n', '\r'])
}

/// Reads a node body with `parse` (a kind's parameter struct), reporting every bad parameter,
/// not just the first: after an error located in one parameter (its key or anything in its
/// value), that parameter is set aside and the rest read again. It stops at an error that no
/// parameter explains (a missing parameter) or after [`MAX_LEAF_ERRORS`] (each retry re-reads the
/// body, so the cap keeps a body with thousands of bad keys linear). A "missing" error for a
/// parameter set aside, or for the one a misspelled key was suggested as, is not repeated.
/// `None` if `parse` answers `None` (not a kind it reads).
fn parse_reporting_all<T>(
    mut params: Value,
    parse: impl Fn(&Value) -> Option<Result<T, DeError>>,
) -> Option<Result<T, Vec<DeError>>> {
    let mut errors = Vec::new();
    let mut set_aside: Vec<String> = Vec::new();
    loop {
        let e = match parse(&params)? {
            Ok(read) if errors.is_empty() => return Some(Ok(read)),
            Ok(_) => return Some(Err(errors)),
            Err(e) => e,
        };
        // "Missing `target`" after `target: cubee` or `targt: cube` was set aside says nothing new.
        if let Some(missing) = e.missing_parameter()
            && set_aside
                .iter()
                .any(|k| k == missing || did_you_mean(k, [missing]).is_some())
        {
            return Some(Err(errors));
        }
        let ValueKind::Map(entries) = &mut params.kind else {
            errors.push(e);
            return Some(Err(errors));
        };
        let culprit = e.loc.and_then(|loc| {
            entries
                .iter()
                .position(|(k, v)| k.loc == loc || contains_loc(v, loc))
        });
        errors.push(e);
        match culprit {
            Some(i) if errors.len() < MAX_LEAF_ERRORS => {
                let (key, _) = entries.remove(i);
                set_aside.extend(key.as_str().map(str::to_string));
            }
            _ => return Some(Err(errors)),
        }
    }
}

/// Whether `loc` is the location of `v` or of a value inside it.
fn contains_loc(v: &Value, loc: Loc) -> bool {
    v.loc == loc
        || match &v.kind {
            ValueKind::Seq(items) => items.iter().any(|i| contains_loc(i, loc)),
            ValueKind::Map(m) => m.iter().any(|(k, v)| k.loc == loc || contains_loc(v, loc)),
            _ => false,
        }
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

/// Replace every `$param` scalar in `v` by its value from `env` (unknown ones are left as they
/// are; they are reported separately by [`undefined_params`]).
pub fn substitute(v: &Value, env: &HashMap<String, Value>) -> Value {
    match &v.kind {
        ValueKind::Str(s) => match param_ref(s).and_then(|p| env.get(p)) {
            Some(arg) => {
                let mut out = arg.clone();
                mark_via(&mut out, v.loc);
                out
            }
            None => v.clone(),
        },
        ValueKind::Seq(items) => Value {
            kind: ValueKind::Seq(items.iter().map(|i| substitute(i, env)).collect()),
            loc: v.loc,
            via: v.via,
        },
        ValueKind::Map(entries) => Value {
            kind: ValueKind::Map(
                entries
                    .iter()
                    .map(|(k, x)| (k.clone(), substitute(x, env)))
                    .collect(),
            ),
            loc: v.loc,
            via: v.via,
        },
        _ => v.clone(),
    }
}

fn mark_via(v: &mut Value, use_loc: Loc) {
    if v.via.is_none() {
        v.via = Some(use_loc);
    }
    match &mut v.kind {
        ValueKind::Seq(items) => items.iter_mut().for_each(|i| mark_via(i, use_loc)),
        ValueKind::Map(entries) => entries.iter_mut().for_each(|(_, x)| mark_via(x, use_loc)),
        _ => {}
    }
}

/// Every `$name` scalar in `v` whose name is not in `params`, with its location.
pub fn undefined_params<'v>(v: &'v Value, params: &[&str], out: &mut Vec<(&'v str, Loc)>) {
    match &v.kind {
        ValueKind::Str(s) => {
            if let Some(p) = param_ref(s)
                && !params.contains(&p)
            {
                out.push((p, v.loc));
            }
        }
        ValueKind::Seq(items) => items.iter().for_each(|i| undefined_params(i, params, out)),
        ValueKind::Map(entries) => entries.iter().for_each(|(_, x)| undefined_params(x, params, out)),
        _ => {}
    }
}

/// Compact flow-style text of a value (for display of subtree arguments).
pub fn render_value(v: &Value) -> String {
    match &v.kind {
        ValueKind::Null => "~".into(),
        ValueKind::Bool(b) => b.to_string(),
        ValueKind::Int(i) => i.to_string(),
        ValueKind::Float(x) => format!("{x}"),
        ValueKind::Str(s) => s.clone(),
        ValueKind::Seq(items) => format!(
            "[{}]",
            items.iter().map(render_value).collect::<Vec<_>>().join(", ")
        ),
        ValueKind::Map(entries) => format!(
            "{{{}}}",
            entries
                .iter()
                .map(|(k, x)| format!("{}: {}", render_value(k), render_value(x)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// For a condition given an action's parameter (`cube_in_bowl: {timeout: 2}`): what to write
/// instead. Conditions are instantaneous, so waiting for one or bounding it in time is the job of
/// the decorators around it. `None` for any other error. Called for conditions only.
fn condition_param_help(kind: &str, message: &str) -> Option<String> {
    let param = message.strip_prefix("unknown parameter `")?.split('`').next()?;
    let timing = [
        "timeout", "seconds", "speed", "wait", "duration", "retries", "attempts", "until", "poll",
    ];
    if !timing.contains(&param) {
        return None;
    }
    Some(format!(
        "conditions are instantaneous: `{kind}` checks the world on the tick it runs and succeeds or fails at once, so it takes no `{param}`. \
         To wait up to 2 s for it to hold, wrap it: `timeout: {{seconds: 2, child: {{retry: {{attempts: 1000, child: {{{kind}: {{}}}}}}}}}}`; \
         to run an action only while it holds, use `guard: {{condition: {{{kind}: {{}}}}, child: ...}}`"
    ))
}
