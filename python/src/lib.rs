//! `macrotree._native`: the Python extension over the Rust library. It converts arguments and
//! results and releases the GIL while Rust steps; every decision lives in `macrotree::env`.
//! The Python package (`python/macrotree/`) wraps it as Gymnasium environments.

mod batch;
mod convert;
mod env;
mod error;
mod macro_action;
mod policy;
mod setup;
mod vector;
mod video;

use pyo3::prelude::*;

/// The Python module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("MacrotreeError", m.py().get_type::<error::MacrotreeError>())?;
    m.add(
        "JOINT_LIMITS",
        macrotree::motion::JOINT_LIMITS
            .iter()
            .map(|&(lo, hi)| (lo, hi))
            .collect::<Vec<_>>(),
    )?;
    m.add("HOME", macrotree::motion::HOME_Q.to_vec())?;
    m.add("MAX_ENVS", macrotree::env::MAX_ENVS)?;
    m.add("CTRL_NAMES", macrotree::motion::COMMAND_NAMES.to_vec())?;
    m.add("STATE_NAMES", macrotree::env::STATE_NAMES.to_vec())?;
    m.add("MACRO_KEYS", macro_action::KEYS.to_vec())?;
    let (low, high) = ctrl_bounds();
    m.add("CTRL_LOW", low)?;
    m.add("CTRL_HIGH", high)?;
    let r = macrotree::env::RESIDUAL_LIMITS;
    let mut residual_high = vec![r.max_joint_offset; 6];
    residual_high.push(r.max_gripper_offset);
    m.add("RESIDUAL_HIGH", residual_high)?;
    m.add_function(wrap_pyfunction!(gripper_command_for_width, m)?)?;
    m.add_function(wrap_pyfunction!(video::write_mp4, m)?)?;
    m.add_function(wrap_pyfunction!(policy::run_policy_model, m)?)?;
    m.add("OBJECT_NAMES", macrotree::world::vectors::OBJECT_NAMES.to_vec())?;
    m.add("VALUES_PER_POSE", macrotree::env::ENVIRONMENT_VALUES_PER_OBJECT)?;
    m.add("MAX_MACRO_STEPS", macrotree::env::MAX_MACRO_STEPS)?;
    m.add(
        "GRIPPER_COMMAND_RANGE",
        (macrotree::motion::OPEN_CTRL, macrotree::motion::CLOSED_CTRL),
    )?;
    m.add_class::<env::Env>()?;
    m.add_class::<vector::VecEnv>()?;
    Ok(())
}

/// The bounds of a `ctrl` action, value by value: joint limits (rad), ± the largest joint speed
/// (rad/s) and acceleration (rad/s²), the gripper's range — `macrotree::env::CTRL_LIMITS`.
fn ctrl_bounds() -> (Vec<f64>, Vec<f64>) {
    use macrotree::env::CTRL_LIMITS;
    let (mut low, mut high) = (Vec::new(), Vec::new());
    for &(lo, hi) in &macrotree::motion::JOINT_LIMITS {
        low.push(lo);
        high.push(hi);
    }
    for bound in [CTRL_LIMITS.max_joint_speed, CTRL_LIMITS.max_joint_acc] {
        low.extend([-bound; 6]);
        high.extend([bound; 6]);
    }
    low.push(macrotree::motion::OPEN_CTRL);
    high.push(macrotree::motion::CLOSED_CTRL);
    (low, high)
}

/// The 2F-85 command (0 … 255) that closes the pads to `width` metres (the gripper calibration).
#[pyfunction]
fn gripper_command_for_width(width: f64) -> PyResult<f64> {
    if !(width.is_finite() && (0.0..=0.1).contains(&width)) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "width is {width}; expected metres within 0 … 0.1"
        )));
    }
    Ok(macrotree::motion::ctrl_for_width(width))
}
