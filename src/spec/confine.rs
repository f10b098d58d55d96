//! What `include:` may read, and how much of a file that is not a tree a diagnostic may show.
//!
//! An include must resolve (after `..` and symbolic links are resolved) to a file inside the
//! folder of the main tree file or one of its subfolders — the *tree folder*. Anything else
//! (`/etc/shadow`, `/proc/self/environ`, `../../secret.yaml`, a link pointing out of the folder)
//! is refused before it is opened, unless the loader allows it (`Loader::includes_anywhere`,
//! the command line's `--allow-include-outside`).
//!
//! A file that is not a tree (not a mapping, or a mapping without any of the tree keys) gets
//! one diagnostic at its start that quotes nothing of it.

use std::path::{Component, Path, PathBuf};

use super::file::{TOP_LEVEL_KEYS, TreeFile, parse_tree_file};
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::value::{Value, ValueKind};

/// The folder includes are confined to, fixed when a tree starts loading.
#[derive(Clone, Debug, Default)]
pub(crate) struct IncludeScope {
    /// The canonical tree folder; `None` when includes may read anywhere, or when the folder
    /// cannot be resolved (then every include is refused).
    root: Option<PathBuf>,
    anywhere: bool,
}

impl IncludeScope {
    /// The scope of a main file whose folder is `base` (`None` or empty: the current folder).
    pub(crate) fn for_base(base: Option<&Path>, anywhere: bool) -> Self {
        let dir = match base {
            Some(b) if !b.as_os_str().is_empty() => b,
            _ => Path::new("."),
        };
        Self {
            root: dir.canonicalize().ok(),
            anywhere,
        }
    }

    /// Checks `written` (the include as written, in a file whose folder is `base`) by its
    /// spelling alone, before anything outside the tree folder is touched.
    pub(crate) fn check_spelling(&self, base: Option<&Path>, written: &Path, loc: Loc) -> Result<(), Issue> {
        if self.anywhere {
            return Ok(());
        }
        let base = match base {
            Some(b) if !b.as_os_str().is_empty() => b,
            _ => Path::new("."),
        };
        match base.canonicalize() {
            Ok(b) => self.check_resolved(&lexical(&b.join(written)), written, loc),
            Err(_) => Ok(()), // the resolved path is checked once it exists
        }
    }

    /// Checks the canonical path `resolved` of the include written `written`.
    pub(crate) fn check_resolved(&self, resolved: &Path, written: &Path, loc: Loc) -> Result<(), Issue> {
        if self.anywhere {
            return Ok(());
        }
        match &self.root {
            Some(root) if resolved.starts_with(root) => Ok(()),
            root => Err(Issue::new(
                loc,
                format!("`{}` is outside the tree's folder", written.display()),
            )
            .label(match root {
                Some(r) => format!("includes may only read files under `{}`", r.display()),
                None => "the tree's folder cannot be resolved".to_string(),
            })
            .help(
                "move the library into the main tree file's folder (or a subfolder), or pass \
                 --allow-include-outside to read it anyway",
            )),
        }
    }
}

/// The folder beside a tree's folder whose YAML files a tree's `scene:` may name too.
pub const SCENES_DIR: &str = "scenes";

/// Checks a tree's `scene:` (written `rel`, at `path` once joined to the tree's folder `base`)
/// against the include rule — by spelling, then (when it exists) resolved — or, for a YAML
/// file, against the [`SCENES_DIR`] folder beside the tree's folder.
pub(crate) fn check_scene_path(
    scope: &IncludeScope,
    base: Option<&Path>,
    path: &Path,
    rel: &str,
    loc: Loc,
) -> Result<(), Issue> {
    let written = Path::new(rel);
    let checked = scope
        .check_spelling(base, written, loc)
        .and_then(|()| match path.canonicalize() {
            Ok(canon) => scope.check_resolved(&canon, written, loc),
            Err(_) => Ok(()), // missing: the scene loader says so
        });
    // The other place scenes live: the `scenes/` folder beside the tree's folder (the
    // repository's and the Python package's layout, `trees/` next to `scenes/`). Judged from the
    // tree's own location, never from the folder the command runs in.
    let yaml = written
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
    let beside = || {
        let tree_dir = match base {
            Some(b) if !b.as_os_str().is_empty() => b,
            _ => Path::new("."),
        };
        let Ok(tree_dir) = tree_dir.canonicalize() else {
            return false;
        };
        let Some(spelled) = tree_dir.parent().map(|p| p.join(SCENES_DIR)) else {
            return false;
        };
        let resolved = spelled.canonicalize().unwrap_or_else(|_| spelled.clone());
        // By spelling first (nothing outside is touched), then resolved when the file exists.
        lexical(&tree_dir.join(written)).starts_with(&spelled)
            && path.canonicalize().map_or(true, |c| c.starts_with(&resolved))
    };
    match checked {
        Ok(()) => Ok(()),
        Err(_) if yaml && beside() => Ok(()),
        Err(issue) => Err(
            Issue::new(loc, format!("the scene `{rel}` is outside the tree's folder"))
                .label(format!(
                    "{}, or YAML files under the `{SCENES_DIR}/` folder beside it",
                    issue
                        .label
                        .unwrap_or_default()
                        .replace("includes may", "a tree may")
                ))
                .help(
                    "move the scene file into the tree's folder (or a subfolder), give it with \
                 `--scene FILE`, or pass --allow-include-outside to read it anyway",
                ),
        ),
    }
}

