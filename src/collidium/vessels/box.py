"""`Box`: a rectangle centred on the origin, reflecting or periodic.

The geometry lives here; the fast time-of-impact and reflection arithmetic used inside a run is in
`kernels/vessels/box.py` (for every engine), which take the half sizes this class provides.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

import numpy as np

from collidium.errors import InputError
from collidium.kernels.vessels import BOX
from collidium.kernels.vessels import box as box_walls
from collidium.state import BoolArray, FloatArray, IntArray
from collidium.vessels.base import OUTSIDE_TOLERANCE, Vessel, check_extent
from collidium.vessels.partitions import Partition
from collidium.vessels.walls import Piston, WallResponse, piston_array, wall_axis

Boundary = Literal["reflecting", "periodic"]
BOUNDARIES: tuple[Boundary, ...] = ("reflecting", "periodic")

#: The walls of a reflecting box, in the order of the wall counters.
WALLS = ("left", "right", "bottom", "top")


class Box(Vessel):
    """Rectangle ``[-width/2, width/2] x [-height/2, height/2]`` in m.

    Parameters
    ----------
    width, height : float
        Side lengths in m, > 0.
    boundary : {"reflecting", "periodic"}
        ``"reflecting"``: walls reflect disks elastically at the exact time of impact (a disk of
        radius r touches a wall when its centre is r away from it). ``"periodic"``: positions wrap,
        pairs and forces use the minimum image, unwrapped displacements are kept in
        ``Particles.image``; it has no walls.
    walls : dict of str to WallResponse, optional
        Responses of walls that are not mirrors, by name (``{"left": Thermal(2.0)}``).
    partitions : sequence of Partition, optional
        Straight walls inside (a reflecting box only).

    Notes
    -----
    One wall of a reflecting box may be a `collidium.vessels.walls.Piston`
    (``walls={"top": Piston(position=5.0, mass=10.0, force=20.0)}``): it moves along its axis
    between the box's edge behind it and the opposite wall.
    """

    kind: ClassVar[str] = "box"
    shape_code: ClassVar[int] = BOX

    def __init__(
        self,
        width: float,
        height: float,
        boundary: Boundary = "reflecting",
        walls: dict[str, WallResponse] | None = None,
        partitions: tuple[Partition, ...] | list[Partition] = (),
    ) -> None:
        self.width = check_extent(width, "vessel.width")
        self.height = check_extent(height, "vessel.height")
        if boundary not in BOUNDARIES:
            raise InputError("vessel.boundary", f"must be one of {BOUNDARIES}, got {boundary!r}")
        self.boundary: Boundary = boundary
        super().__init__(walls, partitions)

    @property
    def periodic(self) -> bool:
        """True for a periodic box."""
        return self.boundary == "periodic"

    @property
    def shape_walls(self) -> tuple[str, ...]:
        """``("left", "right", "bottom", "top")``; none in a periodic box."""
        return () if self.periodic else WALLS

    @property
    def bounds(self) -> FloatArray:
        """``[[-width/2, -height/2], [width/2, height/2]]`` in m."""
        half = 0.5 * self.size
        return np.array([-half, half])

    @property
    def size(self) -> FloatArray:
        """``(width, height)`` in m, shape (2,)."""
        return np.array([self.width, self.height])

    @property
    def area(self) -> float:
        """Area in m^2."""
        return self.width * self.height

    def outline(self) -> FloatArray:
        """The four corners, counter-clockwise from the bottom left, in m, shape (4, 2)."""
        (x0, y0), (x1, y1) = self.bounds
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])

    def _inset(self, radius: float) -> float:
        """How much shorter each side is for the centres of disks of ``radius``: 2 r with walls."""
        return 0.0 if self.periodic else 2.0 * radius

    def _open_area(self, radius: float) -> float:
        """``(width - 2 r) (height - 2 r)`` in m^2 (the whole area in a periodic box)."""
        inset = self._inset(radius)
        return (self.width - inset) * (self.height - inset)

    def _shape_contact_lengths(self, radius: float) -> FloatArray:
        """Left and right walls ``height - 2 r``, bottom and top ``width - 2 r``, in m (none in a
        periodic box)."""
        if self.periodic:
            return np.empty(0)
        inset = self._inset(radius)
        side, across = self.height - inset, self.width - inset
        return np.array([side, side, across, across])

    def _outside_shape(self, position: FloatArray, radius: FloatArray) -> BoolArray:
        """In a reflecting box, disks that reach past a wall by more than round-off; in a
        periodic box, centres outside the primary cell ``[-L/2, L/2]``."""
        half = 0.5 * self.size
        if self.periodic:
            reach = np.abs(position) - half
        else:
            reach = np.abs(position) + radius[:, None] - half
        return np.asarray((reach > OUTSIDE_TOLERANCE * half).any(axis=1))

    def check_fits(self, radius: FloatArray) -> None:
        """Refuse disks too large for the box (periodic: a diameter of at most half a side, so a
        disk never touches two images of another and the minimum image is the one in contact)."""
        if radius.size == 0:
            return
        r = float(radius.max())
        limit = min(self.width, self.height)
        if self.periodic and 4 * r > limit:
            raise InputError(
                "radius", f"diameter {2 * r} too large for a periodic box of side {limit}"
            )
        if 2 * r >= limit:
            raise InputError(
                "radius", f"diameter {2 * r} must be smaller than the box side {limit}"
            )

    def wrap(self, position: FloatArray) -> FloatArray:
        """Positions mapped into the primary cell (periodic); unchanged copy otherwise."""
        if not self.periodic:
            return position.copy()
        size = self.size
        return position - size * np.floor((position + 0.5 * size) / size)

    def minimum_image(self, displacement: FloatArray) -> FloatArray:
        """Shortest periodic image of displacements ``(..., 2)``; unchanged otherwise."""
        if not self.periodic:
            return displacement
        size = self.size
        return displacement - size * np.round(displacement / size)

    def _shape_limits(self, tolerance: float) -> tuple[float, float]:
        """The half sides with the round-off allowance, m."""
        return 0.5 * self.width * (1.0 + tolerance), 0.5 * self.height * (1.0 + tolerance)

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
        """`Vessel.free_flight`: the periodic wrap or the exact fold between mirror walls
        (`collidium.kernels.vessels.box`); hit by hit with other responses or partitions."""
        half_width, half_height = 0.5 * self.width, 0.5 * self.height
        if self.periodic:
            box_walls.drift_periodic(position, velocity, image, self.width, self.height, dt)
        elif self.walls or self.partitions:
            super().free_flight(
                position, velocity, radius, mass, image, dt, wall_hits, wall_impulse, wall_heat
            )
        else:
            box_walls.drift_reflecting(
                position, velocity, radius, mass, half_width, half_height, dt, wall_hits,
                wall_impulse,
            )  # fmt: skip

    def _check_pistons(self) -> None:
        """A piston is one of a reflecting box's walls, at most one, in a box without
        partitions, its face and any stop inside the box."""
        found = [(name, r) for name, r in self.walls.items() if isinstance(r, Piston)]
        if not found:
            return
        name, piston = found[0]
        field = f"vessel.walls.{name}"
        if len(found) > 1:
            raise InputError(f"vessel.walls.{found[1][0]}", "a box has at most one piston")
        if self.partitions:
            raise InputError(field, "a piston needs a box without partitions (it would cross them)")
        axis, sign = wall_axis(WALLS.index(name))
        half = 0.5 * float(self.size[axis])
        if not -half < sign * piston.position <= half:
            raise InputError(
                f"{field}.position",
                f"must be inside the box: in ({-half:g}, {half:g}] from its centre towards the "
                f"{name}, got {piston.position!r}",
            )
        if piston.stop is not None:
            ahead = sign * (piston.stop - piston.position) * np.sign(sign * piston.velocity)
            if not (-half <= sign * piston.stop <= half and ahead >= 0):
                raise InputError(
                    f"{field}.stop", "must be inside the box and ahead of the piston's motion"
                )

    def piston_array(self, position: float, velocity: float, now: float) -> FloatArray:
        """`Vessel.piston_array` for the box's piston."""
        if self.piston is None:
            return np.empty(0)
        wall, piston = self.piston
        half = 0.5 * float(self.size[wall // 2])
        return piston_array(wall, piston, half, position, velocity, now)

    def _chamber(self, piston_at: float | None) -> Vessel:
        """A box of the gas's side of the piston, without one (the same box without a
        piston)."""
        if self.piston is None:
            return self
        wall, piston = self.piston
        face = piston.position if piston_at is None else piston_at
        axis, sign = wall_axis(wall)
        sides = [self.width, self.height]
        sides[axis] = sign * face + 0.5 * sides[axis]
        return Box(sides[0], sides[1])

    def piston_line(self, piston_at: float | None = None) -> FloatArray:
        """`Vessel.piston_line`: across the box at the piston's face."""
        if self.piston is None:
            return np.empty((0, 2))
        wall, piston = self.piston
        face = piston.position if piston_at is None else piston_at
        axis = wall // 2
        line = np.array(self.bounds)  # [[x0, y0], [x1, y1]]: the other axis spans the box
        line[:, axis] = face
        return line

    def piston_face(self, piston_at: float | None = None) -> tuple[int, float, float, float] | None:
        """`Vessel.piston_face`: the piston's wall's axis and outward sign, its face, and the
        round-off allowance of the box's walls."""
        if self.piston is None:
            return None
        wall, piston = self.piston
        face = piston.position if piston_at is None else piston_at
        axis, sign = wall_axis(wall)
        return axis, sign, float(face), OUTSIDE_TOLERANCE * 0.5 * float(self.size.max())

    def describe(self) -> str:
        """``'20 x 10 box (centred on 0, 0)'``, with ``periodic`` when it is."""
        periodic = "periodic " if self.periodic else ""
        return f"{self.width:g} x {self.height:g} {periodic}box (centred on 0, 0)"

    def parameters(self) -> dict[str, Any]:
        """``{"width", "height", "boundary"}``, as in a scenario file (the walls apart)."""
        return {"width": self.width, "height": self.height, "boundary": self.boundary}

    def __repr__(self) -> str:
        return f"Box({self.width!r}, {self.height!r}, boundary={self.boundary!r})"
