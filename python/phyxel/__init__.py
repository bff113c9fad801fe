"""Phyxel from Python: the simulation of `phyxel run`, advanced step by step.

    import phyxel
    sim = phyxel.Simulation("scenes/probe_indent.json", device="cpu")
    sim.advance(100)
    print(sim.time, sim.tool_force("probe"))

docs/python.md documents every class and function.
"""

from ._core import (
    CONTACT,
    FIXED,
    REMOVED,
    SURFACE,
    CheckpointError,
    SceneError,
    Simulation,
    SimulationError,
    VideoWriter,
    VulkanError,
)
from . import tasks

__all__ = [
    "CONTACT",
    "FIXED",
    "REMOVED",
    "SURFACE",
    "CheckpointError",
    "SceneError",
    "Simulation",
    "SimulationError",
    "VideoWriter",
    "VulkanError",
    "tasks",
]
