//! Test doubles: substitution rules that replace leaves, selected by a glob on their node path,
//! with a scripted outcome (`run/sweep/test --substitute 'PATTERN=OUTCOME'`, scenario files).
//!
//! Patterns match whole node paths segment by segment (`/` separates segments): `*` matches any
//! run of characters inside one segment, `?` one character, and a segment that is exactly `**`
//! matches any number of segments (zero included). Everything else is literal, brackets
//! included: `main/**/grasp` matches every unnamed `grasp` leaf, `main/**/grasp*` also
//! `grasp[squeeze]` and `grasp#2`, `main/**/subtree[pick]/**` every leaf of that subtree call.
//!
//! Substitutions replace **leaves** (actions, conditions, `wait`); a pattern that matches
//! composites applies to the leaves it matches, and a pattern that matches no leaf at all is an
//! error ([`SubstitutionError`]), as is a leaf matched by two rules. (BehaviorTree.CPP replaces a
//! whole subtree when a rule names a composite; here a composite's outcome follows from its
//! substituted leaves, so its own logic — retries, fallbacks, guards — is still what is tested.)
//!
//! ```
//! use macrotree::runtime::substitute::{Substitution, Scripted};
//! let s: Substitution = "main/**/grasp=fail_first:1".parse().unwrap();
//! assert_eq!(s.outcome, Scripted::FailFirst(1));
//! assert!(s.matches("main/sequence/retry/subtree[pick]/sequence[pick]/grasp"));
//! assert!(!s.matches("main/sequence/grasp[squeeze]"));
//! ```

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::kinds::Leaf;
use crate::plan::Plan;

/// Largest `N` of `running:N` (ticks) and `fail_first:N` (activations).
pub const MAX_SCRIPTED_COUNT: u32 = 100_000;
/// Longest pattern, characters.
pub const MAX_PATTERN_LEN: usize = 1000;

/// A scripted outcome that replaces what a leaf would do.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Scripted {
    /// `success`: succeed at once, every activation.
    Success,
    /// `failure`: fail at once, every activation (failure kind `substituted`).
    Failure,
    /// `running:N`: answer Running for N ticks, then succeed (each activation).
    Running(u32),
    /// `fail_first:N`: fail the first N activations (kind `substituted`), then run the real leaf.
    FailFirst(u32),
}

impl fmt::Display for Scripted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scripted::Success => f.write_str("success"),
            Scripted::Failure => f.write_str("failure"),
            Scripted::Running(n) => write!(f, "running:{n}"),
            Scripted::FailFirst(n) => write!(f, "fail_first:{n}"),
        }
    }
}

impl FromStr for Scripted {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let form = "expected success, failure, running:N (N ticks Running, then success) or \
                    fail_first:N (fail the first N activations, then run the real node)";
        let count = |n: &str| -> Result<u32, String> {
            match n.trim().parse::<u64>() {
                Ok(v) if (1..=u64::from(MAX_SCRIPTED_COUNT)).contains(&v) => Ok(v as u32),
                _ => Err(format!(
                    "{s:?}: N must be a whole number from 1 to {MAX_SCRIPTED_COUNT}"
                )),
            }
        };
        match s.trim().split_once(':') {
            None if s.trim() == "success" => Ok(Scripted::Success),
            None if s.trim() == "failure" => Ok(Scripted::Failure),
            Some(("running", n)) => Ok(Scripted::Running(count(n)?)),
            Some(("fail_first", n)) => Ok(Scripted::FailFirst(count(n)?)),
            _ => Err(format!("{s:?}: {form}")),
        }
    }
}

impl Serialize for Scripted {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Scripted {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl schemars::JsonSchema for Scripted {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Scripted".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "type": "string",
            "description": "A scripted outcome: `success`, `failure`, `running:N` (N ticks Running, then success) or `fail_first:N` (fail the first N activations, then run the real node); 1 ≤ N ≤ 100000.",
            "pattern": "^(success|failure|running:[0-9]+|fail_first:[0-9]+)$"
        })
    }
}

/// One substitution rule: leaves whose path matches `pattern` get `outcome`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Substitution {
    /// Node path glob (`main/**/grasp`): `*` within a segment, `?` one character, `**` any
    /// number of segments.
    pub pattern: String,
    /// What the matched leaves do instead.
    pub outcome: Scripted,
}

impl Substitution {
    /// The pattern matches `path`.
    pub fn matches(&self, path: &str) -> bool {
        glob_match(&self.pattern, path)
    }

    /// Checks the pattern's form (non-empty, bounded, no empty segment).
    pub fn check_pattern(pattern: &str) -> Result<(), String> {
        if pattern.is_empty() {
            return Err("the pattern is empty".into());
        }
        if pattern.chars().count() > MAX_PATTERN_LEN {
            return Err(format!("the pattern is longer than {MAX_PATTERN_LEN} characters"));
        }
        if pattern.split('/').any(str::is_empty) {
            return Err(format!(
                "{pattern:?} has an empty segment (`//` or a `/` at an end)"
            ));
        }
        if pattern.chars().any(char::is_control) {
            return Err("the pattern holds a control character".into());
        }
        Ok(())
    }
}

