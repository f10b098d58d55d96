//! A checked ONNX policy: its inputs matched to [`Feature`]s, its action output, its metadata —
//! loaded once per process (by file, its size and modification time) and shared by every leaf
//! and worker, each running it on a session of its own.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::SystemTime;

use ort::session::Session;
use ort::value::{Tensor, TensorElementType, ValueType};

use super::features::Feature;
use super::layout::{ActionLayout, ModelAction};
use super::metadata::{ACTION_NAME, ActionMode, Metadata, Normalization};
use super::runtime::environment;

/// Most models kept loaded at once; loading one more forgets the others.
const MAX_CACHED: usize = 16;

/// One model input: the feature it takes and how many values.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInput {
    /// The model's own input name.
    pub name: String,
    /// The feature it is fed.
    pub feature: Feature,
    /// Values (the second dimension of `[1, n]`).
    pub len: usize,
    /// Its statistics, from the metadata.
    pub normalization: Option<Normalization>,
}

/// What a model takes and returns.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    /// Its inputs, in the model's order.
    pub inputs: Vec<ModelInput>,
    /// The name of its action output (its first output).
    pub output: String,
    /// `None` for a single action `[1, n]`; the chunk length for `[1, k, n]` (`None` inside
    /// when `k` is dynamic).
    pub chunk: Option<Option<usize>>,
    /// What an action holds (`n`: 7 or 19 values).
    pub layout: ActionLayout,
    /// What the joint values mean.
    pub mode: ActionMode,
    /// The time between two calls the model declares, seconds.
    pub period: Option<f64>,
    /// The action's statistics (undone on the output).
    pub action_normalization: Option<Normalization>,
}

/// A loaded, checked model.
pub struct PolicyModel {
    /// Where it was read from.
    pub path: PathBuf,
    /// What it takes and returns.
    pub info: ModelInfo,
    bytes: Vec<u8>,
    idle: Mutex<Vec<Session>>,
}

impl std::fmt::Debug for PolicyModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PolicyModel")
            .field("path", &self.path)
            .field("info", &self.info)
            .finish_non_exhaustive()
    }
}

/// A file's identity for the cache: its size and modification time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stamp {
    len: u64,
    modified: Option<SystemTime>,
}

/// A loaded model and the identity of the file it came from.
#[derive(Clone)]
struct Cached {
    stamp: Stamp,
    model: Arc<PolicyModel>,
}

/// The loaded models, by canonical path.
type Cache = Mutex<HashMap<PathBuf, Cached>>;

fn cache() -> &'static Cache {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

/// Reads and checks the model at `path`, as the tree loader does for a `policy`'s `model:`
/// (the error says what is wrong and what to do).
///
/// # Errors
/// The runtime cannot open, the file cannot be read or parsed, or it does not fit
/// ([`PolicyModel::load`]).
pub fn check_model_file(path: &Path) -> Result<(), String> {
    PolicyModel::load(path).map(|_| ())
}

impl PolicyModel {
    /// The model at `path`, loaded on first use and shared afterwards (again when the file
    /// changed).
    ///
    /// # Errors
    /// When ONNX Runtime cannot be opened, the file cannot be read or is not an ONNX model, an
    /// input's name is not a known [`Feature`] or its shape does not fit it, the first output is
    /// not a float32 `[1, n]` or `[1, k, n]` (n = 7 or 19), or the metadata is malformed.
    pub fn load(path: &Path) -> Result<Arc<PolicyModel>, String> {
        let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let max = crate::spec::MAX_LEAF_FILE_BYTES;
        if meta.len() > max {
            return Err(format!(
                "{} has {} bytes; a model may have at most {max}",
                path.display(),
                meta.len()
            ));
        }
        let stamp = Stamp {
            len: meta.len(),
            modified: meta.modified().ok(),
        };
        let key = path.to_path_buf();
        if let Some(hit) = cache().lock().ok().and_then(|c| c.get(&key).cloned())
            && hit.stamp == stamp
        {
            return Ok(hit.model);
        }
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let session = new_session(&bytes)?;
        let info = inspect(&session)?;
        let model = Arc::new(PolicyModel {
            path: key.clone(),
            info,
            bytes,
            idle: Mutex::new(vec![session]),
        });
        if let Ok(mut c) = cache().lock() {
            if c.len() >= MAX_CACHED {
                c.clear();
            }
            c.insert(
                key,
                Cached {
                    stamp,
                    model: model.clone(),
                },
            );
        }
        Ok(model)
    }

