//! A leaf given as a mapping text → a one-leaf [`Plan`], through the tree loader (the same
//! parser, schema checks, suggestions and object-name checks as tree files), with its
//! diagnostics located in the caller's text; and a small cache of compiled leaves.

use std::collections::HashMap;
use std::sync::Arc;

use crate::error::Error;
use crate::kinds::Leaf;
use crate::plan::{Loader, Plan};
use crate::scene::SceneSpec;
use crate::yaml::Diagnostic;

/// The name leaf texts have in diagnostics (`action:1:12`).
pub const LEAF_SOURCE_NAME: &str = "action";

/// Longest leaf text accepted, bytes.
pub const MAX_LEAF_TEXT: usize = 64 * 1024;

/// Compiled leaves kept per environment (the cache is emptied when full).
const CACHE_SIZE: usize = 256;

/// Compiled leaf texts, by text.
#[derive(Default)]
pub(super) struct LeafCache {
    plans: HashMap<String, Arc<Plan>>,
}

impl LeafCache {
    /// The one-leaf plan of `text` (compiled on first use).
    pub fn get(&mut self, loader: &Loader, scene: &Arc<SceneSpec>, text: &str) -> Result<Arc<Plan>, Error> {
        if let Some(p) = self.plans.get(text) {
            return Ok(p.clone());
        }
        let plan = Arc::new(compile_leaf(loader, scene, text)?);
        if self.plans.len() >= CACHE_SIZE {
            self.plans.clear();
        }
        self.plans.insert(text.to_string(), plan.clone());
        Ok(plan)
    }
}

/// Compiles the leaf mapping `text` as the whole tree `main: <text>`, checked against `scene`.
///
/// # Errors
/// [`Error::Tree`] with the loader's diagnostics, located in `text` (file name
/// [`LEAF_SOURCE_NAME`]); or when the mapping is not one action, condition or `wait` leaf.
pub fn compile_leaf(loader: &Loader, scene: &Arc<SceneSpec>, text: &str) -> Result<Plan, Error> {
    let invalid = |d: Vec<Diagnostic>| Error::Tree {
        file: LEAF_SOURCE_NAME.to_string(),
        diagnostics: d,
    };
    if text.len() > MAX_LEAF_TEXT || text.trim().is_empty() {
        return Err(invalid(vec![whole_text(
            text,
            if text.trim().is_empty() {
                "the leaf mapping is empty".to_string()
            } else {
                format!(
                    "the leaf mapping is {} bytes, more than {MAX_LEAF_TEXT}",
                    text.len()
                )
            },
        )]));
    }
    // Each line indented by two spaces under `main:`: line L, column C of the text are line
    // L + 1, column C + 2 of the tree.
    let mut tree = String::with_capacity(text.len() + 64);
    tree.push_str("main:\n");
    for line in text.lines() {
        tree.push_str("  ");
        tree.push_str(line);
        tree.push('\n');
    }
    let plan = loader
        .compile_str_for(&tree, LEAF_SOURCE_NAME, Some(scene.clone()))
        .map_err(|d| invalid(d.into_iter().map(unshift).collect()))?;
    match (plan.nodes.len(), plan.leaves.first().map(|l| &l.kind)) {
        (1, Some(Leaf::Action(_) | Leaf::Condition(_) | Leaf::Wait(_))) => Ok(plan),
        _ => {
            let kind = plan.nodes[0].kind;
            let mut d = whole_text(
                text,
                format!("`{kind}` is not an action, a condition or `wait`: a step runs one leaf"),
            );
            d.help = Some(
                "give one leaf, e.g. `{\"reach\": {\"target\": \"cube\"}}`; run a tree's composite nodes with Action::Subtree"
                    .to_string(),
            );
            Err(invalid(vec![d]))
        }
    }
}

