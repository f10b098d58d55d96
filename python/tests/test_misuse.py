"""The Python API under misuse: threads, invalid batches, malformed macro actions, closed and
copied environments. Each refusal is a clear exception; nothing deadlocks or moves."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import macrotree
from macrotree import MacroMode
from macrotree.spaces import MAX_MACRO_STEPS


def scene(data: Path) -> str:
    return str(data / "scenes/cube_bowl.yaml")


def test_a_second_thread_on_a_busy_environment_is_refused_not_deadlocked(data: Path) -> None:
    env = macrotree.MacroEnv(scene(data))
    env.reset(seed=0)
    started = threading.Event()
    errors: list[BaseException] = []

    def long_step() -> None:
        started.set()
        env.step({"mode": int(MacroMode.WAIT), "steps": [3000]})

    worker = threading.Thread(target=long_step)
    worker.start()
    started.wait(5)
    refused = 0
    deadline = time.monotonic() + 30
    while worker.is_alive() and time.monotonic() < deadline:
        try:
            env.observation()
        except RuntimeError as e:
            assert "another thread" in str(e)
            refused += 1
            break
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)
            break
        time.sleep(0.001)
    worker.join(60)
    assert not worker.is_alive(), "the stepping thread finished"
    assert not errors, errors
    assert refused == 1, "the second caller was refused while the step ran"
    env.observation()  # usable again


def test_an_invalid_action_refuses_the_whole_batch_before_anything_moves(data: Path) -> None:
    vec = macrotree.VectorEnv(scene(data), num_envs=2, action_mode="setpoint")
    vec.reset(seed=0)
    good = np.concatenate([np.asarray(macrotree._native.HOME), [0.0]])
    bad = good.copy()
    bad[3] = np.nan
    with pytest.raises(macrotree.MacrotreeError, match=r"environment 1: setpoint\[3\]"):
        vec.step(np.stack([good, bad]))
    with pytest.raises(macrotree.MacrotreeError, match="environment 1"):
        vec.send(np.stack([good, bad]))
    # Nothing moved, nothing is pending: the vector env steps on.
    after, *_ = vec.step(np.stack([good, good]))
    single = macrotree.MacroEnv(scene(data), action_mode="setpoint")
    single.reset(seed=0)
    one, *_ = single.step(good)
    assert np.array_equal(after["agent_pos"][0], one["agent_pos"])
    vec.send(np.stack([good, good]))
    vec.recv()
    vec.close()


def test_strided_actions_are_taken_and_complex_ones_refused(data: Path) -> None:
    env = macrotree.MacroEnv(scene(data), action_mode="ctrl")
    env.reset(seed=0)
    action = np.concatenate([env.home, np.zeros(12), [0.0]])
    # A column of a batch: the same values with a stride of 4 elements.
    batch = np.zeros((19, 4))
    batch[:, 2] = action
    column = batch[:, 2]
    assert not column.flags["C_CONTIGUOUS"]
    strided, *_ = env.step(column)
    env.reset(seed=0)
    plain, *_ = env.step(action)
    assert np.array_equal(strided["agent_pos"], plain["agent_pos"])
    before = env.observation()["time"]
    with pytest.raises(TypeError, match="real numbers, got complex"):
        env.step(action + 1e-3j)
    with pytest.raises(TypeError, match="real numbers"):
        env.step(np.array(["0"] * 19))
    assert env.observation()["time"] == before, "nothing moved"
    # A Fortran-ordered batch (its rows strided) for a vector environment.
    vec = macrotree.VectorEnv(scene(data), num_envs=2, action_mode="ctrl")
    vec.reset(seed=0)
    rows = np.asfortranarray(np.stack([action, action]))
    assert not rows[0].flags["C_CONTIGUOUS"]
    out, *_ = vec.step(rows)
    assert np.array_equal(out["agent_pos"][0], plain["agent_pos"])
    with pytest.raises(TypeError, match="complex"):
        vec.step(rows.astype(np.complex128))
    vec.close()
    env.close()


def test_actions_of_any_real_dtype_act_as_their_float64_values(data: Path) -> None:
    env = macrotree.MacroEnv(scene(data), action_mode="setpoint")
    target = np.concatenate([env.home + 0.01, [0.0]]).astype(np.float32)
    forms: list[Any] = [
        target.astype(np.float64),
        target,  # float32, read in place
        target.astype(">f8"),  # float64 in the other byte order
        [float(v) for v in target],
    ]
    results = []
    for form in forms:
        env.reset(seed=0)
        obs, *_ = env.step(form)
        results.append(obs["agent_pos"])
    for other in results[1:]:
        assert np.array_equal(other, results[0])
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"a setpoint action has 7 values, got shape \(2, 7\)"):
        env.step(np.stack([target, target]))
    vec = macrotree.VectorEnv(scene(data), num_envs=2, action_mode="setpoint")
    vec.reset(seed=0)
    batch = np.stack([target, target])
    out32, *_ = vec.step(batch)
    vec.reset(seed=0)
    out64, *_ = vec.step(batch.astype(np.float64))
    assert np.array_equal(out32["agent_pos"], out64["agent_pos"])
    assert np.array_equal(out64["agent_pos"][0], results[0])
    with pytest.raises(ValueError, match=r"must have shape \(2, 7\), got \(3, 7\)"):
        vec.step(np.stack([target] * 3))
    with pytest.raises(TypeError, match="real numbers, got <U1"):
        vec.step(np.full((2, 7), "0"))
    vec.close()
    env.close()


@pytest.mark.parametrize(("period", "shown"), [(1e-300, "1.000e-300"), (0.003, "0.003")])
def test_a_control_period_off_the_physics_steps_is_refused_with_the_rule(
    data: Path, period: float, shown: str
) -> None:
    with pytest.raises(macrotree.MacrotreeError) as e:
        macrotree.MacroEnv(scene(data), action_mode="ctrl", control_period=period)
    message = str(e.value)
    assert "whole number (at least 1) of 2 ms physics steps" in message
    assert message.endswith(f"got {shown}"), message
    assert len(message) < 200, "a hostile number is printed shortly"


def macro_env(data: Path) -> macrotree.MacroEnv:
    env = macrotree.MacroEnv(scene(data))
    env.reset(seed=0)
    return env


@pytest.mark.parametrize(
    ("action", "message"),
    [
        ({"mode": 2, "position": [0.4, 0.0, 0.3], "quaternion": [np.nan, 1, 0, 0]}, "quaternion"),
        ({"mode": 0, "steps": [5], "setle_steps": [1]}, "setle_steps"),
        ({"mode": 1.5}, "whole number"),
        ({"mode": "0"}, "whole number"),
        ({"mode": 0, "steps": [2.7]}, "whole number"),
        # One past the action space's bound, which is the extension's own limit.
        ({"mode": 0, "steps": [MAX_MACRO_STEPS + 1]}, f"each at most {MAX_MACRO_STEPS} "),
    ],
)
def test_malformed_macro_actions_are_refused(
    data: Path, action: dict[str, Any], message: str
) -> None:
    env = macro_env(data)
    before = env.observation()["time"]
    with pytest.raises((ValueError, macrotree.MacrotreeError), match=message):
        env.step(action)
    assert env.observation()["time"] == before, "nothing moved"


def test_open_gripper_opens_to_its_gripper_command(data: Path) -> None:
    env = macro_env(data)
    env.step({"mode": int(MacroMode.CLOSE_GRIPPER), "steps": [20]})
    env.step({"mode": int(MacroMode.OPEN_GRIPPER), "gripper_command": [100.0], "steps": [20]})
    assert env.observation()["gripper_command"] == 100.0
    env.step({"mode": int(MacroMode.OPEN_GRIPPER), "steps": [20]})
    assert env.observation()["gripper_command"] == 0.0


def test_a_closed_environment_refuses_every_call_and_none_can_be_copied(data: Path) -> None:
    env = macro_env(data)
    with pytest.raises(TypeError, match="cannot be copied"):
        copy.copy(env)
    with pytest.raises(TypeError, match="cannot be copied"):
        copy.deepcopy(env)
    env.close()
    env.close()
    with pytest.raises(RuntimeError, match="closed"):
        env.reset(seed=1)
    with pytest.raises(RuntimeError, match="closed"):
        env.observation()
    vec = macrotree.VectorEnv(scene(data), num_envs=1)
    vec.close()
    with pytest.raises(RuntimeError, match="closed"):
        vec.reset(seed=0)


INTERRUPTED_STEP = """
import json, os, signal, sys, threading
import macrotree

