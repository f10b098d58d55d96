"""The action and observation spaces, and the conversion of a Gymnasium action to a native one.

The ``macro`` action mirrors TorchRL's ``RobotMacroAction`` as a ``Dict`` (TorchRL converts ``Dict``
to a ``Composite``; it has no converter for ``OneOf``). The ``ctrl`` action is a ``Box(19)``: the
command every leaf gives and a dataset's ``action`` records — six joint set points (rad), six
joint velocities (rad/s), six joint accelerations (rad/s²) and the gripper command — for one
control period. The ``setpoint`` action is a ``Box(7)``: six set points and the gripper command,
with zero velocity and acceleration. The ``residual`` action is a ``Box(7)``: offsets added to the
base tree's six set points (radians) and gripper command for one control period.
"""

from __future__ import annotations

import enum
import math
from typing import Any

import numpy as np
from gymnasium import spaces

from macrotree import _native
from macrotree._native import CTRL_HIGH, CTRL_LOW, JOINT_LIMITS, RESIDUAL_HIGH, STATE_NAMES
from macrotree._native import MACRO_KEYS as _MACRO_KEYS

#: Largest ``steps``, and largest ``settle_steps``, of one macro: reference steps of 10 ms (the
#: extension's ``MAX_MACRO_STEPS``, 60 s each). ``steps = 0`` runs the macro closed loop: until
#: its motion is done and the arm has settled.
MAX_MACRO_STEPS: int = _native.MAX_MACRO_STEPS


#: Range of the gripper command (the 2F-85 actuator's ctrlrange: 0 open … 255 closed; the
#: extension's ``GRIPPER_COMMAND_RANGE``).
GRIPPER_COMMAND_RANGE: tuple[float, float] = _native.GRIPPER_COMMAND_RANGE

#: Values of one pose in an observation (x, y, z in metres, then qw, qx, qy, qz): ``pinch``, and
#: each object's in ``environment_state`` (the extension's ``VALUES_PER_POSE``).
VALUES_PER_POSE: int = _native.VALUES_PER_POSE


def _inside_f32(lo: float, hi: float) -> tuple[np.float32, np.float32]:
    """``[lo, hi]`` as float32 bounds that never round outside the float64 range."""
    low, high = np.float32(lo), np.float32(hi)
    if float(low) < lo:
        low = np.nextafter(low, np.float32(np.inf))
    if float(high) > hi:
        high = np.nextafter(high, np.float32(-np.inf))
    return low, high


#: Half-side of the workspace box for ``position``, metres: the largest whose corners are within
#: the extension's ``MAX_REACH_DISTANCE`` (1.5 m) of the robot's base, rounded down to float32,
#: so every point of the box is accepted (the UR5e reaches about 0.85 m, so far corners are
#: valid input that fails as unreachable, reported in ``info``).
POSITION_BOUND = float(_inside_f32(0.0, _native.MAX_REACH_DISTANCE / math.sqrt(3.0))[1])

#: Each arm joint's target range, radians (the UR5e's: ±2π, the elbow ±π).
JOINT_BOUNDS = [_inside_f32(lo, hi) for lo, hi in JOINT_LIMITS]


class MacroMode(enum.IntEnum):
    """``mode`` of a macro action (the reference's ``RobotMacroActionMode`` ids)."""

    WAIT = 0
    REACH_JOINTS = 1
    REACH_POSE = 2
    OPEN_GRIPPER = 3
    CLOSE_GRIPPER = 4
    RESET = 5


class Path(enum.IntEnum):
    """``path`` of a ``REACH_POSE`` macro: joint-space interpolation or a straight Cartesian
    line."""

    JOINT = 0
    CARTESIAN = 1


class Gripper(enum.IntEnum):
    """``gripper`` of a macro action: the gripper during the motion (2 keeps it as it is)."""

    OPEN = 0
    CLOSED = 1
    KEEP = 2


