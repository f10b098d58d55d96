"""MP4 (H.264) files from frames, through the pinned ffmpeg macrotree uses for ``run --video``.

ffmpeg is the checkout's ``third_party/ffmpeg/ffmpeg`` (filled by ``tools/bootstrap``), or the one
``MACROTREE_FFMPEG`` names (e.g. the binary of the ``imageio-ffmpeg`` wheel).
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from macrotree import _native


def write_mp4(path: str | os.PathLike[str], frames: Sequence[np.ndarray], fps: int = 30) -> int:
    """Writes ``frames`` (each H×W×3 ``uint8``, all one size) to ``path``; returns the frame count.
    The file is written through an exclusive temporary file and renamed into place."""
    if not frames:
        raise ValueError("no frames to write")
    first = np.asarray(frames[0])
    if first.dtype != np.uint8 or first.ndim != 3 or first.shape[2] != 3:
        raise ValueError(f"frames must be H×W×3 uint8, got {first.shape} {first.dtype}")
    h, w = int(first.shape[0]), int(first.shape[1])
    arrays = [np.ascontiguousarray(f) for f in frames]
    for array in arrays:
        if array.shape != (h, w, 3) or array.dtype != np.uint8:
            raise ValueError(
                f"every frame must be {h}×{w}×3 uint8, got {array.shape} {array.dtype}"
            )
    return int(_native.write_mp4(os.fspath(path), arrays, int(fps)))
