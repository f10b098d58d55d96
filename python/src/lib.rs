//! `macrotree._native`: the Python extension over the Rust library. It converts arguments and
//! results and releases the GIL while Rust steps; every decision lives in `macrotree::env`.
//! The Python package (`python/macrotree/`) wraps it as Gymnasium environments.

mod convert;
mod env;
mod error;
mod macro_action;
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
    m.add_function(wrap_pyfunction!(gripper_command_for_width, m)?)?;
    m.add_function(wrap_pyfunction!(video::write_mp4, m)?)?;
    m.add_class::<env::Env>()?;
    m.add_class::<vector::VecEnv>()?;
    Ok(())
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
