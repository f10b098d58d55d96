"""Writes ``macrotree/_native.pyi``, the type stub of the native extension, from the extension
itself: maturin builds it and reads the signatures PyO3 records in it (the ``experimental-inspect``
feature), then ruff tidies the text with the package's configuration. With ``--check`` it writes
nothing and fails when the committed stub differs; the test suite runs it so.

What PyO3 does not record yet is added here: the ``MacrotreeError`` exception (PyO3 writes no stub
for an exception and marks the module incomplete instead, leaving out ``__all__``, which is
therefore written here from the stub's names), and the imports that the annotations written in
``#[pyo3(signature = ...)]`` name (``Any``, ``np``, ``NDArray``).

Usage, from any folder, with maturin and ruff on ``PATH``::

    python python/generate_stub.py [--check]
"""

from __future__ import annotations

import argparse
import ast
import difflib
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
STUB = HERE / "macrotree" / "_native.pyi"
CONFIG = HERE / "pyproject.toml"

# What PyO3 writes for a module it could not see whole: here, only because of the exception.
INCOMPLETE = "def __getattr__(name: str) -> Incomplete: ...\n"
# The class as `python/src/error.rs` makes it (its docstring is the extension's, at run time).
EXCEPTION = '''class MacrotreeError(Exception):
    kind: str
    """The error's stable kind, e.g. ``invalid_tree`` (set on every instance)."""
'''
IMPORTS = "import numpy as np\nfrom numpy.typing import NDArray\nfrom typing import Any\n"


def public_names(stub: str) -> list[str]:
    """The names a stub defines at module level (constants, functions, classes), sorted."""
    names: set[str] = set()
    for node in ast.parse(stub).body:
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.add(node.name)
    return sorted(names)


def generate(work: Path) -> str:
    """The stub as generated from the extension, fixed up and formatted."""
    subprocess.run(
        ["maturin", "generate-stubs", "--profile", "release", "--quiet", "--out", str(work)],
        cwd=HERE,
        check=True,
    )
    path = work / "macrotree" / "_native.pyi"
    text = path.read_text(encoding="utf-8")
    if INCOMPLETE not in text:
        sys.exit(
            "generate_stub.py: the generated stub no longer marks the module incomplete; "
            "PyO3 may now write the exception itself: review the fix-ups in this script"
        )
    text = text.replace(INCOMPLETE, EXCEPTION)
    lines = text.splitlines(keepends=True)
    imports = [i for i, line in enumerate(lines) if line.startswith(("from ", "import "))]
    after = imports[-1] + 1
    text = "".join([*lines[:after], IMPORTS, f"__all__ = {public_names(text)!r}\n", *lines[after:]])
    path.write_text(text, encoding="utf-8")
    # Formatted first (it wraps the long signatures the checker would refuse), then fixed
    # (imports sorted and pruned, annotations unquoted), then formatted again.
    for command in ("format", "check --fix", "format"):
        subprocess.run(
            ["ruff", *command.split(), "--quiet", "--config", str(CONFIG), str(path)], check=True
        )
    return path.read_text(encoding="utf-8")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--check", action="store_true", help="fail if the committed stub differs; write nothing"
    )
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as work:
        text = generate(Path(work))
    committed = STUB.read_text(encoding="utf-8") if STUB.exists() else ""
    if not args.check:
        if text != committed:
            STUB.write_text(text, encoding="utf-8")
        print(f"wrote {STUB}")
        return 0
    if text == committed:
        return 0
    diff = difflib.unified_diff(
        committed.splitlines(keepends=True),
        text.splitlines(keepends=True),
        "committed _native.pyi",
        "generated",
    )
    sys.stdout.writelines(diff)
    print("the stub differs from the extension: run `python python/generate_stub.py`")
    return 1


if __name__ == "__main__":
    sys.exit(main())
