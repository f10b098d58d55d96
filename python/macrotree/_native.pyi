"""
The native core of the `macrotree` package: single and vector environments over the Rust
library, the spaces' constants, video writing and ONNX policy evaluation. Its type stub,
`macrotree/_native.pyi`, is generated from the built module by `python/generate_stub.py`.
"""

from typing import Any, Final, SupportsFloat, SupportsIndex, final

import numpy as np
from _typeshed import SupportsGetItem
from numpy.typing import NDArray

__all__ = [
    "ACTION_LENGTHS",
    "CTRL_HIGH",
    "CTRL_LOW",
    "CTRL_NAMES",
    "GRIPPER_COMMAND_RANGE",
    "HOME",
    "JOINT_LIMITS",
    "MACRO_KEYS",
    "MAX_ENVS",
    "MAX_MACRO_STEPS",
    "MAX_REACH_DISTANCE",
    "OBJECT_NAMES",
    "RESIDUAL_HIGH",
    "STATE_NAMES",
    "VALUES_PER_POSE",
    "Env",
    "MacrotreeError",
    "VecEnv",
    "__version__",
    "gripper_command_for_width",
    "run_policy_model",
    "write_mp4",
]

ACTION_LENGTHS: Final[list[tuple[str, int]]]
"""
The length of each array action mode's action: `ctrl`, `setpoint`, `residual`.
"""

CTRL_HIGH: Final[list[float]]
"""
The highest value of each `ctrl` action value.
"""

CTRL_LOW: Final[list[float]]
"""
The lowest value of each `ctrl` action value (`macrotree::env::CTRL_LIMITS`).
"""

CTRL_NAMES: Final[list[str]]
"""
The names of a `ctrl` action's values (set points, velocities, accelerations, gripper).
"""

GRIPPER_COMMAND_RANGE: Final[tuple[float, float]]
"""
The gripper command's range: open, closed (the 2F-85's 0 … 255).
"""

HOME: Final[list[float]]
"""
The arm's home configuration, radians.
"""

JOINT_LIMITS: Final[list[tuple[float, float]]]
"""
Each arm joint's limits (low, high), radians, shoulder pan … wrist 3.
"""

MACRO_KEYS: Final[list[str]]
"""
The keys a macro action may have.
"""

MAX_ENVS: Final[int]
"""
Most environments of one vector environment.
"""

MAX_MACRO_STEPS: Final[int]
"""
The longest macro primitive (`steps` + `settle_steps`), in 2 ms physics steps.
"""

MAX_REACH_DISTANCE: Final[float]
"""
The farthest a pose target may be from the robot's base, metres (the UR5e reaches about
0.85 m plus the gripper; a farther target is refused, a nearer unreachable one fails).
"""

OBJECT_NAMES: Final[list[str]]
"""
The names of an object vector's values (the dataset's object features).
"""

RESIDUAL_HIGH: Final[list[float]]
"""
The highest value of each residual action value (the lowest is its negative): joint
offsets (rad), then the gripper offset.
"""

STATE_NAMES: Final[list[str]]
"""
The names of the state vector's values (`agent_pos`, the dataset's
`observation.state`).
"""

VALUES_PER_POSE: Final[int]
"""
Values per object in `environment_state` (x, y, z, qw, qx, qy, qz).
"""

__version__: Final[str]
"""
The package version.
"""

