"""TorchRL's own checker on macrotree: ``check_env_specs(GymWrapper(env))`` for the single
environment in both action modes and for the vector environment.

torch is too heavy for CI, so this is not a pytest module: ``tests/system/python_package.rs``
runs it when ``MACROTREE_TORCHRL_PYTHON`` names a Python with torchrl 0.14.1 (it installs the
package there first). By hand: ``python python/tests/check_torchrl.py``.
"""

from __future__ import annotations

import gymnasium as gym
from gymnasium.vector import AutoresetMode
from torchrl.envs import GymWrapper
from torchrl.envs.utils import check_env_specs

import macrotree


def main() -> None:
    print(f"macrotree {macrotree.__version__}")
    for mode in ("macro", "ctrl", "setpoint"):
        env = gym.make("macrotree/CubeToBowl-v0", action_mode=mode).unwrapped
        check_env_specs(GymWrapper(env, categorical_action_encoding=True), seed=0)
        print(f"check_env_specs(GymWrapper(MacroEnv, action_mode={mode!r})): passed")
    vec = gym.make_vec(
        "macrotree/CubeToBowl-v0",
        num_envs=2,
        action_mode="ctrl",
        autoreset_mode=AutoresetMode.DISABLED,
    )
    check_env_specs(
        GymWrapper(vec, categorical_action_encoding=True), seed=0, break_when_any_done="both"
    )
    print("check_env_specs(GymWrapper(VectorEnv, num_envs=2, DISABLED)): passed")


if __name__ == "__main__":
    main()
