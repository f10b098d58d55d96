"""The LeRobot env plugin without LeRobot: its facts come from macrotree's spaces, its gym ids
step one frame per step, and a vector environment built the way ``lerobot-eval`` builds it
reports ``is_success`` in ``final_info`` for an episode that succeeds and one that does not."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import lerobot_env_macrotree as plugin
import macrotree
from lerobot_env_macrotree.facts import LEROBOT_RESET_OPTION, TASKS

CUBE = plugin.DEFAULT_TASK


def test_importing_the_plugin_imports_neither_lerobot_nor_torch_without_lerobot() -> None:
    if importlib.util.find_spec("lerobot") is not None:
        pytest.skip("lerobot is installed here: the plugin imports it on purpose")
    code = (
        "import sys, lerobot_env_macrotree as p; print(p.LEROBOT_INSTALLED, "
        "sorted(m for m in sys.modules if m.split('.')[0] in ('lerobot', 'torch')))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.split() == ["False", "[]"], out


def test_every_macrotree_id_has_a_task_and_a_plugin_id() -> None:
    shipped = {i for i in gym.registry if i.startswith("macrotree/")}
    assert set(TASKS.values()) == shipped
    for task in TASKS:
        assert plugin.gym_id(task) == f"lerobot_env_macrotree/{task}"
        assert plugin.gym_id(task) in gym.registry


def test_features_are_read_from_the_environments_spaces() -> None:
    found = plugin.features(CUBE, cameras=["front", "wrist"], image_size=(48, 64))
    env = macrotree.MacroEnv(
        scene=gym.spec(TASKS[CUBE]).kwargs["scene"],
        action_mode="ctrl",
        cameras=["front", "wrist"],
        image_size=(48, 64),
        observation_keys="lerobot",
    )
    lerobot_space = env.observation_space
    assert isinstance(lerobot_space, gym.spaces.Dict)
    by_policy_key = {f.policy_key: f for f in found.values()}
    # Every array of the LeRobot layout is a feature with its shape, and nothing else is.
    assert set(by_policy_key) == set(lerobot_space) | {"action"}
    for key, space in lerobot_space.items():
        assert by_policy_key[key].shape == space.shape, key
    assert found["agent_pos"] == plugin.Feature(
        "STATE", (len(macrotree.STATE_NAMES),), "observation.state"
    )
    assert found["environment_state"] == plugin.Feature(
        "ENV", (7 * len(env.object_names),), "observation.environment_state"
    )
    assert found["pixels/wrist"] == plugin.Feature(
        "VISUAL", (48, 64, 3), "observation.images.wrist"
    )
    assert found["action"] == plugin.Feature("ACTION", (len(macrotree.CTRL_NAMES),), "action")
    assert "pinch" not in found


def test_features_follow_the_task_and_the_action_mode() -> None:
    cube = plugin.features(CUBE)
    sort = plugin.features("SortByColor-v0", action_mode="residual")
    assert sort["environment_state"].shape[0] > cube["environment_state"].shape[0]
    assert sort["action"].shape == (7,)
    assert not any(key.startswith("pixels") for key in cube)


def test_one_step_is_one_frame_and_the_episode_ends_after_episode_length_frames() -> None:
    env = gym.make(
        plugin.gym_id(CUBE), **plugin.gym_kwargs(fps=25, episode_length=30, action_mode="residual")
    )
    assert isinstance(env.unwrapped, plugin.LeRobotMacroEnv)
    assert env.unwrapped.dt == pytest.approx(1 / 25)
    assert env.unwrapped.metadata["render_fps"] == 25
    assert env.get_wrapper_attr("_max_episode_steps") == 30
    env.reset(seed=0)
    hold_open = np.zeros(7, np.float32)
    hold_open[6] = -255.0
    for frame in range(1, 31):
        _, _, terminated, truncated, info = env.step(hold_open)
        assert info["episode_sim_time"] == pytest.approx(frame / 25)
        assert truncated is (frame == 30) and terminated is False


@pytest.mark.parametrize("fps", [300, 30, 5])
def test_a_frame_rate_the_environment_cannot_step_is_refused_when_it_is_made(fps: int) -> None:
    # 1/300 s and 1/30 s (LeRobot's default fps) are not whole numbers of 2 ms physics steps;
    # 1/5 s is longer than the 0.1 s limit.
    plugin.check(CUBE, fps, 10, "ctrl")
    with pytest.raises(macrotree.MacrotreeError, match="control_period"):
        gym.make(plugin.gym_id(CUBE), **plugin.gym_kwargs(fps=fps))


@pytest.mark.parametrize(
    ("task", "fps", "episode_length", "action_mode", "match"),
    [
        ("CubeBowl-v0", 50, 10, "ctrl", "unknown macrotree task"),
        (CUBE, 0, 10, "ctrl", "fps"),
        (CUBE, 12.5, 10, "ctrl", "fps"),
        (CUBE, 50, 0, "ctrl", "episode_length"),
        (CUBE, 50, 10, "macro", "action_mode"),
        ("MacroEnv-v0", 50, 10, "ctrl", "scene"),
    ],
)
def test_settings_no_environment_can_run_are_a_plugin_error(
    task: str, fps: Any, episode_length: int, action_mode: str, match: str
) -> None:
    with pytest.raises(plugin.PluginError, match=match):
        plugin.check(task, fps, episode_length, action_mode)


def test_lerobots_reset_option_is_taken_and_other_unknown_options_still_refused() -> None:
    env = gym.make(plugin.gym_id(CUBE), **plugin.gym_kwargs())
    obs, info = env.reset(seed=0, options={LEROBOT_RESET_OPTION: True})
    assert set(obs) == {"agent_pos", "environment_state", "pinch"} and info["is_success"] is False
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(options={"lerobot_typo": True})
    with pytest.raises(ValueError, match="unknown reset option"):
        gym.make(TASKS[CUBE]).reset(options={LEROBOT_RESET_OPTION: True})


def test_an_action_beyond_the_action_space_is_clipped_and_counted() -> None:
    env = gym.make(plugin.gym_id(CUBE), **plugin.gym_kwargs())
    obs, _ = env.reset(seed=0)
    hold = np.zeros(len(macrotree.CTRL_NAMES), np.float32)
    hold[:6] = obs["agent_pos"][:6]
    over = hold.copy()
    over[-1] = -1.0  # the gripper command: 0 (open) … 255
    over[0] = 7.0  # the shoulder pan set point, beyond its 2π limit
    with pytest.raises(macrotree.MacrotreeError):
        gym.make(TASKS[CUBE], **plugin.gym_kwargs()).unwrapped.step(over)
    _, _, _, _, info = env.step(over)
    assert info["action_clipped"] == 2
    _, _, _, _, info = env.step(hold)
    assert info["action_clipped"] == 0
    over[0] = np.nan
    with pytest.raises(macrotree.MacrotreeError):
        env.step(over)


ASYNC_ERROR = """
import gymnasium as gym, numpy as np
from gymnasium.vector import AutoresetMode
import lerobot_env_macrotree as plugin

