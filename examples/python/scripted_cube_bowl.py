"""The reference tutorial (TorchRL's CubeBowlEnv macro tutorial), ported to macrotree.

A scripted policy in the tutorial's shape: a generator of macro actions that reads the latest
observation between them (wait, open, hover above the cube, descend, close, lift, carry in four
Cartesian legs over the bowl, lower, open, wait, retreat, reset home, wait). It runs on the default
layout, then on the tutorial's four workspace layouts, one environment reset between rollouts, and
asserts the tutorial's checks on each rollout:

* grasp distance (the nearer pad centre to the cube's surface, after the close) <= 0.025 m,
* cube motion while the gripper is closed >= 0.05 m, and lift while closed >= 0.08 m,
* final distance of the arm from home <= 0.04 rad,
* reward 1 at the end (the cube rests in the bowl), and success.

Macros run closed loop to completion (``steps=0``: until the motion is done and settled) instead of
the tutorial's fixed step counts, so a rollout takes seconds of simulated time, not 47.7 s.

    python examples/python/scripted_cube_bowl.py [--video out.mp4]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Generator
from pathlib import Path
from typing import Any

import numpy as np

import macrotree
from macrotree import Gripper, MacroMode
from macrotree._library import data_dir
from macrotree.video import write_mp4

Action = dict[str, Any]
Obs = dict[str, Any]

#: Cube centre and bowl centre (x, y) of the tutorial's four layouts, metres.
LAYOUTS = [
    ((0.44, -0.21), (0.48, 0.10)),
    ((0.51, -0.18), (0.39, 0.04)),
    ((0.45, -0.20), (0.38, 0.02)),
    ((0.52, -0.18), (0.45, 0.02)),
]

GRASP_DISTANCE_MAX = 0.025
MOTION_WHILE_CLOSED_MIN = 0.05
LIFT_WHILE_CLOSED_MIN = 0.08
HOME_ERROR_MAX = 0.04


def macro(mode: MacroMode, gripper: Gripper = Gripper.KEEP, **fields: Any) -> Action:
    """A macro action; absent fields take their defaults (``steps=0``: closed loop)."""
    action: Action = {"mode": int(mode), "gripper": int(gripper)}
    for key, value in fields.items():
        action[key] = np.asarray(value, dtype=np.float32 if key != "steps" else np.int64)
    return action


def up(dz: float) -> np.ndarray:
    """A vertical offset of ``dz`` metres."""
    return np.array([0.0, 0.0, dz], dtype=np.float32)


def reach(
    position: np.ndarray, quaternion: np.ndarray, gripper: Gripper, cartesian: bool
) -> Action:
    return macro(
        MacroMode.REACH_POSE,
        gripper,
        position=position,
        quaternion=quaternion,
        path=[1 if cartesian else 0],
    )


def policy(env: macrotree.MacroEnv, close_command: float) -> Generator[Action, Obs, None]:
    """The tutorial's script: yields one macro, receives the observation after it."""
    obs = yield macro(MacroMode.WAIT, Gripper.OPEN, steps=[20])
    obs = yield macro(MacroMode.OPEN_GRIPPER, Gripper.OPEN)
    cube = env.object_pose(obs, "cube")[:3]
    bowl = env.object_pose(obs, "bowl")[:3]
    down = obs["pinch"][3:].copy()
    obs = yield reach(cube + up(0.18), down, Gripper.OPEN, cartesian=False)
    obs = yield reach(cube + up(-0.016), down, Gripper.OPEN, cartesian=True)
    obs = yield macro(MacroMode.CLOSE_GRIPPER, Gripper.CLOSED, gripper_command=[close_command])
    obs = yield reach(obs["pinch"][:3] + up(0.20), down, Gripper.CLOSED, cartesian=True)
    start = env.object_pose(obs, "cube")[:2].copy()
    for alpha in (0.25, 0.5, 0.75, 1.0):
        cube_now = env.object_pose(obs, "cube")[:3]
        grip = obs["pinch"][:3] - cube_now
        want = np.array([*(start + alpha * (bowl[:2] - start)), 0.24], dtype=np.float32)
        obs = yield reach(want + grip, down, Gripper.CLOSED, cartesian=True)
    grip = obs["pinch"][:3] - env.object_pose(obs, "cube")[:3]
    obs = yield reach(np.array([bowl[0], bowl[1], 0.13]) + grip, down, Gripper.CLOSED, True)
    obs = yield macro(MacroMode.OPEN_GRIPPER, Gripper.OPEN)
    obs = yield macro(MacroMode.WAIT, Gripper.OPEN, steps=[240])
    pinch = obs["pinch"][:3]
    obs = yield reach(np.array([pinch[0], pinch[1], 0.26]), down, Gripper.OPEN, cartesian=True)
    obs = yield macro(MacroMode.RESET, Gripper.OPEN)
    yield macro(MacroMode.WAIT, Gripper.OPEN, steps=[100])


