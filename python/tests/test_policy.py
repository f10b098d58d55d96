"""The `policy` leaf from Python: models written by macrotree's own ONNX writer, run by the
extension's ONNX Runtime inside `step_leaf`, and the behaviour-cloning trainer's pieces."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import macrotree
from macrotree import bc
from macrotree.onnx_mlp import Mlp, to_onnx

STATE = ("observation.state", len(macrotree.STATE_NAMES))
OBJECT = ("observation.object", len(macrotree.OBJECT_NAMES))


def _random_mlp(rng: np.random.Generator, n_in: int, skip: bool) -> Mlp:
    sizes = [n_in, 16, 7]
    return Mlp(
        weights=[rng.normal(size=(a, b)).astype(np.float32) for a, b in itertools.pairwise(sizes)],
        biases=[rng.normal(size=b).astype(np.float32) for b in sizes[1:]],
        x_mean=rng.normal(size=n_in).astype(np.float32),
        x_std=(1.0 + rng.random(n_in)).astype(np.float32),
        y_mean=rng.normal(size=7).astype(np.float32),
        y_std=(1.0 + rng.random(7)).astype(np.float32),
        skip=np.eye(n_in, 7, dtype=np.float32) if skip else None,
        metadata={"macrotree.action": "absolute"},
    )


@pytest.mark.parametrize("skip", [False, True])
def test_the_onnx_writer_computes_what_the_network_computes(tmp_path: Path, skip: bool) -> None:
    rng = np.random.default_rng(3)
    mlp = _random_mlp(rng, STATE[1] + OBJECT[1], skip)
    path = tmp_path / "m.onnx"
    path.write_bytes(to_onnx(mlp, [STATE, OBJECT]))
    x = rng.normal(size=(1, STATE[1] + OBJECT[1])).astype(np.float32)
    out = macrotree.run_policy_model(
        str(path),
        {STATE[0]: x[0, : STATE[1]].tolist(), OBJECT[0]: x[0, STATE[1] :].tolist()},
    )
    expected = mlp.forward(x)[0]
    assert np.allclose(out[0], expected, rtol=1e-4, atol=1e-4), (out, expected)


def test_the_onnx_writer_writes_an_action_chunk_the_leaf_reads_action_by_action(
    tmp_path: Path,
) -> None:
    rng = np.random.default_rng(4)
    n_in, k = STATE[1] + OBJECT[1], 3
    sizes = [n_in, 16, 7 * k]
    skip = np.zeros((n_in, 7 * k), np.float32)
    for c in range(k):
        skip[np.arange(6), 7 * c + np.arange(6)] = 1.0
    mlp = Mlp(
        weights=[rng.normal(size=(a, b)).astype(np.float32) for a, b in itertools.pairwise(sizes)],
        biases=[rng.normal(size=b).astype(np.float32) for b in sizes[1:]],
        x_mean=rng.normal(size=n_in).astype(np.float32),
        x_std=(1.0 + rng.random(n_in)).astype(np.float32),
        y_mean=rng.normal(size=7 * k).astype(np.float32),
        y_std=(1.0 + rng.random(7 * k)).astype(np.float32),
        skip=skip,
    )
    path = tmp_path / "chunk.onnx"
    path.write_bytes(to_onnx(mlp, [STATE, OBJECT], chunk=k))
    x = rng.normal(size=(1, n_in)).astype(np.float32)
    out = macrotree.run_policy_model(
        str(path),
        {STATE[0]: x[0, : STATE[1]].tolist(), OBJECT[0]: x[0, STATE[1] :].tolist()},
    )
    expected = mlp.forward(x).reshape(k, 7)
    assert np.allclose(np.asarray(out), expected, rtol=1e-4, atol=1e-4), (out, expected)
    with pytest.raises(ValueError, match="do not make a chunk"):
        to_onnx(mlp, [STATE, OBJECT], chunk=2)


def test_a_model_that_does_not_fit_is_refused_with_what_is_wrong(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    path = tmp_path / "m.onnx"
    path.write_bytes(to_onnx(_random_mlp(rng, 4, False), [("obs", 4)]))
    with pytest.raises(ValueError, match="`obs` is not a feature"):
        macrotree.run_policy_model(str(path), {"obs": [0.0] * 4})
    path.write_bytes(to_onnx(_random_mlp(rng, STATE[1], False), [STATE]))
    with pytest.raises(ValueError, match="takes 20 values, 3 were given"):
        macrotree.run_policy_model(str(path), {STATE[0]: [0.0] * 3})


def _home_model(path: Path) -> None:
    """A model that answers the home set points, gripper open, whatever it sees."""
    mlp = Mlp(
        weights=[np.zeros((STATE[1], 7), np.float32)],
        biases=[np.zeros(7, np.float32)],
        x_mean=np.zeros(STATE[1], np.float32),
        x_std=np.ones(STATE[1], np.float32),
        y_mean=np.asarray([*macrotree._native.HOME, 0.0], np.float32),
        y_std=np.ones(7, np.float32),
    )
    path.write_bytes(to_onnx(mlp, [STATE]))


def test_a_policy_leaf_steps_from_python(
    cube_env: macrotree.MacroEnv, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # In `step_leaf`, a model is named relative to the working folder and must lie inside it.
    monkeypatch.chdir(tmp_path)
    _home_model(tmp_path / "home.onnx")
    cube_env.reset(seed=0)
    away = [-1.2, -1.3, 1.4, -1.6, -1.57, 0.3]
    cube_env.step_leaf({"move_joints": {"joints": away}})
    obs, _, _, _, info = cube_env.step_leaf(
        {"policy": {"model": "home.onnx", "until": {"at_home": {}}, "timeout": 2}}
    )
    assert info["status"] == "success", info
    assert np.abs(np.asarray(obs["agent_pos"][:6]) - macrotree._native.HOME).max() < 0.05
    with pytest.raises(macrotree.MacrotreeError, match="outside the tree's folder"):
        cube_env.step_leaf({"policy": {"model": "/etc/hostname"}})


def test_object_features_match_the_leafs_definition() -> None:
    # A block 10 cm in front of the pinch along x, turned 10° more than the tool: the tool at
    # home has its x axis along world +y (tool yaw 0).
    state = np.zeros((1, 20))
    state[0, 13:16] = [0.1, 0.2, 0.3]
    # Pinch frame rotated 90° about z (x axis along world +y): quaternion (cos 45°, 0, 0, sin 45°).
    state[0, 16:20] = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    yaw = np.pi / 2 + np.radians(10)
    env = np.array([[0.2, 0.2, 0.3, np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)]])
    f = bc.object_features(state, env, 0)
    assert np.allclose(f[0, :3], [0.1, 0.0, 0.0])
    assert np.allclose(
        f[0, 3:], [np.sin(4 * np.radians(10)), np.cos(4 * np.radians(10))], atol=1e-9
    )


def test_training_fits_a_smooth_map() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=(2000, 25))
    y = np.column_stack([np.tanh(x[:, :6]) * 0.05, 255.0 / (1.0 + np.exp(-4.0 * x[:, 20]))])
    d = bc.Demonstrations(x, y, np.zeros(len(x), np.int64))
    mlp = bc.train(d, bc.TrainConfig(hidden=(64, 64), epochs=60, seed=0), log=False)
    pred = mlp.forward(x.astype(np.float32))
    pred[:, :6] -= x[:, :6]  # the skip term adds the measured joints back
    # At most half the error of the best constant guess, joints and gripper alike.
    error = np.abs(pred - y).mean(0)
    baseline = np.abs(y - y.mean(0)).mean(0)
    assert (error < 0.5 * baseline).all(), (error, baseline)


def test_training_a_chunk_adds_the_measured_joints_to_every_action() -> None:
    # Labels for a chunk of two: offsets to the next set points, then twice the offsets.
    rng = np.random.default_rng(2)
    x = rng.normal(size=(2000, 25))
    one = np.column_stack([np.tanh(x[:, :6]) * 0.05, 255.0 / (1.0 + np.exp(-4.0 * x[:, 20]))])
    y = np.column_stack([one, 2 * one[:, :6], one[:, 6]])
    d = bc.Demonstrations(x, y, np.zeros(len(x), np.int64))
    mlp = bc.train(d, bc.TrainConfig(hidden=(64, 64), epochs=60, seed=0), log=False)
    pred = mlp.forward(x.astype(np.float32)).reshape(len(x), 2, 7)
    pred[:, :, :6] -= x[:, None, :6]  # the skip term adds the measured joints to each action
    error = np.abs(pred.reshape(len(x), 14) - y).mean(0)
    baseline = np.abs(y - y.mean(0)).mean(0)
    assert (error < 0.5 * baseline).all(), (error, baseline)


def test_checkpoints_are_the_network_after_their_epochs() -> None:
    rng = np.random.default_rng(5)
    x = rng.normal(size=(300, 25))
    y = rng.normal(size=(300, 7))
    d = bc.Demonstrations(x, y, np.zeros(len(x), np.int64))
    saved: dict[int, Mlp] = {}
    cfg = bc.TrainConfig(hidden=(8,), epochs=4, seed=0, checkpoints=(2, 4))
    final = bc.train(d, cfg, log=False, checkpoint=saved.__setitem__)
    # The last epoch is the model `train` returns, not a checkpoint.
    assert list(saved) == [2]
    two = bc.train(d, bc.TrainConfig(hidden=(8,), epochs=4, seed=0), log=False)
    assert all(np.array_equal(a, b) for a, b in zip(final.weights, two.weights, strict=True))
    assert not np.array_equal(saved[2].weights[0], final.weights[0])


def test_a_full_command_model_is_trained_and_read_as_19_values_per_action(
    tmp_path: Path,
) -> None:
    # Labels for a chunk of two full commands: set-point offsets, velocities, accelerations,
    # the gripper command.
    rng = np.random.default_rng(6)
    x = rng.normal(size=(1500, 25))
    one = np.column_stack(
        [np.tanh(x[:, :6]) * 0.05, np.tanh(x[:, 6:18]), 255.0 / (1.0 + np.exp(-4.0 * x[:, 20]))]
    )
    y = np.column_stack([one, one])
    d = bc.Demonstrations(x, y, np.zeros(len(x), np.int64))
    cfg = bc.TrainConfig(hidden=(32,), epochs=5, seed=0, action_len=19)
    mlp = bc.train(d, cfg, log=False)
    assert mlp.skip is not None
    # The measured joints are added back to the set points of each action, and to nothing else.
    rows, cols = np.nonzero(mlp.skip)
    assert rows.tolist() == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5]
    assert sorted(cols.tolist()) == [*range(6), *range(19, 25)]
    path = tmp_path / "command.onnx"
    bc.write_model(mlp, str(path), cfg.action_len)
    probe = rng.normal(size=(1, 25)).astype(np.float32)
    out = macrotree.run_policy_model(
        str(path), {STATE[0]: probe[0, :20].tolist(), OBJECT[0]: probe[0, 20:].tolist()}
    )
    assert [len(a) for a in out] == [19, 19]
    expected = mlp.forward(probe).reshape(2, 19)
    assert np.allclose(np.asarray(out), expected, rtol=1e-4, atol=1e-4), (out, expected)
