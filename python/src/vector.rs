//! `VecEnv`: `macrotree::env::VecEnv` for Python — N cells on Rust worker threads, the GIL
//! released while they step.

use macrotree::env::{Action, Reset};
use std::sync::Mutex;

use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::env::{action_len, array_action, array_action_of, first_camera, image, pixels, reset_of};
use crate::error::{to_py, value};
use crate::macro_action;
use crate::real::reals;
use crate::setup::{self, Settings};
use crate::{batch, convert};

/// N environments stepped in parallel.
#[pyclass(module = "macrotree._native")]
pub struct VecEnv {
    inner: Mutex<macrotree::env::VecEnv>,
    names: Vec<String>,
    cameras: Vec<String>,
    image: (u32, u32),
    /// The mask of a batch of every environment (`batch::full_mask`), made once.
    full_mask: Py<PyAny>,
}

/// An action from Python: a macro dict; `(mode, values)` with `mode` `"ctrl"` (19 real
/// numbers), `"setpoint"` (7) or `"residual"` (7); or `("leaf", text)` (a leaf as YAML or JSON
/// text) or `("subtree", name)`.
fn action_of(a: &Bound<'_, PyAny>) -> PyResult<Action> {
    if let Ok(d) = a.cast::<PyDict>() {
        return Ok(Action::Primitive(macro_action::primitive(d)?));
    }
    let shape = "an action is a macro dict, (mode, values) with mode ctrl, setpoint or residual, \
                 (\"leaf\", text) or (\"subtree\", name)";
    let (mode, payload): (String, Bound<'_, PyAny>) = a.extract().map_err(|_| value(shape))?;
    match mode.as_str() {
        "leaf" | "subtree" => {
            let text: String = payload
                .extract()
                .map_err(|_| value(format!("a {mode} action is ({mode:?}, text)")))?;
            Ok(if mode == "leaf" {
                Action::Leaf(text)
            } else {
                Action::Subtree(text)
            })
        }
        _ => array_action_of(&mode, &payload),
    }
}

/// A batch of `count` actions from Python: `(mode, values)` with `mode` `"ctrl"`, `"setpoint"`
/// or `"residual"` and `values` an array of real numbers of shape `(count, width)` (any dtype
/// and strides: see `real.rs`), or a list of single actions ([`action_of`]).
fn actions_of(actions: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<Action>> {
    if let Ok((mode, values)) = actions.extract::<(String, Bound<'_, PyAny>)>()
        && !values.is_instance_of::<pyo3::types::PyString>()
    {
        let width = action_len(&mode)?;
        let values = reals(&values, &format!("{mode} actions"), |shape| {
            if shape.0 == [count, width] {
                Ok(())
            } else {
                Err(value(format!(
                    "{mode} actions must have shape ({count}, {width}), got {}",
                    shape.text()
                )))
            }
        })?;
        return values
            .chunks_exact(width)
            .map(|row| array_action(&mode, row))
            .collect();
    }
    let list = actions
        .cast::<PyList>()
        .map_err(|_| value("actions are a list of actions or (mode, array of one row per environment)"))?;
    list.iter().map(|a| action_of(&a)).collect()
}

type Guard<'a> = std::sync::MutexGuard<'a, macrotree::env::VecEnv>;

impl VecEnv {
    /// The vector environment, or a clear error when another thread is using it.
    fn vec(&self) -> PyResult<Guard<'_>> {
        crate::error::try_lock(&self.inner)
    }

    /// The batch of results `done` (environment id, result), in that order; the first error
    /// is raised.
    fn batch<'py>(
        &self,
        py: Python<'py>,
        v: &Guard<'_>,
        done: Vec<(usize, Result<macrotree::env::StepResult, macrotree::Error>)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mut results = Vec::with_capacity(done.len());
        let mut images = Vec::with_capacity(done.len());
        let mut ids = Vec::with_capacity(done.len());
        for (i, r) in done {
            results.push(r.map_err(to_py)?);
            let px = if self.cameras.is_empty() {
                Vec::new()
            } else {
                v.with_env(i, |e| pixels(e, &self.cameras, self.image))
                    .map_err(to_py)??
            };
            images.push(px);
            ids.push(i);
        }
        let built;
        let mask = if results.len() == v.num_envs() {
            self.full_mask.bind(py)
        } else {
            built = batch::full_mask(py, results.len())?;
            &built
        };
        let out = batch::batch(py, &results, images, mask)?;
        out.set_item("env_id", ids)?;
        Ok(out)
    }
}

#[pymethods]
impl VecEnv {
    #[new]
    #[pyo3(signature = (*, num_envs, threads, scene, tree, control_period, max_sim_time, fault, cameras, image_size, noise=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        num_envs: usize,
        threads: Option<usize>,
        scene: Option<String>,
        tree: Option<String>,
        control_period: f64,
        max_sim_time: f64,
        fault: Option<String>,
        cameras: Vec<String>,
        image_size: (u32, u32),
        noise: Option<String>,
    ) -> PyResult<Self> {
        let settings = Settings {
            scene: scene.as_deref(),
            tree: tree.as_deref(),
            control_period,
            max_sim_time,
            fault: fault.as_deref(),
            noise: noise.as_deref(),
            image_size,
        };
        let parts = py.detach(|| setup::build(&settings))?;
        let names = parts.scene.spec.objects.iter().map(|o| o.name.clone()).collect();
        let threads = threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |c| c.get()));
        let inner = py
            .detach(|| {
                macrotree::env::VecEnv::with_threads(
                    &parts.app,
                    parts.scene,
                    parts.tree,
                    parts.config,
                    num_envs,
                    threads,
                )
            })
            .map_err(to_py)?;
        Ok(Self {
            inner: Mutex::new(inner),
            names,
            cameras,
            image: image_size,
            full_mask: batch::full_mask(py, num_envs)?.unbind(),
        })
    }

    #[getter]
    fn object_names(&self) -> Vec<String> {
        self.names.clone()
    }

    #[pyo3(signature = (*, ids, seeds, layout=None, scenario=None, sweep_seed=None, placement: "dict[str, list[float]] | None" = None) -> "list[dict[str, Any]]")]
    #[allow(clippy::too_many_arguments)]
    fn reset<'py>(
        &self,
        py: Python<'py>,
        ids: Vec<usize>,
        seeds: Vec<u64>,
        layout: Option<String>,
        scenario: Option<u64>,
        sweep_seed: Option<u64>,
        placement: Option<Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyList>> {
        if ids.len() != seeds.len() {
            return Err(value(format!("{} ids but {} seeds", ids.len(), seeds.len())));
        }
        let mut v = self.vec()?;
        let default = v.with_env(0, |e| e.scene().default_placement()).map_err(to_py)?;
        let how = seeds
            .iter()
            .map(|&s| {
                reset_of(
                    &self.names,
                    &default,
                    s,
                    layout.as_deref(),
                    scenario,
                    sweep_seed,
                    placement.as_ref(),
                )
            })
            .collect::<PyResult<Vec<Reset>>>()?;
        let e: &mut macrotree::env::VecEnv = &mut v;
        let obs = py.detach(|| e.reset_each(&ids, &how)).map_err(to_py)?;
        let out = PyList::empty(py);
        for (&i, o) in ids.iter().zip(&obs) {
            let goal = v
                .with_env(i, |e| macrotree::world::goal::evaluate(e.cell().world()))
                .map_err(to_py)?;
            let px = if self.cameras.is_empty() {
                Vec::new()
            } else {
                v.with_env(i, |e| pixels(e, &self.cameras, self.image))
                    .map_err(to_py)??
            };
            let d = PyDict::new(py);
            d.set_item("obs", convert::observation(py, o, px)?)?;
            d.set_item("info", convert::reset_info(py, o, &goal)?)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// Steps environments `ids` with `actions` in parallel; the batch of their results, in
    /// the order of `ids` (see `batch.rs`).
    #[pyo3(signature = (ids, actions: "list[Any] | tuple[str, Any]") -> "dict[str, Any]")]
    fn step<'py>(
        &self,
        py: Python<'py>,
        ids: Vec<usize>,
        actions: Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let actions = actions_of(&actions, ids.len())?;
        let mut v = self.vec()?;
        let e: &mut macrotree::env::VecEnv = &mut v;
        let signals = crate::error::SignalPoll::default();
        let done = py
            .detach(|| e.step_each_with(&ids, &actions, &mut signals.poll()))
            .map_err(|e| signals.error(e))?;
        self.batch(py, &v, ids.iter().copied().zip(done).collect())
    }

    /// Starts `actions` on environments `ids` and returns at once.
    #[pyo3(signature = (ids, actions: "list[Any] | tuple[str, Any]"))]
    fn send<'py>(&self, py: Python<'py>, ids: Vec<usize>, actions: Bound<'py, PyAny>) -> PyResult<()> {
        let actions = actions_of(&actions, ids.len())?;
        let mut v = self.vec()?;
        let e: &mut macrotree::env::VecEnv = &mut v;
        py.detach(|| e.send(&ids, &actions)).map_err(to_py)
    }

    /// Waits for at least `count` environments to finish; the batch of their results in
    /// finishing order, `env_id` saying whose.
    #[pyo3(signature = (count) -> "dict[str, Any]")]
    fn recv<'py>(&self, py: Python<'py>, count: usize) -> PyResult<Bound<'py, PyDict>> {
        let mut v = self.vec()?;
        let e: &mut macrotree::env::VecEnv = &mut v;
        let signals = crate::error::SignalPoll::default();
        let done = py
            .detach(|| e.recv_with(count, &mut signals.poll()))
            .map_err(|e| signals.error(e))?;
        self.batch(py, &v, done)
    }

    #[pyo3(signature = (camera, height, width) -> "list[NDArray[np.uint8]]")]
    fn render<'py>(
        &self,
        py: Python<'py>,
        camera: Option<String>,
        height: u32,
        width: u32,
    ) -> PyResult<Vec<Bound<'py, PyArray3<u8>>>> {
        let v = self.vec()?;
        (0..v.num_envs())
            .map(|i| {
                let img = v
                    .with_env(i, |e| {
                        let cam = match &camera {
                            Some(c) => c.clone(),
                            None => first_camera(e)?,
                        };
                        e.render(&cam, width, height).map_err(to_py)
                    })
                    .map_err(to_py)??;
                image(py, img)
            })
            .collect()
    }

    /// Waits for running actions, then stops the worker threads.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let mut v = self.vec()?;
        let pending = v.pending();
        if pending > 0 {
            let e: &mut macrotree::env::VecEnv = &mut v;
            py.detach(|| e.recv(pending)).map_err(to_py)?;
        }
        Ok(())
    }
}