def grasp_distance(full: dict[str, Any], cube: np.ndarray, half: float) -> float:
    """The tutorial's gripper-to-cube distance: the nearer pad centre's distance to the cube's
    surface (0 inside), the cube taken as axis-aligned."""
    best = np.inf
    for pad in (np.asarray(full["left_pad_pos"]), np.asarray(full["right_pad_pos"])):
        excess = np.abs(pad - cube) - half
        best = min(best, float(np.linalg.norm(np.maximum(excess, 0.0))))
    return best


def rollout(
    env: macrotree.MacroEnv, options: dict[str, Any], frames: list[np.ndarray] | None
) -> dict[str, float]:
    """One episode of the script; returns its metrics (and asserts the tutorial's checks)."""
    obs, _ = env.reset(options=options)
    half = float(env.observation()["objects"]["cube"]["half_extents"][0])
    close_command = env.gripper_command_for_width(2 * half - 0.001)
    script = policy(env, close_command)
    action = next(script)
    rewards: list[float] = []
    grasp = np.inf
    reference: np.ndarray | None = None
    motion = lift = 0.0
    info: dict[str, Any] = {}
    while True:
        obs, reward, _, truncated, info = env.step(action)
        assert not truncated, "the rollout ran out of simulated time"
        rewards.append(float(reward))
        if frames is not None:
            frames.extend(env.render() or [])
        cube = env.object_pose(obs, "cube")[:3].astype(np.float64)
        if action["mode"] == MacroMode.CLOSE_GRIPPER:
            grasp = min(grasp, grasp_distance(env.observation(), cube, half))
            reference = cube
        elif reference is not None and action["gripper"] == Gripper.CLOSED:
            motion = max(motion, float(np.linalg.norm(cube - reference)))
            lift = max(lift, float(cube[2] - reference[2]))
        try:
            action = script.send(obs)
        except StopIteration:
            break
    home_error = float(np.linalg.norm(obs["agent_pos"][:6] - env.home))
    metrics = {
        "grasp_distance": grasp,
        "motion_while_closed": motion,
        "lift_while_closed": lift,
        "home_error": home_error,
        "max_reward": max(rewards),
        "last_reward": rewards[-1],
        "sim_time": float(info["episode_sim_time"]),
    }
    assert grasp <= GRASP_DISTANCE_MAX, metrics
    assert motion >= MOTION_WHILE_CLOSED_MIN, metrics
    assert lift >= LIFT_WHILE_CLOSED_MIN, metrics
    assert home_error <= HOME_ERROR_MAX, metrics
    assert metrics["max_reward"] == 1.0 and metrics["last_reward"] == 1.0, metrics
    assert info["is_success"] is True, info
    return metrics


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--video", type=Path, help="write the five rollouts as an MP4 here")
    args = parser.parse_args()
    data = data_dir()
    # The video is small (160 × 120 at 10 frames per simulated second): every frame of the five
    # rollouts is held until the end, and software rendering costs more than the physics.
    env = macrotree.MacroEnv(
        data / "scenes/cube_bowl.yaml",
        render_mode="rgb_array_list" if args.video else None,
        image_size=(120, 160),
        render_fps=10,
    )
    layouts: list[dict[str, Any]] = [{"layout": "default"}]
    for (cx, cy), (bx, by) in LAYOUTS:
        layouts.append({"placement": {"cube": [cx, cy, 0.0], "bowl": [bx, by, 0.0]}})
    frames: list[np.ndarray] | None = [] if args.video else None
    for k, options in enumerate(layouts):
        start = time.perf_counter()
        metrics = rollout(env, options, frames)
        wall = time.perf_counter() - start
        shown = ", ".join(f"{name} {value:.4f}" for name, value in metrics.items())
        print(f"rollout {k}: {shown}, wall {wall:.3f} s: checks passed")
    if args.video and frames:
        write_mp4(args.video, frames, fps=int(env.metadata["render_fps"]))
        print(f"video: {args.video} ({len(frames)} frames)")
    env.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
