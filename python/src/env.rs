//! `Env`: one `macrotree::env::MacroEnv` for Python.

use macrotree::env::{Action, MacroEnv, Reset};
use macrotree::scene::{Placement, Pose};
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{self, Pixels};
use crate::error::{to_py, value};
use crate::macro_action;
use crate::setup::{self, Settings};

/// One simulated cell, stepped one action at a time (the GIL is released while it steps).
#[pyclass(module = "macrotree._native")]
pub struct Env {
    inner: MacroEnv,
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
    let given = [layout.is_some(), scenario.is_some() || sweep_seed.is_some(), placement.is_some()];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(value("give at most one of `layout`, `scenario` (with `sweep_seed`) and `placement`"));
    }
    if let Some(l) = layout {
        return match l {
            "default" => Ok(Reset::Default),
            other => Err(value(format!("reset layout `{other}`: the only named layout is `default`"))),
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
                value(format!("reset placement names `{name}`, which is not an object of the scene ({})", env_objects.join(", ")))
            })?;
            let xyz: Vec<f64> = v.extract().map_err(|e| value(format!("placement of `{name}`: {e}")))?;
            let [x, y, yaw]: [f64; 3] = xyz
                .try_into()
                .map_err(|_| value(format!("placement of `{name}` is [x, y, yaw] (metres, radians)")))?;
            poses[i] = Pose { x, y, yaw };
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
    fn finish<'py>(&self, py: Python<'py>, r: Result<macrotree::env::StepResult, macrotree::Error>) -> PyResult<Bound<'py, PyDict>> {
        let r = r.map_err(to_py)?;
        let px = pixels(&self.inner, &self.cameras, self.image)?;
        convert::step_result(py, &r, px)
    }

    fn step(&mut self, py: Python<'_>, action: Action) -> PyResult<Py<PyDict>> {
        let inner = &mut self.inner;
        let r = py.detach(|| inner.step(&action));
        Ok(self.finish(py, r)?.unbind())
    }
}

#[pymethods]
impl Env {
    #[new]
    #[pyo3(signature = (*, scene, tree, control_period, max_sim_time, fault, cameras, image_size, frame_rate=None, render_camera=None))]
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
    ) -> PyResult<Self> {
        let _ = (frame_rate, render_camera);
        let settings = Settings {
            scene: scene.as_deref(),
            tree: tree.as_deref(),
            control_period,
            max_sim_time,
            fault: fault.as_deref(),
        };
        let parts = py.detach(|| setup::build(&settings))?;
        let task = parts.scene.spec.name.clone();
        let inner = py
            .detach(|| MacroEnv::new(&parts.app, parts.scene, parts.tree, parts.config))
            .map_err(to_py)?;
        Ok(Self { inner, cameras, image: image_size, task })
    }

    /// Object names, scene order.
    #[getter]
    fn object_names(&self) -> Vec<String> {
        self.inner.scene().spec.objects.iter().map(|o| o.name.clone()).collect()
    }

    /// The scene's cameras.
    #[getter]
    fn cameras(&self) -> Vec<String> {
        self.inner.scene().camera_names()
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
    fn task_description(&self) -> String {
        let goal = &self.inner.scene().spec.goal;
        if goal.is_empty() {
            format!("scene {}: no goal", self.task)
        } else {
            format!("scene {}: {}", self.task, goal.describe())
        }
    }

    /// Seconds of one control period.
    #[getter]
    fn control_period(&self) -> f64 {
        self.inner.config().control_period
    }

    #[pyo3(signature = (*, seed, layout=None, scenario=None, sweep_seed=None, placement=None))]
    fn reset(
        &mut self,
        py: Python<'_>,
        seed: u64,
        layout: Option<String>,
        scenario: Option<u64>,
        sweep_seed: Option<u64>,
        placement: Option<Bound<'_, PyDict>>,
    ) -> PyResult<Py<PyDict>> {
        let names = self.object_names();
        let how = reset_of(&names, &self.inner.scene().default_placement(), seed, layout.as_deref(), scenario, sweep_seed, placement.as_ref())?;
        let inner = &mut self.inner;
        let obs = py.detach(|| inner.reset(&how)).map_err(to_py)?;
        let goal = macrotree::world::goal::evaluate(self.inner.cell().world());
        let px = pixels(&self.inner, &self.cameras, self.image)?;
        let out = PyDict::new(py);
        out.set_item("obs", convert::observation(py, &obs, px)?)?;
        out.set_item("info", convert::reset_info(py, &obs, &goal)?)?;
        Ok(out.unbind())
    }

    fn step_macro(&mut self, py: Python<'_>, action: Bound<'_, PyDict>) -> PyResult<Py<PyDict>> {
        let p = macro_action::primitive(&action)?;
        self.step(py, Action::Primitive(p))
    }

    fn step_ctrl(&mut self, py: Python<'_>, ctrl: PyReadonlyArray1<'_, f64>) -> PyResult<Py<PyDict>> {
        let u: [f64; 7] = ctrl
            .as_slice()?
            .try_into()
            .map_err(|_| value("a ctrl action has 7 values"))?;
        self.step(py, Action::Ctrl(u))
    }

    fn step_leaf(&mut self, py: Python<'_>, text: String) -> PyResult<Py<PyDict>> {
        self.step(py, Action::Leaf(text))
    }

    fn step_subtree(&mut self, py: Python<'_>, name: String) -> PyResult<Py<PyDict>> {
        self.step(py, Action::Subtree(name))
    }

    fn observation(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        Ok(convert::full_observation(py, &self.inner.observe())?.unbind())
    }

    #[pyo3(signature = (camera, height, width))]
    fn render<'py>(&self, py: Python<'py>, camera: Option<String>, height: u32, width: u32) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let camera = match camera {
            Some(c) => c,
            None => self.inner.scene().camera_names().into_iter().next().ok_or_else(|| value("the scene has no camera"))?,
        };
        let img = self.inner.render(&camera, width, height).map_err(to_py)?;
        img.pixels.into_pyarray(py).reshape([img.height as usize, img.width as usize, 3])
    }

    fn take_frames(&mut self) -> Vec<Py<PyAny>> {
        Vec::new()
    }

    fn gripper_command_for_width(&self, width: f64) -> PyResult<f64> {
        crate::gripper_command_for_width(width)
    }
}
