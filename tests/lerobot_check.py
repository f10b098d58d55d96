"""Loads a dataset written by `macrotree sweep --dataset` with LeRobot itself and checks it.

    python tests/lerobot_check.py DIR FRAMES_DIR

DIR is the dataset; FRAMES_DIR holds `scenario-K.jsonl` files written by
`macrotree run TREE --scenario K --fps FPS --frames FRAMES_DIR/scenario-K.jsonl` for some of
its scenarios (the dataset's episode i is scenario K per meta/macrotree.json). Exits non-zero with
a message on the first mismatch; prints a short report otherwise.

Run by tests/cli/dataset.rs when MACROTREE_LEROBOT_PYTHON names a Python with `lerobot[dataset]`
installed (see docs/datasets.md).
"""

import json
import pathlib
import sys

import numpy as np
from lerobot.datasets.lerobot_dataset import LeRobotDataset


def fail(msg):
    print(f"FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def main():
    root = pathlib.Path(sys.argv[1])
    frames_dir = pathlib.Path(sys.argv[2])
    info = json.loads((root / "meta/info.json").read_text())
    prov = json.loads((root / "meta/macrotree.json").read_text())
    ds = LeRobotDataset(repo_id="local/macrotree", root=root)
    if len(ds) != info["total_frames"]:
        fail(f"{len(ds)} frames loaded, info.json says {info['total_frames']}")
    if ds.meta.total_episodes != info["total_episodes"]:
        fail(f"{ds.meta.total_episodes} episodes loaded, info.json says {info['total_episodes']}")
    cams = [k for k, f in info["features"].items() if f["dtype"] == "video"]
    if sorted(ds.meta.video_keys) != sorted(cams):
        fail(f"video keys {ds.meta.video_keys} != {cams}")
    by_scenario = {e["scenario"]: e["episode_index"] for e in prov["episodes"]}
    checked = 0
    for path in sorted(frames_dir.glob("scenario-*.jsonl")):
        k = int(path.stem.split("-")[1])
        if k not in by_scenario:
            fail(f"scenario {k} is not in the dataset")
        ep = by_scenario[k]
        ours = [json.loads(line) for line in path.read_text().splitlines()]
        start = int(ds.meta.episodes[ep]["dataset_from_index"])
        length = int(ds.meta.episodes[ep]["length"])
        if length != len(ours):
            fail(f"episode {ep} (scenario {k}): {length} frames, run --frames wrote {len(ours)}")
        previous = {}
        for i in sorted({0, length // 3, (2 * length) // 3, length - 1}):
            item = ds[start + i]
            if int(item["episode_index"]) != ep or int(item["frame_index"]) != i:
                fail(f"item {start + i} is episode {item['episode_index']} frame {item['frame_index']}")
            for key in ("observation.state", "action", "observation.environment_state"):
                got = item[key].numpy()
                want = np.array(ours[i][key], dtype=np.float32)
                if got.shape != want.shape or not np.array_equal(got, want):
                    fail(f"episode {ep} frame {i} {key}: {got} != {want}")
            if item["tree.active_leaf"] != ours[i]["tree.active_leaf"]:
                fail(f"episode {ep} frame {i} active leaf {item['tree.active_leaf']!r} != {ours[i]['tree.active_leaf']!r}")
            if abs(float(item["timestamp"]) - ours[i]["timestamp"]) > 1e-6:
                fail(f"episode {ep} frame {i} timestamp {item['timestamp']} != {ours[i]['timestamp']}")
            if item["task"] != ds.meta.episodes[ep]["tasks"][0]:
                fail(f"task {item['task']!r}")
            for cam in cams:
                img = item[cam]
                h, w, c = info["features"][cam]["shape"]
                if tuple(img.shape) != (c, h, w):
                    fail(f"{cam} has shape {tuple(img.shape)}, expected {(c, h, w)}")
                if float(img.std()) < 0.01:
                    fail(f"{cam} frame {i} of episode {ep} is flat")
                if cam in previous and float((img - previous[cam]).abs().mean()) == 0.0:
                    fail(f"{cam}: frame {i} of episode {ep} equals an earlier one")
                previous[cam] = img
        checked += 1
    if checked == 0:
        fail(f"no scenario-K.jsonl in {frames_dir}")
    print(
        f"LeRobot {ds.meta.info.codebase_version} loaded {len(ds)} frames of {ds.meta.total_episodes} episodes "
        f"(cameras: {', '.join(cams) or 'none'}); {checked} episodes match run --frames; "
        f"task: {ds.meta.episodes[0]['tasks'][0]!r}"
    )


if __name__ == "__main__":
    main()
