//! `Env`: one `macrotree::env::MacroEnv` for Python.

use macrotree::env::{Action, MacroEnv, Reset};
use macrotree::scene::{Placement, Pose};
use std::sync::{Mutex, MutexGuard};

use numpy::{IntoPyArray, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{self, Pixels};
use crate::error::{to_py, value};
use crate::macro_action;
use crate::setup::{self, Settings};

/// One simulated cell, stepped one action at a time (the GIL is released while it steps).
#[pyclass(module = "macrotree._native")]
pub struct Env {
    inner: Mutex<MacroEnv>,
    recording: Mutex<Option<macrotree::episode::replay::Controls>>,
    cameras: Vec<String>,
    image: (u32, u32),
    task: String,
}

/// Where a reset puts the objects, from the Python keywords.
pub fn reset_of(
    env_objects: &[String],
    default: &Placement,
    seed: u64,
    layout: Option<&str>,
    scenario: Option<u64>,
    sweep_seed: Option<u64>,
    placement: Option<&Bound<'_, PyDict>>,
) -> PyResult<Reset> {
    let given = [
        layout.is_some(),
        scenario.is_some() || sweep_seed.is_some(),
        placement.is_some(),
    ];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(value(
            "give at most one of `layout`, `scenario` (with `sweep_seed`) and `placement`",
        ));
    }
    if let Some(l) = layout {
        return match l {
            "default" => Ok(Reset::Default),
            other => Err(value(format!(
                "reset layout `{other}`: the only named layout is `default`"
            ))),
        };
    }
    if scenario.is_some() || sweep_seed.is_some() {
        return Ok(Reset::Scenario {
            index: scenario.ok_or_else(|| value("`sweep_seed` needs `scenario`"))?,
            sweep_seed: sweep_seed.unwrap_or(0),
        });
    }
    if let Some(p) = placement {
        let mut poses = default.poses.clone();
        for (k, v) in p.iter() {
            let name: String = k.extract()?;
            let i = env_objects.iter().position(|n| *n == name).ok_or_else(|| {
                value(format!(
                    "reset placement names `{name}`, which is not an object of the scene ({})",
                    env_objects.join(", ")
                ))
            })?;
            let xyz: Vec<f64> = v
                .extract()
                .map_err(|e| value(format!("placement of `{name}`: {e}")))?;
            let [x, y, yaw]: [f64; 3] = xyz
                .try_into()
                .map_err(|_| value(format!("placement of `{name}` is [x, y, yaw] (metres, radians)")))?;
            poses[i] = Pose { x, y, yaw, z: 0.0 };
        }
        return Ok(Reset::Placement(Placement { poses }));
    }
    Ok(Reset::Seed(seed))
}

/// The images of `cameras` now.
pub fn pixels(env: &MacroEnv, cameras: &[String], (h, w): (u32, u32)) -> PyResult<Pixels> {
    cameras
        .iter()
        .map(|c| {
            let img = env.render(c, w, h).map_err(to_py)?;
            Ok((c.clone(), img.width, img.height, img.pixels))
        })
        .collect()
}

impl Env {
    /// The environment, or a clear error when another thread is using it (an environment
    /// serves one thread at a time; waiting here while holding the GIL would deadlock).
    fn env(&self) -> PyResult<MutexGuard<'_, MacroEnv>> {
        crate::error::try_lock(&self.inner)
    }

    fn step(&self, py: Python<'_>, action: Action) -> PyResult<Py<PyDict>> {
        let mut env = self.env()?;
        let e: &mut MacroEnv = &mut env;
        let signals = crate::error::SignalPoll::default();
        let r = py
            .detach(|| e.step_with(&action, &mut signals.poll()))
            .map_err(|e| signals.error(e))?;
        let px = pixels(&env, &self.cameras, self.image)?;
        Ok(convert::step_result(py, &r, px)?.unbind())
    }
}

/// The scene's first camera (what `render()` shows by default).
pub fn first_camera(env: &MacroEnv) -> PyResult<String> {
    env.scene()
        .camera_names()
        .into_iter()
        .next()
        .ok_or_else(|| value("the scene has no camera"))
}

