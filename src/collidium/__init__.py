"""collidium: particles in a 2D vessel with exact elastic collisions, Coulomb forces, gravity,
electric and magnetic fields, drag and a thermostat.

>>> import collidium as cd
>>> sim = cd.load("gas", n=500, seed=3)
>>> sim.run(time=5.0).energy().total  # doctest: +SKIP
"""

from typing import Any

from collidium import observers
from collidium.errors import InputError, SimulationError
from collidium.forces import (
    Coulomb,
    FieldMap,
    Friction,
    Gravity,
    Langevin,
    LinearDrag,
    MagneticField,
    Newton,
    QuadraticDrag,
    UniformField,
)
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
    "FieldMap",
    "Friction",
    "Gravity",
    "InputError",
    "Langevin",
    "LinearDrag",
    "MagneticField",
    "Newton",
    "Particles",
    "Partition",
    "Polygon",
    "QuadraticDrag",
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
