//! Loading tree files: read, follow `include:`, collect subtrees, expand `main:`.

use std::collections::{HashMap, HashSet};

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::confine::{IncludeScope, parse_top_level};
use super::expand::{Expander, undefined_params};
use super::file::{SubtreeDef, TreeFile};
use super::node::Node;
use crate::kinds::Registry;
use crate::scene::SceneSpec;
use crate::yaml::diag::{Diagnostic, FileId, Issue, Loc, Sources};
use crate::yaml::read_limited;
use crate::yaml::suggest::closest;
use crate::yaml::value::{decode_utf8, parse_yaml};

/// Deepest chain of includes.
pub const MAX_INCLUDE_DEPTH: usize = 16;
/// Most files loaded for one tree.
pub const MAX_FILES: usize = 64;

/// A loaded, fully expanded tree with the sources it came from.
#[derive(Clone, Debug)]
pub struct Spec {
    /// The `main:` tree, subtrees expanded.
    pub root: Node,
    /// Every file read (the main file is id 0).
    pub sources: Sources,
    /// Every subtree definition found (main file and includes), in load order.
    pub subtrees: Vec<SubtreeDef>,
    /// The main file's `scene:` (path as written, relative to the main file) and its location.
    pub scene: Option<(String, Loc)>,
    /// The scene the tree's object names were checked against (the `--scene` override, the
    /// tree's `scene:`, or the built-in `cube_bowl`): the scene it runs on.
    pub scene_spec: Arc<SceneSpec>,
    /// The main file's `description:`.
    pub description: Option<String>,
    /// The main file's `breakpoints:`, for the live monitor.
    pub breakpoints: Vec<super::file::DeclaredBreakpoint>,
    /// Every object a leaf names or reads from the blackboard (checked against a scene by
    /// the loader when the tree is compiled).
    pub object_uses: Vec<super::check::ObjectUse>,
    /// Every blackboard variable a `select` or `for_each` writes.
    pub var_defs: Vec<super::check::VarDef>,
    /// The canonical paths of the files read from disk (main file, includes and the files leaves
    /// name, such as a `policy`'s model), sorted.
    pub files: Vec<PathBuf>,
    /// Warnings: accepted, but probably not what was meant (e.g. `yaw: 5`, read as 5 radians).
    pub warnings: Vec<Diagnostic>,
}

impl Spec {
    /// Every file the tree was read from: [`files`](Self::files), then the scene file its
    /// `scene:` names (relative to the main file's folder), if any.
    pub fn inputs(&self) -> Vec<PathBuf> {
        let mut inputs = self.files.clone();
        if let Some((rel, _)) = &self.scene {
            let main = Path::new(self.sources.name(0));
            inputs.push(main.parent().unwrap_or(Path::new(".")).join(rel));
        }
        inputs
    }
}

/// How a tree is read: the node kinds it may use, the scene its object names are checked
/// against, and where its includes may come from. [`crate::plan::Loader`] is the public face of
/// this.
#[derive(Clone, Debug)]
pub(crate) struct LoadOptions<'a> {
    /// The node kinds.
    pub registry: &'a Arc<Registry>,
    /// Check object names against this scene (a `--scene` override) instead of the tree's own
    /// `scene:` (or the built-in `cube_bowl`).
    pub scene: Option<Arc<SceneSpec>>,
    /// Let `include:` read files outside the main file's folder (see [`super::confine`]).
    pub includes_anywhere: bool,
}

/// Where the tree's text comes from.
pub(crate) enum Source<'a> {
    /// A file on disk (read with the limits of [`read_limited`]).
    File(&'a Path),
    /// Text; `name` appears in diagnostics and its folder (if any) is the base for relative
    /// `include:` paths.
    Text { text: &'a str, name: &'a str },
    /// Raw bytes (a file's content), treated exactly as a file's: invalid UTF-8 is a located
    /// error.
    Bytes { bytes: &'a [u8], name: &'a str },
}

