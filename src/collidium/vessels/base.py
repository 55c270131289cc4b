"""What every vessel answers: the geometry that placement, the audit, the observers, the files and
the views ask for, so that none of them knows a shape."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.kernels.vessels import contacts
from collidium.kernels.vessels import segments as segment_kernels
from collidium.state import BoolArray, FloatArray, IntArray
from collidium.vessels.partitions import Partition, distances
from collidium.vessels.walls import (
    Piston,
    WallResponse,
    checked_walls,
    response_to_dict,
    wall_table,
)

#: Relative round-off allowance when deciding that a disk pokes out of a vessel.
OUTSIDE_TOLERANCE = 1e-9

#: Largest extent of a vessel, m: float64 positions still resolve 0.1 mm across it, and its
#: area and cell counts stay far from overflowing.
MAX_EXTENT = 1e12


def check_extent(value: float, field: str) -> float:
    """``value`` (m) as a float, or `InputError` naming ``field`` unless finite, > 0 and at most
    `MAX_EXTENT`."""
    if not (isinstance(value, int | float | np.floating | np.integer) and math.isfinite(value)
            and 0 < value <= MAX_EXTENT):  # fmt: skip
        raise InputError(field, f"must be a finite number > 0 and at most {MAX_EXTENT:g} m, got "
                                f"{value!r}")  # fmt: skip
    return float(value)


class Vessel(ABC):
    """A 2D container of disks, with named walls.

    A shape is one module of this package: a subclass registered in `collidium.vessels.VESSELS`
    under its `kind`, with its fast arithmetic in a kernel file of its own. Any vessel may hold
    partitions (`collidium.vessels.partitions`), walls of their own after the shape's. Each wall
    has a response (`collidium.vessels.walls`), specular unless the vessel's ``walls`` say
    otherwise.
    """

    #: Responses of the walls that are not specular, by wall name.
    walls: dict[str, WallResponse]
    #: Straight walls inside the vessel.
    partitions: tuple[Partition, ...]

    def __init__(
        self,
        walls: dict[str, WallResponse] | None = None,
        partitions: tuple[Partition, ...] | list[Partition] = (),
    ) -> None:
        """Keep the partitions and wall responses (after the shape has set its size) and the
        kernels' tables, made once: a vessel does not change."""
        self._extent = 2.0 * np.max(np.abs(self.bounds), axis=0)
        self._extent.flags.writeable = False
        self.partitions = tuple(partitions)
        self._check_partitions()
        self.walls = checked_walls(self.wall_names, walls)
        self._check_pistons()
        self._wall_table = wall_table(self.wall_names, self.walls)
        own = len(self.shape_walls)
        inner = [partition.segments(own + j) for j, partition in enumerate(self.partitions)]
        self._segments = np.concatenate([self._shape_segments(), *inner])

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
    def shape_walls(self) -> tuple[str, ...]:
        """The shape's own walls, in the order of its kernels; empty when it has none
        (periodic)."""

    @property
    def wall_names(self) -> tuple[str, ...]:
        """The walls, in the order of the wall counters (`collidium.collisions.Tally`): the
        shape's, then the partitions'."""
        return self.shape_walls + tuple(partition.name for partition in self.partitions)

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
    def extent(self) -> FloatArray:
        """Sides ``(width, height)`` in m of the smallest box centred on the origin that holds
        the vessel, shape (2,): what the engines' cell grids cover (made once: a vessel does
        not change)."""
        return self._extent

    @property
    @abstractmethod
    def area(self) -> float:
        """Area enclosed, m^2."""

    @abstractmethod
    def outline(self) -> FloatArray:
        """Corners of the boundary, counter-clockwise, in m, shape (M, 2): what a view draws
        (a curved wall comes as a fine polygon)."""

    def fill(self) -> FloatArray:
        """Triangles that fill the outline, shape (T, 3, 2) in m: what a view paints (any simple
        outline, convex or not; ear clipping)."""
        return ear_clipped(self.outline())

    def partition(self, name: str) -> Partition:
        """The partition called ``name``.

        Raises
        ------
        InputError
            ``partition`` when there is none of that name.
        """
        for partition in self.partitions:
            if partition.name == name:
                return partition
        names = ", ".join(p.name for p in self.partitions) or "none"
        raise InputError("partition", f"the vessel has no partition {name!r} (it has: {names})")

    def partition_lines(self) -> FloatArray:
        """The partitions' pieces as drawn, ``[[start, end], ...]`` in m, shape (P, 2, 2)."""
        pieces = [partition.pieces() for partition in self.partitions]
        return np.concatenate(pieces) if pieces else np.empty((0, 2, 2))

    def segments(self) -> FloatArray:
        """The kernels' segment table (`collidium.kernels.vessels.segments`): a polygon's edges
        and reflex corners, then the partitions' pieces and their ends."""
        return self._segments

    def _shape_segments(self) -> FloatArray:
        """Rows of the segment table that the shape itself needs (a polygon's edges and
        corners); none by default."""
        return np.empty((0, segment_kernels.SEGMENT_COLUMNS))

    def available_area(self, radius: float, piston_at: float | None = None) -> float:
        """Area in m^2 that the centres of disks of ``radius`` m can reach: the shape's, less
        the partitions' (`Partition.excluded_area`); with a piston, on the gas's side of its
        face at ``piston_at`` (m along its axis; default: where it starts)."""
        blocked = sum(partition.excluded_area(radius) for partition in self.partitions)
        return self._chamber(piston_at)._open_area(radius) - blocked

    def _chamber(self, piston_at: float | None) -> Vessel:
        """The vessel the gas has with the piston's face at ``piston_at``: itself, without a
        piston."""
        return self

    @abstractmethod
    def _open_area(self, radius: float) -> float:
        """Area in m^2 that the centres of disks of ``radius`` m can reach in the shape."""

    def contact_lengths(self, radius: float, piston_at: float | None = None) -> FloatArray:
        """Length in m of each wall's line of contact for disks of ``radius`` m: the line their
        centres are on when they touch it, by wall (`wall_names` order), shape (W,). The wall
        pressure is the normal impulse per unit time per unit of it. With a piston, its face
        is at ``piston_at`` (m along its axis; default: where it starts)."""
        inner = [partition.contact_length(radius) for partition in self.partitions]
        return np.concatenate([self._chamber(piston_at)._shape_contact_lengths(radius), inner])

    @abstractmethod
    def _shape_contact_lengths(self, radius: float) -> FloatArray:
        """`contact_lengths` of the shape's own walls, shape (len(shape_walls),)."""

    def outside(
        self, position: FloatArray, radius: FloatArray, piston_at: float | None = None
    ) -> IntArray:
        """Indices of the disks not inside the vessel.

        Parameters
        ----------
        position : ndarray, shape (N, 2)
            Centres in m.
        radius : ndarray, shape (N,)
            Radii in m.
        piston_at : float, optional
            Where the piston's face is now (m, along its axis); default: where it starts.

        Returns
        -------
        ndarray of int, shape (M,)
            Disks that reach past a wall (the piston's face included) or closer to a partition
            than their radius by more than round-off, or whose centre is not finite.
        """
        position = np.asarray(position, dtype=float)
        bad = self._outside_shape(position, radius) | ~np.isfinite(position).all(axis=1)
        bad |= self._past_piston(position, radius, piston_at)
        if len(self.partitions) and len(position):
            table = self._segments[self._segments[:, segment_kernels.BOUNDARY] == 0.0]
            near = distances(np.nan_to_num(position), table).min(axis=1)
            bad |= near < radius - self._slack
        return np.flatnonzero(bad).astype(np.int64)

    def _past_piston(
        self, position: FloatArray, radius: FloatArray, piston_at: float | None
    ) -> BoolArray:
        """Which disks reach past the piston's face at ``piston_at`` (m) by more than round-off
        (`piston_face`), shape (N,); none without a piston."""
        face = self.piston_face(piston_at)
        if face is None:
            return np.zeros(len(position), dtype=bool)
        axis, sign, at, allowance = face
        return np.asarray(sign * (position[:, axis] - at) + radius > allowance)

    def piston_face(self, piston_at: float | None = None) -> tuple[int, float, float, float] | None:
        """The piston's face as the audit tests it (`collidium.kernels.audit.first_past_face`):
        ``(axis, sign, face, allowance)``, a disk being past it when ``sign (x[axis] - face) +
        r`` exceeds the allowance (m); its face at ``piston_at`` (m along its axis; default:
        where it starts). None without a piston."""
        return None

    @abstractmethod
    def _outside_shape(self, position: FloatArray, radius: FloatArray) -> BoolArray:
        """Which disks reach past the shape's walls by more than round-off, shape (N,)."""

    @property
    def _slack(self) -> float:
        """Round-off allowance in m for contacts with segments."""
        return OUTSIDE_TOLERANCE * float(self.extent.max())

    def _check_partitions(self) -> None:
        """Refuse partitions with the name of another wall, in a vessel without walls, or not
        inside the vessel along their whole length."""
        if not self.partitions:
            return
        if self.periodic:
            raise InputError("vessel.partitions", "a periodic box has no walls to hold them")
        names = list(self.shape_walls)
        for partition in self.partitions:
            field = f"vessel.partitions.{partition.name}"
            if partition.name in names:
                raise InputError(field, f"the name {partition.name!r} is already a wall's")
            names.append(partition.name)
            along = np.linspace(0.0, 1.0, 65)[:, None]
            points = np.array(partition.start) + along * np.subtract(partition.end, partition.start)
            if self._outside_shape(points, np.zeros(len(points))).any():
                raise InputError(field, f"must lie inside the {self.describe()}")

    @property
    def piston(self) -> tuple[int, Piston] | None:
        """The wall that is a piston, as ``(index in wall_names, Piston)``, or None."""
        for index, name in enumerate(self.wall_names):
            response = self.walls.get(name)
            if isinstance(response, Piston):
                return index, response
        return None

    def _check_pistons(self) -> None:
        """Refuse pistons where the shape has none (`collidium.vessels.box.Box` has them)."""
        for name, response in self.walls.items():
            if isinstance(response, Piston):
                raise InputError(
                    f"vessel.walls.{name}", "a piston is one of a reflecting box's four walls"
                )

    def piston_line(self, piston_at: float | None = None) -> FloatArray:
        """The piston's face as drawn, ``[start, end]`` in m, shape (2, 2), with it at
        ``piston_at`` (m along its axis; default: where it starts); shape (0, 2) without one."""
        return np.empty((0, 2))

    def piston_array(self, position: float, velocity: float, now: float) -> FloatArray:
        """The exact engine's piston (`collidium.kernels.vessels.piston`) with its face at
        ``position`` (m) moving at ``velocity`` (m/s) along its axis at time ``now`` (s);
        empty for a vessel without one."""
        return np.empty(0)

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

    def audit_arguments(self) -> tuple[int, float, float, float, bool]:
        """What the audit (`collidium.kernels.audit.first_invalid`) takes of the vessel before
        its segments: the shape code, the limits (m) of the outside test with a relative
        round-off allowance of `OUTSIDE_TOLERANCE` (the shape's two, `_shape_limits`, and the
        allowance for segments), and whether it is periodic."""
        tolerance = OUTSIDE_TOLERANCE
        limits = *self._shape_limits(tolerance), tolerance * float(self.extent.max())
        return self.shape_code, *limits, self.periodic

    @abstractmethod
    def _shape_limits(self, tolerance: float) -> tuple[float, float]:
        """The shape's two limits of the audit's outside test (m), allowance included."""

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
        wraps. Hit by hit here (`collidium.kernels.vessels.contacts`); a shape may do better."""
        half_width, half_height = 0.5 * self.extent
        contacts.drift_responding(
            position, velocity, radius, mass, dt, self.shape_code, half_width, half_height,
            self.rim, self._segments, self._wall_table, wall_hits, wall_impulse, wall_heat,
        )  # fmt: skip

    def wall_table(self) -> FloatArray:
        """The kernels' table of wall responses, one row per wall (`wall_names` order)."""
        return self._wall_table

    def to_dict(self) -> dict[str, Any]:
        """`parameters` with the shape's name, any partition and any wall that is not
        specular (``{"shape": kind, ..., "partitions": [...], "walls": {name: {...}}}``)."""
        out = {"shape": self.kind, **self.parameters()}
        if self.partitions:
            out["partitions"] = [partition.to_dict() for partition in self.partitions]
        walls = {name: response_to_dict(response) for name, response in self.walls.items()}
        return out | ({"walls": walls} if walls else {})

    def with_walls(self, responses: dict[str, WallResponse]) -> Vessel:
        """The same vessel with the walls named in ``responses`` given those responses (a
        ``Specular()`` makes one a mirror again); the others keep theirs."""
        return type(self)(**self.parameters(), walls=self.walls | responses,
                          partitions=self.partitions)  # fmt: skip

    def wrap(self, position: FloatArray) -> FloatArray:
        """Positions mapped into the primary cell of a periodic vessel; an unchanged copy
        otherwise."""
        return np.array(position, dtype=float, copy=True)

    def minimum_image(self, displacement: FloatArray) -> FloatArray:
        """The shortest periodic image of displacements ``(..., 2)``; unchanged otherwise."""
        return displacement


