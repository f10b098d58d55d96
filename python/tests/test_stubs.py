"""The type stub of the extension (``macrotree/_native.pyi``, generated from the extension by
``python/generate_stub.py``) holds to the extension as it runs: mypy's own ``stubtest`` compares
every name, class, method, property and parameter of the stub with the compiled module."""

from __future__ import annotations

import subprocess
import sys


def test_mypy_stubtest_finds_the_stub_true_to_the_extension() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "macrotree._native"],
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert out.returncode == 0, out.stdout + out.stderr