def make():
    return gym.make(plugin.gym_id(plugin.DEFAULT_TASK), **plugin.gym_kwargs())

if __name__ == "__main__":
    envs = gym.vector.AsyncVectorEnv(
        [make, make], autoreset_mode=AutoresetMode.SAME_STEP, context="forkserver"
    )
    envs.reset(seed=0)
    try:
        envs.step(np.full((2, 19), np.nan, np.float32))
    except Exception as e:
        print(type(e).__name__, e)
    envs.close(terminate=True)
"""


def test_an_error_in_an_async_worker_reaches_the_caller(tmp_path: Path) -> None:
    # The worker pickles its exception to send it to the caller. An exception that does not
    # pickle dies in the queue's feeder thread, and the caller waits for ever on the queue
    # (lerobot-eval hung so): hence a separate process, given 120 s.
    script = tmp_path / "async_error.py"
    script.write_text(ASYNC_ERROR)
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120, check=True
    ).stdout
    assert "MacrotreeError" in out and "is NaN" in out, out


def make_one(kwargs: dict[str, Any]) -> Callable[[], gym.Env[Any, Any]]:
    """``lerobot-eval``'s environment factory: ``gym.make(gym_id, disable_env_checker=True,
    **gym_kwargs)`` (``EnvConfig.create_envs``)."""

    def make() -> gym.Env[Any, Any]:
        return gym.make(plugin.gym_id(CUBE), disable_env_checker=True, **kwargs)

    return make


@pytest.mark.parametrize("vector", ["sync", "async"])
def test_a_vector_env_reports_success_and_failure_in_final_info(vector: str) -> None:
    # Residual mode: sub-environment 0 adds nothing to the task tree's command (the scripted
    # episode, which succeeds); sub-environment 1 holds the gripper open (the grasp fails, and
    # the episode is truncated after episode_length frames).
    length = 250
    kwargs = plugin.gym_kwargs(episode_length=length, action_mode="residual")
    fns = [make_one(kwargs), make_one(kwargs)]
    envs: gym.vector.VectorEnv[Any, Any, Any]
    if vector == "async":
        envs = gym.vector.AsyncVectorEnv(
            fns, autoreset_mode=AutoresetMode.SAME_STEP, context="forkserver"
        )
    else:
        envs = gym.vector.SyncVectorEnv(fns, autoreset_mode=AutoresetMode.SAME_STEP)
    try:
        assert envs.call("_max_episode_steps") == (length, length)
        assert envs.call("task_description")[0]
        envs.reset(seed=[0, 1], options={LEROBOT_RESET_OPTION: True})
        actions = np.zeros((2, 7), np.float32)
        actions[1, 6] = -255.0
        ended: dict[int, tuple[int, bool, bool, bool]] = {}
        for frame in range(1, length + 1):
            _, _, terminated, truncated, info = envs.step(actions)
            if "final_info" not in info:
                continue
            final = info["final_info"]
            assert final["is_success"].dtype == bool
            for i in np.flatnonzero(final["_is_success"]):
                if int(i) not in ended:
                    ended[int(i)] = (
                        frame,
                        bool(final["is_success"][i]),
                        bool(terminated[i]),
                        bool(truncated[i]),
                    )
        assert set(ended) == {0, 1}, ended
        frame, success, terminated_0, truncated_0 = ended[0]
        assert success and terminated_0 and not truncated_0 and frame < length, ended
        assert ended[1] == (length, False, False, True), ended
    finally:
        envs.close()