# Ctrl-C as in an interactive Python: a process started in the background by a shell without job
# control inherits SIGINT ignored, and then no Ctrl-C reaches it at all.
signal.signal(signal.SIGINT, signal.default_int_handler)

slow = {"control_period": 0.1, "max_sim_time": 3600.0}
env = macrotree.MacroEnv(sys.argv[1], **slow)
env.reset(seed=0)
vec = macrotree.VectorEnv(sys.argv[1], num_envs=2, **slow)
vec.reset(seed=0)
out = {}
long_wait = {"mode": 0, "steps": [6000]}  # 60 s of simulated time: several seconds of wall time
steps = (("env", lambda: env.step(long_wait)), ("vec", lambda: vec.step([long_wait] * 2)))
for name, step in steps:
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    try:
        step()
        out[name] = "finished"
    except KeyboardInterrupt:
        out[name] = "interrupted"
try:
    env.step(long_wait)
except macrotree.MacrotreeError as e:
    out["env_after"] = str(e)
try:
    vec.step([long_wait] * 2)
except macrotree.MacrotreeError as e:
    out["vec_after"] = str(e)
env.reset(seed=1)
out["env_time"] = env.step({"mode": 0, "steps": [1]})[4]["sim_time"]
vec.reset(seed=1)
out["vec_ok"] = bool(vec.step([{"mode": 0, "steps": [1]}] * 2)[0]["agent_pos"].shape[0] == 2)
print(json.dumps(out))
"""


def test_ctrl_c_interrupts_a_long_step_and_the_environment_asks_for_a_reset(data: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", INTERRUPTED_STEP, scene(data)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["env"] == "interrupted" and out["vec"] == "interrupted", out
    assert "reset" in out["env_after"] and "reset" in out["vec_after"], out
    assert out["env_time"] > 0 and out["vec_ok"], out


@pytest.mark.parametrize("size", [(100000, 100000), (8, 320), (240, 0)])
def test_an_image_size_out_of_bounds_is_refused_before_anything_is_built(
    data: Path, size: tuple[int, int]
) -> None:
    scene = data / "scenes/cube_bowl.yaml"
    with pytest.raises(ValueError, match="height must be 16"):
        macrotree.MacroEnv(scene, cameras=["front"], image_size=size)
    with pytest.raises(ValueError, match="height must be 16"):
        macrotree.VectorEnv(scene, num_envs=2, cameras=["front"], image_size=size)


def test_a_file_that_is_not_a_tree_or_a_scene_is_named_never_quoted(tmp_path: Path) -> None:
    secrets = {
        "creds.yaml": "password: s3cr3t-1\nuser: s3cr3t-2\n",
        "token.env": "TOKEN=s3cr3t-1\n",
        "broken.txt": "x: [s3cr3t-1\n",
    }
    for name, text in secrets.items():
        path = tmp_path / name
        path.write_text(text)
        for as_tree in (True, False):
            with pytest.raises(macrotree.MacrotreeError) as caught:
                if as_tree:
                    macrotree.MacroEnv(tree=str(path))
                else:
                    macrotree.MacroEnv(scene=str(path))
            message = str(caught.value)
            assert name in message, message
            assert "s3cr3t" not in message and "password" not in message, (as_tree, message)


def test_an_error_quoting_hostile_input_stays_short(data: Path) -> None:
    env = macrotree.MacroEnv(scene(data))
    env.reset(seed=0)
    huge = "x" * 100_000
    with pytest.raises(macrotree.MacrotreeError) as caught:
        env.step_leaf(json.dumps({"reach": {"target": huge}}))
    assert len(str(caught.value)) <= 8_000, len(str(caught.value))
    with pytest.raises((ValueError, macrotree.MacrotreeError)) as refused:
        env.reset(options={"layout": huge})
    message = str(refused.value)
    assert len(message) <= 8_000 and "characters left out" in message, len(message)
    env.close()