/// A diagnostic of the tree `main:\n  <text>` moved into `text` itself.
fn unshift(mut d: Diagnostic) -> Diagnostic {
    if d.line <= 1 {
        d.line = 1;
        d.column = 1;
        d.source_line = None;
        return d;
    }
    d.line -= 1;
    d.column = d.column.saturating_sub(2).max(1);
    if let Some(src) = &d.source_line
        && let Some(s) = src.strip_prefix("  ")
    {
        d.source_line = Some(s.to_string());
        d.source_column = d.source_column.saturating_sub(2).max(1);
    }
    d
}

/// A diagnostic about the whole text (line 1, column 1).
fn whole_text(text: &str, message: String) -> Diagnostic {
    let first = text.lines().next().unwrap_or("");
    Diagnostic {
        file: LEAF_SOURCE_NAME.to_string(),
        line: 1,
        column: 1,
        message,
        label: None,
        help: None,
        note: None,
        source_line: (!first.is_empty() && first.len() <= 200).then(|| first.to_string()),
        source_column: 1,
        width: first.chars().count().clamp(1, 200) as u32,
        warning: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compile(text: &str) -> Result<Plan, Error> {
        compile_leaf(&Loader::default(), &crate::spec::builtin_scene(), text)
    }

    #[test]
    fn a_leaf_mapping_compiles_to_a_one_leaf_plan() {
        let p = compile(r#"{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}"#).unwrap();
        assert_eq!(p.leaves.len(), 1);
        assert_eq!(p.leaves[0].kind.kind(), "reach");
        let p = compile("grasp:\n  width: 0.03\n").unwrap();
        assert_eq!(p.leaves[0].kind.kind(), "grasp");
        assert!(compile("cube_grasped: {}").is_ok());
        assert!(compile("wait: {seconds: 0.5}").is_ok());
    }

    #[test]
    fn a_misspelt_parameter_is_located_in_the_given_text_with_a_suggestion() {
        let e = compile(r#"{"reach": {"targt": "cube"}}"#).unwrap_err();
        let d = &e.diagnostics()[0];
        assert_eq!((d.line, d.column), (1, 12), "{e}");
        let text = e.to_string();
        assert!(text.contains("action:1:12"), "{text}");
        assert!(text.contains("did you mean `target`?"), "{text}");
        assert!(text.contains(r#"1 | {"reach": {"targt": "cube"}}"#), "{text}");
        // On a later line of a block mapping.
        let e = compile("reach:\n  target: cube\n  ofset: [0, 0, 0.1]\n").unwrap_err();
        let d = &e.diagnostics()[0];
        assert_eq!((d.line, d.column), (3, 3), "{e}");
    }

    #[test]
    fn an_unknown_object_and_an_unknown_kind_are_located() {
        let e = compile(r#"{"reach": {"target": "cub"}}"#).unwrap_err();
        let d = &e.diagnostics()[0];
        assert_eq!(d.line, 1);
        assert!(d.column > 1, "{e}");
        assert!(e.to_string().contains("cube"), "{e}");
        let e = compile("{raech: {target: cube}}").unwrap_err();
        assert!(e.to_string().contains("did you mean `reach`?"), "{e}");
        assert_eq!(e.diagnostics()[0].column, 2, "{e}");
    }

    #[test]
    fn non_finite_numbers_in_a_leaf_are_refused_by_the_loader() {
        for text in [
            "reach: {target: [.nan, 0.1, 0.1]}",
            "reach: {target: cube, offset: [0, 0, .inf]}",
            "wait: {seconds: -1}",
            "wait: {seconds: .nan}",
            "grasp: {width: -0.01}",
        ] {
            let e = compile(text).unwrap_err();
            assert_eq!(e.kind(), "invalid_tree", "{text}");
            assert_eq!(e.diagnostics()[0].line, 1, "{text}: {e}");
        }
    }

    #[test]
    fn composites_and_empty_texts_are_refused() {
        let e = compile("sequence: {children: [{home: {}}]}").unwrap_err();
        assert!(e.to_string().contains("a step runs one leaf"), "{e}");
        assert!(compile("  ").unwrap_err().to_string().contains("empty"));
        assert!(compile(&"x".repeat(MAX_LEAF_TEXT + 1)).is_err());
    }
}