/// An image as an H×W×3 `uint8` numpy array (no copy).
pub fn image(py: Python<'_>, img: macrotree::env::Image) -> PyResult<Bound<'_, PyArray3<u8>>> {
    img.pixels
        .into_pyarray(py)
        .reshape([img.height as usize, img.width as usize, 3])
}

#[pymethods]
impl Env {
    #[new]
    #[pyo3(signature = (*, scene, tree, control_period, max_sim_time, fault, cameras, image_size, frame_rate=None, render_camera=None, noise=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: Option<String>,
        tree: Option<String>,
        control_period: f64,
        max_sim_time: f64,
        fault: Option<String>,
        cameras: Vec<String>,
        image_size: (u32, u32),
        frame_rate: Option<f64>,
        render_camera: Option<String>,
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
        let task = parts.scene.spec.name.clone();
        let mut inner = py
            .detach(|| MacroEnv::new(&parts.app, parts.scene, parts.tree, parts.config))
            .map_err(to_py)?;
        if let Some(rate) = frame_rate {
            let camera = match render_camera {
                Some(c) => c,
                None => first_camera(&inner)?,
            };
            inner
                .film(&camera, image_size.1, image_size.0, rate)
                .map_err(to_py)?;
        }
        Ok(Self {
            inner: Mutex::new(inner),
            recording: Mutex::new(None),
            cameras,
            image: image_size,
            task,
        })
    }

    /// Object names, scene order.
    #[getter]
    fn object_names(&self) -> PyResult<Vec<String>> {
        Ok(self
            .env()?
            .scene()
            .spec
            .objects
            .iter()
            .map(|o| o.name.clone())
            .collect())
    }

    /// The scene's cameras.
    #[getter]
    fn cameras(&self) -> PyResult<Vec<String>> {
        Ok(self.env()?.scene().camera_names())
    }

    /// The UR5e home joint angles, radians.
    #[getter]
    fn home(&self) -> Vec<f64> {
        macrotree::motion::HOME_Q.to_vec()
    }

    /// The scene's name (LeRobot's `task`).
    #[getter]
    fn task(&self) -> String {
        self.task.clone()
    }

    /// A sentence about the task (LeRobot's `task_description`).
    #[getter]
    fn task_description(&self) -> PyResult<String> {
        let env = self.env()?;
        let goal = macrotree::world::goal::evaluate(env.cell().world());
        Ok(if goal.is_empty() {
            format!("scene {}: no goal", self.task)
        } else {
            let parts: Vec<&str> = goal.iter().map(|g| g.predicate.as_str()).collect();
            format!("scene {}: {}", self.task, parts.join(", "))
        })
    }

    /// Seconds of one control period.
    #[getter]
    fn control_period(&self) -> PyResult<f64> {
        Ok(self.env()?.config().control_period)
    }

    #[pyo3(signature = (*, seed, layout=None, scenario=None, sweep_seed=None, placement: "dict[str, list[float]] | None" = None) -> "dict[str, Any]")]
    fn reset(
        &self,
        py: Python<'_>,
        seed: u64,
        layout: Option<String>,
        scenario: Option<u64>,
        sweep_seed: Option<u64>,
        placement: Option<Bound<'_, PyDict>>,
    ) -> PyResult<Py<PyDict>> {
        let names = self.object_names()?;
        let mut env = self.env()?;
        let how = reset_of(
            &names,
            &env.scene().default_placement(),
            seed,
            layout.as_deref(),
            scenario,
            sweep_seed,
            placement.as_ref(),
        )?;
        let e: &mut MacroEnv = &mut env;
        let obs = py.detach(|| e.reset(&how)).map_err(to_py)?;
        let goal = macrotree::world::goal::evaluate(env.cell().world());
        let px = pixels(&env, &self.cameras, self.image)?;
        let out = PyDict::new(py);
        out.set_item("obs", convert::observation(py, &obs, px)?)?;
        out.set_item("info", convert::reset_info(py, &obs, &goal)?)?;
        Ok(out.unbind())
    }

    #[pyo3(signature = (action: "dict[str, Any]") -> "dict[str, Any]")]
    fn step_macro(&self, py: Python<'_>, action: Bound<'_, PyDict>) -> PyResult<Py<PyDict>> {
        let p = macro_action::primitive(&action)?;
        self.step(py, Action::Primitive(p))
    }

    /// One control period of an array mode: `mode` `"ctrl"` (19 values), `"setpoint"` (7) or
    /// `"residual"` (7), `values` any array of that many real numbers (see `real.rs`).
    #[pyo3(signature = (mode, values: "Any") -> "dict[str, Any]")]
    fn step_array(&self, py: Python<'_>, mode: &str, values: Bound<'_, PyAny>) -> PyResult<Py<PyDict>> {
        self.step(py, array_action_of(mode, &values)?)
    }

    #[pyo3(signature = (text) -> "dict[str, Any]")]
    fn step_leaf(&self, py: Python<'_>, text: String) -> PyResult<Py<PyDict>> {
        self.step(py, Action::Leaf(text))
    }

    #[pyo3(signature = (name) -> "dict[str, Any]")]
    fn step_subtree(&self, py: Python<'_>, name: String) -> PyResult<Py<PyDict>> {
        self.step(py, Action::Subtree(name))
    }

    #[pyo3(signature = () -> "dict[str, Any]")]
    fn observation(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let env = self.env()?;
        Ok(convert::full_observation(py, &env.observe())?.unbind())
    }

    #[pyo3(signature = (camera, height, width) -> "NDArray[np.uint8]")]
    fn render<'py>(
        &self,
        py: Python<'py>,
        camera: Option<String>,
        height: u32,
        width: u32,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let env = self.env()?;
        let camera = match camera {
            Some(c) => c,
            None => first_camera(&env)?,
        };
        let img = env.render(&camera, width, height).map_err(to_py)?;
        image(py, img)
    }

    /// The frames filmed since the last call (`rgb_array_list`), each H×W×3 `uint8`.
    #[pyo3(signature = () -> "list[NDArray[np.uint8]]")]
    fn take_frames<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyArray3<u8>>>> {
        let frames = self.env()?.take_frames();
        frames.into_iter().map(|img| image(py, img)).collect()
    }

    /// Records the actuator commands of every physics step from now until the next reset.
    fn record_controls(&self) -> PyResult<()> {
        let log = self.env()?.record_controls();
        *self.recording.lock().unwrap_or_else(|e| e.into_inner()) = Some(log);
        Ok(())
    }

    /// Replays the recorded commands on a fresh simulation with bare `mj_step` from this
    /// episode's start: `(wall seconds, physics steps, ends in this environment's state bit for
    /// bit)`. For benchmarks: the same controls, no tree, no controllers, no Python.
    fn replay_recorded(&self, py: Python<'_>) -> PyResult<(f64, usize, bool)> {
        let log = self
            .recording
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
            .ok_or_else(|| value("nothing recorded: call record_controls() after reset() first"))?;
        let env = self.env()?;
        let controls = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
        let nu = env.cell().sim().ctrl().len().max(1);
        let (scene, placement) = (env.scene(), env.placement());
        let (wall, state) =
            py.detach(|| macrotree::episode::replay::replay_controls(scene, placement, &controls));
        Ok((
            wall,
            controls.len() / nu,
            state == env.cell().sim().state_fingerprint(),
        ))
    }

    fn gripper_command_for_width(&self, width: f64) -> PyResult<f64> {
        crate::gripper_command(width)
    }
}

