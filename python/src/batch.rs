//! A vector environment's step results as columns, built once per batch: observations as
//! `(n, …)` arrays, rewards and flags as `(n,)` arrays, and the info in Gymnasium 1.x's vector
//! layout (each key an array over sub-environments with a `_key` mask; nested dicts batched the
//! same way). The Python side then only handles the sub-environments that ended.

use macrotree::env::StepResult;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use crate::convert::{Pixels, tree_status};

/// One column of an info: its values for every sub-environment and its `_key` mask (all set:
/// every sub-environment of a batch gives every key).
fn column<'py>(info: &Bound<'py, PyDict>, key: &str, values: Bound<'py, PyAny>, n: usize) -> PyResult<()> {
    info.set_item(key, values)?;
    info.set_item(format!("_{key}"), vec![true; n].into_pyarray(info.py()))
}

/// An object array of Python values.
fn objects<'py>(py: Python<'py>, values: Vec<Py<PyAny>>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, values).into_any()
}

/// `(n, width)` float32 array of `n` rows.
fn rows<'py>(py: Python<'py>, flat: Vec<f32>, n: usize) -> PyResult<Bound<'py, PyAny>> {
    let width = flat.len().checked_div(n).unwrap_or(0);
    Ok(flat.into_pyarray(py).reshape([n, width])?.into_any())
}

/// The batch `{"obs", "reward", "terminated", "truncated", "info"}` of `results` (one per
/// sub-environment stepped, in order) with their camera images `pixels`.
pub fn batch<'py>(
    py: Python<'py>,
    results: &[StepResult],
    pixels: Vec<Pixels>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = results.len();
    let obs = PyDict::new(py);
    let flat = |f: &dyn Fn(&StepResult) -> Vec<f32>| results.iter().flat_map(f).collect::<Vec<f32>>();
    obs.set_item(
        "agent_pos",
        rows(py, flat(&|r| r.observation.state().to_vec()), n)?,
    )?;
    obs.set_item(
        "environment_state",
        rows(py, flat(&|r| r.observation.environment_state()), n)?,
    )?;
    obs.set_item(
        "pinch",
        rows(
            py,
            flat(&|r| {
                let o = &r.observation;
                o.pinch_pos
                    .iter()
                    .chain(&o.pinch_quat)
                    .map(|&v| v as f32)
                    .collect()
            }),
            n,
        )?,
    )?;
    if pixels.first().is_some_and(|p| !p.is_empty()) {
        let images = PyDict::new(py);
        for c in 0..pixels[0].len() {
            let (name, w, h, _) = &pixels[0][c];
            let (w, h) = (*w as usize, *h as usize);
            let mut all = Vec::with_capacity(n * w * h * 3);
            for p in &pixels {
                all.extend_from_slice(&p[c].3);
            }
            images.set_item(name, all.into_pyarray(py).reshape([n, h, w, 3])?)?;
        }
        obs.set_item("pixels", images)?;
    }
    let out = PyDict::new(py);
    out.set_item("obs", obs)?;
    out.set_item(
        "reward",
        results
            .iter()
            .map(|r| r.reward)
            .collect::<Vec<f64>>()
            .into_pyarray(py),
    )?;
    out.set_item(
        "terminated",
        results
            .iter()
            .map(|r| r.terminated)
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    out.set_item(
        "truncated",
        results
            .iter()
            .map(|r| r.truncated)
            .collect::<Vec<bool>>()
            .into_pyarray(py),
    )?;
    out.set_item("info", info(py, results)?)?;
    Ok(out)
}

