"""``MacroEnv``: a ``gymnasium.Env`` over the Rust ``macrotree`` environment.

One ``step`` runs one macro action to completion on simulated time, closed loop inside the action
(``action_mode="macro"``), or commands the arm and gripper for one control period: the 19-D
command every leaf gives and a dataset's ``action`` records (``action_mode="ctrl"``), or plain
7-D set points (``action_mode="setpoint"``), or adds a 7-D correction to the command the tree
gives in that period (``action_mode="residual"``, residual RL). Any registered leaf runs through
:meth:`MacroEnv.step_leaf`, a named subtree through :meth:`MacroEnv.step_subtree`. Everything
heavy happens in Rust with the GIL released; this class converts arguments and results.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any, Literal, SupportsFloat

import gymnasium as gym
import numpy as np

from macrotree import _native
from macrotree.spaces import (
    OBSERVATION_KEYS,
    ctrl_action_space,
    macro_action_space,
    macro_to_native,
    observation_space,
    residual_action_space,
    setpoint_action_space,
    with_keys,
)

ActionMode = Literal["macro", "ctrl", "setpoint", "residual"]

#: Every action mode, and the shape of its array actions (``None`` for the macro ``Dict``).
ACTION_MODES: dict[str, tuple[int, ...] | None] = {
    "macro": None,
    **{mode: (length,) for mode, length in _native.ACTION_LENGTHS},
}
Observation = dict[str, Any]
StepReturn = tuple[Observation, SupportsFloat, bool, bool, dict[str, Any]]

#: Reset options understood by :meth:`MacroEnv.reset` (anything else is refused).
RESET_OPTIONS = ("layout", "scenario", "sweep_seed", "placement", "reset_mask")


class Closed:
    """What a closed environment's native part becomes: every use raises ``RuntimeError``."""

    def __init__(self, what: str) -> None:
        self._what = what

    def __getattr__(self, name: str) -> Any:
        raise RuntimeError(f"this {self._what} is closed; make a new one")


def _path(value: str | os.PathLike[str] | None) -> str | None:
    return None if value is None else os.fspath(value)