@final
class Env:
    """
    One simulated cell, stepped one action at a time (the GIL is released while it steps).
    """
    def __new__(
        cls,
        /,
        *,
        scene: str | None,
        tree: str | None,
        control_period: SupportsFloat | SupportsIndex,
        max_sim_time: SupportsFloat | SupportsIndex,
        fault: str | None,
        cameras: SupportsGetItem[int, str],
        image_size: tuple[SupportsIndex, SupportsIndex],
        frame_rate: SupportsFloat | SupportsIndex | None = None,
        render_camera: str | None = None,
        noise: str | None = None,
    ) -> Env: ...
    @property
    def cameras(self, /) -> list[str]:
        """
        The scene's cameras.
        """
    @property
    def control_period(self, /) -> float:
        """
        Seconds of one control period.
        """
    def gripper_command_for_width(self, /, width: SupportsFloat | SupportsIndex) -> float: ...
    @property
    def home(self, /) -> list[float]:
        """
        The UR5e home joint angles, radians.
        """
    @property
    def object_names(self, /) -> list[str]:
        """
        Object names, scene order.
        """
    def observation(self, /) -> dict[str, Any]: ...
    def record_controls(self, /) -> None:
        """
        Records the actuator commands of every physics step from now until the next reset.
        """
    def render(
        self, /, camera: str | None, height: SupportsIndex, width: SupportsIndex
    ) -> NDArray[np.uint8]: ...
    def replay_recorded(self, /) -> tuple[float, int, bool]:
        """
        Replays the recorded commands on a fresh simulation with bare `mj_step` from this
        episode's start: `(wall seconds, physics steps, ends in this environment's state bit for
        bit)`. For benchmarks: the same controls, no tree, no controllers, no Python.
        """
    def reset(
        self,
        /,
        *,
        seed: SupportsIndex,
        layout: str | None = None,
        scenario: SupportsIndex | None = None,
        sweep_seed: SupportsIndex | None = None,
        placement: dict[str, list[float]] | None = None,
    ) -> dict[str, Any]: ...
    def step_array(self, /, mode: str, values: Any) -> dict[str, Any]:
        """
        One control period of an array mode: `mode` `"ctrl"` (19 values), `"setpoint"` (7) or
        `"residual"` (7), `values` any array of that many real numbers (see `real.rs`).
        """
    def step_leaf(self, /, text: str) -> dict[str, Any]: ...
    def step_macro(self, /, action: dict[str, Any]) -> dict[str, Any]: ...
    def step_subtree(self, /, name: str) -> dict[str, Any]: ...
    def take_frames(self, /) -> list[NDArray[np.uint8]]:
        """
        The frames filmed since the last call (`rgb_array_list`), each H×W×3 `uint8`.
        """
    @property
    def task(self, /) -> str:
        """
        The scene's name (LeRobot's `task`).
        """
    @property
    def task_description(self, /) -> str:
        """
        A sentence about the task (LeRobot's `task_description`).
        """

@final
class VecEnv:
    """
    N environments stepped in parallel.
    """
    def __new__(
        cls,
        /,
        *,
        num_envs: SupportsIndex,
        threads: SupportsIndex | None,
        scene: str | None,
        tree: str | None,
        control_period: SupportsFloat | SupportsIndex,
        max_sim_time: SupportsFloat | SupportsIndex,
        fault: str | None,
        cameras: SupportsGetItem[int, str],
        image_size: tuple[SupportsIndex, SupportsIndex],
        noise: str | None = None,
    ) -> VecEnv: ...
    def close(self, /) -> None:
        """
        Waits for running actions, then stops the worker threads.
        """
    @property
    def object_names(self, /) -> list[str]: ...
    def recv(self, /, count: SupportsIndex) -> dict[str, Any]:
        """
        Waits for at least `count` environments to finish; the batch of their results in
        finishing order, `env_id` saying whose.
        """
    def render(
        self, /, camera: str | None, height: SupportsIndex, width: SupportsIndex
    ) -> list[NDArray[np.uint8]]: ...
    def reset(
        self,
        /,
        *,
        ids: SupportsGetItem[int, SupportsIndex],
        seeds: SupportsGetItem[int, SupportsIndex],
        layout: str | None = None,
        scenario: SupportsIndex | None = None,
        sweep_seed: SupportsIndex | None = None,
        placement: dict[str, list[float]] | None = None,
    ) -> list[dict[str, Any]]: ...
    def send(
        self, /, ids: SupportsGetItem[int, SupportsIndex], actions: list[Any] | tuple[str, Any]
    ) -> None:
        """
        Starts `actions` on environments `ids` and returns at once.
        """
    def step(
        self, /, ids: SupportsGetItem[int, SupportsIndex], actions: list[Any] | tuple[str, Any]
    ) -> dict[str, Any]:
        """
        Steps environments `ids` with `actions` in parallel; the batch of their results, in
        the order of `ids` (see `batch.rs`).
        """

def gripper_command_for_width(width: SupportsFloat | SupportsIndex) -> float:
    """
    The 2F-85 command (0 … 255) that closes the pads to `width` metres (the gripper
    calibration).
    """

def run_policy_model(
    path: str, inputs: dict[str, SupportsGetItem[int, SupportsFloat | SupportsIndex]]
) -> list[list[float]]:
    """
    Runs the ONNX model at `path` once on `inputs` (input name → values, not normalised), as a
    `policy` leaf does: the actions, un-normalised, one list per chunk step in the model's own
    layout (7 values: six joint set points in radians or offsets and the gripper command; or
    19: set points, velocities, accelerations and the gripper command).
    """

def write_mp4(path: str, frames: list[NDArray[np.uint8]], fps: SupportsIndex) -> int:
    """
    Writes `frames` (H×W×3 uint8, one size) at `fps` to `path`; returns the number of frames.
    """

class MacrotreeError(Exception):
    kind: str
    """The error's stable kind, e.g. ``invalid_tree`` (set on every instance)."""
