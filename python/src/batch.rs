//! A vector environment's step results as columns, built once per batch: observations as
//! `(n, …)` arrays, rewards and flags as `(n,)` arrays, and the info in Gymnasium 1.x's vector
//! layout (each key an array over sub-environments with a `_key` mask; nested dicts batched the
//! same way). The Python side then only handles the sub-environments that ended.
//!
//! This runs on the calling thread while the worker threads wait for the next batch, so it is
//! kept lean: the fixed keys are interned Python strings, every array but the images is copied
//! into memory numpy owns (the images' buffers are handed over), and the masks of a batch are
//! one read-only all-true array (every sub-environment of a batch gives every key), made once
//! per vector environment for its full batches ([`full_mask`]).

use macrotree::env::StepResult;
use numpy::ndarray::ArrayView2;
use numpy::{Element, IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use crate::convert::{Pixels, tree_status};
use crate::error::value;

/// An info key and its mask's key (`_key`), interned.
macro_rules! key {
    ($py:expr, $k:literal) => {
        (intern!($py, $k), intern!($py, concat!("_", $k)))
    };
}

/// A batched info under construction: its dict and the batch's one mask.
struct Columns<'py> {
    dict: Bound<'py, PyDict>,
    /// The `(n,)` all-true read-only mask every key of the batch shares.
    mask: Bound<'py, PyAny>,
}

impl<'py> Columns<'py> {
    fn new(py: Python<'py>, mask: &Bound<'py, PyAny>) -> Self {
        Self {
            dict: PyDict::new(py),
            mask: mask.clone(),
        }
    }

    /// Sets a fixed key (`key!`) and its mask.
    fn put(
        &self,
        (key, mask): (&Bound<'py, PyString>, &Bound<'py, PyString>),
        values: Bound<'py, PyAny>,
    ) -> PyResult<()> {
        self.dict.set_item(key, values)?;
        self.dict.set_item(mask, &self.mask)
    }

    /// Sets a key named at run time (a goal predicate, an object) and its mask.
    fn put_named(&self, key: &str, values: Bound<'py, PyAny>) -> PyResult<()> {
        self.dict.set_item(key, values)?;
        self.dict.set_item(format!("_{key}"), &self.mask)
    }
}

/// A `(n,)` array of `values`.
fn array<'py, T: Element + Copy>(py: Python<'py>, values: impl Iterator<Item = T>) -> Bound<'py, PyAny> {
    // Copied into an array numpy owns: one Python object, where handing over the `Vec` would
    // make two (the array and a container that owns the `Vec`).
    PyArray1::from_slice(py, &values.collect::<Vec<T>>()).into_any()
}

/// An `(n,)` object array of Python values.
fn objects<'py>(py: Python<'py>, values: Vec<Py<PyAny>>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, values).into_any()
}

/// The `(rows, width)` array holding `flat` (row-major), copied into one array numpy owns.
fn matrix<'py, T: Element + Copy>(
    py: Python<'py>,
    [rows, width]: [usize; 2],
    flat: &[T],
) -> PyResult<Bound<'py, PyAny>> {
    let view = ArrayView2::from_shape([rows, width], flat)
        .map_err(|e| value(format!("a batch of {rows} rows of {width}: {e}")))?;
    Ok(PyArray2::from_array(py, &view).into_any())
}

/// The `(n, width)` float32 array whose row `k` is `row(results[k])`.
fn rows<'py, R: AsRef<[f32]>>(
    py: Python<'py>,
    results: &[StepResult],
    row: impl Fn(&StepResult) -> R,
) -> PyResult<Bound<'py, PyAny>> {
    let mut flat = Vec::new();
    for r in results {
        flat.extend_from_slice(row(r).as_ref());
    }
    let width = flat.len().checked_div(results.len()).unwrap_or(0);
    matrix(py, [results.len(), width], &flat)
}

/// The read-only all-true `(n,)` mask every key of a batch of `n` shares.
pub fn full_mask(py: Python<'_>, n: usize) -> PyResult<Bound<'_, PyAny>> {
    let mask = array(py, std::iter::repeat_n(true, n));
    mask.getattr(intern!(py, "flags"))?
        .setattr(intern!(py, "writeable"), false)?;
    Ok(mask)
}

/// The batch `{"obs", "reward", "terminated", "truncated", "info", "ended"}` of `results` (one per
/// sub-environment stepped, in order) with their camera images `pixels`; `mask` is
/// [`full_mask`] of `results.len()`.
pub fn batch<'py>(
    py: Python<'py>,
    results: &[StepResult],
    pixels: Vec<Pixels>,
    mask: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = results.len();
    let obs = PyDict::new(py);
    obs.set_item(
        intern!(py, "agent_pos"),
        rows(py, results, |r| r.observation.state())?,
    )?;
    obs.set_item(
        intern!(py, "environment_state"),
        rows(py, results, |r| r.observation.environment_state())?,
    )?;
    obs.set_item(
        intern!(py, "pinch"),
        rows(py, results, |r| r.observation.pinch())?,
    )?;
    if pixels.first().is_some_and(|p| !p.is_empty()) {
        let images = PyDict::new(py);
        for c in 0..pixels[0].len() {
            let (name, w, h, _) = &pixels[0][c];
            let mut all = Vec::with_capacity(n * *w as usize * *h as usize * 3);
            for p in &pixels {
                all.extend_from_slice(&p[c].3);
            }
            // Images are large: the `Vec` is handed over, not copied.
            let image = all.into_pyarray(py).reshape([n, *h as usize, *w as usize, 3])?;
            images.set_item(name, image)?;
        }
        obs.set_item(intern!(py, "pixels"), images)?;
    }
    let out = PyDict::new(py);
    out.set_item(intern!(py, "obs"), obs)?;
    out.set_item(intern!(py, "reward"), array(py, results.iter().map(|r| r.reward)))?;
    out.set_item(
        intern!(py, "terminated"),
        array(py, results.iter().map(|r| r.terminated)),
    )?;
    out.set_item(
        intern!(py, "truncated"),
        array(py, results.iter().map(|r| r.truncated)),
    )?;
    out.set_item(intern!(py, "info"), info(py, results, mask)?)?;
    // Whether any sub-environment ended, so that the common step needs no array reduction.
    out.set_item(
        intern!(py, "ended"),
        results.iter().any(|r| r.terminated || r.truncated),
    )?;
    Ok(out)
}

