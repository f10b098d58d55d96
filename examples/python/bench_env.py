"""How fast the Python environment is, measured in one run (ratios hold on a noisy machine).

1. The flagship task driven leaf by leaf from Python (``step_leaf``) against a bare ``mj_step``
   replay of the same controls (``replay_recorded``: the same physics, bit for bit).
2. ``setpoint`` mode: ``env.step`` of 7-D targets (10 ms = 5 physics steps each) against the bare
   replay of the same controls.
3. Vector environments, envpool-style: N single environments in a Python loop, Gymnasium's
   ``SyncVectorEnv`` and ``AsyncVectorEnv``, and ``macrotree.VectorEnv``, in ``ctrl`` steps per
   second; ``vector_vs_single`` is the median ratio of alternating rounds of the native vector env
   and one environment.

    python examples/python/bench_env.py [--repeat 5] [--envs 2] [--json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

import macrotree
from macrotree._library import data_dir

#: The action leaves the flagship tree (``trees/cube_to_bowl.yaml``) starts, in order, when its
#: first attempt succeeds (``tests/physics/env_replay.rs`` checks these give ``run_episode``'s
#: physics).
FLAGSHIP_LEAVES: list[dict[str, Any]] = [
    {"home": {}},
    {"release": {"width": 0.065, "retreat": 0}},
    {"reach": {"target": "cube", "offset": [0, 0, 0.12]}},
    {"reach": {"target": "cube", "offset": [0, 0, 0.0], "path": "cartesian"}},
    {"grasp": {}},
    {"carry": {"to": "bowl", "lift": 0.15, "place_height": 0.02, "speed": 1.0}},
    {"release": {"retreat": 0.10}},
    {"home": {}},
]

CTRL_STEPS = 2000


def scene() -> str:
    return str(data_dir() / "scenes/cube_bowl.yaml")


def wave(k: int, home: np.ndarray) -> np.ndarray:
    """A smooth 7-D target sequence around home (radians, gripper command)."""
    s = np.sin(k * 0.01)
    u = np.concatenate([home, [100.0 + 80.0 * s]])
    u[0] += 0.3 * s
    u[2] -= 0.2 * s
    return u.astype(np.float32)


def flagship(repeat: int) -> dict[str, float]:
    env = macrotree.MacroEnv(scene())
    ratios, walls, replays = [], [], []
    success = True
    for _ in range(repeat):
        env.reset(options={"layout": "default"})
        env.record_controls()
        start = time.perf_counter()
        info: dict[str, Any] = {}
        for leaf in FLAGSHIP_LEAVES:
            _, _, _, _, info = env.step_leaf(leaf)
        wall = time.perf_counter() - start
        replay, _, same = env.replay_recorded()
        success = success and bool(info["is_success"]) and same
        walls.append(wall)
        replays.append(replay)
        ratios.append(wall / replay)
    return {
        "python_wall_s": statistics.median(walls),
        "bare_replay_s": statistics.median(replays),
        "ratio": statistics.median(ratios),
        "success_and_same_physics": float(success),
    }


def ctrl(repeat: int) -> dict[str, float]:
    env = macrotree.MacroEnv(scene(), action_mode="setpoint")
    home = env.home
    ratios, walls = [], []
    for _ in range(repeat):
        env.reset(options={"layout": "default"})
        env.record_controls()
        targets = [wave(k, home) for k in range(CTRL_STEPS)]
        start = time.perf_counter()
        for u in targets:
            env.step(u)
        wall = time.perf_counter() - start
        replay, _, same = env.replay_recorded()
        assert same, "the replay did not end in the environment's state"
        walls.append(wall)
        ratios.append(replay / wall)
    return {
        "env_steps_per_s": CTRL_STEPS / statistics.median(walls),
        "throughput_vs_bare": statistics.median(ratios),
    }


def steps_per_second(step: Callable[[int], object], n_envs: int, repeat: int) -> float:
    rates = []
    for _ in range(repeat):
        start = time.perf_counter()
        for k in range(CTRL_STEPS // 4):
            step(k)
        rates.append(n_envs * (CTRL_STEPS // 4) / (time.perf_counter() - start))
    return statistics.median(rates)


def vector(n: int, repeat: int) -> dict[str, float]:
    home = np.asarray(macrotree._native.HOME)
    batch = np.stack([np.stack([wave(k, home)] * n) for k in range(CTRL_STEPS // 4)])
    out: dict[str, float] = {}

    one = macrotree.MacroEnv(scene(), action_mode="setpoint")
    one.reset(seed=0)
    out["single_env"] = steps_per_second(lambda k: one.step(batch[k][0]), 1, repeat)

    loop = [macrotree.MacroEnv(scene(), action_mode="setpoint") for _ in range(n)]
    for e in loop:
        e.reset(seed=0)

    def python_loop(k: int) -> None:
        for i, e in enumerate(loop):
            e.step(batch[k][i])

    out["python_loop"] = steps_per_second(python_loop, n, repeat)

    def make() -> gym.Env[Any, Any]:
        return macrotree.MacroEnv(scene(), action_mode="setpoint")

    kinds: list[tuple[str, Any]] = [
        ("sync_vector_env", gym.vector.SyncVectorEnv),
        ("async_vector_env", gym.vector.AsyncVectorEnv),
    ]
    for name, cls in kinds:
        envs = cls([make] * n)
        envs.reset(seed=0)

        def step(k: int, envs: Any = envs) -> object:
            return envs.step(batch[k])

        out[name] = steps_per_second(step, n, repeat)
        envs.close()

    # The native vector env against one environment in alternating rounds: the ratio of each
    # round, so a machine whose speed drifts still compares like with like.
    native = macrotree.VectorEnv(scene(), num_envs=n, action_mode="setpoint", threads=n)
    native.reset(seed=0)
    rounds = 4 * repeat + 1
    chunk = len(batch) // rounds
    singles, vectors, ratios = [], [], []
    for r in range(rounds):
        ks = range(r * chunk, (r + 1) * chunk)
        start = time.perf_counter()
        for k in ks:
            one.step(batch[k][0])
        single = chunk / (time.perf_counter() - start)
        start = time.perf_counter()
        for k in ks:
            native.step(batch[k])
        vector = n * chunk / (time.perf_counter() - start)
        singles.append(single)
        vectors.append(vector)
        ratios.append(vector / single)
    native.close()
    out["macrotree_vector_env"] = statistics.median(vectors)
    out["single_env_paired"] = statistics.median(singles)
    out["vector_vs_single"] = statistics.median(ratios)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--envs", type=int, default=2)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results = {
        "flagship_leaf_by_leaf": flagship(args.repeat),
        "ctrl": ctrl(args.repeat),
        f"vector_{args.envs}_envs": vector(args.envs, args.repeat),
    }
    if args.json:
        print(json.dumps(results))
    else:
        for group, values in results.items():
            shown = ", ".join(f"{k} {v:.4g}" for k, v in values.items())
            print(f"{group}: {shown}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
