"""Behaviour cloning of one skill of a macrotree dataset, in numpy, exported for the `policy` leaf.

    python -m macrotree.bc DATASET --leaf 'subtree[pick]' --object cube --out pick.onnx

reads a LeRobot dataset that ``macrotree sweep --dataset`` wrote (best with ``--noise``: DART
demonstrations, whose labels are the clean commands), keeps the frames whose running leaf's path
contains ``--leaf``, and fits a multilayer perceptron from what the `policy` leaf feeds a model
(``observation.state`` and ``observation.object``, the named object's pose relative to the
gripper) to the commands of the next ``--chunk`` frames (an action chunk ``[1, k, n]``; the
tree's ``n_action_steps`` says how many of them run before the model is called again): with
``--action setpoint`` (the default) n = 7, the set points and gripper commands; with ``--action
command`` n = 19, the whole recorded command — set points, joint velocities, accelerations and
the gripper command — which the leaf holds with the servos' feedforward, as the demonstrations
ran it. The network predicts offsets from the measured joints; the exported
graph adds them back (``action`` is absolute set points, ``macrotree.action = absolute``), bakes
the normalisation in, and records the dataset's digest, the segment and the training settings
in its metadata. Reading Parquet needs ``pyarrow``; training needs only numpy (two CPU cores,
minutes).

Why chunks: a scripted skill often holds still while one leaf settles and then moves on from the
same state (the pick's pre-grasp pose above the block, then the descent). Cloned one command at
a time, "hold" and "move on" average into a fixed point where the policy stops; a chunk of the
coming commands includes the move, so running a few of its actions leaves that state.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .onnx_mlp import Mlp, to_onnx

F64 = npt.NDArray[np.float64]
F32 = npt.NDArray[np.float32]

#: Values of ``observation.state`` (the Rust ``STATE_LEN``) and of ``observation.object``.
STATE_LEN = 20
OBJECT_LEN = 5
#: Values per object in ``observation.environment_state``.
VALUES_PER_OBJECT = 7
#: Values of a dataset's ``action`` (the `policy` leaf's full command): six joint set points,
#: six velocities, six accelerations, the gripper command.
COMMAND_LEN = 19
#: Index of the gripper command in a dataset's ``action``.
GRIPPER_IN_ACTION = 18
#: The dataset ``action`` columns each ``--action`` layout keeps, in the order the `policy` leaf
#: reads them (the first six, set points, are learned as offsets from the measured joints).
ACTION_LAYOUTS: dict[str, list[int]] = {
    "setpoint": [*range(6), GRIPPER_IN_ACTION],
    "command": list(range(COMMAND_LEN)),
}
#: Commands a model predicts by default (``--chunk``): 0.4 s at 50 fps, longer than the
#: flagship's pick holds still at its pre-grasp pose.
DEFAULT_CHUNK = 20
#: The smallest input spread normalisation divides by (a near-constant input, such as the
#: tool's orientation during a top grasp, must not blow small deviations up).
MIN_STD = 1e-2


def _yaw_of_x_axis(q: F64) -> F64:
    """Yaw (about world z) of the x axis of quaternions ``[w, x, y, z]`` (rows)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z))


def object_features(state: F64, environment: F64, index: int) -> F64:
    """``observation.object`` of object ``index`` for frames (rows), as the `policy` leaf
    computes it: its centre minus the pinch point (metres), then sin and cos of four times its
    yaw minus the tool's yaw."""
    o = environment[:, index * VALUES_PER_OBJECT : (index + 1) * VALUES_PER_OBJECT]
    d = o[:, :3] - state[:, 13:16]
    w, x, y, z = (state[:, 16 + i] for i in range(4))
    # The pinch frame's x axis (first column of its rotation matrix); tool yaw = atan2(-x0, x1).
    x0 = 1 - 2 * (y * y + z * z)
    x1 = 2 * (x * y + w * z)
    tool_yaw = np.arctan2(-x0, x1)
    rel = 4 * (_yaw_of_x_axis(o[:, 3:7]) - tool_yaw)
    return np.column_stack([d, np.sin(rel), np.cos(rel)])


