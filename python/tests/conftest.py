"""Shared fixtures: the shipped scene and tree files inside the installed package."""

from __future__ import annotations

from pathlib import Path

import pytest

import macrotree
from macrotree._library import data_dir


@pytest.fixture(scope="session")
def data() -> Path:
    return data_dir()


@pytest.fixture()
def cube_env(data: Path) -> macrotree.MacroEnv:
    return macrotree.MacroEnv(data / "scenes/cube_bowl.yaml", data / "trees/cube_to_bowl.yaml")
