"""The single environment on real physics: determinism, each action kind, errors, rendering."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import macrotree
from macrotree import Gripper, MacroMode, _native
from macrotree.spaces import POSITION_BOUND


def macro(mode: MacroMode, **fields: object) -> dict[str, object]:
    action: dict[str, object] = {"mode": int(mode)}
    action.update(fields)
    return action


def same_bits(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> bool:
    return all(np.array_equal(a[k].view(np.uint8), b[k].view(np.uint8)) for k in a)


def test_seeded_reset_and_steps_are_bit_identical(cube_env: macrotree.MacroEnv) -> None:
    runs = []
    for _ in range(2):
        cube_env.action_space.seed(11)
        obs, _ = cube_env.reset(seed=7)
        trace = [obs]
        for _ in range(3):
            obs, *_ = cube_env.step(cube_env.action_space.sample())
            trace.append(obs)
        runs.append(trace)
    assert all(same_bits(a, b) for a, b in zip(runs[0], runs[1], strict=True))


def test_different_seeds_place_objects_differently(cube_env: macrotree.MacroEnv) -> None:
    a, _ = cube_env.reset(seed=1)
    b, _ = cube_env.reset(seed=2)
    assert not np.array_equal(a["environment_state"], b["environment_state"])


def test_default_layout_is_the_scenes_own(cube_env: macrotree.MacroEnv) -> None:
    obs, _ = cube_env.reset(options={"layout": "default"})
    cube = cube_env.object_pose(obs, "cube")
    assert cube[:2] == pytest.approx([0.45, -0.18], abs=1e-6)


def test_reach_pose_ends_at_the_pose(cube_env: macrotree.MacroEnv) -> None:
    obs, _ = cube_env.reset(options={"layout": "default"})
    target = obs["pinch"][:3] + np.array([0.05, 0.0, -0.05], dtype=np.float32)
    quat = obs["pinch"][3:]
    obs, _, _, _, info = cube_env.step(
        macro(
            MacroMode.REACH_POSE, position=target, quaternion=quat, steps=[150], settle_steps=[50]
        )
    )
    assert info["failure_kind"] is None, info
    assert np.linalg.norm(obs["pinch"][:3] - target) < 0.01


def test_ctrl_step_is_one_control_period(cube_env: macrotree.MacroEnv) -> None:
    ctrl_env = macrotree.MacroEnv(cube_env_scene(cube_env), action_mode="ctrl")
    ctrl_env.reset(seed=0)
    assert ctrl_env.action_space.shape == (19,)
    target = np.concatenate([ctrl_env.home, np.zeros(12), [0.0]])
    _, _, _, _, info = ctrl_env.step(target)
    assert info["physics_steps"] == 5
    assert info["sim_time"] == pytest.approx(0.01)
    assert info["ctrl_clamped"] == 0
    assert ctrl_env.dt == info["sim_time"] == 0.01


def test_dt_is_the_control_period_asked_for(cube_env: macrotree.MacroEnv) -> None:
    env = macrotree.MacroEnv(cube_env_scene(cube_env), action_mode="ctrl", control_period=0.02)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.concatenate([env.home, np.zeros(12), [0.0]]))
    assert env.dt == 0.02
    assert info["sim_time"] == pytest.approx(env.dt)
    env.close()


def test_a_ctrl_jump_is_clamped_to_the_largest_joint_speed(cube_env: macrotree.MacroEnv) -> None:
    ctrl_env = macrotree.MacroEnv(cube_env_scene(cube_env), action_mode="ctrl")
    ctrl_env.reset(seed=0)
    target = np.concatenate([ctrl_env.home, np.zeros(12), [0.0]])
    target[0] += 1.0  # 1 rad in one 10 ms period: 100 rad/s asked for
    target[6] = 50.0  # rad/s
    _, _, _, _, info = ctrl_env.step(target)
    assert info["ctrl_clamped"] == 2
    speed = abs(ctrl_env.observation()["joint_vel"][0])
    assert speed < 4.0, speed


def test_setpoint_action_holds_seven_values(cube_env: macrotree.MacroEnv) -> None:
    env = macrotree.MacroEnv(cube_env_scene(cube_env), action_mode="setpoint")
    env.reset(seed=0)
    assert env.action_space.shape == (7,)
    _, _, _, _, info = env.step(np.concatenate([env.home, [0.0]]))
    assert info["physics_steps"] == 5
    with pytest.raises(ValueError, match="setpoint action"):
        env.step(np.zeros(19))


def cube_env_scene(env: macrotree.MacroEnv) -> Path:
    from macrotree._library import data_dir

    return data_dir() / "scenes/cube_bowl.yaml"


def test_close_on_the_cube_grasps_it(cube_env: macrotree.MacroEnv) -> None:
    obs, _ = cube_env.reset(options={"layout": "default"})
    cube = cube_env.object_pose(obs, "cube")
    down = obs["pinch"][3:]
    for z, gripper in ((0.18, Gripper.OPEN), (-0.016, Gripper.OPEN)):
        cube_env.step(
            macro(
                MacroMode.REACH_POSE,
                position=cube[:3] + np.array([0, 0, z], dtype=np.float32),
                quaternion=down,
                gripper=int(gripper),
                steps=[180],
                settle_steps=[60],
            )
        )
    command = cube_env.gripper_command_for_width(0.043)
    _, _, _, _, info = cube_env.step(
        macro(MacroMode.CLOSE_GRIPPER, gripper_command=[command], steps=[160], settle_steps=[80])
    )
    assert info["grasped"]["cube"] is True


def test_the_full_observation_is_the_rust_observations_serde_form(
    cube_env: macrotree.MacroEnv,
) -> None:
    obs, _ = cube_env.reset(options={"layout": "default"})
    full = cube_env.observation()
    # The Rust field names, not renamed ones; the last command is there too.
    for key in ("joint_pos", "left_pad_pos", "right_pad_pos", "pinch_pos", "last_command"):
        assert key in full, key
    assert len(full["last_command"]) == len(macrotree.CTRL_NAMES)
    # Objects by name, in scene order, each with its kind and bounding box.
    assert list(full["objects"]) == cube_env.object_names
    cube = full["objects"]["cube"]
    assert cube["kind"] == "block"
    assert np.allclose(cube["pos"], cube_env.object_pose(obs, "cube")[:3], atol=1e-6)
    half = cube["half_extents"]
    assert half[0] == half[1] == half[2] > 0.0
    assert all(set(c) == {"a", "b"} for c in full["contacts"])


def test_the_far_corner_of_the_position_box_is_accepted_and_fails_as_unreachable(
    cube_env: macrotree.MacroEnv,
) -> None:
    obs, _ = cube_env.reset(options={"layout": "default"})
    corner = np.full(3, POSITION_BOUND, dtype=np.float32)
    assert float(np.linalg.norm(corner.astype(np.float64))) <= _native.MAX_REACH_DISTANCE
    _, _, _, _, info = cube_env.step(
        macro(MacroMode.REACH_POSE, position=corner, quaternion=obs["pinch"][3:], steps=[50])
    )
    assert info["status"] == "failure", info
    assert info["failure_kind"] == "unreachable", info


def test_a_leaf_runs_by_mapping(cube_env: macrotree.MacroEnv) -> None:
    cube_env.reset(options={"layout": "default"})
    _, _, _, _, info = cube_env.step_leaf({"reach": {"target": "cube", "offset": [0, 0, 0.12]}})
    assert info["status"] == "success", info
    assert info["sim_time"] > 0


def test_a_bad_leaf_is_a_located_error(cube_env: macrotree.MacroEnv) -> None:
    cube_env.reset(seed=0)
    with pytest.raises(macrotree.MacrotreeError, match=r"(?s)action:1:2.*did you mean `reach`"):
        cube_env.step_leaf('{"raech": {"target": "cube"}}')
    with pytest.raises(macrotree.MacrotreeError, match="bowl2"):
        cube_env.step_leaf({"reach": {"target": "bowl2"}})


def test_a_failed_action_is_typed_not_raised(cube_env: macrotree.MacroEnv) -> None:
    cube_env.reset(options={"layout": "default"})
    _, _, terminated, truncated, info = cube_env.step(
        macro(MacroMode.REACH_POSE, position=[0.84, 0.84, 0.84], steps=[10])
    )
    assert info["failure_kind"] is not None and info["failure_message"]
    assert truncated is False and terminated is False


def test_the_whole_tree_reaches_the_goal(cube_env: macrotree.MacroEnv) -> None:
    cube_env.reset(options={"layout": "default"})
    _, reward, terminated, _, info = cube_env.step_subtree("main")
    assert info["status"] == "success"
    assert info["is_success"] is True and reward == 1.0 and terminated is True


def test_out_of_range_numbers_are_refused(cube_env: macrotree.MacroEnv) -> None:
    cube_env.reset(seed=0)
    with pytest.raises((macrotree.MacrotreeError, ValueError)):
        cube_env.step(macro(MacroMode.REACH_JOINTS, joints=[float("nan")] * 6, steps=[10]))
    with pytest.raises((macrotree.MacrotreeError, ValueError)):
        cube_env.step(macro(MacroMode.WAIT, steps=[-3]))


def test_render_gives_an_rgb_image(data: Path) -> None:
    env = macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml", render_mode="rgb_array", image_size=(48, 64)
    )
    env.reset(seed=0)
    frame = env.render()
    assert frame is not None and frame.shape == (48, 64, 3) and frame.dtype == np.uint8
    assert frame.std() > 0


def test_camera_images_are_observations(data: Path) -> None:
    env = macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml", cameras=["front", "wrist"], image_size=(32, 48)
    )
    obs, _ = env.reset(seed=0)
    assert obs in env.observation_space
    for camera in ("front", "wrist"):
        image = obs["pixels"][camera]
        assert image.shape == (32, 48, 3) and image.dtype == np.uint8 and image.std() > 0
    obs, *_ = env.step({"mode": int(MacroMode.WAIT), "steps": [5]})
    assert obs in env.observation_space


def test_rgb_array_list_films_the_step_at_render_fps(data: Path) -> None:
    env = macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml",
        render_mode="rgb_array_list",
        image_size=(32, 48),
        render_fps=10,
    )
    env.reset(seed=0)
    env.step({"mode": int(MacroMode.WAIT), "steps": [100]})  # one simulated second
    frames = env.render()
    # The reset's frame, then one every 0.1 s of simulated time.
    assert len(frames) == 11 and all(f.shape == (32, 48, 3) for f in frames)
    assert env.render() == []
