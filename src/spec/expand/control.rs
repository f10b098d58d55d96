//! Composites and decorators: their typed parameters, read through the registry, and their
//! nodes.

use super::{Expander, parse_reporting_all, without_name};
use crate::kinds::{Category, NodeType};
use crate::kinds::{Control, ControlKind, NodeList, NodeValue};
use crate::spec::check::VarDef;
use crate::spec::node::{Node, NodeKind};
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::value::Value;

impl Expander<'_> {
    /// Reads a composite or decorator of kind `ty`: its parameters through the registry (its
    /// typed parameter struct; every bad parameter reported at once), then its nodes. After bad
    /// parameters, the nodes the body holds (in the parameters whose type holds nodes) are still
    /// read, so that their mistakes are reported too.
    pub(super) fn control(
        &mut self,
        ty: &NodeType,
        loc: Loc,
        body: &Value,
        depth: usize,
    ) -> Option<NodeKind> {
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
    pub(super) fn control_nodes(
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
    pub(super) fn children(
        &mut self,
        k: &str,
        kind: ControlKind,
        list: &NodeList,
        depth: usize,
    ) -> Option<Vec<Node>> {
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
}
