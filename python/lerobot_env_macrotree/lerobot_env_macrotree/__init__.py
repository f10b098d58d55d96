"""LeRobot env plugin for macrotree: ``lerobot-eval --env.type=macrotree --policy.path=…``.

Importing it registers the gym ids ``lerobot_env_macrotree/<task>`` (one per macrotree task,
:data:`lerobot_env_macrotree.facts.TASKS`) and, only when LeRobot is installed, the LeRobot
``EnvConfig`` subclass :class:`lerobot_env_macrotree.config.MacrotreeEnv` under the type
``macrotree``. LeRobot 0.6 imports every installed distribution whose name starts with
``lerobot_env_``; LeRobot 0.4–0.5 import it with ``--env.discover_packages_path=
lerobot_env_macrotree``. Without LeRobot (and torch) the facts — tasks, gym ids, keyword
arguments, features — and the environments work the same.
"""

from __future__ import annotations

import importlib.util

from lerobot_env_macrotree.facts import (
    DEFAULT_ACTION_MODE,
    DEFAULT_EPISODE_LENGTH,
    DEFAULT_FPS,
    DEFAULT_IMAGE_SIZE,
    DEFAULT_TASK,
    ENV_TYPE,
    NAMESPACE,
    TASKS,
    Feature,
    LeRobotMacroEnv,
    PluginError,
    check,
    features,
    gym_id,
    gym_kwargs,
    register_gym_ids,
)

register_gym_ids()

#: Whether LeRobot is installed (then :mod:`lerobot_env_macrotree.config` is imported, which
#: registers the ``macrotree`` env type).
LEROBOT_INSTALLED = importlib.util.find_spec("lerobot") is not None

if LEROBOT_INSTALLED:
    import lerobot_env_macrotree.config  # noqa: F401  (registers the env type)

__all__ = [
    "DEFAULT_ACTION_MODE",
    "DEFAULT_EPISODE_LENGTH",
    "DEFAULT_FPS",
    "DEFAULT_IMAGE_SIZE",
    "DEFAULT_TASK",
    "ENV_TYPE",
    "LEROBOT_INSTALLED",
    "NAMESPACE",
    "TASKS",
    "Feature",
    "LeRobotMacroEnv",
    "PluginError",
    "check",
    "features",
    "gym_id",
    "gym_kwargs",
]
