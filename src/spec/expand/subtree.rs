//! Subtree calls: arguments matched with the subtree's parameters, `$param` substitution (each
//! substituted value keeps its location and remembers the use), expansion in place.

use std::collections::HashMap;

use super::Expander;
use crate::kinds::SubtreeParams;
use crate::spec::file::param_ref;
use crate::spec::node::NodeKind;
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, ValueKind};

impl Expander<'_> {
    pub(super) fn subtree_call(
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