    /// A session to run the model on, of this model's idle ones or a new one; give it back with
    /// [`Self::give_back`].
    pub(super) fn session(&self) -> Result<Session, String> {
        match self.idle.lock().ok().and_then(|mut v| v.pop()) {
            Some(s) => Ok(s),
            None => new_session(&self.bytes),
        }
    }

    /// Returns a session taken with [`Self::session`].
    pub(super) fn give_back(&self, session: Session) {
        if let Ok(mut v) = self.idle.lock() {
            v.push(session);
        }
    }

    /// Runs the model once on `inputs` (one vector per [`ModelInfo::inputs`], in order, not yet
    /// normalised), as a `policy` leaf does: the actions, un-normalised, one per chunk step, each
    /// in the model's own layout ([`ModelInfo::layout`]). For checking an exported model against
    /// the network it came from.
    ///
    /// # Errors
    /// An input of the wrong length, or the model failing to run.
    pub fn evaluate(&self, inputs: Vec<Vec<f32>>) -> Result<Vec<Vec<f32>>, String> {
        if inputs.len() != self.info.inputs.len() {
            return Err(format!(
                "the model takes {} inputs, {} were given",
                self.info.inputs.len(),
                inputs.len()
            ));
        }
        for (spec, values) in self.info.inputs.iter().zip(&inputs) {
            if values.len() != spec.len {
                return Err(format!(
                    "input `{}` takes {} values, {} were given",
                    spec.name,
                    spec.len,
                    values.len()
                ));
            }
        }
        let mut session = self.session()?;
        let out = self.run(&mut session, inputs);
        self.give_back(session);
        let layout = self.info.layout;
        out.map(|actions| actions.iter().map(|a| layout.compact(a)).collect())
    }

    /// Runs the model on `inputs` (one vector per [`ModelInfo::inputs`], in order, not yet
    /// normalised): the actions, un-normalised, one per chunk step.
    pub(super) fn run(
        &self,
        session: &mut Session,
        inputs: Vec<Vec<f32>>,
    ) -> Result<Vec<ModelAction>, String> {
        let mut feed = Vec::with_capacity(inputs.len());
        for (spec, mut values) in self.info.inputs.iter().zip(inputs) {
            if let Some(n) = &spec.normalization {
                n.apply(&mut values);
            }
            let tensor = Tensor::from_array(([1usize, values.len()], values))
                .map_err(|e| format!("input `{}`: {e}", spec.name))?;
            feed.push((spec.name.as_str(), tensor));
        }
        let outputs = session
            .run(feed)
            .map_err(|e| format!("the model failed to run: {e}"))?;
        let value = outputs
            .get(&self.info.output)
            .ok_or_else(|| format!("the model returned no `{}`", self.info.output))?;
        let (shape, data) = value
            .try_extract_tensor::<f32>()
            .map_err(|e| format!("output `{}`: {e}", self.info.output))?;
        let layout = self.info.layout;
        let n = layout.width() as i64;
        let steps = match shape.len() {
            2 if shape[0] == 1 && shape[1] == n => 1,
            3 if shape[0] == 1 && shape[2] == n && shape[1] >= 1 => shape[1] as usize,
            _ => {
                return Err(format!(
                    "output `{}` has shape {:?}; expected [1, {n}] or [1, k, {n}]",
                    self.info.output,
                    &shape[..]
                ));
            }
        };
        let mut actions = Vec::with_capacity(steps);
        let mut values = vec![0f32; layout.width()];
        for chunk in data.chunks_exact(layout.width()).take(steps) {
            values.copy_from_slice(chunk);
            if let Some(n) = &self.info.action_normalization {
                n.invert(&mut values);
            }
            actions.push(layout.expand(&values));
        }
        Ok(actions)
    }
}

