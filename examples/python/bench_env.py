"""How fast the Python environment is, measured in one run (ratios hold on a noisy machine).

1. The flagship task driven leaf by leaf from Python (``step_leaf``) against a bare ``mj_step``
   replay of the same controls (``replay_recorded``: the same physics, bit for bit).
2. ``setpoint`` mode: ``env.step`` of 7-D targets (10 ms = 5 physics steps each) against the bare
   replay of the same controls.
3. Vector environments, envpool-style: N single environments in a Python loop, Gymnasium's
   ``SyncVectorEnv`` and ``AsyncVectorEnv``, and ``macrotree.VectorEnv``, in ``ctrl`` steps per
   second; ``vector_vs_single`` is the median ratio of alternating rounds of the native vector env
   and one environment, ``processes_vs_single`` that of N processes stepping one environment each
   (the machine's ceiling in that run) and ``vector_vs_processes`` the share of it reached.
4. The same ratio for macro steps (a 0.5 s wait each).

    python examples/python/bench_env.py [--repeat 5] [--envs 2] [--json]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from typing import Any

import gymnasium as gym
import numpy as np

import macrotree
from macrotree._library import data_dir
from macrotree.env import ActionMode

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
#: Steps of each environment in one paired round (about 15 ms each at 10 ms control periods on
#: this machine; rounds much shorter are dominated by waking the free processes).
ROUND_STEPS = 100


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

    # The native vector env against one environment, and against n processes stepping one
    # environment each (what the machine's cores give at best, without a GIL or a hand-off), in
    # alternating rounds: the ratios of each round, so a machine whose speed drifts still
    # compares like with like.
    native = macrotree.VectorEnv(scene(), num_envs=n, action_mode="setpoint", threads=n)
    native.reset(seed=0)
    rounds = 4 * repeat + 1
    chunk = ROUND_STEPS
    batch = np.stack([np.stack([wave(k, home)] * n) for k in range(rounds * chunk)])
    free = [FreeProcess("setpoint", batch[:, i]) for i in range(n)]
    out.update(
        paired_rounds(
            n,
            rounds,
            chunk,
            single=lambda k: one.step(batch[k][0]),
            vector=lambda k: native.step(batch[k]),
            free=free,
        )
    )
    native.close()
    for p in free:
        p.close()
    return out


def paired_rounds(
    n: int,
    rounds: int,
    steps: int,
    single: Callable[[int], object],
    vector: Callable[[int], object],
    free: Sequence[FreeProcess],
) -> dict[str, float]:
    """Alternating rounds of ``steps`` steps (step indices ``r * steps`` on): one environment
    (``single(k)``), the n-environment vector env (``vector(k)``, n steps each) and the n free
    processes; the medians of the rates and of each round's ratios, so a machine whose speed
    drifts still compares like with like."""
    singles, vectors, ratios, ceilings, shares = [], [], [], [], []
    for r in range(rounds):
        ks = range(r * steps, (r + 1) * steps)
        start = time.perf_counter()
        for k in ks:
            single(k)
        one = steps / (time.perf_counter() - start)
        start = time.perf_counter()
        for k in ks:
            vector(k)
        together = n * steps / (time.perf_counter() - start)
        start = time.perf_counter()
        for p in free:
            p.start(ks.start, ks.stop)
        for p in free:
            p.wait()
        apart = n * steps / (time.perf_counter() - start)
        singles.append(one)
        vectors.append(together)
        ratios.append(together / one)
        ceilings.append(apart / one)
        shares.append(together / apart)
    return {
        "single_env_paired": statistics.median(singles),
        "macrotree_vector_env": statistics.median(vectors),
        "vector_vs_single": statistics.median(ratios),
        "processes_vs_single": statistics.median(ceilings),
        "vector_vs_processes": statistics.median(shares),
    }


def _free_worker(conn: Connection, mode: ActionMode, actions: Sequence[Any] | np.ndarray) -> None:
    """A process stepping its own environment through ``actions[start:stop]`` on request."""
    env = macrotree.MacroEnv(scene(), action_mode=mode)
    env.reset(seed=0)
    conn.send("ready")
    while (job := conn.recv()) is not None:
        start, stop = job
        for k in range(start, stop):
            env.step(actions[k])
        conn.send("done")
    env.close()


class FreeProcess:
    """One environment in a process of its own, stepped on request (the machine's ceiling)."""

    def __init__(self, mode: ActionMode, actions: Sequence[Any] | np.ndarray) -> None:
        context = multiprocessing.get_context("spawn")
        self._conn, theirs = context.Pipe()
        self._process = context.Process(
            target=_free_worker, args=(theirs, mode, actions), daemon=True
        )
        self._process.start()
        if self._conn.recv() != "ready":
            raise RuntimeError("the free process did not start")

    def start(self, first: int, stop: int) -> None:
        self._conn.send((first, stop))

    def wait(self) -> None:
        if self._conn.recv() != "done":
            raise RuntimeError("the free process did not finish its steps")

    def close(self) -> None:
        self._conn.send(None)
        self._process.join(timeout=30)


#: A macro action of a 0.5 s wait (50 reference steps of 10 ms; mode 0 is the reference's wait).
WAIT_MACRO: dict[str, Any] = {"mode": 0, "steps": [50]}


def vector_macro(n: int, repeat: int) -> dict[str, float]:
    """Macro steps (:data:`WAIT_MACRO`): ``macrotree.VectorEnv`` against one environment and
    against n free processes, in alternating rounds of 10 steps; medians of the rounds' ratios."""
    one = macrotree.MacroEnv(scene())
    native = macrotree.VectorEnv(scene(), num_envs=n, threads=n)
    rounds = 2 * repeat - 1
    free = [FreeProcess("macro", [WAIT_MACRO] * 10 * rounds) for _ in range(n)]
    # 10 rounds of 10 waits of 0.5 s stay within the default 120 s episode.
    one.reset(seed=0)
    native.reset(seed=0)
    actions = [WAIT_MACRO] * n
    out = paired_rounds(
        n,
        rounds,
        10,
        single=lambda _: one.step(WAIT_MACRO),
        vector=lambda _: native.step(actions),
        free=free,
    )
    native.close()
    for p in free:
        p.close()
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
        f"vector_{args.envs}_envs_macro": vector_macro(args.envs, args.repeat),
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
