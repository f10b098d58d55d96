"""Gymnasium ids for the shipped tasks, registered when ``macrotree`` is imported.

``gymnasium.make("macrotree/CubeToBowl-v0")`` and the other ids below run a shipped scene with its
tree; ``gymnasium.make("macrotree/MacroEnv-v0", scene=PATH)`` runs any scene file. Every id has a
native ``vector_entry_point``: ``gymnasium.make_vec(id, num_envs=N)`` gives a
:class:`macrotree.VectorEnv`.
"""

from __future__ import annotations

import gymnasium as gym

from macrotree._library import data_dir

#: Gymnasium id → (scene file, tree file) under the package's data folder.
SHIPPED: dict[str, tuple[str, str]] = {
    "macrotree/CubeToBowl-v0": ("scenes/cube_bowl.yaml", "trees/cube_to_bowl.yaml"),
    "macrotree/SortByColor-v0": ("scenes/sort_three.yaml", "trees/sort_by_color.yaml"),
    "macrotree/StackThree-v0": ("scenes/stack_three.yaml", "trees/stack_three.yaml"),
    "macrotree/ClearTable-v0": ("scenes/clear_table.yaml", "trees/clear_table.yaml"),
}

#: The id that takes any scene: ``gymnasium.make("macrotree/MacroEnv-v0", scene=PATH)``.
GENERIC_ID = "macrotree/MacroEnv-v0"

ENTRY_POINT = "macrotree.env:MacroEnv"
VECTOR_ENTRY_POINT = "macrotree.vector:VectorEnv"


def register_envs() -> None:
    """Registers every id (idempotent: ids already registered are left alone)."""
    data = data_dir()
    for env_id, (scene, tree) in SHIPPED.items():
        if env_id in gym.registry:
            continue
        gym.register(
            id=env_id,
            entry_point=ENTRY_POINT,
            vector_entry_point=VECTOR_ENTRY_POINT,
            kwargs={"scene": str(data / scene), "tree": str(data / tree)},
        )
    if GENERIC_ID not in gym.registry:
        gym.register(id=GENERIC_ID, entry_point=ENTRY_POINT, vector_entry_point=VECTOR_ENTRY_POINT)