@dataclass
class Demonstrations:
    """Training pairs: inputs (state then object features), labels (per action of the chunk:
    six joint offsets from the measured joints to the set point, radians, and the gripper
    command), and the episode of each row."""

    x: F64
    y: F64
    episode: npt.NDArray[np.int64]


def load_dataset(
    path: str,
    leaf: str,
    object_index: int,
    drop_holds: bool = False,
    chunk: int = 1,
    layout: str = "setpoint",
) -> tuple[Demonstrations, dict[str, object]]:
    """The demonstrations of the frames whose running leaf's path contains ``leaf``, and the
    dataset's ``meta/info.json``. Frame k's labels are the commands of frames k + 1 … k +
    ``chunk`` (the last frame of the episode repeated past its end), each the ``action`` columns
    of ``ACTION_LAYOUTS[layout]``, set points as offsets from the measured joints.

    With ``drop_holds``, frames where the arm only holds still (the next command's joint
    velocities all zero and the gripper command unchanged) are left out — an attempt at the
    ambiguity of a scripted leaf settling at its goal before the next leaf starts from the same
    state (the pre-grasp pose above the block, then the descent). On the flagship's pick it
    made things worse (docs/history.md, 2026-11-29)."""
    try:
        import pyarrow.parquet as pq  # type: ignore[import-not-found,import-untyped,unused-ignore]
    except ImportError as e:  # pragma: no cover - depends on the machine
        raise SystemExit("reading a dataset needs pyarrow: pip install pyarrow") from e
    with open(os.path.join(path, "meta", "info.json"), encoding="utf-8") as f:
        info: dict[str, object] = json.load(f)
    files = sorted(
        os.path.join(root, n)
        for root, _, names in os.walk(os.path.join(path, "data"))
        for n in names
        if n.endswith(".parquet")
    )
    xs: list[F64] = []
    ys: list[F64] = []
    eps: list[npt.NDArray[np.int64]] = []
    for file in files:
        t = pq.read_table(file)
        state = np.asarray(t.column("observation.state").to_pylist(), np.float64)
        env = np.asarray(t.column("observation.environment_state").to_pylist(), np.float64)
        action = np.asarray(t.column("action").to_pylist(), np.float64)
        episode = np.asarray(t.column("episode_index").to_pylist(), np.int64)
        active = t.column("tree.active_leaf").to_pylist()
        # Frame k's label is the command of frame k + 1 (where the arm must be one period on),
        # within one episode.
        keep = np.array([leaf in a for a in active[:-1]], bool) & (episode[:-1] == episode[1:])
        if drop_holds:
            moving = np.abs(action[1:, 6:12]).max(1) > 1e-9
            gripping = action[1:, GRIPPER_IN_ACTION] != action[:-1, GRIPPER_IN_ACTION]
            keep &= moving | gripping
        idx = np.nonzero(keep)[0]
        x = np.column_stack([state[idx], object_features(state[idx], env[idx], object_index)])
        # The last frame of each frame's episode: a chunk running past it repeats it.
        starts = np.r_[0, np.nonzero(episode[1:] != episode[:-1])[0] + 1, len(episode)]
        last = np.repeat(starts[1:] - 1, np.diff(starts))
        columns = ACTION_LAYOUTS[layout]
        y = np.column_stack(
            [
                np.column_stack([action[j, :6] - state[idx, :6], action[j][:, columns[6:]]])
                for j in (np.minimum(idx + step, last[idx]) for step in range(1, chunk + 1))
            ]
        )
        xs.append(x)
        ys.append(y)
        eps.append(episode[idx])
    if not xs or sum(len(x) for x in xs) == 0:
        raise SystemExit(f"no frame of {path} runs a leaf whose path contains {leaf!r}")
    return Demonstrations(np.concatenate(xs), np.concatenate(ys), np.concatenate(eps)), info


def dataset_digest(path: str) -> str:
    """sha256 over the dataset's Parquet data files, in name order (the model records it)."""
    h = hashlib.sha256()
    for root, _, names in sorted(os.walk(os.path.join(path, "data"))):
        for n in sorted(names):
            with open(os.path.join(root, n), "rb") as f:
                h.update(f.read())
    return h.hexdigest()


