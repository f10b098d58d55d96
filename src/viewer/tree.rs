//! The server's copy of the scene: the latest state per path, replayed to a browser that joins
//! late. Never a growing history: each path keeps its last object, its last transform and its
//! properties keyed by name (latest wins); `delete` prunes the subtree.

use std::collections::BTreeMap;

use tungstenite::Bytes;

use super::proto::normalize_path;

/// Stored, pre-encoded messages of one path.
#[derive(Debug, Default, Clone)]
struct Node {
    object: Option<Bytes>,
    transform: Option<Bytes>,
    props: BTreeMap<String, Bytes>,
}

impl Node {
    fn is_empty(&self) -> bool {
        self.object.is_none() && self.transform.is_none() && self.props.is_empty()
    }
}

/// Latest state per path, as encoded MeshCat commands.
#[derive(Debug, Default, Clone)]
pub struct SceneTree {
    nodes: BTreeMap<String, Node>,
    animation: Option<Bytes>,
}

impl SceneTree {
    /// An empty tree.
    pub fn new() -> Self {
        Self::default()
    }

    fn node(&mut self, path: &str) -> &mut Node {
        self.nodes.entry(normalize_path(path)).or_default()
    }

    /// Stores a `set_object` at `path`: replaces the previous object there and drops the
    /// properties stored for the old object (`path/<object>`). The transform and children stay.
    pub fn set_object(&mut self, path: &str, msg: Bytes) {
        let path = normalize_path(path);
        let object_path = normalize_path(&format!("{path}/<object>"));
        if let Some(node) = self.nodes.get_mut(&object_path) {
            node.props.clear();
            if node.is_empty() {
                self.nodes.remove(&object_path);
            }
        }
        self.node(&path).object = Some(msg);
    }

    /// Stores a `set_transform` at `path` (latest wins).
    pub fn set_transform(&mut self, path: &str, msg: Bytes) {
        // Keys are normalized, so an exact hit is the path's node (the per-frame case: no
        // allocation).
        if let Some(node) = self.nodes.get_mut(path) {
            node.transform = Some(msg);
            return;
        }
        self.node(path).transform = Some(msg);
    }

    /// Stores a `set_property` of `property` at `path` (latest wins per property).
    pub fn set_property(&mut self, path: &str, property: &str, msg: Bytes) {
        self.node(path).props.insert(property.to_owned(), msg);
    }

    /// Removes `path` and everything below it.
    pub fn delete(&mut self, path: &str) {
        let path = normalize_path(path);
        if path == "/" {
            self.nodes.clear();
            return;
        }
        let prefix = format!("{path}/");
        self.nodes.retain(|k, _| k != &path && !k.starts_with(&prefix));
    }

    /// Stores the animation (one at a time; a new one replaces it).
    pub fn set_animation(&mut self, msg: Bytes) {
        self.animation = Some(msg);
    }

    /// Number of stored paths.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty() && self.animation.is_none()
    }

    /// Whether anything is stored at exactly `path`.
    pub fn contains(&self, path: &str) -> bool {
        self.nodes.contains_key(&normalize_path(path))
    }

    /// The stored transform message at `path`.
    pub fn transform(&self, path: &str) -> Option<&Bytes> {
        self.nodes.get(&normalize_path(path))?.transform.as_ref()
    }

    /// The stored object message at `path`.
    pub fn object(&self, path: &str) -> Option<&Bytes> {
        self.nodes.get(&normalize_path(path))?.object.as_ref()
    }

    /// The stored property message `property` at `path`.
    pub fn property(&self, path: &str, property: &str) -> Option<&Bytes> {
        self.nodes.get(&normalize_path(path))?.props.get(property)
    }

    /// Every stored message in replay order: paths in order (parents before children), per path
    /// object, transform, then properties by name; the animation last.
    pub fn snapshot(&self) -> Vec<Bytes> {
        let mut out = Vec::new();
        for node in self.nodes.values() {
            out.extend(node.object.iter().cloned());
            out.extend(node.transform.iter().cloned());
            out.extend(node.props.values().cloned());
        }
        out.extend(self.animation.iter().cloned());
        out
    }

    /// Total size of [`SceneTree::snapshot`] in bytes.
    pub fn snapshot_bytes(&self) -> usize {
        self.snapshot().iter().map(|m| m.len()).sum()
    }
}