fn new_session(bytes: &[u8]) -> Result<Session, String> {
    let env = environment()?;
    Session::builder(env)
        .and_then(|b| b.with_intra_threads(1).map_err(Into::into))
        .and_then(|mut b| b.commit_from_memory(bytes))
        .map_err(|e| format!("ONNX Runtime cannot load the model: {e}"))
}

/// A float32 tensor's shape, or why the outlet is not one.
fn float_shape(what: &str, ty: &ValueType) -> Result<Vec<i64>, String> {
    match ty {
        ValueType::Tensor {
            ty: TensorElementType::Float32,
            shape,
            ..
        } => Ok(shape.to_vec()),
        other => Err(format!("{what} is {other:?}; expected a float32 tensor")),
    }
}

fn inspect(session: &Session) -> Result<ModelInfo, String> {
    let meta = session
        .metadata()
        .map_err(|e| format!("cannot read the model's metadata: {e}"))?;
    let metadata = Metadata::read(|k| meta.custom(k))?;
    let mut normalization = metadata.normalization;
    let mut inputs = Vec::new();
    for outlet in session.inputs() {
        let name = outlet.name();
        let Some(feature) = Feature::named(name) else {
            let known: Vec<&str> = Feature::ALL.iter().map(|f| f.name()).collect();
            return Err(format!(
                "the model's input `{name}` is not a feature macrotree can feed; name each input after one of {}",
                known.join(", ")
            ));
        };
        let shape = float_shape(&format!("input `{name}`"), outlet.dtype())?;
        let len = match shape[..] {
            [b, n] if (b == 1 || b == -1) && n > 0 && feature.fits(n as usize) => n as usize,
            _ => {
                return Err(format!(
                    "input `{name}` has shape {shape:?}; expected [1, n] with n = {}",
                    feature.expected()
                ));
            }
        };
        let norm = normalization.remove(name);
        if let Some(n) = &norm
            && n.len() != len
        {
            return Err(format!(
                "the statistics of `{name}` have {} values; the input has {len}",
                n.len()
            ));
        }
        inputs.push(ModelInput {
            name: name.to_string(),
            feature,
            len,
            normalization: norm,
        });
    }
    if inputs.is_empty() {
        return Err("the model has no input".into());
    }
    let action_normalization = normalization.remove(ACTION_NAME);
    if let Some(extra) = normalization.keys().next() {
        return Err(format!(
            "the metadata has statistics for `{extra}`, which is not an input of the model (or `{ACTION_NAME}`)"
        ));
    }
    let Some(first) = session.outputs().first() else {
        return Err("the model has no output".into());
    };
    let shape = float_shape(&format!("output `{}`", first.name()), first.dtype())?;
    let layout_of = |n: i64| usize::try_from(n).ok().and_then(ActionLayout::of_len);
    let (layout, chunk) = match shape[..] {
        [b, n] if (b == 1 || b == -1) && layout_of(n).is_some() => (layout_of(n), None),
        [b, k, n] if (b == 1 || b == -1) && layout_of(n).is_some() && (k >= 1 || k == -1) => {
            (layout_of(n), Some((k >= 1).then_some(k as usize)))
        }
        _ => (None, None),
    };
    let Some(layout) = layout else {
        let [set, full] = ActionLayout::ALL.map(|l| (l.width(), l.describe()));
        return Err(format!(
            "the model's first output `{}` has shape {shape:?}; expected the action, [1, n] or a chunk [1, k, n], with n = {} ({}) or n = {} ({})",
            first.name(),
            set.0,
            set.1,
            full.0,
            full.1
        ));
    };
    if let Some(n) = &action_normalization
        && n.len() != layout.width()
    {
        return Err(format!(
            "the statistics of `{ACTION_NAME}` have {} values; the model's action has {}",
            n.len(),
            layout.width()
        ));
    }
    Ok(ModelInfo {
        inputs,
        output: first.name().to_string(),
        chunk,
        layout,
        mode: metadata.action,
        period: metadata.period,
        action_normalization,
    })
}