#: The ``observation.state`` values each ``--state`` choice feeds the network (the others get
#: zero weights): ``all`` 20, ``joints`` the six joint angles and the gripper closure,
#: ``joints_velocities`` those and the six joint velocities.
STATE_CHOICES: dict[str, list[int]] = {
    "all": list(range(STATE_LEN)),
    "joints": list(range(7)),
    "joints_velocities": list(range(13)),
}


@dataclass
class TrainConfig:
    """How the network is trained."""

    hidden: tuple[int, ...] = (256, 256)
    epochs: int = 60
    batch: int = 256
    lr: float = 1e-3
    seed: int = 0
    state: str = "all"
    #: Values per action of the labels (``len(ACTION_LAYOUTS[...])``: 7 or 19).
    action_len: int = len(ACTION_LAYOUTS["setpoint"])
    #: Epochs after which ``train`` hands the network to its ``checkpoint`` callback.
    checkpoints: tuple[int, ...] = ()


@dataclass
class Normalised:
    """Demonstrations as a trainer sees them: the ``used`` input columns and the labels, each
    normalised (float32), with the statistics the exported graph undoes."""

    x: F32
    y: F32
    used: npt.NDArray[np.int64]
    x_mean: F64
    x_std: F64
    y_mean: F64
    y_std: F64

    def export(self, d: Demonstrations, action_len: int, ws: list[F32], bs: list[F32]) -> Mlp:
        """The trained weights ``ws`` and biases ``bs`` as the exported MLP."""
        return _mlp(
            d, action_len, self.used, ws, bs, self.x_mean, self.x_std, self.y_mean, self.y_std
        )


def normalise(d: Demonstrations, cfg: TrainConfig) -> Normalised:
    """``d`` normalised for training: inputs by mean and spread (at least ``MIN_STD``) over the
    columns ``cfg.state`` keeps, labels by mean and spread."""
    used = np.array([*STATE_CHOICES[cfg.state], *range(STATE_LEN, STATE_LEN + OBJECT_LEN)])
    x_mean = np.zeros(d.x.shape[1])
    x_std = np.ones(d.x.shape[1])
    x_mean[used] = d.x[:, used].mean(0)
    x_std[used] = np.maximum(d.x[:, used].std(0), MIN_STD)
    y_mean = d.y.mean(0)
    y_std = np.maximum(d.y.std(0), 1e-6)
    return Normalised(
        x=((d.x[:, used] - x_mean[used]) / x_std[used]).astype(np.float32),
        y=((d.y - y_mean) / y_std).astype(np.float32),
        used=used,
        x_mean=x_mean,
        x_std=x_std,
        y_mean=y_mean,
        y_std=y_std,
    )


def cosine_lr(cfg: TrainConfig, epoch: int) -> np.float64:
    """The learning rate of ``epoch`` (from 0): ``cfg.lr`` on a half cosine down to 0."""
    lr: np.float64 = cfg.lr * 0.5 * (1 + np.cos(np.pi * epoch / cfg.epochs))
    return lr