class MacroEnv(gym.Env[Observation, Any]):
    """A UR5e + 2F-85 cell of a macrotree scene, stepped one macro action at a time.

    Args:
        scene: a scene file (``scenes/*.yaml``); ``None`` takes the tree's ``scene:``.
        tree: a tree file, for :meth:`step_subtree` and a scene goal of the tree; optional.
        action_mode: ``"macro"`` (a ``Dict`` mirroring TorchRL's ``RobotMacroAction``) or
            ``"ctrl"`` (``Box(19)``: six joint set points in radians, six velocities in rad/s,
            six accelerations in rad/s² and the gripper command 0…255 for one control period —
            what every leaf commands and a dataset's ``action`` column records) or
            ``"setpoint"`` (``Box(7)``: six set points and the gripper command, zero velocity)
            or ``"residual"`` (``Box(7)``: each step runs one control period of the base tree
            and adds these offsets — six joint set points in radians, ±0.1, and the gripper
            command, ±255 — to the command the tree gives; ``info["base_action"]`` holds the
            tree's command, ``info["base_status"]`` its status; a zero residual replays the
            scripted episode bit for bit).
        base: the base tree of ``"residual"`` (default: ``tree``, the id's own tree).
        render_mode: ``None``, ``"rgb_array"`` (``render()`` gives an H×W×3 ``uint8`` image of
            ``render_camera`` now) or ``"rgb_array_list"`` (``render()`` gives the frames sampled
            at ``render_fps`` of simulated time during the steps since the last call).
        cameras: cameras whose images are added to observations under ``pixels``.
        image_size: ``(height, width)`` of camera images and of ``render()``, pixels.
        render_camera: the camera ``render()`` shows (default: the scene's first camera).
        control_period: seconds of one ``ctrl`` step and of one macro ``steps`` unit (a whole
            number of 2 ms physics steps; default 0.01 s, the reference's 5-step frame skip).
        max_sim_time: simulated seconds after which an episode is truncated.
        fault: a fault injected through physics (``slip``, ``nudge``, …), or ``None``.
        render_fps: frames per simulated second of ``rgb_array_list`` (``metadata["render_fps"]``).
        noise: DART-style noise on what the arm and gripper execute, as ``sweep --dataset
            --noise`` takes it: ``"JOINT_SIGMA[,GRIPPER_SIGMA]"`` (radians, actuator units) or a
            pair; seeded per episode; the leaves' and the base tree's commands stay clean.
        observation_keys: ``"gym"`` (``agent_pos``, ``environment_state``, ``pinch``,
            ``pixels``) or ``"lerobot"`` (``observation.state``, ``observation.environment_state``,
            ``observation.images.<camera>``: a LeRobot dataset's keys).

    Attributes:
        dt: simulated seconds of one ``ctrl``, ``setpoint`` or ``residual`` step, as in
            Gymnasium's MuJoCo environments (``control_period``); a macro step lasts a whole
            number of them (``info["sim_time"]`` says how long).
    """

    metadata: dict[str, Any] = {  # noqa: RUF012  (Gymnasium declares it so)
        "render_modes": ["rgb_array", "rgb_array_list"],
        "render_fps": 30,
    }

    def __init__(
        self,
        scene: str | os.PathLike[str] | None = None,
        tree: str | os.PathLike[str] | None = None,
        *,
        action_mode: ActionMode = "macro",
        base: str | os.PathLike[str] | None = None,
        render_mode: str | None = None,
        cameras: tuple[str, ...] | list[str] = (),
        image_size: tuple[int, int] = (240, 320),
        render_camera: str | None = None,
        control_period: float = 0.01,
        max_sim_time: float = 120.0,
        fault: str | None = None,
        render_fps: int = 30,
        noise: str | tuple[float, float] | None = None,
        observation_keys: str = "gym",
    ) -> None:
        tree = _base_tree(action_mode, tree, base)
        _check_keys(observation_keys)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        if scene is None and tree is None:
            raise ValueError("MacroEnv needs a scene file, a tree file, or both")
        self._native: _native.Env | Closed = _native.Env(
            scene=_path(scene),
            tree=_path(tree),
            control_period=float(control_period),
            max_sim_time=float(max_sim_time),
            fault=fault,
            cameras=list(cameras),
            image_size=(int(image_size[0]), int(image_size[1])),
            frame_rate=float(render_fps) if render_mode == "rgb_array_list" else None,
            render_camera=render_camera,
            noise=_noise_text(noise),
        )
        self.observation_keys = observation_keys
        self.metadata = {**self.metadata, "render_fps": int(render_fps)}
        self.action_mode: ActionMode = action_mode
        self.render_mode = render_mode
        self.cameras = list(cameras)
        self.image_size = (int(image_size[0]), int(image_size[1]))
        self.render_camera = render_camera
        self.object_names: list[str] = list(self._native.object_names)
        self.observation_space = observation_space(
            len(self.object_names), self.cameras, self.image_size, observation_keys
        )
        self.action_space = action_space(action_mode)
        # LeRobot's environment contract.
        self.task = str(self._native.task)
        self.task_description = str(self._native.task_description)
        # Gymnasium's MuJoCo environments' `dt`: simulated seconds of one control period (one
        # `ctrl`, `setpoint` or `residual` step; a macro step runs a whole number of them).
        self.dt: float = float(control_period)
        self._last_info: dict[str, Any] = {}

    # --- Gymnasium API -------------------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Observation, dict[str, Any]]:
        """Starts an episode.

        Without options the objects are placed by the scene's random sampler, seeded from
        ``seed`` (through ``self.np_random``, so ``reset()`` after ``reset(seed=s)`` continues the
        sequence deterministically). Options (at most one of them):

        * ``{"layout": "default"}``: the scene's own placement (the reference's default layout);
        * ``{"scenario": K, "sweep_seed": S}``: scenario K of sweep seed S, the placement
          ``macrotree run --scenario K --sweep-seed S`` uses;
        * ``{"placement": {"cube": [x, y, yaw], …}}``: explicit poses on the table (metres,
          radians) for the objects named (the others as in the scene's default placement).
        """
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = sorted(set(options) - set(RESET_OPTIONS))
        if unknown:
            raise ValueError(f"unknown reset option(s) {unknown}; expected {list(RESET_OPTIONS)}")
        options.pop("reset_mask", None)
        draw = int(self.np_random.integers(0, 2**63 - 1))
        result = self._native.reset(
            seed=draw,
            layout=options.get("layout"),
            scenario=options.get("scenario"),
            sweep_seed=options.get("sweep_seed"),
            placement=options.get("placement"),
        )
        self._last_info = dict(result["info"])
        return with_keys(result["obs"], self.observation_keys), dict(result["info"])

    def step(self, action: Any) -> StepReturn:
        """Runs one action: a macro to completion, or one control period of ``ctrl``."""
        if self.action_mode == "macro":
            result = self._native.step_macro(macro_to_native(action))
        else:
            # The extension reads any real array of the mode's length and says what is wrong
            # with any other.
            result = self._native.step_array(self.action_mode, action)
        return self._unpack(result)

    def render(self) -> Any:
        """``rgb_array``: an H×W×3 ``uint8`` image of ``render_camera`` now. ``rgb_array_list``:
        the frames sampled during the steps since the last call (and the current one)."""
        if self.render_mode is None:
            gym.logger.warn("render() called with render_mode=None; pass render_mode='rgb_array'")
            return None
        if self.render_mode == "rgb_array_list":
            return list(self._native.take_frames())
        h, w = self.image_size
        return self._native.render(self.render_camera, h, w)

    def close(self) -> None:
        """Frees the native cell; idempotent. Every later call raises ``RuntimeError``."""
        self._native = Closed("MacroEnv")

    def __copy__(self) -> MacroEnv:
        raise TypeError(
            "a MacroEnv cannot be copied (a copy would share its simulation); make a new one"
        )

    def __deepcopy__(self, memo: dict[int, Any]) -> MacroEnv:
        return self.__copy__()

    # --- beyond Gymnasium ------------------------------------------------------------------------

    def step_leaf(self, leaf: Mapping[str, Any] | str) -> StepReturn:
        """Runs any registered leaf to completion, given as a mapping such as
        ``{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}`` (or its YAML/JSON text). A bad
        mapping raises :class:`macrotree.MacrotreeError` with a located message."""
        text = leaf if isinstance(leaf, str) else json.dumps(leaf)
        return self._unpack(self._native.step_leaf(text))

    def step_subtree(self, name: str = "main") -> StepReturn:
        """Runs a named subtree of the tree (``"main"``: the whole tree) until it finishes."""
        return self._unpack(self._native.step_subtree(name))

    def observation(self) -> dict[str, Any]:
        """The full typed observation of the cell now, as the Rust ``env::Observation`` serializes
        it: joints, velocities and targets, gripper width and command, the last command, pinch
        and pad positions, every object's kind, half extents, pose, velocities and grasped flag
        by name, contacts."""
        return dict(self._native.observation())

    def object_pose(self, obs: Observation, name: str) -> np.ndarray:
        """The pose ``[x, y, z, qw, qx, qy, qz]`` of object ``name`` in an observation."""
        i = self.object_names.index(name)
        return np.asarray(obs["environment_state"][7 * i : 7 * i + 7])

    def record_controls(self) -> None:
        """Records the actuator commands of every physics step until the next reset (for
        :meth:`replay_recorded`)."""
        self._native.record_controls()

    def replay_recorded(self) -> tuple[float, int, bool]:
        """Replays the recorded commands with bare ``mj_step`` from this episode's start: wall
        seconds, physics steps, and whether it ended in this environment's state bit for bit. The
        benchmark of what the environment costs over physics (``examples/python/bench_env.py``)."""
        return self._native.replay_recorded()

    @property
    def home(self) -> np.ndarray:
        """The UR5e home joint angles, radians."""
        return np.asarray(self._native.home, dtype=np.float64)

    def gripper_command_for_width(self, width: float) -> float:
        """The 2F-85 command (0…255) that closes the pads to ``width`` metres."""
        return float(self._native.gripper_command_for_width(float(width)))

    def _unpack(self, result: dict[str, Any]) -> StepReturn:
        info = dict(result["info"])
        self._last_info = info
        return (
            with_keys(result["obs"], self.observation_keys),
            float(result["reward"]),
            bool(result["terminated"]),
            bool(result["truncated"]),
            info,
        )