/// Reads a tree, follows its includes, expands its subtrees and checks its object names.
pub(crate) fn load(opts: &LoadOptions<'_>, source: Source<'_>) -> Result<Spec, Vec<Diagnostic>> {
    let reader = || TreeReader {
        scene_override: opts.scene.clone(),
        registry: Some(opts.registry.clone()),
        includes_anywhere: opts.includes_anywhere,
        ..TreeReader::default()
    };
    let (bytes, name, path): (std::borrow::Cow<'_, [u8]>, String, &Path) = match source {
        Source::Text { text, name } => {
            let mut l = reader();
            let path = Path::new(name);
            if let Ok(c) = path.canonicalize() {
                l.loaded.insert(c);
            }
            return l.finish(text, name, path.parent(), false);
        }
        Source::File(path) => match read_limited(path) {
            Ok(bytes) => (bytes.into(), path.display().to_string(), path),
            Err((msg, help)) => {
                let mut l = TreeReader::default();
                let id = l.sources.add(path.display().to_string(), "");
                l.issues.push(Issue::new(Loc::file_start(id), msg).help(help));
                return Err(l.sources.diagnostics(&l.issues));
            }
        },
        Source::Bytes { bytes, name } => (bytes.into(), name.to_string(), Path::new(name)),
    };
    let mut l = reader();
    let text = match std::str::from_utf8(&bytes) {
        Ok(t) => t,
        Err(_) => {
            let id = l
                .sources
                .add_file(Path::new(&name), String::from_utf8_lossy(&bytes).into_owned());
            let issue = decode_utf8(&bytes, id)
                .err()
                .unwrap_or_else(|| Issue::new(Loc::file_start(id), "not UTF-8"));
            l.issues.push(issue);
            return Err(l.sources.diagnostics(&l.issues));
        }
    };
    if let Ok(c) = path.canonicalize() {
        l.loaded.insert(c);
    }
    l.finish(text, &name, path.parent(), true)
}

#[derive(Default)]
struct TreeReader {
    sources: Sources,
    issues: Vec<Issue>,
    loaded: HashSet<PathBuf>,
    defs: Vec<SubtreeDef>,
    /// The scene to check object names against instead of the tree's own.
    scene_override: Option<Arc<SceneSpec>>,
    /// Diagnostics of a scene file the tree names (reported with the tree's).
    scene_diagnostics: Vec<Diagnostic>,
    scope: IncludeScope,
    /// The node kinds.
    registry: Option<Arc<Registry>>,
    /// Whether `include:` may read outside the main file's folder.
    includes_anywhere: bool,
}

/// The built-in `cube_bowl` scene, parsed once.
pub fn builtin_scene() -> Arc<SceneSpec> {
    static BUILTIN: std::sync::OnceLock<Arc<SceneSpec>> = std::sync::OnceLock::new();
    BUILTIN.get_or_init(|| Arc::new(SceneSpec::builtin())).clone()
}

