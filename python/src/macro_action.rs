//! A Gymnasium `macro` action (a dict mirroring TorchRL's `RobotMacroAction`) as a
//! `macrotree::env::Primitive`. Ranges are checked by the library; this side reads the fields.

use macrotree::env::{Duration, Primitive};
use macrotree::kinds::PathKind;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::value;

/// `mode` ids (the reference's `RobotMacroActionMode`).
const WAIT: i64 = 0;
const REACH_JOINTS: i64 = 1;
const REACH_POSE: i64 = 2;
const OPEN_GRIPPER: i64 = 3;
const CLOSE_GRIPPER: i64 = 4;
const RESET: i64 = 5;

/// `gripper` ids: open, closed, keep.
const GRIPPER_OPEN: i64 = 0;
const GRIPPER_CLOSED: i64 = 1;
const GRIPPER_KEEP: i64 = 2;

fn field<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) => v.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            value(format!("macro action `{key}`: {e}"))
        }),
    }
}

fn array<const N: usize>(d: &Bound<'_, PyDict>, key: &str, mode: &str) -> PyResult<[f64; N]> {
    let v: Vec<f64> =
        field(d, key)?.ok_or_else(|| value(format!("a `{mode}` macro needs `{key}` ({N} values)")))?;
    v.try_into().map_err(|v: Vec<f64>| {
        value(format!(
            "macro action `{key}` has {} values, expected {N}",
            v.len()
        ))
    })
}

/// The duration of `steps` and `settle_steps` (reference steps of 10 ms): 0 steps is closed
/// loop (`Auto`, then `settle_steps` held); a wait of 0 steps lasts one reference step.
fn duration(d: &Bound<'_, PyDict>, wait: bool) -> PyResult<Duration> {
    let steps: i64 = field(d, "steps")?.unwrap_or(0);
    let settle: i64 = field(d, "settle_steps")?.unwrap_or(0);
    let count = |n: i64, key: &str| {
        u32::try_from(n).map_err(|_| value(format!("macro action `{key}` is {n}; expected 0 … {}", u32::MAX)))
    };
    let (steps, settle) = (count(steps, "steps")?, count(settle, "settle_steps")?);
    Ok(match (steps, settle, wait) {
        (0, 0, false) => Duration::Auto,
        (0, settle, false) => Duration::AutoThen { settle },
        (0, 0, true) => Duration::Steps { steps: 1, settle: 0 },
        (steps, settle, _) => Duration::Steps { steps, settle },
    })
}

/// The gripper command during a wait or a reach: `None` keeps the current one.
fn gripper_during(d: &Bound<'_, PyDict>) -> PyResult<Option<f64>> {
    let code: i64 = field(d, "gripper")?.unwrap_or(GRIPPER_KEEP);
    let command: Option<f64> = field::<f64>(d, "gripper_command")?.filter(|c| !c.is_nan());
    Ok(match (command, code) {
        (Some(c), _) => Some(c),
        (None, GRIPPER_OPEN) => Some(macrotree::motion::OPEN_CTRL),
        (None, GRIPPER_CLOSED) => Some(macrotree::motion::CLOSED_CTRL),
        (None, GRIPPER_KEEP) => None,
        (None, other) => {
            return Err(value(format!(
                "macro action `gripper` is {other}; expected 0 (open), 1 (closed) or 2 (keep)"
            )));
        }
    })
}

/// The keys a macro action may have (exported to Python as `MACRO_KEYS`).
pub const KEYS: [&str; 9] = [
    "mode",
    "position",
    "quaternion",
    "joints",
    "gripper",
    "gripper_command",
    "path",
    "steps",
    "settle_steps",
];

/// Reads a macro action; unknown keys are refused, with the closest known one.
pub fn primitive(d: &Bound<'_, PyDict>) -> PyResult<Primitive> {
    for key in d.keys() {
        let key: String = key
            .extract()
            .map_err(|_| value("macro action keys are strings"))?;
        if !KEYS.contains(&key.as_str()) {
            let hint = macrotree::yaml::suggest::closest(&key, KEYS.iter().copied())
                .map(|c| format!("did you mean `{c}`? "))
                .unwrap_or_default();
            let shown: String = key.chars().take(40).collect();
            return Err(value(format!(
                "macro action key `{shown}` is unknown; {hint}keys: {}",
                KEYS.join(", ")
            )));
        }
    }
    let mode: i64 = field(d, "mode")?.ok_or_else(|| value("a macro action needs `mode` (0 … 5)"))?;
    let gripper = gripper_during(d)?;
    Ok(match mode {
        WAIT => Primitive::Wait {
            duration: duration(d, true)?,
            gripper,
        },
        REACH_JOINTS => Primitive::ReachJoints {
            joints: array(d, "joints", "reach_joints")?,
            duration: duration(d, false)?,
            gripper,
        },
        REACH_POSE => {
            let quaternion = match field::<Vec<f64>>(d, "quaternion")? {
                None => None,
                Some(q) => {
                    let q: [f64; 4] = q
                        .try_into()
                        .map_err(|_| value("macro action `quaternion` needs 4 values (w, x, y, z)"))?;
                    if let Some(i) = q.iter().position(|v| !v.is_finite()) {
                        return Err(value(format!(
                            "macro action `quaternion[{i}]` is {}; give a finite quaternion (w, x, y, z), or all zeros to keep the current orientation",
                            q[i]
                        )));
                    }
                    // The reference's convention: an all-zero quaternion means position only.
                    (q.iter().map(|v| v * v).sum::<f64>() > 1e-12).then_some(q)
                }
            };
            let path = match field::<i64>(d, "path")?.unwrap_or(0) {
                0 => PathKind::Joint,
                1 => PathKind::Cartesian,
                other => {
                    return Err(value(format!(
                        "macro action `path` is {other}; expected 0 (joint) or 1 (cartesian)"
                    )));
                }
            };
            Primitive::ReachPose {
                position: array(d, "position", "reach_pose")?,
                quaternion,
                path,
                duration: duration(d, false)?,
                gripper,
            }
        }
        OPEN_GRIPPER => Primitive::OpenGripper {
            command: field::<f64>(d, "gripper_command")?.filter(|c| !c.is_nan()),
            duration: duration(d, false)?,
        },
        CLOSE_GRIPPER => Primitive::CloseGripper {
            command: field::<f64>(d, "gripper_command")?.filter(|c| !c.is_nan()),
            width: None,
            duration: duration(d, false)?,
        },
        RESET => Primitive::Reset {
            duration: duration(d, false)?,
        },
        other => {
            return Err(value(format!(
                "macro action `mode` is {other}; expected 0 (wait), 1 (reach_joints), 2 (reach_pose), 3 (open_gripper), 4 (close_gripper) or 5 (reset)"
            )));
        }
    })
}
