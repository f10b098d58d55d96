//! Results as Python values: observations as dicts of numpy arrays, step results as
//! `{"obs", "reward", "terminated", "truncated", "info"}` with Python bools and floats.

use macrotree::env::{Observation, StepResult};
use numpy::{IntoPyArray, PyArray1, PyArray3, PyArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Camera images to add to an observation under `pixels`, by camera name (H×W×3 bytes).
pub type Pixels = Vec<(String, u32, u32, Vec<u8>)>;

/// The Gymnasium observation: `agent_pos`, `environment_state`, `pinch` (float32), and `pixels`.
pub fn observation<'py>(py: Python<'py>, o: &Observation, pixels: Pixels) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(intern!(py, "agent_pos"), PyArray1::from_slice(py, &o.state()))?;
    d.set_item(
        intern!(py, "environment_state"),
        PyArray1::from_slice(py, &o.environment_state()),
    )?;
    d.set_item(intern!(py, "pinch"), PyArray1::from_slice(py, &o.pinch()))?;
    if !pixels.is_empty() {
        let images = PyDict::new(py);
        for (name, w, h, rgb) in pixels {
            let array = rgb.into_pyarray(py).reshape([h as usize, w as usize, 3])?;
            let array: Bound<'py, PyArray3<u8>> = array;
            images.set_item(name, array)?;
        }
        d.set_item(intern!(py, "pixels"), images)?;
    }
    Ok(d)
}

/// The full typed observation: [`Observation`]'s serde form as Python values (mappings as
/// dicts, `objects` keyed by name, fixed-size vectors as tuples, lists as lists), so its keys
/// and layout are the Rust type's.
pub fn full_observation<'py>(py: Python<'py>, o: &Observation) -> PyResult<Bound<'py, PyAny>> {
    Ok(pythonize::pythonize(py, o)?)
}

/// The info of a reset: success so far, the goal predicates, grasped flags.
pub fn reset_info<'py>(
    py: Python<'py>,
    o: &Observation,
    goal: &[macrotree::world::goal::GoalValue],
) -> PyResult<Bound<'py, PyDict>> {
    let info = PyDict::new(py);
    let success = !goal.is_empty() && goal.iter().all(|g| g.holds);
    info.set_item(intern!(py, "is_success"), success)?;
    info.set_item(intern!(py, "goal"), goal_dict(py, goal)?)?;
    info.set_item(intern!(py, "grasped"), grasped(py, o)?)?;
    info.set_item(intern!(py, "episode_sim_time"), o.time)?;
    Ok(info)
}

fn goal_dict<'py>(
    py: Python<'py>,
    goal: &[macrotree::world::goal::GoalValue],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for g in goal {
        d.set_item(&g.predicate, g.holds)?;
    }
    Ok(d)
}

fn grasped<'py>(py: Python<'py>, o: &Observation) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for ob in &o.objects {
        d.set_item(&ob.name, ob.grasped)?;
    }
    Ok(d)
}

/// A step's result as `{"obs", "reward", "terminated", "truncated", "info"}`.
pub fn step_result<'py>(py: Python<'py>, r: &StepResult, pixels: Pixels) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item(intern!(py, "obs"), observation(py, &r.observation, pixels)?)?;
    out.set_item(intern!(py, "reward"), r.reward)?;
    out.set_item(intern!(py, "terminated"), r.terminated)?;
    out.set_item(intern!(py, "truncated"), r.truncated)?;
    let info = reset_info(py, &r.observation, &r.goal)?;
    info.set_item(
        intern!(py, "status"),
        if r.success() { "success" } else { "failure" },
    )?;
    let f = r.failure.as_ref();
    info.set_item(intern!(py, "failure_kind"), f.map(|f| f.kind.as_str()))?;
    info.set_item(intern!(py, "failure_message"), f.map(|f| f.message.as_str()))?;
    info.set_item(intern!(py, "failure_node"), f.and_then(|f| f.node.as_deref()))?;
    info.set_item(intern!(py, "sim_time"), r.sim_time)?;
    info.set_item(intern!(py, "physics_steps"), r.physics_steps)?;
    info.set_item(intern!(py, "ctrl_clamped"), r.ctrl_clamped)?;
    if let Some(base) = &r.base {
        info.set_item(
            intern!(py, "base_action"),
            PyArray1::from_slice(py, &base.command),
        )?;
        info.set_item(intern!(py, "base_status"), tree_status(base.status))?;
    }
    info.set_item(intern!(py, "goal_steps"), r.goal_ticks)?;
    let collisions: Vec<&str> = r.collisions.iter().map(|c| c.what.as_str()).collect();
    info.set_item(intern!(py, "collisions"), collisions)?;
    info.set_item(intern!(py, "faults"), r.faults_fired.clone())?;
    if !r.rewards.is_empty() {
        info.set_item(intern!(py, "rewards"), PyArray1::from_slice(py, &r.rewards))?;
    }
    out.set_item(intern!(py, "info"), info)?;
    Ok(out)
}

/// A tree's status as the info says it: `running`, `success` or `failure`.
pub fn tree_status(s: macrotree::runtime::TreeStatus) -> &'static str {
    match s {
        macrotree::runtime::TreeStatus::Running => "running",
        macrotree::runtime::TreeStatus::Success => "success",
        macrotree::runtime::TreeStatus::Failure => "failure",
    }
}