def train(
    d: Demonstrations,
    cfg: TrainConfig,
    log: bool = True,
    checkpoint: Callable[[int, Mlp], None] | None = None,
) -> Mlp:
    """Fits an MLP (ReLU, Adam, mean squared error on normalised labels) to ``d``; calls
    ``checkpoint(epoch, mlp)`` after each epoch listed in ``cfg.checkpoints``."""
    rng = np.random.default_rng(cfg.seed)
    nd = normalise(d, cfg)
    x, y = nd.x, nd.y
    sizes = [x.shape[1], *cfg.hidden, y.shape[1]]
    ws = [
        (rng.standard_normal((a, b)) * np.sqrt(2.0 / a)).astype(np.float32)
        for a, b in itertools.pairwise(sizes)
    ]
    bs = [np.zeros(b, np.float32) for b in sizes[1:]]
    params = [*ws, *bs]
    m = [np.zeros_like(p) for p in params]
    v = [np.zeros_like(p) for p in params]
    b1, b2, eps = 0.9, 0.999, 1e-8
    step = 0
    n = len(x)
    for epoch in range(cfg.epochs):
        order = rng.permutation(n)
        total = 0.0
        for start in range(0, n, cfg.batch):
            i = order[start : start + cfg.batch]
            hs = [x[i]]
            for k, (w, b) in enumerate(zip(ws, bs, strict=True)):
                z = hs[-1] @ w + b
                hs.append(np.maximum(z, 0.0) if k < len(ws) - 1 else z)
            err = hs[-1] - y[i]
            total += float((err**2).sum())
            g = 2.0 * err / len(i)
            grads_w: list[F32] = []
            grads_b: list[F32] = []
            for k in range(len(ws) - 1, -1, -1):
                grads_w.insert(0, hs[k].T @ g)
                grads_b.insert(0, g.sum(0))
                if k > 0:
                    g = (g @ ws[k].T) * (hs[k] > 0)
            step += 1
            lr = cosine_lr(cfg, epoch)
            for j, (p, gr) in enumerate(zip(params, [*grads_w, *grads_b], strict=True)):
                m[j] = b1 * m[j] + (1 - b1) * gr
                v[j] = b2 * v[j] + (1 - b2) * gr * gr
                mh = m[j] / (1 - b1**step)
                vh = v[j] / (1 - b2**step)
                p -= (lr * mh / (np.sqrt(vh) + eps)).astype(np.float32)
        if log and (epoch % 10 == 0 or epoch == cfg.epochs - 1):
            print(
                f"epoch {epoch + 1}/{cfg.epochs}: mse {total / n / y.shape[1]:.4f}", file=sys.stderr
            )
        if checkpoint is not None and epoch + 1 in cfg.checkpoints and epoch + 1 < cfg.epochs:
            checkpoint(epoch + 1, nd.export(d, cfg.action_len, ws, bs))
    return nd.export(d, cfg.action_len, ws, bs)


