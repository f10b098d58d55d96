"""The behaviour-cloning trainer of :mod:`macrotree.bc` on PyTorch (``--trainer torch``).

The same network (ReLU MLP), loss (mean squared error on normalised labels), optimiser (Adam,
the same half-cosine learning rate), batch size, epochs and export as the numpy trainer: only
the arithmetic runs in PyTorch, so the one training loop can use a GPU or a wider network
without a second export path. PyTorch is not a dependency of macrotree (it is too heavy for
CI); install it beside the package (``pip install torch``). Its results are reproducible on one
machine, PyTorch build and thread count (``torch.manual_seed``, deterministic algorithms), not
bit-identical to the numpy trainer's.
"""

from __future__ import annotations

import itertools
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from .bc import Demonstrations, TrainConfig, cosine_lr, normalise
from .onnx_mlp import Mlp


def _torch() -> Any:
    try:
        import torch
    except ImportError as e:
        raise SystemExit("--trainer torch needs PyTorch: pip install torch") from e
    return torch


def train_torch(
    d: Demonstrations,
    cfg: TrainConfig,
    log: bool = True,
    checkpoint: Callable[[int, Mlp], None] | None = None,
    device: str = "cpu",
) -> Mlp:
    """Fits the MLP of :func:`macrotree.bc.train` to ``d`` with PyTorch on ``device``; calls
    ``checkpoint(epoch, mlp)`` after each epoch listed in ``cfg.checkpoints``."""
    torch = _torch()
    torch.manual_seed(cfg.seed)
    torch.use_deterministic_algorithms(True)
    nd = normalise(d, cfg)
    x = torch.from_numpy(nd.x).to(device)
    y = torch.from_numpy(nd.y).to(device)
    sizes = [x.shape[1], *cfg.hidden, y.shape[1]]
    layers: list[Any] = []
    for k, (a, b) in enumerate(itertools.pairwise(sizes)):
        linear = torch.nn.Linear(a, b)
        # He initialisation with zero biases, as the numpy trainer starts.
        torch.nn.init.kaiming_normal_(linear.weight, nonlinearity="relu")
        torch.nn.init.zeros_(linear.bias)
        layers.append(linear)
        if k < len(sizes) - 2:
            layers.append(torch.nn.ReLU())
    net = torch.nn.Sequential(*layers).to(device)
    opt = torch.optim.Adam(net.parameters(), lr=cfg.lr, betas=(0.9, 0.999), eps=1e-8)
    generator = torch.Generator().manual_seed(cfg.seed)
    n = len(x)

    def export() -> Mlp:
        linears = [m for m in net if isinstance(m, torch.nn.Linear)]
        ws = [np.ascontiguousarray(m.weight.detach().cpu().numpy().T) for m in linears]
        bs = [m.bias.detach().cpu().numpy().copy() for m in linears]
        return nd.export(d, cfg.action_len, ws, bs)

    for epoch in range(cfg.epochs):
        for group in opt.param_groups:
            group["lr"] = float(cosine_lr(cfg, epoch))
        order = torch.randperm(n, generator=generator).to(device)
        total = 0.0
        for start in range(0, n, cfg.batch):
            i = order[start : start + cfg.batch]
            err = net(x[i]) - y[i]
            loss = (err**2).sum(1).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float((err.detach() ** 2).sum())
        if log and (epoch % 10 == 0 or epoch == cfg.epochs - 1):
            print(
                f"epoch {epoch + 1}/{cfg.epochs}: mse {total / n / y.shape[1]:.4f}", file=sys.stderr
            )
        if checkpoint is not None and epoch + 1 in cfg.checkpoints and epoch + 1 < cfg.epochs:
            checkpoint(epoch + 1, export())
    return export()
