"""DART-style noise on what the arm executes, from the Python environment."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import macrotree


def run_tree(data: Path, noise: str | tuple[float, float] | None, seed: int) -> np.ndarray:
    env = macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml", data / "trees/cube_to_bowl.yaml", noise=noise
    )
    env.reset(seed=seed)
    obs, reward, terminated, _, info = env.step_subtree("main")
    assert info["status"] == "success", info["failure_message"]
    assert terminated and reward == 1.0
    return np.asarray(obs["agent_pos"])


def test_noise_is_seeded_and_the_tree_still_succeeds(data: Path) -> None:
    clean = run_tree(data, None, 5)
    noisy = run_tree(data, "0.02,10", 5)
    again = run_tree(data, (0.02, 10.0), 5)
    assert np.array_equal(noisy, again), "the same seed gives the same noise"
    assert not np.array_equal(noisy, clean), "the noise changed the motion"


def test_noise_out_of_range_is_refused(data: Path) -> None:
    for bad in ("0.5", "-0.1", "nan", "0.01,500", "a,b"):
        with pytest.raises(ValueError, match="noise"):
            macrotree.MacroEnv(data / "scenes/cube_bowl.yaml", noise=bad)
