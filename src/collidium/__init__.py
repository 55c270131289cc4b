"""collidium: particles in a 2D vessel with exact elastic collisions, Coulomb forces, gravity
and fields.

>>> import collidium as cd
>>> sim = cd.load("gas", n=500, seed=3)
>>> sim.run(time=5.0).energy().total  # doctest: +SKIP
"""

from typing import Any

from collidium import observers
from collidium.errors import InputError, SimulationError
from collidium.forces import Coulomb, Gravity, Newton, UniformField
from collidium.loading import load
from collidium.presets import presets
from collidium.simulation import Counters, Energy, Simulation, restore
from collidium.state import Particles
from collidium.vessels import Box, Circle, Partition, Polygon

__all__ = [
    "Box",
    "Circle",
    "Coulomb",
    "Counters",
    "Energy",
    "Gravity",
    "InputError",
    "Newton",
    "Particles",
    "Partition",
    "Polygon",
    "Simulation",
    "SimulationError",
    "UniformField",
    "load",
    "observers",
    "presets",
    "restore",
    "sweep",
]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    """``cd.sweep``, imported on first use (it brings pandas and Dask)."""
    if name == "sweep":
        from collidium.sweeps import sweep

        return sweep
    raise AttributeError(f"module 'collidium' has no attribute {name!r}")
