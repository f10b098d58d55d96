"""The plugin's plain facts, without LeRobot: the tasks, gym ids, keyword arguments and features.

Everything shaped by the Rust side (the state's length, the objects of a scene, the action's
length, the camera images) is read from the ``macrotree`` package's own spaces, and the mapping
from the environment's observation keys to a LeRobot dataset's keys from ``macrotree``'s
:func:`macrotree.spaces.with_keys`. LeRobot's config (:mod:`lerobot_env_macrotree.config`) turns
these into its ``PolicyFeature`` objects.
"""

from __future__ import annotations

import inspect
import os
from dataclasses import dataclass
from typing import Any, Literal

import gymnasium as gym
import numpy as np

from macrotree.env import ACTION_MODES, MacroEnv, StepReturn
from macrotree.registration import GENERIC_ID, SHIPPED
from macrotree.spaces import with_keys

#: ``--env.type`` of ``lerobot-eval``.
ENV_TYPE = "macrotree"

#: The gym namespace of the plugin's ids and the module LeRobot imports to register them
#: (``EnvConfig.package_name``; LeRobot's gym id is ``f"{package_name}/{task}"``).
NAMESPACE = "lerobot_env_macrotree"

#: The task ``lerobot-eval --env.type=macrotree`` runs without ``--env.task``.
DEFAULT_TASK = "CubeToBowl-v0"

#: Camera image and ``render()`` size, (height, width) pixels: ``MacroEnv``'s own default.
DEFAULT_IMAGE_SIZE: tuple[int, int] = tuple(
    inspect.signature(MacroEnv.__init__).parameters["image_size"].default
)

#: Frames per second (one ``env.step`` per frame): a macrotree dataset's default rate
#: (``macrotree sweep --dataset``, 20 ms frames), so a policy trained on one acts at its rate.
DEFAULT_FPS = 50

#: Frames of an episode before it is truncated (1000 frames: 20 s of simulated time at 50 fps).
DEFAULT_EPISODE_LENGTH = 1000

#: The action a LeRobot policy trained on a macrotree dataset emits: the dataset's ``action``
#: column, the 19-value ``ctrl`` command (docs/datasets.md).
DEFAULT_ACTION_MODE = "ctrl"

#: The reset option ``lerobot-eval`` 0.6 passes on every reset (``lerobot.envs.utils.
#: NEW_ROLLOUT_OPTION``): :class:`LeRobotMacroEnv` accepts and drops it.
LEROBOT_RESET_OPTION = "lerobot_new_rollout"

#: LeRobot task (``--env.task``) → the macrotree gym id it runs: the shipped ids (a scene with
#: its tree) and ``MacroEnv-v0`` (any scene: ``--env.scene=PATH``).
TASKS: dict[str, str] = {env_id.split("/", 1)[1]: env_id for env_id in [*SHIPPED, GENERIC_ID]}

#: LeRobot's ``FeatureType`` member of a feature (its name: ``lerobot.configs.FeatureType[kind]``).
FeatureKind = Literal["ACTION", "STATE", "ENV", "VISUAL"]

#: The prefix of a LeRobot dataset's camera keys (``observation.images.<camera>``).
IMAGES_PREFIX = "observation.images."


class PluginError(ValueError):
    """A plugin setting that cannot work (an unknown task or action mode, a frame rate or an
    episode length that is not a positive whole number, ``MacroEnv-v0`` without a scene)."""


@dataclass(frozen=True)
class Feature:
    """One feature of the environment, as LeRobot's ``EnvConfig.features`` describes it.

    Attributes:
        kind: the ``FeatureType`` member's name.
        shape: the array's shape: values (``ACTION``, ``STATE``, ``ENV``) or height × width × 3
            pixels (``VISUAL``, channel last, as the environment gives it).
        policy_key: the key a policy reads it under (``EnvConfig.features_map``): a LeRobot
            dataset's key.
    """

    kind: FeatureKind
    shape: tuple[int, ...]
    policy_key: str


def gym_id(task: str) -> str:
    """The plugin's gym id of ``task`` (LeRobot's ``EnvConfig.gym_id``)."""
    return f"{NAMESPACE}/{task}"