def macro_action_space() -> spaces.Dict:
    """The ``macro`` action space (one macro per ``env.step``)."""
    f32 = np.float32
    return spaces.Dict(
        {
            "mode": spaces.Discrete(len(MacroMode)),
            "position": spaces.Box(-POSITION_BOUND, POSITION_BOUND, (3,), f32),
            "quaternion": spaces.Box(-1.0, 1.0, (4,), f32),
            "joints": spaces.Box(
                np.array([lo for lo, _ in JOINT_BOUNDS]),
                np.array([hi for _, hi in JOINT_BOUNDS]),
                (6,),
                f32,
            ),
            "gripper": spaces.Discrete(len(Gripper)),
            "gripper_command": spaces.Box(*GRIPPER_COMMAND_RANGE, (1,), f32),
            "path": spaces.Discrete(len(Path)),
            "steps": spaces.Box(0, MAX_MACRO_STEPS, (1,), np.int64),
            "settle_steps": spaces.Box(0, MAX_MACRO_STEPS, (1,), np.int64),
        }
    )


def ctrl_action_space() -> spaces.Box:
    """The ``ctrl`` action space, from the extension's bounds: six joint set points (radians),
    six velocities (rad/s), six accelerations (rad/s²), the gripper command (0…255). Velocities
    and accelerations outside it, and set points further than the largest speed allows in one
    period, are clamped (``info["ctrl_clamped"]`` counts them)."""
    bounds = [_inside_f32(lo, hi) for lo, hi in zip(CTRL_LOW, CTRL_HIGH, strict=True)]
    low = np.array([lo for lo, _ in bounds], dtype=np.float32)
    high = np.array([hi for _, hi in bounds], dtype=np.float32)
    return spaces.Box(low, high, dtype=np.float32)


def setpoint_action_space() -> spaces.Box:
    """The ``setpoint`` action space: six arm joint set points (radians) and the gripper
    command (0…255)."""
    low = np.array([lo for lo, _ in JOINT_BOUNDS] + [GRIPPER_COMMAND_RANGE[0]], dtype=np.float32)
    high = np.array([hi for _, hi in JOINT_BOUNDS] + [GRIPPER_COMMAND_RANGE[1]], dtype=np.float32)
    return spaces.Box(low, high, dtype=np.float32)


def residual_action_space() -> spaces.Box:
    """The ``residual`` action space, from the extension's bounds: offsets of the six joint set
    points (±0.1 rad) and of the gripper command (±255) added to the base tree's command for one
    control period. Values beyond it are clamped (``info["ctrl_clamped"]`` counts them)."""
    bounds = [_inside_f32(-hi, hi) for hi in RESIDUAL_HIGH]
    low = np.array([lo for lo, _ in bounds], dtype=np.float32)
    high = np.array([hi for _, hi in bounds], dtype=np.float32)
    return spaces.Box(low, high, dtype=np.float32)


#: The observation key layouts: Gymnasium's (``agent_pos``, ``environment_state``, ``pinch``,
#: ``pixels``; what LeRobot's ``preprocess_observation`` and its env plugins read) or LeRobot's
#: dataset keys (``observation.state``, ``observation.environment_state``,
#: ``observation.images.<camera>``; what a policy trained on a macrotree dataset takes).
OBSERVATION_KEYS = ("gym", "lerobot")


def observation_space(
    objects: int, cameras: list[str], image_size: tuple[int, int], keys: str = "gym"
) -> spaces.Dict:
    """Observations: ``agent_pos`` (the dataset's ``observation.state``, named by
    ``STATE_NAMES``: six joint angles and the gripper closure in radians, six joint velocities in
    rad/s, the pinch point in metres and its orientation qw, qx, qy, qz), ``environment_state``
    (every object's x, y, z, qw, qx, qy, qz in scene order: the dataset's
    ``observation.environment_state``), ``pinch`` (the gripper's pinch point and orientation: x,
    y, z, qw, qx, qy, qz), and ``pixels`` (one H×W×3 ``uint8`` image per camera) when cameras are
    asked for. With ``keys="lerobot"`` the same arrays under the dataset's keys (see
    :data:`OBSERVATION_KEYS`; ``pinch`` is part of the state)."""
    f32 = np.float32
    state = spaces.Box(-np.inf, np.inf, (len(STATE_NAMES),), f32)
    environment = spaces.Box(-np.inf, np.inf, (VALUES_PER_POSE * objects,), f32)
    h, w = image_size
    if keys == "lerobot":
        lerobot: dict[str, spaces.Space[Any]] = {
            "observation.state": state,
            "observation.environment_state": environment,
        }
        for c in cameras:
            lerobot[f"observation.images.{c}"] = spaces.Box(0, 255, (h, w, 3), np.uint8)
        return spaces.Dict(lerobot)
    fields: dict[str, spaces.Space[Any]] = {
        "agent_pos": state,
        "environment_state": environment,
        "pinch": spaces.Box(-np.inf, np.inf, (VALUES_PER_POSE,), f32),
    }
    if cameras:
        fields["pixels"] = spaces.Dict(
            {c: spaces.Box(0, 255, (h, w, 3), np.uint8) for c in cameras}
        )
    return spaces.Dict(fields)


