//! [`Loader`]: the one way to read, validate and compile a tree.

use std::path::Path;
use std::sync::Arc;

use super::{Plan, compile_spec};
use crate::kinds::Registry;
use crate::scene::SceneSpec;
use crate::spec::{LoadOptions, Source, load};
use crate::yaml::Diagnostic;

/// Reads, validates and compiles trees: which node kinds they may use ([`Registry`]) and where
/// their `include:`s may come from. Each tree file is parsed once; the [`Plan`] holds everything
/// a command needs afterwards (its scene, the files it read, its warnings).
///
/// ```
/// use macrotree::plan::Loader;
/// let plan = Loader::default()
///     .compile_str("main: {sequence: {children: [{home: {}}, {at_home: {}}]}}", "t.yaml")
///     .unwrap();
/// assert_eq!(plan.leaves.len(), 2);
/// ```
#[derive(Clone, Debug)]
pub struct Loader {
    registry: Arc<Registry>,
    includes_anywhere: bool,
}

impl Default for Loader {
    /// The built-in node kinds; includes confined to the main file's folder.
    fn default() -> Self {
        Self::new(Arc::new(Registry::builtin()))
    }
}

impl Loader {
    /// A loader for the node kinds of `registry`, with includes confined to the main file's
    /// folder (see `docs/security.md`).
    pub fn new(registry: Arc<Registry>) -> Self {
        Self {
            registry,
            includes_anywhere: false,
        }
    }

    /// Lets `include:` read files outside the main file's folder (`true`; the command line's
    /// `--allow-include-outside`) or not (`false`, the default).
    pub fn includes_anywhere(mut self, allow: bool) -> Self {
        self.includes_anywhere = allow;
        self
    }

    /// Whether `include:` may read files outside the main file's folder.
    pub fn allows_includes_anywhere(&self) -> bool {
        self.includes_anywhere
    }

    /// The node kinds trees may use.
    pub fn registry(&self) -> &Arc<Registry> {
        &self.registry
    }

    fn options(&self, scene: Option<Arc<SceneSpec>>) -> LoadOptions<'_> {
        LoadOptions {
            registry: &self.registry,
            scene,
            includes_anywhere: self.includes_anywhere,
        }
    }

    /// Reads, validates and compiles the tree file at `path` (following its includes), for its
    /// own `scene:` (or the built-in `cube_bowl` scene when it names none).
    ///
    /// # Errors
    /// Every problem, located (`file:line:column`), in source order.
    pub fn load(&self, path: &Path) -> Result<Plan, Vec<Diagnostic>> {
        self.load_for(path, None)
    }

    /// Like [`load`](Self::load), checked against and run on `scene` (a `--scene` override)
    /// when given instead of the tree's own `scene:`.
    ///
    /// # Errors
    /// As for [`load`](Self::load).
    pub fn load_for(&self, path: &Path, scene: Option<Arc<SceneSpec>>) -> Result<Plan, Vec<Diagnostic>> {
        compile_spec(&load(&self.options(scene), Source::File(path))?)
    }

    /// Reads, validates and compiles a tree from text. `file_name` appears in diagnostics, and
    /// its folder (if any) is the base for relative `include:` paths.
    ///
    /// # Errors
    /// As for [`load`](Self::load).
    pub fn compile_str(&self, text: &str, file_name: &str) -> Result<Plan, Vec<Diagnostic>> {
        compile_spec(&load(
            &self.options(None),
            Source::Text {
                text,
                name: file_name,
            },
        )?)
    }

    /// Like [`compile_str`](Self::compile_str), with object names checked against and run on
    /// `scene` when given (instead of the tree's own `scene:` or the built-in `cube_bowl`).
    ///
    /// # Errors
    /// As for [`load`](Self::load).
    pub fn compile_str_for(
        &self,
        text: &str,
        file_name: &str,
        scene: Option<Arc<SceneSpec>>,
    ) -> Result<Plan, Vec<Diagnostic>> {
        compile_spec(&load(
            &self.options(scene),
            Source::Text {
                text,
                name: file_name,
            },
        )?)
    }

    /// Reads, validates and compiles a tree from raw bytes (a file's content), as
    /// [`load`](Self::load) treats what it read: invalid UTF-8 is a located error. The entry
    /// point of the loader's fuzz target (`fuzz/`).
    ///
    /// # Errors
    /// As for [`load`](Self::load).
    pub fn compile_bytes(&self, bytes: &[u8], file_name: &str) -> Result<Plan, Vec<Diagnostic>> {
        compile_spec(&load(
            &self.options(None),
            Source::Bytes {
                bytes,
                name: file_name,
            },
        )?)
    }
}