def macrotree_id(task: str) -> str:
    """The macrotree gym id ``task`` runs; :class:`PluginError` for an unknown task."""
    if task not in TASKS:
        raise PluginError(f"unknown macrotree task {task!r}; tasks: {sorted(TASKS)}")
    return TASKS[task]


def check(
    task: str, fps: int, episode_length: int, action_mode: str, scene: str | None = None
) -> None:
    """Raises :class:`PluginError` for settings no environment can run with: an unknown task or
    action mode, a frame rate (frames per second) or episode length (frames) that is not a
    positive whole number, or ``MacroEnv-v0`` without a scene. A frame rate whose period is not a
    whole number of the environment's 2 ms physics steps (or longer than its 0.1 s limit) is
    refused by the environment itself when it is made (``macrotree.MacrotreeError``)."""
    macrotree_id(task)
    if action_mode not in ACTION_MODES or ACTION_MODES[action_mode] is None:
        arrays = [m for m, shape in ACTION_MODES.items() if shape is not None]
        raise PluginError(
            f"action_mode must be one of {arrays} (a policy emits an array), got {action_mode!r}"
        )
    for name, value in (("fps", fps), ("episode_length", episode_length)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise PluginError(f"{name} must be a positive whole number, got {value!r}")
    if TASKS[task] not in SHIPPED and scene is None:
        raise PluginError(f"task {task!r} runs any scene: give scene=PATH")


def gym_kwargs(
    *,
    fps: int = DEFAULT_FPS,
    episode_length: int = DEFAULT_EPISODE_LENGTH,
    action_mode: str = DEFAULT_ACTION_MODE,
    cameras: list[str] | tuple[str, ...] = (),
    image_size: tuple[int, int] = DEFAULT_IMAGE_SIZE,
    scene: str | os.PathLike[str] | None = None,
    tree: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """The keyword arguments of ``gym.make(gym_id(task), **kwargs)`` (LeRobot's
    ``EnvConfig.gym_kwargs``).

    One ``env.step`` is one frame: ``control_period`` is ``1 / fps`` seconds. The episode is
    truncated after ``episode_length`` frames by Gymnasium's ``TimeLimit``
    (``max_episode_steps``, whose ``_max_episode_steps`` ``lerobot-eval`` reads); the
    environment's own limit on simulated time is one frame later, a backstop. ``render()``
    gives ``image_size`` (height, width) pixels, filmed at ``fps``.
    """
    out: dict[str, Any] = {
        "action_mode": action_mode,
        "control_period": 1.0 / fps,
        "max_sim_time": (episode_length + 1) / fps,
        "max_episode_steps": episode_length,
        "cameras": list(cameras),
        "image_size": (int(image_size[0]), int(image_size[1])),
        "render_mode": "rgb_array",
        "render_fps": fps,
    }
    if scene is not None:
        out["scene"] = os.fspath(scene)
    if tree is not None:
        out["tree"] = os.fspath(tree)
    return out


def features(
    task: str,
    *,
    action_mode: str = DEFAULT_ACTION_MODE,
    cameras: list[str] | tuple[str, ...] = (),
    image_size: tuple[int, int] = DEFAULT_IMAGE_SIZE,
    scene: str | os.PathLike[str] | None = None,
    tree: str | os.PathLike[str] | None = None,
) -> dict[str, Feature]:
    """The features of ``task`` by the environment's observation keys (``agent_pos``,
    ``environment_state``, ``pixels/<camera>``) and ``action``, read from a macrotree
    environment's own spaces (it is made, read and closed: about 0.2 s).

    ``pinch`` is left out: it is part of the state (``observation.state``) and has no key of its
    own in a LeRobot dataset.
    """
    files: dict[str, Any] = {
        k: os.fspath(v) for k, v in (("scene", scene), ("tree", tree)) if v is not None
    }
    env = gym.make(
        macrotree_id(task),
        disable_env_checker=True,
        action_mode=action_mode,
        cameras=list(cameras),
        image_size=image_size,
        observation_keys="gym",
        **files,
    )
    try:
        space = env.observation_space
        assert isinstance(space, gym.spaces.Dict), space
        mapping = _policy_keys(space)
        out: dict[str, Feature] = {}
        action_shape = env.action_space.shape
        assert action_shape is not None, env.action_space
        out["action"] = Feature("ACTION", tuple(action_shape), "action")
        for env_key, policy_key in mapping.items():
            sub: gym.Space[Any] = space
            for part in env_key.split("/"):
                assert isinstance(sub, gym.spaces.Dict), sub
                sub = sub[part]
            assert sub.shape is not None, sub
            out[env_key] = Feature(_kind(policy_key), tuple(sub.shape), policy_key)
        return out
    finally:
        env.close()


def _policy_keys(space: gym.spaces.Dict) -> dict[str, str]:
    """Each observation key (``pixels/<camera>`` for a camera) → the key
    :func:`macrotree.spaces.with_keys` gives the same array under in LeRobot's layout."""
    markers: dict[str, Any] = {}
    names: dict[int, str] = {}
    for key, sub in space.items():
        if isinstance(sub, gym.spaces.Dict):
            markers[key] = {}
            for camera in sub:
                marker = object()
                markers[key][camera] = marker
                names[id(marker)] = f"{key}/{camera}"
        else:
            marker = object()
            markers[key] = marker
            names[id(marker)] = key
    lerobot = with_keys(markers, "lerobot")
    return {names[id(marker)]: policy_key for policy_key, marker in lerobot.items()}


def _kind(policy_key: str) -> FeatureKind:
    """The ``FeatureType`` of a LeRobot dataset key."""
    if policy_key.startswith(IMAGES_PREFIX):
        return "VISUAL"
    if policy_key == "observation.environment_state":
        return "ENV"
    if policy_key == "observation.state":
        return "STATE"
    raise PluginError(f"no LeRobot feature type for {policy_key!r}")


class LeRobotMacroEnv(MacroEnv):
    """A :class:`macrotree.MacroEnv` for a LeRobot policy: it takes ``lerobot-eval``'s reset
    option and clips array actions into the action space.

    ``lerobot-eval`` 0.6 resets with ``options={"lerobot_new_rollout": True}`` (its mark of a
    new rollout, for its own wrappers); ``MacroEnv`` refuses options it does not know, so this
    drops that one and passes the rest on. A policy's action is a regression un-normalised with
    its dataset's statistics, which ``lerobot-eval`` does not bound: it can overshoot (a gripper
    command of -1 for "open"), and ``MacroEnv`` refuses a set point beyond a joint limit or a
    gripper command outside 0…255; so :meth:`step` clips it first.
    """

    def step(self, action: Any) -> StepReturn:
        """``MacroEnv.step`` of the action clipped into ``action_space``'s bounds;
        ``info["action_clipped"]`` counts the values that were outside them. Values that are
        not finite are not clipped: ``MacroEnv`` refuses them (``macrotree.MacrotreeError``)."""
        space = self.action_space
        if not isinstance(space, gym.spaces.Box):
            return super().step(action)
        values = np.asarray(action, dtype=np.float64)
        if values.shape != space.shape:
            return super().step(action)  # refused there, with the shape it takes
        clipped = np.clip(values, space.low, space.high)
        outside = int(np.count_nonzero((clipped != values) & np.isfinite(values)))
        obs, reward, terminated, truncated, info = super().step(clipped)
        info["action_clipped"] = outside
        return obs, reward, terminated, truncated, info

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """``MacroEnv.reset`` without :data:`LEROBOT_RESET_OPTION` in ``options``."""
        rest = {k: v for k, v in (options or {}).items() if k != LEROBOT_RESET_OPTION}
        return super().reset(seed=seed, options=rest or None)


def register_gym_ids() -> None:
    """Registers ``lerobot_env_macrotree/<task>`` for every task (idempotent): a
    :class:`LeRobotMacroEnv` of the task's scene and tree."""
    for task, macrotree_id in TASKS.items():
        if gym_id(task) not in gym.registry:
            gym.register(
                id=gym_id(task),
                entry_point=f"{__name__}:LeRobotMacroEnv",
                kwargs=dict(gym.spec(macrotree_id).kwargs),
            )
