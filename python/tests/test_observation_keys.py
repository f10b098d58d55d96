"""LeRobot's dataset keys on the environment's observations."""

from __future__ import annotations

import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import macrotree


def test_lerobot_keys_carry_the_same_arrays_as_the_gym_keys(data: Path) -> None:
    scene = data / "scenes/cube_bowl.yaml"
    gym_env = macrotree.MacroEnv(scene)
    lerobot_env = macrotree.MacroEnv(scene, observation_keys="lerobot")
    a, _ = gym_env.reset(seed=2)
    b, _ = lerobot_env.reset(seed=2)
    assert set(b) == {"observation.state", "observation.environment_state"}
    space = lerobot_env.observation_space
    assert isinstance(space, gym.spaces.Dict)
    assert set(b) == set(space.spaces)
    assert np.array_equal(a["agent_pos"], b["observation.state"])
    assert np.array_equal(a["environment_state"], b["observation.environment_state"])
    assert b["observation.state"].shape == (len(macrotree.STATE_NAMES),)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(lerobot_env)


def test_lerobot_keys_in_the_vector_env(data: Path) -> None:
    vec = macrotree.VectorEnv(
        data / "scenes/cube_bowl.yaml", num_envs=2, observation_keys="lerobot"
    )
    obs, _ = vec.reset(seed=0)
    assert obs["observation.state"].shape == (2, len(macrotree.STATE_NAMES))
    assert vec.observation_space.contains(obs)
    vec.close()


def test_unknown_observation_keys_are_refused(data: Path) -> None:
    with pytest.raises(ValueError, match="observation_keys"):
        macrotree.MacroEnv(data / "scenes/cube_bowl.yaml", observation_keys="torch")