impl fmt::Display for Substitution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.pattern, self.outcome)
    }
}

impl FromStr for Substitution {
    type Err = String;
    /// `PATTERN=OUTCOME`, split at the last `=` (names may hold `=`, outcomes never do).
    fn from_str(s: &str) -> Result<Self, String> {
        let (pattern, outcome) = s
            .rsplit_once('=')
            .ok_or_else(|| format!("{s:?}: expected PATTERN=OUTCOME, e.g. 'main/**/grasp=fail_first:1'"))?;
        let pattern = pattern.trim();
        Self::check_pattern(pattern)?;
        Ok(Self {
            pattern: pattern.to_string(),
            outcome: outcome.parse()?,
        })
    }
}

/// `pattern` matches the whole of `path` (see the [module docs](self)).
pub fn glob_match(pattern: &str, path: &str) -> bool {
    let p: Vec<&str> = pattern.split('/').collect();
    let s: Vec<&str> = path.split('/').collect();
    // Dynamic programming over (pattern segment, path segment): no exponential backtracking.
    let (np, ns) = (p.len(), s.len());
    let mut m = vec![vec![false; ns + 1]; np + 1];
    m[np][ns] = true;
    for i in (0..np).rev() {
        for j in (0..=ns).rev() {
            m[i][j] = if p[i] == "**" {
                m[i + 1][j] || (j < ns && m[i][j + 1])
            } else {
                j < ns && segment_match(p[i], s[j]) && m[i + 1][j + 1]
            };
        }
    }
    m[0][0]
}

/// One segment against one glob segment (`*`, `?`).
fn segment_match(pattern: &str, text: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let t: Vec<char> = text.chars().collect();
    let (mut pi, mut ti) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while ti < t.len() {
        if pi < p.len() && (p[pi] == '?' || (p[pi] != '*' && p[pi] == t[ti])) {
            pi += 1;
            ti += 1;
        } else if pi < p.len() && p[pi] == '*' {
            star = Some((pi, ti));
            pi += 1;
        } else if let Some((sp, st)) = star {
            pi = sp + 1;
            ti = st + 1;
            star = Some((sp, st + 1));
        } else {
            return false;
        }
    }
    p[pi..].iter().all(|&c| c == '*')
}

/// Why substitutions do not fit a tree. `Display` says which pattern and what to do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SubstitutionError {
    /// The offending rule's index in the list given to [`resolve`], from 0.
    pub index: usize,
    /// The offending rule, as written (`PATTERN=OUTCOME`).
    pub rule: String,
    /// What is wrong.
    pub reason: String,
    /// Node paths close to the pattern (at most five).
    pub close: Vec<String>,
}

impl fmt::Display for SubstitutionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "substitution `{}`: {}", self.rule, self.reason)?;
        if !self.close.is_empty() {
            write!(f, "\n  help: leaves with close paths:")?;
            for c in &self.close {
                write!(f, "\n    {c}")?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for SubstitutionError {}

/// Substitutions resolved against a plan: the scripted outcome of each leaf, if any.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Resolved {
    /// Indexed like `plan.leaves`.
    pub by_leaf: Vec<Option<Scripted>>,
    /// What this resolution is for: the rules, and the leaf paths of the plan they were
    /// resolved against (a leaf's path names its kind).
    key: ResolvedFor,
}

/// The inputs a [`Resolved`] depends on, compared before it is reused.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct ResolvedFor {
    rules: Vec<Substitution>,
    leaves: Vec<String>,
}

impl ResolvedFor {
    fn new(plan: &Plan, rules: &[Substitution]) -> Self {
        Self {
            rules: rules.to_vec(),
            leaves: plan.leaves.iter().map(|l| l.path.clone()).collect(),
        }
    }

    fn matches(&self, plan: &Plan, rules: &[Substitution]) -> bool {
        self.rules == rules
            && self.leaves.len() == plan.leaves.len()
            && self.leaves.iter().zip(&plan.leaves).all(|(a, b)| *a == b.path)
    }
}

impl Resolved {
    /// Whether this is the resolution of `rules` against `plan` (a plan with the same leaves
    /// at the same paths), so that it can be reused instead of resolving again.
    pub fn is_for(&self, plan: &Plan, rules: &[Substitution]) -> bool {
        self.key.matches(plan, rules)
    }
}

