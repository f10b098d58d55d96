"""Gymnasium's own checker on every registered id, in every action mode."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import macrotree
from macrotree.registration import GENERIC_ID, SHIPPED


@pytest.mark.parametrize("action_mode", ["macro", "ctrl", "setpoint", "residual"])
@pytest.mark.parametrize("env_id", [*SHIPPED, GENERIC_ID])
def test_check_env_passes(env_id: str, action_mode: str, data: Path) -> None:
    kwargs: dict[str, Any] = {"action_mode": action_mode}
    if env_id == GENERIC_ID:
        kwargs["scene"] = str(data / "scenes/cube_bowl.yaml")
        if action_mode == "residual":
            kwargs["base"] = str(data / "trees/cube_to_bowl.yaml")
    env = gym.make(env_id, **kwargs)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    # Two advisories are by design: poses have no natural bound (infinite observation bounds),
    # and actions are in physical units like the reference's (metres, radians, 0…255), not
    # normalised to [-1, 1]. Nothing else may warn.
    advisories = ("infinity", "symmetric and normalized")
    unexpected = [
        str(w.message) for w in caught if not any(a in str(w.message) for a in advisories)
    ]
    assert not unexpected, unexpected
    env.close()


def test_every_id_makes_a_native_vector_env() -> None:
    for env_id in SHIPPED:
        vec = gym.make_vec(env_id, num_envs=2)
        assert isinstance(vec, macrotree.VectorEnv)
        vec.close()