/// The length of each array action mode's action: `ctrl`, `setpoint`, `residual`.
pub const ACTION_LENGTHS: [(&str, usize); 3] = [
    ("ctrl", macrotree::motion::COMMAND_LEN),
    ("setpoint", macrotree::env::SETPOINT_LEN),
    ("residual", macrotree::env::RESIDUAL_LEN),
];

/// The number of values of an array mode's action ([`ACTION_LENGTHS`]).
pub fn action_len(mode: &str) -> PyResult<usize> {
    ACTION_LENGTHS
        .iter()
        .find(|(m, _)| *m == mode)
        .map(|&(_, n)| n)
        .ok_or_else(|| {
            value(format!(
                "unknown action mode `{mode}`; expected ctrl, setpoint or residual"
            ))
        })
}

/// The action of an array mode from Python: `values` any array of real numbers holding the
/// mode's [`ACTION_LENGTHS`] values, in any shape (see `real.rs`).
pub fn array_action_of(mode: &str, values: &Bound<'_, PyAny>) -> PyResult<Action> {
    let n = action_len(mode)?;
    let what = format!("a {mode} action");
    let values = crate::real::reals(values, &what, |shape| {
        if shape.count() == n {
            Ok(())
        } else {
            Err(value(format!(
                "{what} has {n} values, got shape {}",
                shape.text()
            )))
        }
    })?;
    array_action(mode, &values)
}

/// The action of an array mode from its values `u` ([`ACTION_LENGTHS`] of them).
pub fn array_action(mode: &str, u: &[f64]) -> PyResult<Action> {
    let n = action_len(mode)?;
    let wrong = || value(format!("a {mode} action has {n} values, got {}", u.len()));
    match mode {
        "ctrl" => Ok(Action::Ctrl(u.try_into().map_err(|_| wrong())?)),
        "setpoint" => Ok(Action::Setpoint(u.try_into().map_err(|_| wrong())?)),
        _ => Ok(Action::Residual(u.try_into().map_err(|_| wrong())?)),
    }
}