def _mlp(
    d: Demonstrations,
    action_len: int,
    used: npt.NDArray[np.int64],
    ws: list[F32],
    bs: list[F32],
    x_mean: F64,
    x_std: F64,
    y_mean: F64,
    y_std: F64,
) -> Mlp:
    """The network of weights ``ws`` and biases ``bs`` (over the ``used`` inputs) as the
    exported MLP: every input, the normalisation, the skip term (copies of the current values)."""
    skip = np.zeros((d.x.shape[1], d.y.shape[1]), np.float32)
    for c in range(d.y.shape[1] // action_len):
        # offsets from the measured joints → set points, for each action of a chunk
        skip[np.arange(6), c * action_len + np.arange(6)] = 1.0
    first = np.zeros((d.x.shape[1], ws[0].shape[1]), np.float32)
    first[used] = ws[0]  # unused inputs get zero weights
    return Mlp(
        weights=[first.copy(), *(w.copy() for w in ws[1:])],
        biases=[b.copy() for b in bs],
        x_mean=x_mean.astype(np.float32),
        x_std=x_std.astype(np.float32),
        y_mean=y_mean.astype(np.float32),
        y_std=y_std.astype(np.float32),
        skip=skip,
    )


def write_model(mlp: Mlp, out: str, action_len: int) -> None:
    """Writes ``mlp`` as the `policy` leaf's ONNX model at ``out``, through an exclusive
    temporary file beside it (an existing file is replaced only once the new one is whole): one
    action ``[1, n]``, or a chunk ``[1, k, n]`` when the network has n k outputs (n =
    ``action_len``)."""
    data = to_onnx(
        mlp,
        [("observation.state", STATE_LEN), ("observation.object", OBJECT_LEN)],
        chunk=mlp.y_mean.size // action_len,
    )
    folder = os.path.dirname(os.path.abspath(out))
    fd, tmp = tempfile.mkstemp(prefix=".policy-", suffix=".onnx", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, out)
    except BaseException:
        os.unlink(tmp)
        raise


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m macrotree.bc", description=__doc__.split("\n\n")[0])
    p.add_argument("dataset", help="a dataset folder `macrotree sweep --dataset` wrote")
    p.add_argument(
        "--leaf", required=True, help="keep frames whose running leaf's path contains this"
    )
    p.add_argument(
        "--object",
        type=int,
        default=0,
        metavar="INDEX",
        help="the object's index in the scene (default 0)",
    )
    p.add_argument("--out", required=True, help="the ONNX file to write")
    p.add_argument("--epochs", type=int, default=TrainConfig.epochs)
    p.add_argument("--hidden", type=int, nargs="+", default=list(TrainConfig.hidden))
    p.add_argument("--lr", type=float, default=TrainConfig.lr)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--drop-holds",
        action="store_true",
        help="leave out the frames where the arm only holds still",
    )
    p.add_argument(
        "--state",
        choices=sorted(STATE_CHOICES),
        default="all",
        help="the state values the network sees",
    )
    p.add_argument(
        "--chunk",
        type=int,
        default=DEFAULT_CHUNK,
        metavar="K",
        help=f"predict the next K commands, a chunk [1, K, n] (1: one action [1, n]; "
        f"default {DEFAULT_CHUNK})",
    )
    p.add_argument(
        "--action",
        choices=sorted(ACTION_LAYOUTS),
        default="setpoint",
        help="what an action holds: set points and the gripper (7 values), or the whole "
        "recorded command with velocities and accelerations (19)",
    )
    p.add_argument(
        "--trainer",
        choices=["numpy", "torch"],
        default="numpy",
        help="numpy (the default: two CPU cores, minutes) or PyTorch (installed beside macrotree; "
        "the same network, loss, optimiser and export)",
    )
    p.add_argument("--device", default="cpu", help="the PyTorch device of --trainer torch")
    p.add_argument(
        "--checkpoints",
        type=int,
        nargs="+",
        default=[],
        metavar="EPOCH",
        help="also write the network after these epochs, to OUT with -eEPOCH before .onnx",
    )
    a = p.parse_args(argv)
    if not 1 <= a.epochs <= 10_000 or not all(1 <= h <= 4096 for h in a.hidden) or not 0 < a.lr < 1:
        p.error("--epochs is 1 … 10000, --hidden widths 1 … 4096, --lr in (0, 1)")
    if not 1 <= a.chunk <= 1000:
        p.error("--chunk is 1 … 1000")
    d, info = load_dataset(a.dataset, a.leaf, a.object, a.drop_holds, a.chunk, a.action)
    fps = info.get("fps")
    if not isinstance(fps, (int, float)) or fps <= 0:
        raise SystemExit(f"{a.dataset}/meta/info.json has no valid `fps`")
    cfg = TrainConfig(
        hidden=tuple(a.hidden),
        epochs=a.epochs,
        lr=a.lr,
        seed=a.seed,
        state=a.state,
        action_len=len(ACTION_LAYOUTS[a.action]),
        checkpoints=tuple(a.checkpoints),
    )
    print(
        f"{len(d.x)} frames of {len(np.unique(d.episode))} episodes from {a.dataset}",
        file=sys.stderr,
    )
    digest = dataset_digest(a.dataset)

    def save(epoch: int, mlp: Mlp, out: str) -> None:
        mlp.metadata = {
            "macrotree.action": "absolute",
            "macrotree.period": repr(1.0 / float(fps)),
            "macrotree.dataset": digest,
            "macrotree.segment": a.leaf,
            "macrotree.training": json.dumps(
                {
                    "hidden": list(cfg.hidden),
                    "epochs": epoch,
                    "lr": cfg.lr,
                    "seed": cfg.seed,
                    "state": cfg.state,
                    "drop_holds": a.drop_holds,
                    "chunk": a.chunk,
                    "action": a.action,
                    "trainer": a.trainer,
                    "frames": len(d.x),
                }
            ),
            "macrotree.inputs": "observation.state,observation.object",
        }
        write_model(mlp, out, cfg.action_len)
        print(f"wrote {out}", file=sys.stderr)

    stem, ext = os.path.splitext(a.out)

    def checkpoint(epoch: int, mlp: Mlp) -> None:
        save(epoch, mlp, f"{stem}-e{epoch}{ext or '.onnx'}")

    if a.trainer == "torch":
        from .bc_torch import train_torch

        mlp = train_torch(d, cfg, checkpoint=checkpoint, device=a.device)
    else:
        mlp = train(d, cfg, checkpoint=checkpoint)
    save(cfg.epochs, mlp, a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
