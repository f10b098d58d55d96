"""``VectorEnv``: N cells stepped on Rust threads with the GIL released.

A ``gymnasium.vector.VectorEnv`` (registered as every id's ``vector_entry_point``) with the
autoreset modes ``SAME_STEP`` and ``DISABLED`` (TorchRL refuses ``NEXT_STEP``), deterministic
per-sub-environment seeds, and envpool-style :meth:`VectorEnv.send` / :meth:`VectorEnv.recv` that
return whichever environments finish first: macros differ widely in duration, so a batch smaller
than N keeps every core busy.
"""

from __future__ import annotations

import json
import operator
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode
from gymnasium.vector import VectorEnv as GymVectorEnv
from gymnasium.vector.utils import batch_space

from macrotree import _native
from macrotree.env import (
    ACTION_MODES,
    RESET_OPTIONS,
    ActionMode,
    Closed,
    MacroEnv,
    _base_tree,
    _check_keys,
    _noise_text,
    _path,
    action_space,
)
from macrotree.spaces import (
    macro_to_native,
    observation_space,
    with_keys,
)

#: Most sub-environments one ``VectorEnv`` takes (the extension's ``MAX_ENVS``).
MAX_ENVS: int = _native.MAX_ENVS


def _stack(items: Sequence[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in items[0].items():
        if isinstance(value, dict):
            out[key] = _stack([item[key] for item in items])
        else:
            out[key] = np.stack([np.asarray(item[key]) for item in items])
    return out


def _batch_infos(infos: Sequence[dict[str, Any] | None]) -> dict[str, Any]:
    """Gymnasium's vector info layout: each key an array over sub-environments (arrays of one
    shape stacked, e.g. ``base_action`` as ``(n, 19)``; nested dicts batched the same way), with
    a boolean mask ``_key`` saying which sub-environments gave it."""
    n = len(infos)
    out: dict[str, Any] = {}
    for i, info in enumerate(infos):
        if info is None:
            continue
        for key, value in info.items():
            if isinstance(value, dict):
                continue
            if key not in out:
                if isinstance(value, (bool, np.bool_)):
                    out[key] = np.zeros(n, dtype=bool)
                elif isinstance(value, (int, np.integer)):
                    out[key] = np.zeros(n, dtype=np.int64)
                elif isinstance(value, (float, np.floating)):
                    out[key] = np.zeros(n, dtype=np.float64)
                elif isinstance(value, np.ndarray):
                    out[key] = np.zeros((n, *value.shape), dtype=value.dtype)
                else:
                    out[key] = np.full(n, None, dtype=object)
                out[f"_{key}"] = np.zeros(n, dtype=bool)
            column = out[key]
            if column.ndim > 1 and np.shape(value) != column.shape[1:]:
                # Arrays of different shapes (per-tick rewards of steps of different lengths).
                ragged = np.full(n, None, dtype=object)
                for k in np.flatnonzero(out[f"_{key}"]):
                    ragged[k] = column[k]
                out[key] = column = ragged
            column[i] = value
            out[f"_{key}"][i] = True
    present = [info for info in infos if info is not None]
    nested = {k for info in present for k, v in info.items() if isinstance(v, dict)}
    for key in sorted(nested):
        inner: list[dict[str, Any] | None] = [
            info.get(key) if info is not None and isinstance(info.get(key), dict) else None
            for info in infos
        ]
        out[key] = _batch_infos(inner)
        out[f"_{key}"] = np.array([x is not None for x in inner], dtype=bool)
    return out


def _put_rows(dst: dict[str, Any], rows: Sequence[int], src: dict[str, Any]) -> None:
    """Writes the batch ``src`` into rows ``rows`` of the batch ``dst`` (nested dicts alike)."""
    for key, value in src.items():
        if isinstance(value, dict):
            _put_rows(dst[key], rows, value)
        else:
            dst[key][list(rows)] = value


def _mask_rows(info: dict[str, Any], keep: np.ndarray) -> dict[str, Any]:
    """The batched ``info`` with every ``_key`` mask limited to the rows of ``keep``."""
    out: dict[str, Any] = {}
    for key, value in info.items():
        if key.startswith("_"):
            out[key] = value & keep
        elif isinstance(value, dict):
            out[key] = _mask_rows(value, keep)
        else:
            out[key] = value
    return out


def _rows(batch: dict[str, Any], k: int) -> dict[str, Any]:
    """Row ``k`` of a batched observation (nested dicts alike)."""
    return {key: _rows(v, k) if isinstance(v, dict) else v[k] for key, v in batch.items()}


class VectorEnv(GymVectorEnv[dict[str, Any], Any, Any]):
    """``num_envs`` macrotree cells, stepped in parallel in Rust.

    Takes :class:`macrotree.MacroEnv`'s arguments, plus ``num_envs``, ``autoreset_mode``
    (``SAME_STEP``, the default, or ``DISABLED``) and ``threads`` (worker threads; default: one per
    core, at most ``num_envs``). Sub-environment *i* gives, bit for bit, what a single
    ``MacroEnv`` gives with the same resets and actions.
    """

    metadata: dict[str, Any] = {  # noqa: RUF012  (Gymnasium declares it so)
        "render_modes": ["rgb_array"],
        "render_fps": 30,
        "autoreset_mode": AutoresetMode.SAME_STEP,
    }

    def __init__(
        self,
        scene: str | os.PathLike[str] | None = None,
        tree: str | os.PathLike[str] | None = None,
        *,
        num_envs: int = 2,
        action_mode: ActionMode = "macro",
        base: str | os.PathLike[str] | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.SAME_STEP,
        render_mode: str | None = None,
        cameras: tuple[str, ...] | list[str] = (),
        image_size: tuple[int, int] = (240, 320),
        control_period: float = 0.01,
        max_sim_time: float = 120.0,
        fault: str | None = None,
        threads: int | None = None,
        noise: str | tuple[float, float] | None = None,
        observation_keys: str = "gym",
    ) -> None:
        try:
            count = operator.index(num_envs)
        except TypeError:
            raise ValueError(f"num_envs must be a whole number, got {num_envs!r:.40}") from None
        if not 1 <= count <= MAX_ENVS:
            raise ValueError(f"num_envs must be 1…{MAX_ENVS}, got {num_envs}")
        mode = AutoresetMode(autoreset_mode)
        if mode not in (AutoresetMode.SAME_STEP, AutoresetMode.DISABLED):
            raise ValueError(
                "autoreset_mode must be SAME_STEP or DISABLED (TorchRL refuses NEXT_STEP), "
                f"got {mode}"
            )
        tree = _base_tree(action_mode, tree, base)
        _check_keys(observation_keys)
        self.observation_keys = observation_keys
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if scene is None and tree is None:
            raise ValueError("VectorEnv needs a scene file, a tree file, or both")
        self.num_envs = count
        self.autoreset_mode = mode
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.action_mode: ActionMode = action_mode
        self.render_mode = render_mode
        self.image_size = (int(image_size[0]), int(image_size[1]))
        self._native: _native.VecEnv | Closed = _native.VecEnv(
            num_envs=self.num_envs,
            threads=threads,
            scene=_path(scene),
            tree=_path(tree),
            control_period=float(control_period),
            max_sim_time=float(max_sim_time),
            fault=fault,
            cameras=list(cameras),
            image_size=self.image_size,
            noise=_noise_text(noise),
        )
        self.object_names: list[str] = list(self._native.object_names)
        self.single_observation_space = observation_space(
            len(self.object_names), list(cameras), self.image_size, observation_keys
        )
        self.single_action_space = action_space(action_mode)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._pending: set[int] = set()
        self._rngs: list[np.random.Generator | None] = [None] * self.num_envs
        # The last observation of every sub-environment, batched (rows of those in ``_unseen``,
        # never reset, are meaningless).
        self._last_obs: dict[str, Any] | None = None
        self._last_shared = False
        self._unseen = set(range(self.num_envs))
        # The ids of every sub-environment, in order.
        self._every = list(range(self.num_envs))

    def _draw(self, i: int, seed: int | None) -> int:
        """Sub-environment *i*'s placement seed, drawn exactly as :meth:`MacroEnv.reset` draws
        it."""
        rng = self._rngs[i]
        if seed is not None or rng is None:
            rng, _ = seeding.np_random(seed)
            self._rngs[i] = rng
        return int(rng.integers(0, 2**63 - 1))

    # --- Gymnasium vector API --------------------------------------------------------------------

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Resets every sub-environment, or those of ``options["reset_mask"]``. An int seed gives
        sub-environment *i* the seed ``seed + i``; a list gives one seed each. Other options are
        :meth:`MacroEnv.reset`'s, applied to every sub-environment reset."""
        if isinstance(seed, int):
            seeds: list[int | None] = [seed + i for i in range(self.num_envs)]
        elif seed is None:
            seeds = [None] * self.num_envs
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"{len(seeds)} seeds for {self.num_envs} environments")
        super().reset(seed=seeds[0] if seed is not None else None)
        options = dict(options or {})
        unknown = sorted(set(options) - set(RESET_OPTIONS))
        if unknown:
            raise ValueError(f"unknown reset option(s) {unknown}; expected {list(RESET_OPTIONS)}")
        mask = options.pop("reset_mask", None)
        ids = (
            list(range(self.num_envs))
            if mask is None
            else [int(i) for i in np.flatnonzero(np.asarray(mask, dtype=bool))]
        )
        draws = [self._draw(i, seeds[i]) for i in ids]
        results = self._native.reset(ids=ids, seeds=draws, **options)
        return self._gather(ids, results)

    def step(
        self, actions: Any
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Steps every sub-environment with its action, in parallel. Under ``SAME_STEP`` a
        sub-environment that ended is reset in the same step; its last observation and info are in
        ``info["final_obs"]`` and ``info["final_info"]``."""
        return self._finish(
            self._native.step(self._every, self._native_actions(actions, self.num_envs))
        )

    def send(self, actions: Any, env_ids: Sequence[int] | np.ndarray | None = None) -> None:
        """Starts the actions of ``env_ids`` (default: all) on the worker threads and returns at
        once; collect the results with :meth:`recv`."""
        ids = list(range(self.num_envs)) if env_ids is None else [int(i) for i in env_ids]
        busy = self._pending.intersection(ids)
        if busy:
            raise ValueError(f"environments {sorted(busy)} are still running; recv() them first")
        self._native.send(ids, self._native_actions(actions, len(ids)))
        self._pending.update(ids)

    def recv(
        self, batch_size: int | None = None
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Waits until ``batch_size`` (default: all pending) sub-environments finished and returns
        their results; ``info["env_id"]`` says which, in the order they finished."""
        if not self._pending:
            raise ValueError("recv() with nothing sent")
        want = len(self._pending) if batch_size is None else int(batch_size)
        if not 1 <= want <= len(self._pending):
            raise ValueError(f"batch_size must be 1…{len(self._pending)}, got {batch_size}")
        try:
            batch = self._native.recv(want)
        except KeyboardInterrupt:
            # Every pending step stopped at its next control period and was collected.
            self._pending.clear()
            raise
        self._pending.difference_update(int(i) for i in batch["env_id"])
        obs, rew, term, trunc, info = self._finish(batch)
        info["env_id"] = np.asarray(batch["env_id"], dtype=np.int64)
        return obs, rew, term, trunc, info

    # --- beyond Gymnasium ------------------------------------------------------------------------

    def step_leaf(
        self,
        leaves: Mapping[str, Any] | str | Sequence[Mapping[str, Any] | str],
        env_ids: Sequence[int] | np.ndarray | None = None,
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Runs a leaf to completion on each sub-environment of ``env_ids`` (default: all), in
        parallel, as :meth:`MacroEnv.step_leaf` does: one leaf for all (a mapping such as
        ``{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}``, or its YAML/JSON text), or a
        list of one per sub-environment. Every leaf is checked before any sub-environment moves
        (a bad one raises :class:`macrotree.MacrotreeError` with a located message). Results come
        in the order of ``env_ids``, which ``info["env_id"]`` repeats; under ``SAME_STEP`` those
        that ended are reset, as in :meth:`step`."""
        ids = self._ids(env_ids)
        if isinstance(leaves, (str, Mapping)):
            items: list[Mapping[str, Any] | str] = [leaves] * len(ids)
        else:
            items = list(leaves)
            if len(items) != len(ids):
                raise ValueError(f"{len(items)} leaves for {len(ids)} environments")
        texts = [leaf if isinstance(leaf, str) else json.dumps(leaf) for leaf in items]
        return self._step_ids(ids, [("leaf", t) for t in texts])

    def step_subtree(
        self, name: str = "main", env_ids: Sequence[int] | np.ndarray | None = None
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Runs a node of the tree (a subtree call's name, a node path, or ``"main"``: the whole
        tree) until it finishes, on each sub-environment of ``env_ids`` (default: all), in
        parallel; results as :meth:`step_leaf`'s."""
        if not isinstance(name, str):
            raise TypeError(f"name must be a str, got {type(name).__name__}")
        ids = self._ids(env_ids)
        return self._step_ids(ids, [("subtree", name)] * len(ids))

    def render(self) -> tuple[np.ndarray, ...] | None:
        """One H×W×3 ``uint8`` image per sub-environment (``render_mode="rgb_array"``)."""
        if self.render_mode is None:
            return None
        h, w = self.image_size
        return tuple(self._native.render(None, h, w))

    def close_extras(self, **kwargs: Any) -> None:
        """Waits for the actions still running, then frees the cells; every later call raises
        ``RuntimeError``."""
        self._native.close()
        self._native = Closed("VectorEnv")
        self._pending.clear()

    # --- helpers ------------------------------------------------------------------------------

    def _ids(self, env_ids: Sequence[int] | np.ndarray | None) -> list[int]:
        """``env_ids`` as a list of distinct, idle sub-environment indices (default: all)."""
        every = range(self.num_envs)
        ids = list(every) if env_ids is None else [operator.index(i) for i in env_ids]
        if len(set(ids)) != len(ids) or not all(i in every for i in ids):
            raise ValueError(f"env_ids must be distinct indices 0…{self.num_envs - 1}, got {ids}")
        busy = self._pending.intersection(ids)
        if busy:
            raise ValueError(f"environments {sorted(busy)} are still running; recv() them first")
        return ids

    def _step_ids(
        self, ids: list[int], actions: list[Any]
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Steps sub-environments ``ids`` with native ``actions``; results in that order."""
        obs, rew, term, trunc, info = self._finish(self._native.step(ids, actions))
        info["env_id"] = np.asarray(ids, dtype=np.int64)
        return obs, rew, term, trunc, info

    def _native_actions(self, actions: Any, n: int) -> list[Any] | tuple[str, Any]:
        """The extension's form of a batch of ``n`` actions: ``(mode, values)`` in an array mode
        (the extension reads any real array of shape ``(n, width)`` in place and says what is
        wrong with any other), else a list of single actions."""
        if ACTION_MODES[self.action_mode] is not None:
            return (self.action_mode, actions)
        if isinstance(actions, dict):
            return [
                macro_to_native({k: np.asarray(v)[i] for k, v in actions.items()}) for i in range(n)
            ]
        items = list(actions)
        if len(items) != n:
            raise ValueError(f"{len(items)} macro actions for {n} environments")
        return [macro_to_native(a) for a in items]

    def _gather(
        self, ids: list[int], results: list[dict[str, Any]]
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """The whole batch after a (maybe partial) reset: reset sub-environments give their new
        observation and info, the others their last observation and no info."""
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        for i, r in zip(ids, results, strict=True):
            infos[i] = dict(r["info"])
        fresh = _stack([with_keys(r["obs"], self.observation_keys) for r in results])
        self._remember(ids, fresh)
        if self._unseen:
            raise ValueError(
                f"environments {sorted(self._unseen)} were never reset; reset them all first"
            )
        assert self._last_obs is not None
        return _copy(self._last_obs), _batch_infos(infos)

    def _remember(self, ids: list[int], batch: dict[str, Any]) -> None:
        """Keeps the batched observations ``batch`` of ``ids`` as their last ones: by reference
        when they are every sub-environment's (a step), else written into a private copy."""
        if ids == self._every:
            self._last_obs, self._last_shared = batch, True
            self._unseen.clear()
            return
        if self._last_obs is None:
            self._last_obs = {k: _zeros_like(v, self.num_envs) for k, v in batch.items()}
        elif self._last_shared:
            self._last_obs = _copy(self._last_obs)
        self._last_shared = False
        _put_rows(self._last_obs, ids, batch)
        self._unseen.difference_update(ids)

    def _finish(
        self, batch: dict[str, Any]
    ) -> tuple[dict[str, Any], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """A batch of step results (built by the extension) as Gymnasium returns it; under
        ``SAME_STEP`` the sub-environments that ended are reset and their rows replaced."""
        ids: list[int] = batch["env_id"]
        observations = with_keys(batch["obs"], self.observation_keys)
        # The extension gives these as float64 and bool arrays.
        rewards: np.ndarray = batch["reward"]
        terminated: np.ndarray = batch["terminated"]
        truncated: np.ndarray = batch["truncated"]
        info: dict[str, Any] = batch["info"]
        # ``ended``: whether any sub-environment terminated or was truncated (from the extension).
        if batch["ended"] and self.autoreset_mode == AutoresetMode.SAME_STEP:
            ended = [int(k) for k in np.flatnonzero(terminated | truncated)]
            # Gymnasium 1.x: ``final_obs`` an object array, ``final_info`` the ended
            # sub-environments' infos batched like any info (``final_info["is_success"]`` and its
            # mask ``final_info["_is_success"]``), each with its ``_key`` mask.
            was_ended = np.zeros(len(ids), dtype=bool)
            was_ended[ended] = True
            final_obs = np.full(len(ids), None, dtype=object)
            for k in ended:
                final_obs[k] = _rows(observations, k)
            final_info = _mask_rows(info, was_ended)
            again = self._native.reset(
                ids=[ids[k] for k in ended], seeds=[self._draw(ids[k], None) for k in ended]
            )
            observations = _copy(observations)
            _put_rows(
                observations,
                ended,
                _stack([with_keys(r["obs"], self.observation_keys) for r in again]),
            )
            # The reset sub-environments' info is their reset's.
            info = _mask_rows(info, ~was_ended)
            fresh: list[dict[str, Any] | None] = [None] * len(ids)
            for k, r in zip(ended, again, strict=True):
                fresh[k] = dict(r["info"])
            _merge_infos(info, _batch_infos(fresh))
            info["final_obs"] = final_obs
            info["final_info"] = final_info
            info["_final_obs"] = was_ended
            info["_final_info"] = was_ended.copy()
        self._remember(ids, observations)
        return observations, rewards, terminated, truncated, info


def _copy(batch: dict[str, Any]) -> dict[str, Any]:
    """A copy of a batch (nested dicts alike), so that later writes do not reach the caller's."""
    return {k: _copy(v) if isinstance(v, dict) else np.array(v) for k, v in batch.items()}


def _zeros_like(value: Any, n: int) -> Any:
    """A batch of ``n`` zero rows shaped like the batch ``value`` (nested dicts alike)."""
    if isinstance(value, dict):
        return {k: _zeros_like(v, n) for k, v in value.items()}
    array = np.asarray(value)
    return np.zeros((n, *array.shape[1:]), dtype=array.dtype)


def _merge_infos(info: dict[str, Any], rows: dict[str, Any]) -> None:
    """Writes the batched ``rows`` (with their masks) into the batched ``info``: where a row's
    mask is set, its value and mask replace ``info``'s."""
    for key, value in rows.items():
        if key.startswith("_"):
            continue
        mask = rows[f"_{key}"]
        if isinstance(value, dict):
            if key not in info:
                info[key] = value
                info[f"_{key}"] = mask.copy()
            else:
                _merge_infos(info[key], value)
                info[f"_{key}"] = info[f"_{key}"] | mask
            continue
        if key not in info:
            info[key] = value
            info[f"_{key}"] = mask.copy()
            continue
        column = info[key]
        if column.dtype != value.dtype and column.dtype != object:
            column = column.astype(object)
        column[mask] = value[mask]
        info[key] = column
        info[f"_{key}"] = info[f"_{key}"] | mask


def make_single(**kwargs: Any) -> MacroEnv:
    """A single :class:`MacroEnv` with the same arguments (for comparisons)."""
    kwargs.pop("num_envs", None)
    kwargs.pop("autoreset_mode", None)
    kwargs.pop("threads", None)
    return MacroEnv(**kwargs)
