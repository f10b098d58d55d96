"""Gymnasium's own checker on every registered id, in both action modes."""

from __future__ import annotations

import warnings

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import macrotree  # noqa: F401  (registers the ids)
from macrotree.registration import GENERIC_ID, SHIPPED


@pytest.mark.parametrize("action_mode", ["macro", "ctrl"])
@pytest.mark.parametrize("env_id", [*SHIPPED, GENERIC_ID])
def test_check_env_passes(env_id: str, action_mode: str, data: object) -> None:
    kwargs: dict[str, object] = {"action_mode": action_mode}
    if env_id == GENERIC_ID:
        kwargs["scene"] = str(data / "scenes/cube_bowl.yaml")  # type: ignore[operator]
    env = gym.make(env_id, **kwargs)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    # Only the observation bounds are open (poses have no natural bound); nothing else may warn.
    unexpected = [str(w.message) for w in caught if "infinite" not in str(w.message).lower()]
    assert not unexpected, unexpected
    env.close()


def test_every_id_makes_a_native_vector_env() -> None:
    for env_id in SHIPPED:
        vec = gym.make_vec(env_id, num_envs=2)
        assert isinstance(vec, macrotree.VectorEnv)
        vec.close()
