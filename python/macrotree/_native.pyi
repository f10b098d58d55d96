"""Type stubs of the native extension (``python/src/``)."""

from typing import Any

import numpy as np

__version__: str
JOINT_LIMITS: list[tuple[float, float]]
HOME: list[float]
MAX_ENVS: int
CTRL_NAMES: list[str]
STATE_NAMES: list[str]
MACRO_KEYS: list[str]
CTRL_LOW: list[float]
CTRL_HIGH: list[float]
RESIDUAL_HIGH: list[float]
OBJECT_NAMES: list[str]
VALUES_PER_POSE: int
MAX_MACRO_STEPS: int
GRIPPER_COMMAND_RANGE: tuple[float, float]

class MacrotreeError(Exception):
    """Invalid input: the message is located (``file:line:column``) and says what to do."""

def gripper_command_for_width(width: float) -> float: ...

class Env:
    object_names: list[str]
    cameras: list[str]
    home: list[float]
    task: str
    task_description: str
    control_period: float
    def __init__(
        self,
        *,
        scene: str | None,
        tree: str | None,
        control_period: float,
        max_sim_time: float,
        fault: str | None,
        cameras: list[str],
        image_size: tuple[int, int],
        frame_rate: float | None = None,
        render_camera: str | None = None,
        noise: str | None = None,
    ) -> None: ...
    def reset(
        self,
        *,
        seed: int,
        layout: str | None = None,
        scenario: int | None = None,
        sweep_seed: int | None = None,
        placement: dict[str, list[float]] | None = None,
    ) -> dict[str, Any]: ...
    def step_macro(self, action: dict[str, Any]) -> dict[str, Any]: ...
    def step_ctrl(self, ctrl: np.ndarray) -> dict[str, Any]: ...
    def step_setpoint(self, setpoint: np.ndarray) -> dict[str, Any]: ...
    def step_residual(self, residual: np.ndarray) -> dict[str, Any]: ...
    def step_leaf(self, text: str) -> dict[str, Any]: ...
    def step_subtree(self, name: str) -> dict[str, Any]: ...
    def observation(self) -> dict[str, Any]: ...
    def render(self, camera: str | None, height: int, width: int) -> np.ndarray: ...
    def take_frames(self) -> list[np.ndarray]: ...
    def gripper_command_for_width(self, width: float) -> float: ...
    def record_controls(self) -> None: ...
    def replay_recorded(self) -> tuple[float, int, bool]: ...

class VecEnv:
    object_names: list[str]
    def __init__(
        self,
        *,
        num_envs: int,
        threads: int | None,
        scene: str | None,
        tree: str | None,
        control_period: float,
        max_sim_time: float,
        fault: str | None,
        cameras: list[str],
        image_size: tuple[int, int],
        noise: str | None = None,
    ) -> None: ...
    def reset(
        self,
        *,
        ids: list[int],
        seeds: list[int],
        layout: str | None = None,
        scenario: int | None = None,
        sweep_seed: int | None = None,
        placement: dict[str, list[float]] | None = None,
    ) -> list[dict[str, Any]]: ...
    def step(self, ids: list[int], actions: list[Any]) -> dict[str, Any]: ...
    def send(self, ids: list[int], actions: list[Any]) -> None: ...
    def recv(self, count: int) -> dict[str, Any]: ...
    def render(self, camera: str | None, height: int, width: int) -> list[np.ndarray]: ...
    def close(self) -> None: ...

def write_mp4(path: str, frames: list[np.ndarray], fps: int) -> int: ...
def run_policy_model(path: str, inputs: dict[str, list[float]]) -> list[list[float]]: ...
