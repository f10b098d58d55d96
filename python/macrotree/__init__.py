"""macrotree from Python: a step-wise macro-action environment for a MuJoCo UR5e + Robotiq 2F-85.

* :class:`MacroEnv`: a ``gymnasium.Env``; one ``step`` runs one macro action (the reference
  tutorial's ``RobotMacroAction``), one control period of the 19-D command every leaf gives, any
  registered leaf (:meth:`MacroEnv.step_leaf`), or a named subtree (:meth:`MacroEnv.step_subtree`).
* :class:`VectorEnv`: N cells stepped on Rust threads, with envpool-style ``send``/``recv``.
* Gymnasium ids (registered on import): ``macrotree/CubeToBowl-v0``, ``macrotree/SortByColor-v0``,
  ``macrotree/StackThree-v0``, ``macrotree/ClearTable-v0`` and ``macrotree/MacroEnv-v0`` (any
  scene: ``gymnasium.make("macrotree/MacroEnv-v0", scene=PATH)``).

* :func:`run_policy_model`: an ONNX model run once as a ``policy`` leaf runs it;
  ``python -m macrotree.bc`` clones a skill of a dataset into one (docs/learning.md).

Errors in input (a bad leaf mapping, a bad scene file) raise :class:`MacrotreeError` with the
located message (``file:line:column``).
"""

from macrotree._library import SetupError, prepare

prepare()

from macrotree._native import (  # noqa: E402
    CTRL_NAMES,
    OBJECT_NAMES,
    STATE_NAMES,
    MacrotreeError,
    __version__,
    run_policy_model,
)
from macrotree.env import MacroEnv  # noqa: E402
from macrotree.registration import register_envs  # noqa: E402
from macrotree.spaces import Gripper, MacroMode  # noqa: E402
from macrotree.vector import VectorEnv  # noqa: E402

register_envs()

__all__ = [
    "CTRL_NAMES",
    "OBJECT_NAMES",
    "STATE_NAMES",
    "Gripper",
    "MacroEnv",
    "MacroMode",
    "MacrotreeError",
    "SetupError",
    "VectorEnv",
    "__version__",
    "run_policy_model",
]
