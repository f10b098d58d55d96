//! A leaf's parameters, read with every bad one reported, and the objects a leaf names.

use super::{Expander, MAX_LEAF_ERRORS};
use crate::kinds::NodeType;
use crate::kinds::ObjectRole;
use crate::spec::check::ObjectUse;
use crate::yaml::de::DeError;
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, ValueKind};

/// Largest file a leaf may name (a `policy`'s model), bytes.
pub const MAX_LEAF_FILE_BYTES: u64 = 256 << 20;

impl Expander<'_> {
    /// `out` (a leaf's body) with each file parameter of `ty` ([`crate::kinds::Params::FILE_PARAMS`]) replaced
    /// by the canonical path of the file it names, relative to the file it is written in and
    /// confined like `include:`; `None` (the problem reported, at the value) when one cannot be
    /// read. The files are noted in [`Self::leaf_files`].
    pub(super) fn resolve_files(&mut self, ty: &NodeType, mut out: Value) -> Option<Value> {
        let keys = ty.file_params();
        let ValueKind::Map(entries) = &mut out.kind else {
            return Some(out);
        };
        if keys.is_empty() {
            return Some(out);
        }
        for (k, v) in entries.iter_mut() {
            let (Some(key), ValueKind::Str(written)) = (k.as_str(), &v.kind) else {
                continue;
            };
            if !keys.contains(&key) {
                continue;
            }
            match self.resolve_file(ty.name(), key, written, v.loc) {
                Ok(canon) => v.kind = ValueKind::Str(canon.display().to_string()),
                Err(issue) => {
                    self.issues.push(issue);
                    return None;
                }
            }
        }
        Some(out)
    }

    fn resolve_file(
        &mut self,
        kind: &str,
        key: &str,
        written: &str,
        loc: Loc,
    ) -> Result<std::path::PathBuf, Issue> {
        use std::path::Path;
        let rel = Path::new(written);
        let base = Path::new(self.sources.name(loc.file)).parent();
        let path = match base {
            Some(b) if !b.as_os_str().is_empty() => b.join(rel),
            _ => rel.to_path_buf(),
        };
        self.scope.check_spelling(base, rel, loc)?;
        let help = format!(
            "`{key}:` is a path relative to the file that names it, inside the tree's folder (see `macrotree nodes {kind}`)"
        );
        let canon = path.canonicalize().map_err(|e| {
            Issue::new(loc, format!("cannot read `{written}` ({key} of `{kind}`): {e}"))
                .label("expected a file relative to this file's folder")
                .help(help.clone())
        })?;
        self.scope.check_resolved(&canon, rel, loc)?;
        match std::fs::metadata(&canon) {
            Ok(m) if m.is_file() && m.len() <= MAX_LEAF_FILE_BYTES => {}
            Ok(m) if m.is_file() => {
                return Err(Issue::new(
                    loc,
                    format!(
                        "`{written}` is {} bytes; a file a leaf names may have at most {MAX_LEAF_FILE_BYTES}",
                        m.len()
                    ),
                )
                .help(help));
            }
            Ok(_) => {
                return Err(Issue::new(loc, format!("`{written}` is not a regular file")).help(help));
            }
            Err(e) => {
                return Err(Issue::new(loc, format!("cannot read `{written}`: {e}")).help(help));
            }
        }
        if let Some(check) = self.registry.file_check(kind) {
            check(&canon).map_err(|why| {
                Issue::new(
                    loc,
                    format!("`{written}` ({key} of `{kind}`) does not fit: {why}"),
                )
                .label("this file")
                .help(format!(
                    "see `macrotree nodes {kind}` for what the file must hold"
                ))
            })?;
        }
        self.leaf_files.push(canon.clone());
        Ok(canon)
    }

    /// Notes where leaf `kind` names objects or variables (for the scene and blackboard checks),
    /// even when the leaf has other errors, so that every mistake is reported at once.
    /// The parameters that name objects are the ones the kind declares
    /// ([`crate::kinds::Params::OBJECT_PARAMS`]).
    pub(super) fn record_objects(&mut self, ty: &NodeType, body: &Value) {
        let kind = ty.name();
        for &(key, role) in ty.object_params() {
            // A dotted key reaches into a nested mapping (`until.grasped.object`).
            let Some(v) = key.split('.').try_fold(body, |v, k| v.get(k)) else {
                continue;
            };
            let reference = match &v.kind {
                // `cube` and `bowl` are legacy names only where a `Target` is read (any object):
                // an `ObjectRef` parameter resolves them as plain names when the tree runs.
                ValueKind::Str(s) if s == "cube" && role == ObjectRole::Any => {
                    Some(crate::spec::check::Named::LegacyCube)
                }
                ValueKind::Str(s) if s == "bowl" && role == ObjectRole::Any => {
                    Some(crate::spec::check::Named::LegacyBowl)
                }
                ValueKind::Str(s) => crate::kinds::objects::ObjectRef::parse(s)
                    .ok()
                    .map(crate::spec::check::Named::Ref),
                ValueKind::Map(m) if m.len() == 1 => m[0]
                    .0
                    .as_str()
                    .and_then(crate::kinds::objects::Ident::new)
                    .map(|k| crate::spec::check::Named::Ref(crate::kinds::objects::ObjectRef::Var(k))),
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
                reference: crate::spec::check::Named::LegacyCube,
                role: ObjectRole::Block,
                loc: body.loc,
                via: body.via,
                leaf: kind.to_string(),
            });
        }
        if kind == "cube_in_bowl" {
            self.object_uses.push(ObjectUse {
                reference: crate::spec::check::Named::LegacyBowl,
                role: ObjectRole::Container,
                loc: body.loc,
                via: body.via,
                leaf: kind.to_string(),
            });
        }
    }
}

/// Reads a node body with `parse` (a kind's parameter struct), reporting every bad parameter,
/// not just the first: after an error located in one parameter (its key or anything in its
/// value), that parameter is set aside and the rest read again. It stops at an error that no
/// parameter explains (a missing parameter) or after [`MAX_LEAF_ERRORS`] (each retry re-reads the
/// body, so the cap keeps a body with thousands of bad keys linear). A "missing" error for a
/// parameter set aside, or for the one a misspelled key was suggested as, is not repeated.
/// `None` if `parse` answers `None` (not a kind it reads).
pub(super) fn parse_reporting_all<T>(
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
pub(super) fn contains_loc(v: &Value, loc: Loc) -> bool {
    v.loc == loc
        || match &v.kind {
            ValueKind::Seq(items) => items.iter().any(|i| contains_loc(i, loc)),
            ValueKind::Map(m) => m.iter().any(|(k, v)| k.loc == loc || contains_loc(v, loc)),
            _ => false,
        }
}

/// For a condition given an action's parameter (`cube_in_bowl: {timeout: 2}`): what to write
/// instead. Conditions are instantaneous, so waiting for one or bounding it in time is the job of
/// the decorators around it. `None` for any other error. Called for conditions only.
pub(super) fn condition_param_help(kind: &str, message: &str) -> Option<String> {
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