impl TreeReader {
    /// Reads the main file `text` (named `name`; read from disk when `on_disk`, whose name
    /// then decides whether its lines may be quoted, [`Sources::add_file`]).
    fn finish(
        mut self,
        text: &str,
        name: &str,
        base: Option<&Path>,
        on_disk: bool,
    ) -> Result<Spec, Vec<Diagnostic>> {
        self.scope = IncludeScope::for_base(base, self.includes_anywhere);
        let mut warnings = Vec::new();
        let id = if on_disk {
            self.sources.add_file(Path::new(name), text)
        } else {
            self.sources.add(name, text)
        };
        let root_file = match parse_yaml(text, id).map(|v| parse_top_level(&v, &mut self.issues)) {
            Ok((Some(f), true)) => f,
            Ok((_, is_tree)) => {
                if !is_tree {
                    self.sources.withhold(id);
                }
                return Err(self.sources.diagnostics(&self.issues));
            }
            Err(issue) => {
                self.issues.push(issue);
                return Err(self.sources.diagnostics(&self.issues));
            }
        };
        self.collect(&root_file, base, 0);
        let main = match (&root_file.main, root_file.main_key) {
            (Some(m), _) => m.clone(),
            _ => {
                self.issues.push(
                    Issue::new(Loc::file_start(id), "the file has no `main:` tree")
                        .label("expected `main: <node>`")
                        .help("add `main:` with the root node; files that only define subtrees are included with `include:`"),
                );
                return Err(self.sources.diagnostics(&self.issues));
            }
        };

        // Subtree table (duplicates are errors).
        let mut table: HashMap<String, SubtreeDef> = HashMap::new();
        for d in &self.defs {
            if let Some(first) = table.get(&d.name) {
                self.issues.push(
                    Issue::new(d.loc, format!("subtree `{}` is defined twice", d.name))
                        .label("second definition")
                        .note(format!("first defined at {}", self.sources.describe(first.loc)))
                        .help("rename one of them"),
                );
            } else {
                table.insert(d.name.clone(), d.clone());
            }
        }

        // `$params` must be declared, and only used inside subtrees.
        for d in &self.defs {
            let names: Vec<&str> = d.params.iter().map(|p| p.name.as_str()).collect();
            let mut undefined = Vec::new();
            undefined_params(&d.root, &names, &mut undefined);
            for (p, loc) in undefined {
                let label = if names.is_empty() {
                    format!("subtree `{}` declares no parameters", d.name)
                } else {
                    format!(
                        "declared parameters: {}",
                        names
                            .iter()
                            .map(|n| format!("`${n}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                };
                self.issues.push(
                    Issue::new(loc, format!("undefined parameter `${p}` in subtree `{}`", d.name))
                        .label(label)
                        .maybe_help(
                            closest(p, names.iter().copied()).map(|c| format!("did you mean `${c}`?")),
                        )
                        .help_or(format!("declare it: `params: {{{p}: <default or ~>}}`")),
                );
            }
        }
        let mut in_main = Vec::new();
        undefined_params(&main, &[], &mut in_main);
        for (p, loc) in in_main {
            self.issues.push(
                Issue::new(loc, format!("`${p}` is used outside a subtree"))
                    .label("parameters only exist inside `subtrees:` bodies")
                    .help("write the value itself here, or move this part into a subtree with `params:`"),
            );
        }

        let reported: Vec<Loc> = self.issues.iter().map(|i| i.loc).collect();
        let registry = self
            .registry
            .clone()
            .unwrap_or_else(|| Arc::new(Registry::builtin()));
        let mut ex = Expander::new(&registry, &table, &self.sources).with_scope(self.scope.clone());
        ex.reported.clone_from(&reported);
        let root = ex.node(&main, 0);
        self.loaded.extend(std::mem::take(&mut ex.leaf_files));
        let called: HashSet<String> = ex.calls.keys().cloned().collect();
        self.issues.append(&mut ex.issues);
        warnings.append(&mut ex.warnings);
        let object_uses = std::mem::take(&mut ex.object_uses);
        let var_defs = std::mem::take(&mut ex.var_defs);
        let scene = self.scene_for(&root_file, base);
        {
            let sources = &self.sources;
            let mut found = super::check::check_vars(&object_uses, &var_defs, |l| sources.describe(l));
            if let Some(scene) = &scene {
                found.extend(super::check::check_scene(&object_uses, scene, |l| {
                    sources.describe(l)
                }));
            }
            self.issues.append(&mut found);
        }

        // Check unused subtrees that can be expanded with defaults alone.
        let mut names: Vec<&String> = table.keys().collect();
        names.sort();
        for n in names {
            let d = &table[n];
            if called.contains(n) || d.params.iter().any(|p| p.default.is_none()) {
                continue;
            }
            let mut ex = Expander::new(&registry, &table, &self.sources).with_scope(self.scope.clone());
            ex.reported.clone_from(&reported);
            let call = crate::yaml::value::Value::new(
                crate::yaml::value::ValueKind::Map(vec![(
                    crate::yaml::value::Value::new(
                        crate::yaml::value::ValueKind::Str("subtree".into()),
                        d.loc,
                    ),
                    crate::yaml::value::Value::new(
                        crate::yaml::value::ValueKind::Map(vec![(
                            crate::yaml::value::Value::new(
                                crate::yaml::value::ValueKind::Str("ref".into()),
                                d.loc,
                            ),
                            crate::yaml::value::Value::new(
                                crate::yaml::value::ValueKind::Str(n.clone()),
                                d.loc,
                            ),
                        )]),
                        d.loc,
                    ),
                )]),
                d.loc,
            );
            let _ = ex.node(&call, 0);
            self.issues.append(&mut ex.issues);
            warnings.append(&mut ex.warnings);
        }

        match root {
            Some(root) if self.issues.is_empty() => {
                let mut files: Vec<PathBuf> = self.loaded.into_iter().collect();
                files.sort();
                let warnings = self.sources.warnings(&warnings);
                let breakpoints = root_file
                    .breakpoints
                    .iter()
                    .map(|(text, loc)| super::file::DeclaredBreakpoint {
                        text: text.clone(),
                        file: self.sources.name(loc.file).to_string(),
                        line: loc.line,
                        column: loc.col,
                    })
                    .collect();
                Ok(Spec {
                    root,
                    sources: self.sources,
                    subtrees: self.defs,
                    scene: root_file.scene.clone(),
                    scene_spec: scene.unwrap_or_else(builtin_scene),
                    description: root_file.description.clone(),
                    breakpoints,
                    object_uses,
                    var_defs,
                    files,
                    warnings,
                })
            }
            _ => {
                if self.issues.is_empty() {
                    self.issues
                        .push(Issue::new(Loc::file_start(id), "the tree could not be read"));
                }
                let mut diags = self.sources.diagnostics(&self.issues);
                diags.append(&mut self.scene_diagnostics);
                Err(diags)
            }
        }
    }

    /// The scene object names are checked against: the override, the tree's `scene:` (relative
    /// to the tree's folder), or the built-in scene. `None` when the named scene file is broken
    /// (its diagnostics are kept, and an issue points at `scene:`).
    fn scene_for(&mut self, file: &TreeFile, base: Option<&Path>) -> Option<Arc<SceneSpec>> {
        if let Some(s) = &self.scene_override {
            return Some(s.clone());
        }
        let Some((rel, loc)) = &file.scene else {
            return Some(builtin_scene());
        };
        let path = match base {
            Some(b) if !Path::new(rel).is_absolute() => b.join(rel),
            _ => PathBuf::from(rel),
        };
        // The include rule: a scene outside the tree's folder is refused before it is opened.
        if let Err(issue) = super::confine::check_scene_path(&self.scope, base, &path, rel, *loc) {
            self.issues.push(issue);
            return None;
        }
        match crate::scene::load_scene_file(&path) {
            Ok(s) => Some(Arc::new(s)),
            Err(diags) => {
                self.issues.push(
                    Issue::new(
                        *loc,
                        format!("the scene `{rel}` is invalid ({} error(s), below)", diags.len()),
                    )
                    .label("the scene file named here")
                    .help("fix the scene file, or give another with `--scene FILE`"),
                );
                self.scene_diagnostics = diags;
                None
            }
        }
    }

    /// Record `file`'s subtrees and load its includes (recursively).
    fn collect(&mut self, file: &TreeFile, base: Option<&Path>, depth: usize) {
        self.defs.extend(file.subtrees.iter().cloned());
        for inc in &file.includes {
            let rel = Path::new(&inc.path);
            let path = match base {
                Some(b) if !rel.is_absolute() => b.join(rel),
                _ => rel.to_path_buf(),
            };
            if depth + 1 > MAX_INCLUDE_DEPTH {
                self.issues.push(
                    Issue::new(
                        inc.loc,
                        format!("includes are nested more than {MAX_INCLUDE_DEPTH} deep"),
                    )
                    .help("flatten the include chain"),
                );
                continue;
            }
            if self.sources.len() >= MAX_FILES {
                self.issues.push(
                    Issue::new(inc.loc, format!("more than {MAX_FILES} files are included"))
                        .help("merge small libraries"),
                );
                continue;
            }
            if let Err(issue) = self.scope.check_spelling(base, rel, inc.loc) {
                self.issues.push(issue);
                continue;
            }
            let canon = match path.canonicalize() {
                Ok(c) => c,
                Err(e) => {
                    self.issues.push(
                        Issue::new(inc.loc, format!("cannot include `{}`: {e}", path.display()))
                            .label("expected a path relative to this file's folder")
                            .help("check the file name; include paths are relative to the file that includes them"),
                    );
                    continue;
                }
            };
            if let Err(issue) = self.scope.check_resolved(&canon, rel, inc.loc) {
                self.issues.push(issue);
                continue;
            }
            if !self.loaded.insert(canon) {
                continue; // already loaded (diamond or cycle): its subtrees are known
            }
            let bytes = match read_limited(&path) {
                Ok(b) => b,
                Err((msg, help)) => {
                    self.issues.push(Issue::new(inc.loc, msg).help(help));
                    continue;
                }
            };
            let id: FileId;
            let text = match String::from_utf8(bytes) {
                Ok(t) => {
                    id = self.sources.add_file(&path, t.as_str());
                    t
                }
                Err(e) => {
                    id = self
                        .sources
                        .add_file(&path, String::from_utf8_lossy(e.as_bytes()).into_owned());
                    if let Err(issue) = decode_utf8(e.as_bytes(), id) {
                        self.issues.push(issue);
                    }
                    continue;
                }
            };
            match parse_yaml(&text, id) {
                Ok(v) => {
                    // A library's own `main:` is ignored (it can be a demo of its subtrees).
                    match parse_top_level(&v, &mut self.issues) {
                        (Some(f), true) => self.collect(&f, path.parent(), depth + 1),
                        (_, is_tree) => {
                            if !is_tree {
                                self.sources.withhold(id);
                            }
                        }
                    }
                }
                Err(issue) => self.issues.push(issue),
            }
        }
    }
}