fn info<'py>(
    py: Python<'py>,
    results: &[StepResult],
    mask: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = results.len();
    let info = Columns::new(py, mask);
    let bools = |f: &dyn Fn(&StepResult) -> bool| array(py, results.iter().map(f));
    let floats = |f: &dyn Fn(&StepResult) -> f64| array(py, results.iter().map(f));
    let ints = |f: &dyn Fn(&StepResult) -> i64| array(py, results.iter().map(f));
    let strings = |f: &dyn Fn(&StepResult) -> Option<&str>| {
        let v = results
            .iter()
            .map(|r| match f(r) {
                Some(s) => PyString::new(py, s).into_any().unbind(),
                None => py.None(),
            })
            .collect();
        objects(py, v)
    };
    info.put(
        key!(py, "is_success"),
        bools(&|r| !r.goal.is_empty() && r.goal.iter().all(|g| g.holds)),
    )?;
    let goal = Columns::new(py, mask);
    if let Some(first) = results.first() {
        for (k, g) in first.goal.iter().enumerate() {
            goal.put_named(&g.predicate, bools(&|r| r.goal.get(k).is_some_and(|x| x.holds)))?;
        }
    }
    info.put(key!(py, "goal"), goal.dict.into_any())?;
    let grasped = Columns::new(py, mask);
    if let Some(first) = results.first() {
        for (k, o) in first.observation.objects.iter().enumerate() {
            grasped.put_named(
                &o.name,
                bools(&|r| r.observation.objects.get(k).is_some_and(|x| x.grasped)),
            )?;
        }
    }
    info.put(key!(py, "grasped"), grasped.dict.into_any())?;
    info.put(key!(py, "episode_sim_time"), floats(&|r| r.observation.time))?;
    let status = |r: &StepResult| {
        if r.success() {
            intern!(py, "success")
        } else {
            intern!(py, "failure")
        }
        .clone()
        .into_any()
        .unbind()
    };
    info.put(
        key!(py, "status"),
        objects(py, results.iter().map(status).collect()),
    )?;
    info.put(
        key!(py, "failure_kind"),
        strings(&|r| r.failure.as_ref().map(|f| f.kind.as_str())),
    )?;
    info.put(
        key!(py, "failure_message"),
        strings(&|r| r.failure.as_ref().map(|f| f.message.as_str())),
    )?;
    info.put(
        key!(py, "failure_node"),
        strings(&|r| r.failure.as_ref().and_then(|f| f.node.as_deref())),
    )?;
    info.put(key!(py, "sim_time"), floats(&|r| r.sim_time))?;
    info.put(key!(py, "physics_steps"), ints(&|r| r.physics_steps as i64))?;
    info.put(key!(py, "ctrl_clamped"), ints(&|r| i64::from(r.ctrl_clamped)))?;
    let lists = |f: &dyn Fn(&StepResult) -> Vec<&str>| -> PyResult<Bound<'py, PyAny>> {
        let v = results
            .iter()
            .map(|r| Ok(PyList::new(py, f(r))?.into_any().unbind()))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(objects(py, v))
    };
    if results.first().is_some_and(|r| r.base.is_some()) {
        const WIDTH: usize = macrotree::motion::COMMAND_LEN;
        let flat: Vec<f64> = results
            .iter()
            .flat_map(|r| r.base.as_ref().map_or([f64::NAN; WIDTH], |b| b.command))
            .collect();
        let base = matrix(py, [n, WIDTH], &flat)?;
        info.put(key!(py, "base_action"), base)?;
        info.put(
            key!(py, "base_status"),
            strings(&|r| r.base.as_ref().map(|b| tree_status(b.status))),
        )?;
    }
    info.put(key!(py, "goal_steps"), ints(&|r| r.goal_ticks as i64))?;
    info.put(
        key!(py, "collisions"),
        lists(&|r| r.collisions.iter().map(|c| c.what.as_str()).collect())?,
    )?;
    info.put(
        key!(py, "faults"),
        lists(&|r| r.faults_fired.iter().map(String::as_str).collect())?,
    )?;
    if results.iter().any(|r| !r.rewards.is_empty()) {
        let v = results
            .iter()
            .map(|r| PyArray1::from_slice(py, &r.rewards).into_any().unbind())
            .collect();
        info.put(key!(py, "rewards"), objects(py, v))?;
    }
    Ok(info.dict)
}
