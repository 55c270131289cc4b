"""`Circle`: a circular vessel centred on the origin, with one wall, its rim.

The rim's arithmetic used inside a run (time to the rim, contact point, reflection, the audit's
outside test) is in `kernels/vessels/circle.py`. Angular momentum about the centre is conserved
by the rim (`collidium.simulation.Simulation.angular_momentum`).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.kernels.vessels import CIRCLE
from collidium.state import BoolArray, FloatArray
from collidium.vessels.base import OUTSIDE_TOLERANCE, Vessel, check_extent
from collidium.vessels.partitions import Partition
from collidium.vessels.walls import WallResponse

#: Corners of the polygon that stands for the rim in drawings.
OUTLINE_CORNERS = 256


class Circle(Vessel):
    """The disk ``x^2 + y^2 <= radius^2`` (m), with reflecting walls.

    Parameters
    ----------
    radius : float
        The vessel's radius in m, > 0. A disk of radius r touches the rim when its centre is
        ``radius - r`` from the origin.
    walls : dict of str to WallResponse, optional
        The rim's response if it is not a mirror (``{"rim": Inelastic(0.9)}``).
    partitions : sequence of Partition, optional
        Straight walls inside.
    """

    kind: ClassVar[str] = "circle"
    shape_code: ClassVar[int] = CIRCLE

    def __init__(
        self,
        radius: float,
        walls: dict[str, WallResponse] | None = None,
        partitions: tuple[Partition, ...] | list[Partition] = (),
    ) -> None:
        self.radius = check_extent(radius, "vessel.radius")
        super().__init__(walls, partitions)

    @property
    def shape_walls(self) -> tuple[str, ...]:
        """``("rim",)``."""
        return ("rim",)

    @property
    def bounds(self) -> FloatArray:
        """``[[-radius, -radius], [radius, radius]]`` in m."""
        return np.array([[-self.radius, -self.radius], [self.radius, self.radius]])

    @property
    def area(self) -> float:
        """``pi radius^2`` in m^2."""
        return math.pi * self.radius**2

    def outline(self) -> FloatArray:
        """`OUTLINE_CORNERS` points of the rim, counter-clockwise from (radius, 0)."""
        angle = np.linspace(0.0, 2.0 * math.pi, OUTLINE_CORNERS, endpoint=False)
        return self.radius * np.column_stack([np.cos(angle), np.sin(angle)])

    def _open_area(self, radius: float) -> float:
        """``pi (R - r)^2`` in m^2: the circle the centres of disks of radius r move in."""
        return math.pi * (self.radius - radius) ** 2

    def _shape_contact_lengths(self, radius: float) -> FloatArray:
        """The rim's line of contact, ``2 pi (R - r)`` in m, shape (1,)."""
        return np.array([2.0 * math.pi * (self.radius - radius)])

    def _outside_shape(self, position: FloatArray, radius: FloatArray) -> BoolArray:
        """Disks whose rim passes the vessel's by more than round-off."""
        reach = np.hypot(position[:, 0], position[:, 1]) + radius
        return np.asarray(reach > self.radius * (1.0 + OUTSIDE_TOLERANCE))

    def check_fits(self, radius: FloatArray) -> None:
        """Refuse disks whose diameter is not smaller than the vessel's radius (they would have
        no room to move)."""
        if radius.size and 2.0 * float(radius.max()) >= self.radius:
            raise InputError(
                "radius",
                f"diameter {2.0 * float(radius.max())} must be smaller than the vessel's "
                f"radius {self.radius}",
            )

    @property
    def rim(self) -> float:
        """The vessel's radius, m."""
        return self.radius

    def _shape_limits(self, tolerance: float) -> tuple[float, float]:
        """The radius with the round-off allowance, twice (m)."""
        limit = self.radius * (1.0 + tolerance)
        return limit, limit

    def describe(self) -> str:
        """``'circle of radius 10 m (centred on 0, 0)'``."""
        return f"circle of radius {self.radius:g} m (centred on 0, 0)"

    def parameters(self) -> dict[str, Any]:
        """``{"radius"}``, as in a scenario file (the walls apart)."""
        return {"radius": self.radius}

    def __repr__(self) -> str:
        return f"Circle({self.radius!r})"
