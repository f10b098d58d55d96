"""LeRobot's ``EnvConfig`` for macrotree, registered as ``--env.type=macrotree``.

Imported by :mod:`lerobot_env_macrotree` only when LeRobot is installed (LeRobot pulls in torch).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from lerobot.configs import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig

from lerobot_env_macrotree import facts


@EnvConfig.register_subclass(facts.ENV_TYPE)
@dataclass
class MacrotreeEnv(EnvConfig):  # type: ignore[misc]
    """``lerobot-eval --env.type=macrotree``: a macrotree task, one frame per ``env.step``.

    Attributes:
        task: the task (``--env.task``), a key of :data:`lerobot_env_macrotree.facts.TASKS`
            (``CubeToBowl-v0``, ``SortByColor-v0``, ``StackThree-v0``, ``ClearTable-v0``,
            ``MacroEnv-v0`` with ``scene``).
        fps: frames per second of simulated time; one step lasts ``1 / fps`` seconds (the
            environment's ``control_period``). Use the training dataset's rate (50 by default).
        episode_length: frames before an episode is truncated.
        action_mode: what the policy's action is: ``ctrl`` (19 values, a macrotree dataset's
            ``action``), ``setpoint`` (7) or ``residual`` (7 offsets added to the task tree's
            command).
        cameras: cameras whose images the policy gets as ``observation.images.<camera>``.
        image_height: camera and ``render()`` image height, pixels.
        image_width: camera and ``render()`` image width, pixels.
        scene: a scene file (``MacroEnv-v0``; with a shipped task, replaces its scene).
        tree: a tree file (the residual mode's base tree; with a shipped task, replaces its tree).
        features: computed from the environment's spaces (``action``, ``agent_pos``,
            ``environment_state``, ``pixels/<camera>``); not to be set.
        features_map: each feature's policy key (``action``, ``observation.state``,
            ``observation.environment_state``, ``observation.images.<camera>``); not to be set.
    """

    task: str | None = facts.DEFAULT_TASK
    fps: int = facts.DEFAULT_FPS
    episode_length: int = facts.DEFAULT_EPISODE_LENGTH
    action_mode: str = facts.DEFAULT_ACTION_MODE
    cameras: list[str] = field(default_factory=list)
    image_height: int = facts.DEFAULT_IMAGE_SIZE[0]
    image_width: int = facts.DEFAULT_IMAGE_SIZE[1]
    scene: str | None = None
    tree: str | None = None
    features: dict[str, PolicyFeature] = field(default_factory=dict)
    features_map: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Checks the settings (:class:`lerobot_env_macrotree.PluginError`) and reads the
        features from the environment's spaces."""
        task = self.task or ""
        facts.check(task, self.fps, self.episode_length, self.action_mode, self.scene)
        found = facts.features(
            task,
            action_mode=self.action_mode,
            cameras=self.cameras,
            image_size=(self.image_height, self.image_width),
            scene=self.scene,
            tree=self.tree,
        )
        self.features = {
            key: PolicyFeature(type=FeatureType[f.kind], shape=f.shape) for key, f in found.items()
        }
        self.features_map = {key: f.policy_key for key, f in found.items()}

    @property
    def package_name(self) -> str:
        """The module that registers the gym ids (``lerobot_env_macrotree``)."""
        return facts.NAMESPACE

    @property
    def gym_kwargs(self) -> dict[str, Any]:
        """``gym.make`` keyword arguments: :func:`lerobot_env_macrotree.facts.gym_kwargs`."""
        return facts.gym_kwargs(
            fps=self.fps,
            episode_length=self.episode_length,
            action_mode=self.action_mode,
            cameras=self.cameras,
            image_size=(self.image_height, self.image_width),
            scene=self.scene,
            tree=self.tree,
        )
