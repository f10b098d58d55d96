"""Memory per additional environment: resident set (``VmRSS`` of ``/proc/self/status``) of one
environment against 1 + N, each case in a fresh process so freed memory never hides a cost.

- ``vector``: ``VectorEnv(num_envs=…)`` after ``reset``, its sub-environments never planning.
- ``vector_planning``: the same in ``residual`` mode after 600 zero-residual steps: the flagship
  tree (the base) plans its motions, so every sub-environment has built its collision checker.
- ``separate``: ``MacroEnv`` constructed one by one (what Gymnasium's ``SyncVectorEnv`` does),
  each after ``reset`` and 600 residual steps.

    python examples/python/memory.py [--envs 16] [--json]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from typing import Any

import numpy as np

#: Zero-residual steps each environment takes in the planning cases (2.4 s at the 4 ms control
#: period: the base tree has planned its reach above the cube and the descent by then).
PLANNING_STEPS = 600


def rss_mb() -> float:
    """This process's resident set, megabytes."""
    with open("/proc/self/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS in /proc/self/status")


def measure(case: str, n: int) -> float:
    """Resident set after building ``case`` with ``n`` environments (run in a child process)."""
    import macrotree
    from macrotree._library import data_dir

    scene = str(data_dir() / "scenes/cube_bowl.yaml")
    tree = str(data_dir() / "trees/cube_to_bowl.yaml")
    keep: list[Any] = []
    if case == "vector":
        v = macrotree.VectorEnv(scene, num_envs=n, action_mode="ctrl")
        v.reset(seed=0)
        keep.append(v)
    elif case == "vector_planning":
        v = macrotree.VectorEnv(scene, tree, num_envs=n, action_mode="residual")
        v.reset(seed=0)
        zero = np.zeros((n, 7), dtype=np.float32)
        for _ in range(PLANNING_STEPS):
            v.step(zero)
        keep.append(v)
    elif case == "separate":
        for k in range(n):
            e = macrotree.MacroEnv(scene, tree, action_mode="residual")
            e.reset(seed=k)
            for _ in range(PLANNING_STEPS):
                e.step(np.zeros(7, dtype=np.float32))
            keep.append(e)
    else:
        raise ValueError(f"unknown case {case!r}")
    return rss_mb()


def child(case: str, n: int) -> float:
    out = subprocess.run(
        [sys.executable, __file__, "--child", case, str(n)],
        check=True,
        capture_output=True,
        text=True,
    )
    return float(out.stdout.strip())


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--envs", type=int, default=16, help="additional environments (N)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--child", nargs=2, metavar=("CASE", "N"), help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        print(measure(args.child[0], int(args.child[1])))
        return 0
    n = args.envs
    results: dict[str, float] = {}
    for case in ("vector", "vector_planning", "separate"):
        one, many = child(case, 1), child(case, 1 + n)
        results[case] = (many - one) / n
        results[f"{case}_one_mb"] = one
    if args.json:
        print(json.dumps(results))
    else:
        for case in ("vector", "vector_planning", "separate"):
            print(
                f"{case}: {results[case]:.1f} MB per additional environment "
                f"(one: {results[case + '_one_mb']:.0f} MB)"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