fn info<'py>(py: Python<'py>, results: &[StepResult]) -> PyResult<Bound<'py, PyDict>> {
    let n = results.len();
    let info = PyDict::new(py);
    let bools = |f: &dyn Fn(&StepResult) -> bool| {
        results
            .iter()
            .map(f)
            .collect::<Vec<bool>>()
            .into_pyarray(py)
            .into_any()
    };
    let floats = |f: &dyn Fn(&StepResult) -> f64| {
        results
            .iter()
            .map(f)
            .collect::<Vec<f64>>()
            .into_pyarray(py)
            .into_any()
    };
    let ints = |f: &dyn Fn(&StepResult) -> i64| {
        results
            .iter()
            .map(f)
            .collect::<Vec<i64>>()
            .into_pyarray(py)
            .into_any()
    };
    let strings = |f: &dyn Fn(&StepResult) -> Option<String>| {
        let v = results
            .iter()
            .map(|r| match f(r) {
                Some(s) => PyString::new(py, &s).into_any().unbind(),
                None => py.None(),
            })
            .collect();
        objects(py, v)
    };
    column(
        &info,
        "is_success",
        bools(&|r| !r.goal.is_empty() && r.goal.iter().all(|g| g.holds)),
        n,
    )?;
    let goal = PyDict::new(py);
    if let Some(first) = results.first() {
        for (k, g) in first.goal.iter().enumerate() {
            column(
                &goal,
                &g.predicate,
                bools(&|r| r.goal.get(k).is_some_and(|x| x.holds)),
                n,
            )?;
        }
    }
    column(&info, "goal", goal.into_any(), n)?;
    let grasped = PyDict::new(py);
    if let Some(first) = results.first() {
        for (k, o) in first.observation.objects.iter().enumerate() {
            column(
                &grasped,
                &o.name,
                bools(&|r| r.observation.objects.get(k).is_some_and(|x| x.grasped)),
                n,
            )?;
        }
    }
    column(&info, "grasped", grasped.into_any(), n)?;
    column(&info, "episode_sim_time", floats(&|r| r.observation.time), n)?;
    column(
        &info,
        "status",
        strings(&|r| Some(if r.success() { "success" } else { "failure" }.to_string())),
        n,
    )?;
    column(
        &info,
        "failure_kind",
        strings(&|r| r.failure.as_ref().map(|f| f.kind.as_str().to_string())),
        n,
    )?;
    column(
        &info,
        "failure_message",
        strings(&|r| r.failure.as_ref().map(|f| f.message.clone())),
        n,
    )?;
    column(
        &info,
        "failure_node",
        strings(&|r| r.failure.as_ref().and_then(|f| f.node.clone())),
        n,
    )?;
    column(&info, "sim_time", floats(&|r| r.sim_time), n)?;
    column(&info, "physics_steps", ints(&|r| r.physics_steps as i64), n)?;
    column(&info, "ctrl_clamped", ints(&|r| i64::from(r.ctrl_clamped)), n)?;
    let lists = |f: &dyn Fn(&StepResult) -> Vec<String>| -> PyResult<Bound<'py, PyAny>> {
        let v = results
            .iter()
            .map(|r| Ok(PyList::new(py, f(r))?.into_any().unbind()))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(objects(py, v))
    };
    if results.first().is_some_and(|r| r.base.is_some()) {
        let width = macrotree::motion::COMMAND_LEN;
        let flat: Vec<f64> = results
            .iter()
            .flat_map(|r| {
                r.base
                    .as_ref()
                    .map_or([f64::NAN; macrotree::motion::COMMAND_LEN], |b| b.command)
            })
            .collect();
        column(
            &info,
            "base_action",
            flat.into_pyarray(py).reshape([n, width])?.into_any(),
            n,
        )?;
        column(
            &info,
            "base_status",
            strings(&|r| r.base.as_ref().map(|b| tree_status(b.status).to_string())),
            n,
        )?;
    }
    column(&info, "goal_steps", ints(&|r| r.goal_ticks as i64), n)?;
    column(
        &info,
        "collisions",
        lists(&|r| r.collisions.iter().map(|c| c.what.clone()).collect())?,
        n,
    )?;
    column(&info, "faults", lists(&|r| r.faults_fired.clone())?, n)?;
    if results.iter().any(|r| !r.rewards.is_empty()) {
        let v = results
            .iter()
            .map(|r| r.rewards.clone().into_pyarray(py).into_any().unbind())
            .collect();
        column(&info, "rewards", objects(py, v), n)?;
    }
    Ok(info)
}