/// Checks `written`, a path read back from a results file (a scenario file's path), against
/// the include rule with the current folder as the root: it must resolve inside
/// the current folder, unless `anywhere` (the command line's `--allow-include-outside`) allows
/// any path. `Err` says why.
#[cfg(feature = "cli")]
pub fn check_path_from_results(written: &Path, anywhere: bool) -> Result<(), String> {
    if anywhere {
        return Ok(());
    }
    let cwd = std::env::current_dir()
        .and_then(|d| d.canonicalize())
        .map_err(|e| format!("the current folder cannot be resolved: {e}"))?;
    let inside = lexical(&cwd.join(written)).starts_with(&cwd)
        && written.canonicalize().map_or(true, |c| c.starts_with(&cwd));
    if inside {
        Ok(())
    } else {
        Err(format!(
            "the results name `{}`, which is outside the current folder {}; run `report` from \
             the folder the results were written in, or pass --allow-include-outside to read it \
             anyway",
            written.display(),
            cwd.display()
        ))
    }
}

/// `path` with `.` and `..` resolved by spelling alone (no file system access).
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// Reads the top level of a file like [`parse_tree_file`], and returns whether it is a tree (a
/// mapping with a tree key or a plausible typo of one). A file that is not leaves exactly one
/// issue in `issues`, at its start, that quotes nothing of it (not even a key); the caller
/// withholds its text ([`Sources::withhold`]).
///
/// [`Sources::withhold`]: crate::yaml::Sources::withhold
pub(crate) fn parse_top_level(v: &Value, issues: &mut Vec<Issue>) -> (Option<TreeFile>, bool) {
    // A tree key, or a plausible typo of one (`subtree:`), says the file is meant as a tree.
    let is_tree = v.as_map().is_some_and(|entries| {
        entries.iter().any(|(k, _)| {
            k.as_str().is_some_and(|k| {
                TOP_LEVEL_KEYS.contains(&k)
                    || crate::yaml::suggest::closest(k, TOP_LEVEL_KEYS.iter().copied()).is_some()
            })
        })
    });
    if !is_tree {
        let message = match v.kind {
            ValueKind::Map(_) => format!(
                "this is not a tree file: it has none of {}",
                TOP_LEVEL_KEYS
                    .iter()
                    .map(|k| format!("`{k}:`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => format!(
                "a tree file must be a mapping, found {}",
                crate::yaml::value::kind_of(v)
            ),
        };
        issues.push(
            Issue::new(Loc::file_start(v.loc.file), message)
                .label("expected `main:` (and optionally `include:` and `subtrees:`)")
                .help("name a tree file (see docs/tree_format.md); nothing of this file is shown"),
        );
        return (None, false);
    }
    let mut found = Vec::new();
    let file = parse_tree_file(v, &mut found);
    issues.append(&mut found);
    (file, is_tree)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lexical_resolution() {
        assert_eq!(lexical(Path::new("/a/b/../../../etc/x")), Path::new("/etc/x"));
        assert_eq!(lexical(Path::new("/a/./b/c/../d")), Path::new("/a/b/d"));
    }

    #[test]
    fn a_scope_without_a_root_refuses_everything() {
        let scope = IncludeScope {
            root: None,
            anywhere: false,
        };
        let e = scope
            .check_resolved(Path::new("/x/y.yaml"), Path::new("y.yaml"), Loc::default())
            .unwrap_err();
        assert!(e.message.contains("outside"), "{}", e.message);
    }
}
