//! The ONNX Runtime library: opened once per process, on first use, from
//! [`library_path`] (ONNX Runtime's C API through the `ort` crate's `load-dynamic`).

use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

/// The environment variable naming the ONNX Runtime library to open
/// (`libonnxruntime.so.1.32.0` or a compatible 1.2x–1.3x release).
pub const LIBRARY_VAR: &str = "MACROTREE_ONNXRUNTIME";

/// The library tools/bootstrap extracts, set at build time (`.cargo/config.toml`).
const BUILT_IN: Option<&str> = option_env!("MACROTREE_ONNXRUNTIME_DEFAULT");

static OVERRIDE: Mutex<Option<PathBuf>> = Mutex::new(None);
static ENVIRONMENT: OnceLock<Result<ort::environment::Environment, String>> = OnceLock::new();

/// Names the library to open before the first model loads (the Python package passes the
/// `onnxruntime` wheel's). Without it: [`LIBRARY_VAR`], else the bootstrapped one.
pub fn set_library_path(path: PathBuf) {
    if let Ok(mut o) = OVERRIDE.lock() {
        *o = Some(path);
    }
}

/// The ONNX Runtime library this process opens: [`set_library_path`]'s, else [`LIBRARY_VAR`]'s,
/// else the one tools/bootstrap extracted; `None` when none is known.
pub fn library_path() -> Option<PathBuf> {
    if let Some(p) = OVERRIDE.lock().ok().and_then(|o| o.clone()) {
        return Some(p);
    }
    if let Some(p) = std::env::var_os(LIBRARY_VAR).filter(|p| !p.is_empty()) {
        return Some(PathBuf::from(p));
    }
    BUILT_IN.map(PathBuf::from)
}

/// The process's ONNX Runtime environment, the library opened on the first call; an error that
/// says what to do when it cannot be opened (the same error on every later call).
pub(super) fn environment() -> Result<&'static ort::environment::Environment, String> {
    ENVIRONMENT
        .get_or_init(|| {
            let help = format!(
                "run tools/bootstrap (it fetches the pinned onnxruntime 1.32.0 wheel from PyPI), or set {LIBRARY_VAR} to a libonnxruntime.so"
            );
            let Some(path) = library_path() else {
                return Err(format!("no ONNX Runtime library is known: {help}"));
            };
            if !path.is_file() {
                return Err(format!(
                    "the ONNX Runtime library {} does not exist: {help}",
                    path.display()
                ));
            }
            ort::init_from(&path)
                .map_err(|e| format!("cannot open the ONNX Runtime library {}: {e}; {help}", path.display()))?
                .with_name("macrotree")
                .with_telemetry(false)
                .build()
                .map_err(|e| format!("ONNX Runtime did not start: {e}"))
        })
        .as_ref()
        .map_err(Clone::clone)
}
