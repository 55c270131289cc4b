"""The wall a viewer's user may drag to change the volume: a box's piston, or one of its mirror
walls, moved as a driven piston (`collidium.vessels.walls.Piston`) so that the work it does on
the gas is counted as that wall's heat.

Only a reflecting box in the exact engine without forces has one (that is where a piston can
be); its travel stops short of squeezing the gas past `MAX_PACKING`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from collidium.simulation import Simulation
from collidium.vessels import Box, Vessel
from collidium.vessels.walls import Piston, Specular, wall_axis

#: Densest the gas may be squeezed by dragging: the fraction of the gas's side of the box that
#: its disks cover (hard disks jam near 0.82).
MAX_PACKING = 0.6
#: A dragged wall moves at this fraction of the gas's rms speed: slow enough that a compression
#: stays close to the adiabat (T A = const for a dilute 2D gas), fast enough to watch.
SPEED_FRACTION = 0.2
#: Which wall of a box without a piston is offered, first that is a mirror (the hatch the pump
#: uses is on the left wall).
PREFERRED_WALLS = ("right", "top", "bottom", "left")


@dataclass(frozen=True)
class MovableWall:
    """A box wall the user may drag along its normal.

    Attributes
    ----------
    wall : int
        Index of the wall (0 left, 1 right, 2 bottom, 3 top).
    name : str
        Its name.
    rest : float
        Where its face is before any drag, m, a coordinate along its axis.
    low, high : float
        The range its face may be dragged over, m (the gas keeps room for its disks).
    piston : Piston or None
        The box's own piston (free), or None for a mirror wall.
    """

    wall: int
    name: str
    rest: float
    low: float
    high: float
    piston: Piston | None

    @property
    def axis(self) -> int:
        """0: the face moves along x; 1: along y."""
        return wall_axis(self.wall)[0]

    def to_dict(self) -> dict[str, Any]:
        """As the viewer's scene message sends it."""
        return {"name": self.name, "axis": self.axis, "rest": self.rest, "low": self.low,
                "high": self.high}  # fmt: skip

    def clip(self, to: float) -> float:
        """``to`` (m) kept within the range the face may be dragged over."""
        return min(max(to, self.low), self.high)

    def driven(self, at: float, to: float, speed: float) -> Piston:
        """A piston whose face is at ``at`` (m) and moves at ``speed`` (m/s) towards ``to`` (m,
        within `clip`'s range), stopping there; at rest if already there."""
        restitution = 1.0 if self.piston is None else self.piston.restitution
        if to == at or speed <= 0.0:
            return Piston(position=at, driven=True, restitution=restitution)
        velocity = math.copysign(speed, to - at)
        return Piston(position=at, driven=True, velocity=velocity, stop=to,
                      restitution=restitution)  # fmt: skip


def movable_wall(sim: Simulation, vessel: Vessel) -> MovableWall | None:
    """The wall of ``vessel`` (the simulation's own, before any hold or drag) that the user may
    drag, or None: only a reflecting box without partitions in the exact engine, without forces,
    has one."""
    if not isinstance(vessel, Box) or vessel.periodic or vessel.partitions:
        return None
    if sim.forces or sim.collisions != "exact":
        return None
    if vessel.piston is not None:
        wall, piston = vessel.piston
        return _travel(vessel, sim, wall, piston)
    for name in PREFERRED_WALLS:
        if isinstance(vessel.walls.get(name, Specular()), Specular):
            return _travel(vessel, sim, vessel.wall_names.index(name), None)
    return None


def _travel(vessel: Box, sim: Simulation, wall: int, piston: Piston | None) -> MovableWall:
    """The wall with its range: from the box's edge inwards until the gas's disks would cover
    `MAX_PACKING` of its side (or be squeezed below two diameters across)."""
    axis, sign = wall_axis(wall)
    half = 0.5 * float(vessel.size[axis])
    across = float(vessel.size[1 - axis])
    radius = sim.particles.radius
    covered = float(np.sum(np.pi * radius**2)) / (MAX_PACKING * across)
    shortest = min(max(covered, 4.0 * float(radius.max(initial=0.0))), 2.0 * half)
    state = sim.piston()
    if state is not None:  # the gas may already be denser than that: it keeps its room
        shortest = min(shortest, sign * state.position + half)
    near, far = sign * (shortest - half), sign * half
    return MovableWall(wall, vessel.wall_names[wall], sign * half, min(near, far), max(near, far),
                       piston)  # fmt: skip
