"""The PyTorch trainer of ``python -m macrotree.bc --trainer torch``: it fits as the numpy
trainer does, repeats itself, and exports a model the `policy` leaf reads. Skipped without
PyTorch (too heavy for CI); the system test runs it where ``MACROTREE_TORCH_PYTHON`` names a
Python with torch."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import macrotree
from macrotree import bc
from macrotree.bc_torch import train_torch

pytest.importorskip("torch")


def _demonstrations(seed: int) -> bc.Demonstrations:
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(2000, 25))
    y = np.column_stack([np.tanh(x[:, :6]) * 0.05, 255.0 / (1.0 + np.exp(-4.0 * x[:, 20]))])
    return bc.Demonstrations(x, y, np.zeros(len(x), np.int64))


def test_the_torch_trainer_fits_a_smooth_map_as_the_numpy_one_does() -> None:
    d = _demonstrations(1)
    cfg = bc.TrainConfig(hidden=(64, 64), epochs=60, seed=0)
    baseline = np.abs(d.y - d.y.mean(0)).mean(0)
    for mlp in [train_torch(d, cfg, log=False), bc.train(d, cfg, log=False)]:
        pred = mlp.forward(d.x.astype(np.float32))
        pred[:, :6] -= d.x[:, :6]  # the skip term adds the measured joints back
        error = np.abs(pred - d.y).mean(0)
        assert (error < 0.5 * baseline).all(), (error, baseline)


def test_the_torch_trainer_repeats_itself_and_exports_what_the_leaf_runs(tmp_path: Path) -> None:
    d = _demonstrations(2)
    cfg = bc.TrainConfig(hidden=(16,), epochs=3, seed=4)
    a, b = train_torch(d, cfg, log=False), train_torch(d, cfg, log=False)
    assert all(np.array_equal(u, v) for u, v in zip(a.weights, b.weights, strict=True))
    other = train_torch(d, bc.TrainConfig(hidden=(16,), epochs=3, seed=5), log=False)
    assert not np.array_equal(a.weights[0], other.weights[0])
    path = tmp_path / "torch.onnx"
    bc.write_model(a, str(path), cfg.action_len)
    probe = d.x[:1].astype(np.float32)
    out = macrotree.run_policy_model(
        str(path),
        {"observation.state": probe[0, :20].tolist(), "observation.object": probe[0, 20:].tolist()},
    )
    assert np.allclose(np.asarray(out), a.forward(probe), rtol=1e-4, atol=1e-4)
