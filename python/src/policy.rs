//! A `policy` leaf's model, run from Python as the leaf runs it (to check an exported model
//! against the network it came from).

use std::collections::HashMap;
use std::path::Path;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use macrotree::actions::policy::PolicyModel;

/// Largest input vector accepted, values.
const MAX_VALUES: usize = 1 << 20;

/// Runs the ONNX model at `path` once on `inputs` (input name → values, not normalised), as a
/// `policy` leaf does: the actions, un-normalised, one list per chunk step in the model's own
/// layout (7 values: six joint set points in radians or offsets and the gripper command; or
/// 19: set points, velocities, accelerations and the gripper command).
#[pyfunction]
pub fn run_policy_model(
    py: Python<'_>,
    path: String,
    inputs: HashMap<String, Vec<f32>>,
) -> PyResult<Vec<Vec<f32>>> {
    if inputs.values().any(|v| v.len() > MAX_VALUES) {
        return Err(PyValueError::new_err(format!(
            "an input has more than {MAX_VALUES} values"
        )));
    }
    py.detach(move || {
        let model = PolicyModel::load(Path::new(&path))?;
        let mut ordered = Vec::with_capacity(model.info.inputs.len());
        let mut inputs = inputs;
        for spec in &model.info.inputs {
            let values = inputs
                .remove(&spec.name)
                .ok_or_else(|| format!("the model's input `{}` was not given", spec.name))?;
            ordered.push(values);
        }
        if let Some(extra) = inputs.keys().next() {
            return Err(format!("`{extra}` is not an input of the model"));
        }
        let actions = model.evaluate(ordered)?;
        Ok(actions)
    })
    .map_err(|e: String| PyValueError::new_err(e))
}