/// Resolves `subs` against `plan`: every rule must match at least one substitutable leaf, no
/// leaf may match two rules, a `select` cannot be substituted (the blackboard would stay
/// unset) and a condition cannot be `running:N` (conditions answer at once).
pub fn resolve(plan: &Plan, subs: &[Substitution]) -> Result<Resolved, SubstitutionError> {
    let mut by_leaf: Vec<Option<Scripted>> = vec![None; plan.leaves.len()];
    let mut owner: Vec<Option<usize>> = vec![None; plan.leaves.len()];
    for (k, sub) in subs.iter().enumerate() {
        let err = |reason: String, close: Vec<String>| SubstitutionError {
            index: k,
            rule: sub.to_string(),
            reason,
            close,
        };
        Substitution::check_pattern(&sub.pattern).map_err(|r| err(r, Vec::new()))?;
        let mut hits = 0;
        for (i, leaf) in plan.leaves.iter().enumerate() {
            if !sub.matches(&leaf.path) {
                continue;
            }
            match (&leaf.kind, sub.outcome) {
                (Leaf::Select(_), _) => {
                    return Err(err(
                        format!(
                            "`{}` is a `select`, which cannot be substituted (the variables it \
                             writes would stay unset); substitute the leaves that use them",
                            leaf.path
                        ),
                        Vec::new(),
                    ));
                }
                (Leaf::Condition(_), Scripted::Running(_)) => {
                    return Err(err(
                        format!(
                            "`{}` is a condition, which answers at once: use success, failure \
                             or fail_first:N",
                            leaf.path
                        ),
                        Vec::new(),
                    ));
                }
                _ => {}
            }
            if let Some(other) = owner[i] {
                return Err(err(
                    format!("leaf `{}` is also matched by `{}`", leaf.path, subs[other]),
                    Vec::new(),
                ));
            }
            owner[i] = Some(k);
            by_leaf[i] = Some(sub.outcome);
            hits += 1;
        }
        if hits == 0 {
            let composites: Vec<&str> = plan
                .nodes
                .iter()
                .filter(|n| n.leaf.is_none() && sub.matches(&n.path))
                .map(|n| n.path.as_str())
                .collect();
            let reason = match composites.first() {
                Some(c) => format!(
                    "it matches only composite nodes (e.g. `{c}`); substitutions replace leaves: \
                     add `/**` to substitute every leaf below it, or name a leaf"
                ),
                None => "it matches no node of the tree".into(),
            };
            return Err(err(reason, close_paths(plan, &sub.pattern)));
        }
    }
    Ok(Resolved {
        by_leaf,
        key: ResolvedFor::new(plan, subs),
    })
}

/// Up to five leaf paths closest to `pattern` (by edit distance of the last segments).
pub(crate) fn close_paths(plan: &Plan, pattern: &str) -> Vec<String> {
    let last = pattern.rsplit('/').next().unwrap_or(pattern);
    let mut scored: Vec<(usize, &str)> = plan
        .leaves
        .iter()
        .map(|l| {
            let seg = l.path.rsplit('/').next().unwrap_or(&l.path);
            let d = crate::yaml::suggest::edit_distance(last, seg)
                .min(crate::yaml::suggest::edit_distance(pattern, &l.path));
            (d, l.path.as_str())
        })
        .collect();
    scored.sort();
    scored.into_iter().take(5).map(|(_, p)| p.to_string()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs() {
        let p = "main/seq/retry[a]/subtree[pick]/sequence[pick]/grasp";
        assert!(glob_match("main/**/grasp", p));
        assert!(glob_match("**/grasp", p));
        assert!(glob_match("main/*/retry*/**", p));
        assert!(glob_match(p, p));
        assert!(!glob_match("main/*/grasp", p));
        assert!(!glob_match("main/**/gras", p));
        assert!(glob_match("main/**/gras?", p));
        assert!(glob_match("main/**/subtree[pick]/**", p));
        assert!(!glob_match("main/**/grasp", "main/seq/grasp[squeeze]"));
        assert!(glob_match("main/**/grasp*", "main/seq/grasp[squeeze]"));
        assert!(glob_match("main/**", "main"));
        assert!(!glob_match("main", "main/x"));
        // Many stars stay fast (no exponential backtracking).
        let long = "a/".repeat(200) + "b";
        assert!(!glob_match(
            &"**/"
                .repeat(50)
                .to_string()
                .trim_end_matches('/')
                .replace("**", "**/c"),
            &long
        ));
    }

    #[test]
    fn parse_and_bounds() {
        let s: Substitution = "main/**/grasp=running:3".parse().unwrap();
        assert_eq!(s.outcome, Scripted::Running(3));
        assert_eq!(s.to_string(), "main/**/grasp=running:3");
        for bad in [
            "main/**/grasp",
            "=success",
            "main//x=success",
            "x=fail_first:0",
            "x=running:100001",
            "x=fail_first:-1",
            "x=sometimes",
            "x=running:",
        ] {
            assert!(bad.parse::<Substitution>().is_err(), "{bad}");
        }
        assert_eq!("a=b=failure".parse::<Substitution>().unwrap().pattern, "a=b");
    }
}
