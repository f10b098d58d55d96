"""Checks the LeRobot v3.0 layout of a dataset written by `macrotree sweep --dataset`, with
pyarrow (no LeRobot needed) and ffmpeg.

    PYTHONPATH=third_party/pyarrow python3 tests/dataset_layout.py DIR FFMPEG

Exits non-zero with a message on the first problem; prints a one-line summary otherwise.
Run by tests/cli/dataset.rs.
"""

import json
import pathlib
import re
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq


def fail(msg):
    print(f"FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def expect(cond, msg):
    if not cond:
        fail(msg)


def decode(ffmpeg, path):
    """(frame count, WxH, distinct frames) of a video, decoded to the end."""
    out = subprocess.run(
        [ffmpeg, "-hide_banner", "-nostdin", "-i", str(path), "-map", "0:v:0", "-f", "framemd5", "-"],
        capture_output=True,
        text=True,
    )
    expect(out.returncode == 0, f"ffmpeg cannot decode {path}: {out.stderr[-500:]}")
    m = re.search(r"Video: h264\b.*?, (\d+)x(\d+)", out.stderr)
    expect(m is not None, f"{path} is not H.264 video: {out.stderr[-500:]}")
    hashes = [line.split(",")[-1].strip() for line in out.stdout.splitlines() if line and not line.startswith("#")]
    return len(hashes), (int(m.group(1)), int(m.group(2))), len(set(hashes))


def main():
    root = pathlib.Path(sys.argv[1])
    ffmpeg = sys.argv[2]
    info = json.loads((root / "meta/info.json").read_text())
    for key in (
        "codebase_version", "robot_type", "fps", "features", "total_episodes", "total_frames", "total_tasks",
        "chunks_size", "data_files_size_in_mb", "video_files_size_in_mb", "data_path", "video_path", "splits",
    ):
        expect(key in info, f"info.json has no {key}")
    expect(info["codebase_version"] == "v3.0", f"codebase_version {info['codebase_version']}")
    fps = info["fps"]
    feats = info["features"]
    for key in ("timestamp", "frame_index", "episode_index", "index", "task_index", "observation.state", "action",
                "tree.active_leaf"):
        expect(key in feats, f"feature {key} missing")
    for f in feats.values():
        expect({"dtype", "shape", "names"} <= set(f), f"feature {f} lacks dtype/shape/names")
    videos = [k for k, f in feats.items() if f["dtype"] == "video"]

    # Tasks: pandas reads `task` back as the index.
    tasks = pq.read_table(root / "meta/tasks.parquet")
    expect(tasks.schema.pandas_metadata["index_columns"] == ["task"], "tasks.parquet index is not `task`")
    expect(tasks.column("task_index").to_pylist() == [0], "one task with index 0")
    task = tasks.column("task")[0].as_py()
    expect(info["total_tasks"] == 1, "total_tasks")

    eps = pq.read_table(sorted((root / "meta/episodes").glob("chunk-*/file-*.parquet"))[0]).to_pylist()
    expect(len(eps) == info["total_episodes"], f"{len(eps)} episode rows, total_episodes {info['total_episodes']}")
    data_files = sorted((root / "data").glob("chunk-*/file-*.parquet"))
    table = pa.concat_tables([pq.read_table(p) for p in data_files])
    expect(table.num_rows == info["total_frames"], f"{table.num_rows} rows, total_frames {info['total_frames']}")
    schema = table.schema
    for key, f in feats.items():
        if f["dtype"] == "video":
            expect(key not in schema.names, f"video feature {key} stored in the data")
            continue
        t = schema.field(key).type
        if f["dtype"] == "string":
            expect(t == pa.string(), f"{key} is {t}")
        elif f["shape"] == [1]:
            expect(str(t) == {"float32": "float", "int64": "int64"}[f["dtype"]], f"{key} is {t}")
        else:
            expect(pa.types.is_list(t) and t.value_type == pa.float32(), f"{key} is {t}")
            lens = set(len(v) for v in table.column(key).to_pylist())
            expect(lens == {f["shape"][0]}, f"{key} rows have lengths {lens}, shape {f['shape']}")
            expect(len(f["names"]) == f["shape"][0], f"{key} names")
    hf = json.loads(pq.read_metadata(data_files[0]).metadata[b"huggingface"])
    expect(set(hf["info"]["features"]) == set(schema.names), "huggingface metadata lists other columns")

    cols = table.to_pydict()
    total = 0
    for e, ep in enumerate(eps):
        expect(ep["episode_index"] == e, f"episode rows out of order at {e}")
        expect(ep["tasks"] == [task], f"episode {e} tasks {ep['tasks']}")
        lo, hi, n = ep["dataset_from_index"], ep["dataset_to_index"], ep["length"]
        expect(lo == total and hi - lo == n and n > 0, f"episode {e}: rows {lo}..{hi}, length {n}")
        expect(cols["episode_index"][lo:hi] == [e] * n, f"episode {e} rows")
        expect(cols["frame_index"][lo:hi] == list(range(n)), f"episode {e} frame_index")
        expect(cols["index"][lo:hi] == list(range(lo, hi)), f"episode {e} index")
        expect(all(abs(t - i / fps) < 1e-6 for i, t in enumerate(cols["timestamp"][lo:hi])), f"episode {e} timestamps")
        path = info["data_path"].format(chunk_index=ep["data/chunk_index"], file_index=ep["data/file_index"])
        expect((root / path).is_file(), f"episode {e}: {path} missing")
        for key in videos:
            vpath = root / info["video_path"].format(
                video_key=key, chunk_index=ep[f"videos/{key}/chunk_index"], file_index=ep[f"videos/{key}/file_index"]
            )
            expect(vpath.is_file(), f"episode {e}: {vpath} missing")
            frames, size, distinct = decode(ffmpeg, vpath)
            span = ep[f"videos/{key}/to_timestamp"] - ep[f"videos/{key}/from_timestamp"]
            expect(frames == n and abs(span - n / fps) < 1e-9, f"episode {e} {key}: {frames} frames, {span} s, {n} rows")
            h, w, _ = feats[key]["shape"]
            expect(size == (w, h), f"episode {e} {key}: {size}, feature says {w}x{h}")
            expect(distinct > n // 2, f"episode {e} {key}: only {distinct} distinct frames of {frames}")
        total = hi

    stats = json.loads((root / "meta/stats.json").read_text())
    for key, f in feats.items():
        if f["dtype"] == "string":
            continue
        expect(key in stats, f"stats.json has no {key}")
        for s in ("min", "max", "mean", "std", "count", "q01", "q50", "q99"):
            expect(s in stats[key], f"stats.json {key} has no {s}")
        expect(stats[key]["count"] == [info["total_frames"]], f"stats {key} count")
    print(
        f"layout ok: {len(eps)} episodes, {table.num_rows} frames, {len(data_files)} data file(s), "
        f"videos {videos}, task {task!r}"
    )


if __name__ == "__main__":
    main()