def ear_clipped(outline: FloatArray) -> FloatArray:
    """Triangles, shape (M - 2, 3, 2), that fill a simple polygon whose M corners are given
    counter-clockwise: clip a convex corner with no other corner inside its triangle, repeat."""
    corners = np.asarray(outline, dtype=float)
    before, after = np.roll(corners, 1, axis=0), np.roll(corners, -1, axis=0)
    turns = (corners - before)[:, 0] * (after - corners)[:, 1] - (corners - before)[:, 1] * (
        after - corners
    )[:, 0]
    if (turns > 0).all():  # convex: a fan from the first corner
        count = len(corners)
        return np.stack([np.repeat(corners[:1], count - 2, axis=0), corners[1:-1], corners[2:]], 1)
    left = list(range(len(corners)))
    triangles = []

    def turn(a: FloatArray, b: FloatArray, c: FloatArray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    while len(left) > 3:
        for k in range(len(left)):
            ear = [left[(k + step) % len(left)] for step in (-1, 0, 1)]
            a, b, c = corners[ear]
            if turn(a, b, c) <= 0.0:
                continue  # a reflex or straight corner is no ear
            others = (corners[p] for p in left if p not in ear)
            if any(turn(a, b, p) >= 0 and turn(b, c, p) >= 0 and turn(c, a, p) >= 0
                   for p in others):  # fmt: skip
                continue
            triangles.append((a, b, c))
            del left[k]
            break
        else:  # only round-off leaves no ear: fan out what is left
            break
    first = corners[left[0]]
    triangles += [(first, corners[left[k]], corners[left[k + 1]]) for k in range(1, len(left) - 1)]
    return np.array(triangles)
