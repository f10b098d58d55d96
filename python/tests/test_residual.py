"""The residual mode: the tree is the base controller, the action a correction to its command."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import macrotree


def residual_env(data: Path, **kwargs: object) -> macrotree.MacroEnv:
    return macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml",
        action_mode="residual",
        base=data / "trees/cube_to_bowl.yaml",
        **kwargs,  # type: ignore[arg-type]
    )


def test_a_zero_residual_runs_the_base_tree_to_its_goal(data: Path) -> None:
    env = residual_env(data)
    env.reset(seed=3)
    zero = np.zeros(7, dtype=np.float32)
    info: dict[str, object] = {}
    for _ in range(2000):
        _, reward, terminated, truncated, info = env.step(zero)
        assert not truncated
        if info["base_status"] != "running":
            break
    assert info["base_status"] == "success"
    assert terminated and reward == 1.0 and info["is_success"]
    base = np.asarray(info["base_action"])
    assert base.shape == (len(macrotree.CTRL_NAMES),)
    assert info["ctrl_clamped"] == 0


def test_the_residual_moves_the_arm_off_the_base_command(data: Path) -> None:
    env = residual_env(data)
    env.reset(seed=3)
    push = np.zeros(7, dtype=np.float32)
    push[0] = 0.05
    for _ in range(100):
        obs, _, _, _, info = env.step(push)
    pan = macrotree.STATE_NAMES.index("shoulder_pan")
    gap = float(obs["agent_pos"][pan]) - float(np.asarray(info["base_action"])[0])
    assert 0.02 < gap <= 0.1, gap


def test_the_vector_env_steps_residuals_as_single_envs_do(data: Path) -> None:
    vec = macrotree.VectorEnv(
        data / "scenes/cube_bowl.yaml",
        data / "trees/cube_to_bowl.yaml",
        num_envs=2,
        action_mode="residual",
    )
    single = residual_env(data)
    obs, _ = vec.reset(seed=[4, 9])
    one, _ = single.reset(seed=9)
    actions = np.zeros((2, 7), dtype=np.float32)
    actions[:, 1] = 0.01
    for _ in range(20):
        obs, _, _, _, info = vec.step(actions)
        one, _, _, _, one_info = single.step(actions[1])
    assert np.array_equal(obs["agent_pos"][1], one["agent_pos"])
    assert info["base_action"].shape == (2, len(macrotree.CTRL_NAMES))
    assert np.array_equal(info["base_action"][1], one_info["base_action"])
    vec.close()


def test_base_outside_the_residual_mode_and_a_residual_without_a_tree_are_refused(
    data: Path,
) -> None:
    with pytest.raises(ValueError, match="residual mode's base"):
        macrotree.MacroEnv(
            data / "scenes/cube_bowl.yaml",
            action_mode="ctrl",
            base=data / "trees/cube_to_bowl.yaml",
        )
    with pytest.raises(ValueError, match="needs a base tree"):
        macrotree.MacroEnv(data / "scenes/cube_bowl.yaml", action_mode="residual")
    env = residual_env(data)
    env.reset(seed=1)
    bad = np.zeros(7)
    bad[2] = np.nan
    with pytest.raises(macrotree.MacrotreeError, match=r"residual\[2\]"):
        env.step(bad)