def action_space(action_mode: str) -> gym.Space[Any]:
    """The action space of ``action_mode`` (see :class:`MacroEnv`)."""
    if action_mode == "ctrl":
        return ctrl_action_space()
    if action_mode == "setpoint":
        return setpoint_action_space()
    if action_mode == "residual":
        return residual_action_space()
    return macro_action_space()


def _base_tree(
    action_mode: str,
    tree: str | os.PathLike[str] | None,
    base: str | os.PathLike[str] | None,
) -> str | os.PathLike[str] | None:
    """The tree of an environment: ``base`` for the residual mode when given, else ``tree``;
    raises ``ValueError`` for an unknown mode, a ``base`` outside the residual mode, or a
    residual mode without a tree."""
    if action_mode not in ACTION_MODES:
        raise ValueError(f"action_mode must be one of {list(ACTION_MODES)}, got {action_mode!r}")
    if base is not None and action_mode != "residual":
        raise ValueError(f"base= is the residual mode's base tree; action_mode is {action_mode!r}")
    if action_mode == "residual":
        tree = base if base is not None else tree
        if tree is None:
            raise ValueError("action_mode='residual' needs a base tree: give tree= or base=")
    return tree


def _check_keys(observation_keys: str) -> None:
    if observation_keys not in OBSERVATION_KEYS:
        raise ValueError(
            f"observation_keys must be one of {list(OBSERVATION_KEYS)}, got {observation_keys!r}"
        )


def _noise_text(noise: str | tuple[float, float] | None) -> str | None:
    """``noise`` as the extension reads it (``"JOINT_SIGMA[,GRIPPER_SIGMA]"``)."""
    if noise is None or isinstance(noise, str):
        return noise
    joint, gripper = noise
    return f"{float(joint)!r},{float(gripper)!r}"
