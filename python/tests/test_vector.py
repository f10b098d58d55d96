"""The native vector environment: bit-for-bit agreement with single environments, autoreset,
send/recv."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import macrotree
import macrotree.vector
from macrotree import MacroMode, _native


def scene(data: Path) -> str:
    return str(data / "scenes/cube_bowl.yaml")


def test_each_sub_env_matches_a_single_env_bit_for_bit(data: Path) -> None:
    # Autoreset off: random macros can reach the time limit, and a single env does not reset.
    vec = macrotree.VectorEnv(scene(data), num_envs=3, autoreset_mode=AutoresetMode.DISABLED)
    space = vec.single_action_space
    space.seed(5)
    actions = [[space.sample() for _ in range(3)] for _ in range(3)]
    # Random macros of at most 1 s each: drawn lengths reach 60 s, and agreement does not depend
    # on them (modes, targets and the rest stay as drawn).
    for batch in actions:
        for action in batch:
            action["steps"] = np.minimum(action["steps"], 100)
            action["settle_steps"] = np.minimum(action["settle_steps"], 100)
    obs, _ = vec.reset(seed=40)
    traces = [obs]
    for batch in actions:
        obs, *_ = vec.step(batch)
        traces.append(obs)
    vec.close()
    for i in range(3):
        single = macrotree.MacroEnv(scene(data))
        obs, _ = single.reset(seed=40 + i)
        mine = [obs]
        for batch in actions:
            obs, *_ = single.step(batch[i])
            mine.append(obs)
        for batched, own in zip(traces, mine, strict=True):
            for key in own:
                assert np.array_equal(batched[key][i].view(np.uint8), own[key].view(np.uint8)), key


def test_send_recv_returns_whichever_finish_first(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2)
    vec.reset(seed=0)
    long = {"mode": int(MacroMode.WAIT), "steps": [400]}
    short = {"mode": int(MacroMode.WAIT), "steps": [1]}
    vec.send([long, short])
    _, _, _, _, info = vec.recv(1)
    assert list(info["env_id"]) == [1]
    _, _, _, _, info = vec.recv(1)
    assert list(info["env_id"]) == [0]
    with pytest.raises(ValueError):
        vec.recv(1)
    vec.close()


def test_same_step_autoreset_returns_the_final_observation(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2, max_sim_time=0.05)
    vec.reset(seed=0)
    _, _, _, truncated, info = vec.step([{"mode": int(MacroMode.WAIT), "steps": [10]}] * 2)
    assert truncated.all()
    assert info["_final_obs"].all()
    # Gymnasium 1.x's layout, which LeRobot's evaluation reads: a dict of arrays with masks.
    final = info["final_info"]
    assert isinstance(final, dict)
    assert final["is_success"].dtype == bool and final["_is_success"].all()
    assert not final["is_success"].any()
    vec.close()


def test_an_autoreset_replaces_only_the_ended_rows_and_masks_their_infos(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2, max_sim_time=0.1)
    vec.reset(seed=0)
    short = {"mode": int(MacroMode.WAIT), "steps": [2]}
    long = {"mode": int(MacroMode.WAIT), "steps": [20]}
    obs, _, _, truncated, info = vec.step([short, short])
    assert not truncated.any()
    before = obs["agent_pos"].copy()
    obs, _, _, truncated, info = vec.step([long, short])
    assert list(truncated) == [True, False]
    # The ended row holds the new episode's first observation (time zero), the other its step's.
    assert list(info["_final_obs"]) == [True, False]
    assert info["final_obs"][0]["agent_pos"].shape == before[0].shape
    assert list(info["final_info"]["_status"]) == [True, False]
    assert info["final_info"]["failure_kind"][0] == "time_limit"
    # The ended row's info is its reset's: the step's keys are masked out there.
    assert list(info["_status"]) == [False, True]
    assert list(info["_episode_sim_time"]) == [True, True]
    assert info["episode_sim_time"][0] == 0.0 and info["episode_sim_time"][1] > 0.0
    # Nested dicts are batched alike: one array per goal predicate, with its mask.
    goal = info["goal"]
    assert isinstance(goal, dict) and goal
    for key, value in goal.items():
        if not key.startswith("_"):
            assert value.shape == (2,) and goal[f"_{key}"].all()
    vec.close()


def test_disabled_autoreset_takes_a_reset_mask(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2, autoreset_mode=AutoresetMode.DISABLED)
    first, _ = vec.reset(seed=3)
    stepped, *_ = vec.step([{"mode": int(MacroMode.WAIT), "steps": [20]}] * 2)
    again, info = vec.reset(seed=3, options={"reset_mask": np.array([True, False])})
    assert again["agent_pos"].shape == (2, len(macrotree.STATE_NAMES))
    assert np.array_equal(again["environment_state"][0], first["environment_state"][0])
    assert np.array_equal(again["agent_pos"][1], stepped["agent_pos"][1])
    assert list(info["_is_success"]) == [True, False]
    vec.close()


def test_num_envs_is_bounded_by_the_extensions_maximum(data: Path) -> None:
    assert macrotree.vector.MAX_ENVS == _native.MAX_ENVS == 1024
    for bad in (0, _native.MAX_ENVS + 1, 1.5, "2"):
        with pytest.raises(ValueError, match="num_envs"):
            macrotree.VectorEnv(scene(data), num_envs=bad)  # type: ignore[arg-type]


def test_step_leaf_runs_one_leaf_per_sub_env_as_a_single_env_does(data: Path) -> None:
    reach = {"reach": {"target": "cube", "offset": [0, 0, 0.12]}}
    vec = macrotree.VectorEnv(scene(data), num_envs=3, autoreset_mode=AutoresetMode.DISABLED)
    vec.reset(seed=7)
    obs, _, _, _, info = vec.step_leaf(reach)
    assert list(info["env_id"]) == [0, 1, 2]
    assert list(info["status"]) == ["success"] * 3, info["status"]
    # One leaf each, on a subset, in the order given; the others do not move.
    before = obs["agent_pos"][1].copy()
    home: dict[str, dict[str, float]] = {"home": {}}
    obs2, _, _, _, info = vec.step_leaf([home, '{"wait": {"seconds": 0.1}}'], env_ids=[2, 0])
    assert list(info["env_id"]) == [2, 0]
    assert obs2["agent_pos"].shape[0] == 2
    # A bad leaf anywhere in the batch is a located error and nothing moves.
    with pytest.raises(macrotree.MacrotreeError, match=r"(?s)action:1:2.*did you mean `reach`"):
        vec.step_leaf([reach, '{"raech": {"target": "cube"}}'], env_ids=[1, 0])
    with pytest.raises(ValueError, match="2 leaves for 3 environments"):
        vec.step_leaf([reach, reach])
    with pytest.raises(ValueError, match="distinct indices"):
        vec.step_leaf(reach, env_ids=[1, 1])
    # Sub-environment 1 stayed where the first reach left it.
    obs3, *_ = vec.step_leaf('{"wait": {"seconds": 0.0}}', env_ids=[1])
    assert np.allclose(obs3["agent_pos"][0], before, atol=1e-3)
    vec.close()
    # Bit for bit what a single environment gives for the same seed and leaf.
    single = macrotree.MacroEnv(scene(data))
    single.reset(seed=8)
    own, *_ = single.step_leaf(reach)
    assert np.array_equal(obs["agent_pos"][1].view(np.uint8), own["agent_pos"].view(np.uint8))
    single.close()


def test_step_subtree_runs_the_whole_tree_on_each_sub_env(data: Path) -> None:
    vec = macrotree.VectorEnv(
        tree=str(data / "trees/cube_to_bowl.yaml"),
        num_envs=2,
        autoreset_mode=AutoresetMode.DISABLED,
    )
    vec.reset(seed=3)
    _, _, terminated, _, info = vec.step_subtree("main")
    assert list(info["env_id"]) == [0, 1]
    assert terminated.all(), info
    assert list(info["is_success"]) == [True, True], info
    with pytest.raises(macrotree.MacrotreeError, match="pik"):
        vec.step_subtree("pik")
    vec.close()


def test_a_steps_info_masks_are_set_for_every_sub_env_and_read_only(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2, action_mode="setpoint")
    vec.reset(seed=0)
    hold = np.concatenate([np.asarray(_native.HOME), [0.0]])
    _, _, _, _, info = vec.step(np.stack([hold, hold]))
    masks = {k: v for k, v in info.items() if k.startswith("_")}
    assert {"_is_success", "_goal", "_grasped", "_status", "_sim_time"} <= set(masks)
    for key, mask in masks.items():
        assert mask.dtype == bool and mask.shape == (2,) and mask.all(), key
        # The masks of one batch may be one array: a write would reach every key, so none is
        # allowed.
        assert not mask.flags.writeable, key
    with pytest.raises(ValueError, match="read-only"):
        info["_is_success"][0] = False
    vec.close()


def test_a_steps_camera_images_are_each_sub_envs_own(data: Path) -> None:
    cameras = ["front", "wrist"]
    vec = macrotree.VectorEnv(scene(data), num_envs=2, cameras=cameras, image_size=(32, 48))
    vec.reset(seed=[1, 2])
    wait = {"mode": int(MacroMode.WAIT), "steps": [5]}
    obs, *_ = vec.step([wait, wait])
    assert obs in vec.observation_space
    single = macrotree.MacroEnv(scene(data), cameras=cameras, image_size=(32, 48))
    single.reset(seed=2)
    one, *_ = single.step(wait)
    for camera in cameras:
        images = obs["pixels"][camera]
        assert images.shape == (2, 32, 48, 3) and images.dtype == np.uint8
        assert np.array_equal(images[1], one["pixels"][camera]), camera
        assert not np.array_equal(images[0], images[1]), "two layouts, two images"
    vec.close()
