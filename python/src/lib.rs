//! `macrotree._native`: the Python extension over the Rust library. It converts arguments and
//! results and releases the GIL while Rust steps; every decision lives in `macrotree::env`.
//! The Python package (`python/macrotree/`) wraps it as Gymnasium environments.
//!
//! The module is declared inline so that PyO3 records what it holds: its type stub,
//! `macrotree/_native.pyi`, is generated from the built extension (`python/generate_stub.py`),
//! and a test fails when the committed stub differs.

mod batch;
mod convert;
mod env;
mod error;
mod macro_action;
mod policy;
mod real;
mod setup;
mod vector;
mod video;

/// The native core of the `macrotree` package: single and vector environments over the Rust
/// library, the spaces' constants, video writing and ONNX policy evaluation. Its type stub,
/// `macrotree/_native.pyi`, is generated from the built module by `python/generate_stub.py`.
#[pyo3::pymodule]
mod _native {
    use pyo3::prelude::*;

    use macrotree::motion::{CLOSED_CTRL, COMMAND_LEN, CTRL_LIMITS, OPEN_CTRL};

    #[pymodule_export]
    use crate::env::Env;
    #[pymodule_export]
    use crate::error::MacrotreeError;
    #[pymodule_export]
    use crate::policy::run_policy_model;
    #[pymodule_export]
    use crate::vector::VecEnv;
    #[pymodule_export]
    use crate::video::write_mp4;

    /// The package version.
    #[allow(non_upper_case_globals)]
    #[pymodule_export]
    const __version__: &str = env!("CARGO_PKG_VERSION");
    /// Each arm joint's limits (low, high), radians, shoulder pan … wrist 3.
    #[pymodule_export]
    const JOINT_LIMITS: [(f64, f64); 6] = macrotree::motion::JOINT_LIMITS;
    /// The arm's home configuration, radians.
    #[pymodule_export]
    const HOME: [f64; 6] = macrotree::motion::HOME_Q;
    /// Most environments of one vector environment.
    #[pymodule_export]
    const MAX_ENVS: usize = macrotree::env::MAX_ENVS;
    /// The names of a `ctrl` action's values (set points, velocities, accelerations, gripper).
    #[pymodule_export]
    const CTRL_NAMES: [&str; COMMAND_LEN] = macrotree::motion::COMMAND_NAMES;
    /// The names of the state vector's values (`agent_pos`, the dataset's
    /// `observation.state`).
    #[pymodule_export]
    const STATE_NAMES: [&str; macrotree::env::STATE_LEN] = macrotree::env::STATE_NAMES;
    /// The keys a macro action may have.
    #[pymodule_export]
    const MACRO_KEYS: [&str; crate::macro_action::KEYS.len()] = crate::macro_action::KEYS;
    /// The lowest value of each `ctrl` action value (`macrotree::env::CTRL_LIMITS`).
    #[pymodule_export]
    const CTRL_LOW: [f64; COMMAND_LEN] = CTRL_LIMITS.bounds().low;
    /// The highest value of each `ctrl` action value.
    #[pymodule_export]
    const CTRL_HIGH: [f64; COMMAND_LEN] = CTRL_LIMITS.bounds().high;
    /// The highest value of each residual action value (the lowest is its negative): joint
    /// offsets (rad), then the gripper offset.
    #[pymodule_export]
    const RESIDUAL_HIGH: [f64; macrotree::env::RESIDUAL_LEN] = macrotree::env::RESIDUAL_LIMITS.high();
    /// The names of an object vector's values (the dataset's object features).
    #[pymodule_export]
    const OBJECT_NAMES: [&str; macrotree::world::vectors::OBJECT_LEN] =
        macrotree::world::vectors::OBJECT_NAMES;
    /// Values per object in `environment_state` (x, y, z, qw, qx, qy, qz).
    #[pymodule_export]
    const VALUES_PER_POSE: usize = macrotree::env::ENVIRONMENT_VALUES_PER_OBJECT;
    /// The longest macro primitive (`steps` + `settle_steps`), in 2 ms physics steps.
    #[pymodule_export]
    const MAX_MACRO_STEPS: u32 = macrotree::env::MAX_MACRO_STEPS;
    /// The length of each array action mode's action: `ctrl`, `setpoint`, `residual`.
    #[pymodule_export]
    const ACTION_LENGTHS: [(&str, usize); 3] = crate::env::ACTION_LENGTHS;
    /// The farthest a pose target may be from the robot's base, metres (the UR5e reaches about
    /// 0.85 m plus the gripper; a farther target is refused, a nearer unreachable one fails).
    #[pymodule_export]
    const MAX_REACH_DISTANCE: f64 = macrotree::env::MAX_REACH_DISTANCE;
    /// The gripper command's range: open, closed (the 2F-85's 0 … 255).
    #[pymodule_export]
    const GRIPPER_COMMAND_RANGE: (f64, f64) = (OPEN_CTRL, CLOSED_CTRL);

    /// The 2F-85 command (0 … 255) that closes the pads to `width` metres (the gripper
    /// calibration).
    #[pyfunction]
    fn gripper_command_for_width(width: f64) -> PyResult<f64> {
        crate::gripper_command(width)
    }
}

/// The 2F-85 command (0 … 255) that closes the pads to `width` metres, refusing a width outside
/// 0 … 0.1 m.
fn gripper_command(width: f64) -> pyo3::PyResult<f64> {
    if !(width.is_finite() && (0.0..=0.1).contains(&width)) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "width is {width}; expected metres within 0 … 0.1"
        )));
    }
    Ok(macrotree::motion::ctrl_for_width(width))
}
