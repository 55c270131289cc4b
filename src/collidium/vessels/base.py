"""What every vessel answers: the geometry that placement, the audit, the observers, the files and
the views ask for, so that none of them knows a shape."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from collidium.state import FloatArray, IntArray
from collidium.vessels.walls import WallResponse, checked_walls, response_to_dict, wall_table

#: Relative round-off allowance when deciding that a disk pokes out of a vessel.
OUTSIDE_TOLERANCE = 1e-9


class Vessel(ABC):
    """A 2D container of disks, with named walls.

    A shape is one module of this package: a subclass registered in `collidium.vessels.VESSELS`
    under its `kind`, with its fast arithmetic in a kernel file of its own. Each wall has a
    response (`collidium.vessels.walls`), specular unless the vessel's ``walls`` say otherwise.
    """

    #: Responses of the walls that are not specular, by wall name.
    walls: dict[str, WallResponse]

    def __init__(self, walls: dict[str, WallResponse] | None = None) -> None:
        """Keep the wall responses (after the shape has set what names its walls) and the
        kernels' table of them, made once: a vessel does not change."""
        self.walls = checked_walls(self.wall_names, walls)
        self._wall_table = wall_table(self.wall_names, self.walls)

    #: The shape's name in scenario files and checkpoints (``shape: box``).
    kind: ClassVar[str]
    #: The code the kernels know the shape by (`collidium.kernels.vessels`).
    shape_code: ClassVar[int]

    @property
    def periodic(self) -> bool:
        """True when positions wrap around instead of meeting walls."""
        return False

    @property
    @abstractmethod
    def wall_names(self) -> tuple[str, ...]:
        """The walls, in the order of the wall counters (`collidium.collisions.Tally`); empty
        when the vessel has none (periodic)."""

    @property
    @abstractmethod
    def bounds(self) -> FloatArray:
        """The bounding box ``[[x_min, y_min], [x_max, y_max]]`` in m, shape (2, 2)."""

    @property
    def size(self) -> FloatArray:
        """Sides of the bounding box ``(width, height)`` in m, shape (2,)."""
        low, high = self.bounds
        return high - low

    @property
    @abstractmethod
    def area(self) -> float:
        """Area enclosed, m^2."""

    @abstractmethod
    def outline(self) -> FloatArray:
        """Corners of the boundary, counter-clockwise, in m, shape (M, 2): what a view draws
        (a curved wall comes as a fine polygon)."""

    @abstractmethod
    def available_area(self, radius: float) -> float:
        """Area in m^2 that the centres of disks of ``radius`` m can reach."""

    @abstractmethod
    def contact_lengths(self, radius: float) -> FloatArray:
        """Length in m of each wall's line of contact for disks of ``radius`` m: the line their
        centres are on when they touch it, by wall (`wall_names` order), shape (W,). The wall
        pressure is the normal impulse per unit time per unit of it."""

    @abstractmethod
    def outside(self, position: FloatArray, radius: FloatArray) -> IntArray:
        """Indices of the disks not inside the vessel.

        Parameters
        ----------
        position : ndarray, shape (N, 2)
            Centres in m.
        radius : ndarray, shape (N,)
            Radii in m.

        Returns
        -------
        ndarray of int, shape (M,)
            Disks that reach past a wall by more than round-off, or whose centre is not finite.
        """

    @abstractmethod
    def check_fits(self, radius: FloatArray) -> None:
        """Refuse (`collidium.errors.InputError`) disks too large for the vessel."""

    @abstractmethod
    def describe(self) -> str:
        """The vessel in words, for messages: ``'20 x 20 box (centred on 0, 0)'``."""

    @abstractmethod
    def parameters(self) -> dict[str, Any]:
        """The constructor's parameters, plain, as in a scenario file."""

    @property
    def rim(self) -> float:
        """A circle's radius in m, for the kernels (NaN for shapes without one)."""
        return math.nan

    @abstractmethod
    def audit_limits(self, tolerance: float) -> tuple[float, float]:
        """The two limits (m) of the audit's outside test (`collidium.kernels.audit`) with a
        relative round-off allowance ``tolerance``."""

    @abstractmethod
    def free_flight(
        self,
        position: FloatArray,
        velocity: FloatArray,
        radius: FloatArray,
        mass: FloatArray,
        image: IntArray,
        dt: float,
        wall_hits: IntArray,
        wall_impulse: FloatArray,
        wall_heat: FloatArray,
    ) -> None:
        """Move every disk for ``dt`` s in straight lines, in place, responding to the walls at
        the exact times they are met (or wrapping periodically), adding each wall's hits, the
        momentum it receives (kg m/s) and the energy it gives (J) to ``wall_hits``,
        ``wall_impulse`` and ``wall_heat`` (`wall_names` order); ``image`` counts periodic
        wraps."""

    @abstractmethod
    def wall_gap(
        self,
        wall: int,
        position: FloatArray,
        velocity: FloatArray,
        acceleration: FloatArray,
        radius: float,
    ) -> Callable[[float], tuple[float, float]]:
        """How far a disk of ``radius`` m on the path ``x + v s + a s^2 / 2`` (shapes (2,), m,
        m/s, m/s^2) is from touching ``wall`` at time s: ``s -> (gap, d gap / ds)``, zero at
        contact and negative inside (in a unit of the shape's choosing), for Newton's method."""

    def wall_table(self) -> FloatArray:
        """The kernels' table of wall responses, one row per wall (`wall_names` order)."""
        return self._wall_table

    def to_dict(self) -> dict[str, Any]:
        """`parameters` with the shape's name and any wall that is not specular
        (``{"shape": kind, ..., "walls": {name: {"response": ...}}}``)."""
        walls = {name: response_to_dict(response) for name, response in self.walls.items()}
        return {"shape": self.kind, **self.parameters(), **({"walls": walls} if walls else {})}

    def wrap(self, position: FloatArray) -> FloatArray:
        """Positions mapped into the primary cell of a periodic vessel; an unchanged copy
        otherwise."""
        return np.array(position, dtype=float, copy=True)

    def minimum_image(self, displacement: FloatArray) -> FloatArray:
        """The shortest periodic image of displacements ``(..., 2)``; unchanged otherwise."""
        return displacement