def with_keys(obs: dict[str, Any], keys: str) -> dict[str, Any]:
    """An observation (Gymnasium keys, as the extension gives it) under the layout ``keys``."""
    if keys != "lerobot":
        return obs
    out = {
        "observation.state": obs["agent_pos"],
        "observation.environment_state": obs["environment_state"],
    }
    for camera, image in obs.get("pixels", {}).items():
        out[f"observation.images.{camera}"] = image
    return out


def real_array(value: Any, what: str) -> np.ndarray:
    """``value`` as a C-contiguous float64 array (any strides and real dtypes accepted); complex,
    text or object values raise ``TypeError`` naming ``what`` rather than losing a part."""
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        kind = "complex" if array.dtype.kind == "c" else f"{array.dtype}"
        raise TypeError(f"{what} must be real numbers, got {kind} values")
    return np.ascontiguousarray(array, dtype=np.float64)


def _vector(value: Any, n: int, name: str) -> list[float]:
    array = real_array(value, f"macro action `{name}`").reshape(-1)
    if array.shape != (n,):
        raise ValueError(f"macro action `{name}` must have {n} values, got shape {array.shape}")
    return [float(v) for v in array]


def _scalar(value: Any, name: str) -> float:
    array = real_array(value, f"macro action `{name}`").reshape(-1)
    if array.shape != (1,):
        raise ValueError(f"macro action `{name}` must be one value, got shape {array.shape}")
    return float(array[0])


#: The keys of a ``macro`` action (the extension's).
MACRO_KEYS = tuple(_MACRO_KEYS)


def _integer(value: Any, name: str) -> int:
    """One whole number (``mode``, ``steps``, …): a float must be integral, a string is refused."""
    array = np.asarray(value)
    if array.dtype.kind not in "biuf" or array.size != 1:
        raise ValueError(f"macro action `{name}` must be one whole number, got {value!r:.60}")
    number = float(array.reshape(-1)[0])
    if not number.is_integer():
        raise ValueError(f"macro action `{name}` must be a whole number, got {number!r:.60}")
    return int(number)


def macro_to_native(action: Any) -> dict[str, Any]:
    """A ``macro`` action (mapping) as the native extension takes it; raises ``ValueError`` on a
    malformed one (missing or unknown key, wrong shape, a fractional or text count). Ranges are
    checked by the native side."""
    if not isinstance(action, dict):
        raise ValueError(f"a macro action is a dict of the action space's keys, got {type(action)}")
    unknown = sorted(str(k)[:40] for k in action if k not in MACRO_KEYS)
    if unknown:
        raise ValueError(f"macro action keys {unknown} are unknown; keys: {list(MACRO_KEYS)}")
    missing = [k for k in ("mode",) if k not in action]
    if missing:
        raise ValueError(f"macro action misses {missing}")
    out: dict[str, Any] = {"mode": _integer(action["mode"], "mode")}
    if "position" in action:
        out["position"] = _vector(action["position"], 3, "position")
    if "quaternion" in action:
        out["quaternion"] = _vector(action["quaternion"], 4, "quaternion")
    if "joints" in action:
        out["joints"] = _vector(action["joints"], 6, "joints")
    if "gripper" in action:
        out["gripper"] = _integer(action["gripper"], "gripper")
    if "gripper_command" in action:
        out["gripper_command"] = _scalar(action["gripper_command"], "gripper_command")
    if "path" in action:
        out["path"] = _integer(action["path"], "path")
    if "steps" in action:
        out["steps"] = _integer(action["steps"], "steps")
    if "settle_steps" in action:
        out["settle_steps"] = _integer(action["settle_steps"], "settle_steps")
    return out
