"""Partitions: straight walls inside any vessel, each a named wall with its own response, with an
optional gap (two chambers joined by a hole). Also the segment table the kernels take
(`collidium.kernels.vessels.segments`), which polygons build their edges and corners with too."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from collidium.errors import InputError
from collidium.kernels.vessels import segments as segment_kernels
from collidium.state import FloatArray


@dataclass(frozen=True)
class Partition:
    """A straight wall from ``start`` to ``end`` (m) inside a vessel, that disks meet on either
    side and at its ends.

    Parameters
    ----------
    name : str
        The wall's name (its counters, pressure and response go by it).
    start, end : tuple of float
        Its ends, (x, y) in m, inside the vessel (on its walls at most).
    gap : float
        Width in m of a hole in it, 0 for none; the hole is centred at ``gap_at``.
    gap_at : float
        Where along the partition the hole's centre is, as a fraction of its length (0 to 1).
    """

    name: str
    start: tuple[float, float]
    end: tuple[float, float]
    gap: float = 0.0
    gap_at: float = 0.5

    def __post_init__(self) -> None:
        field = f"vessel.partitions.{self.name}"
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise InputError("vessel.partitions.name", f"must be a name, got {self.name!r}")
        for key in ("start", "end"):
            point = getattr(self, key)
            if not (
                isinstance(point, list | tuple)
                and len(point) == 2
                and all(isinstance(v, int | float) and math.isfinite(v) for v in point)
            ):
                raise InputError(f"{field}.{key}", f"must be two finite numbers, got {point!r}")
            object.__setattr__(self, key, (float(point[0]), float(point[1])))
        if self.length == 0.0:
            raise InputError(field, "start and end must differ")
        if not (isinstance(self.gap, int | float) and 0.0 <= self.gap < self.length):
            raise InputError(
                f"{field}.gap", f"must be >= 0 and shorter than the partition, got {self.gap!r}"
            )
        if not (isinstance(self.gap_at, int | float) and 0.0 <= self.gap_at <= 1.0):
            raise InputError(f"{field}.gap_at", f"must be in [0, 1], got {self.gap_at!r}")
        half = 0.5 * self.gap / self.length
        if self.gap > 0 and (self.gap_at - half < 0.0 or self.gap_at + half > 1.0):
            raise InputError(f"{field}.gap", "the hole must lie within the partition")

    @property
    def length(self) -> float:
        """Length in m, hole included."""
        return math.dist(self.start, self.end)

    def pieces(self) -> FloatArray:
        """The wall that stands, ``[[start, end], ...]`` in m, shape (P, 2, 2): one piece, or two
        on either side of the hole."""
        a, b = np.array(self.start), np.array(self.end)
        if self.gap == 0.0:
            return np.array([[a, b]])
        half = 0.5 * self.gap / self.length
        return np.array([[a, a + (b - a) * (self.gap_at - half)],
                         [a + (b - a) * (self.gap_at + half), b]])  # fmt: skip

    def piece_lengths(self) -> FloatArray:
        """Length in m of each piece that stands, shape (P,)."""
        pieces = self.pieces()
        return np.asarray(np.linalg.norm(pieces[:, 1] - pieces[:, 0], axis=1))

    def segments(self, wall: int) -> FloatArray:
        """Its rows of the kernels' segment table, as wall ``wall``: each piece, then each
        piece's two ends (points, where disks meet a free end)."""
        pieces = self.pieces()
        ends = pieces.reshape(-1, 2)
        return np.concatenate([segment_table(pieces[:, 0], pieces[:, 1], wall, boundary=False),
                               segment_table(ends, ends, wall, boundary=False)])  # fmt: skip

    def excluded_area(self, radius: float) -> float:
        """Area (m^2) that the centres of disks of ``radius`` m cannot reach because of it: a
        capsule around each piece (exact where the pieces stand free of other walls)."""
        return float(np.sum(2.0 * radius * self.piece_lengths() + math.pi * radius**2))

    def contact_length(self, radius: float) -> float:
        """Length (m) of the line the centres of touching disks are on: both sides of each
        piece and the half circles around its ends."""
        return float(np.sum(2.0 * self.piece_lengths() + 2.0 * math.pi * radius))

    def to_dict(self) -> dict[str, Any]:
        """As in a scenario file's ``[[vessel.partitions]]`` table."""
        out: dict[str, Any] = {"name": self.name, "start": list(self.start), "end": list(self.end)}
        if self.gap > 0:
            out |= {"gap": self.gap, "gap_at": self.gap_at}
        return out


def partition_from_dict(data: Any, index: int) -> Partition:
    """The partition of a scenario or checkpoint table (`Partition.to_dict`)."""
    if not isinstance(data, dict):
        raise InputError(f"vessel.partitions[{index}]", f"must be a table, got {data!r}")
    unknown = set(data) - {"name", "start", "end", "gap", "gap_at"}
    if unknown:
        raise InputError(f"vessel.partitions[{index}]", f"unknown key(s) {sorted(unknown)}")
    for key in ("name", "start", "end"):
        if key not in data:
            raise InputError(f"vessel.partitions[{index}].{key}", "is required")
    return Partition(**data)


def segment_table(starts: FloatArray, ends: FloatArray, walls: Any, boundary: bool) -> FloatArray:
    """Rows of the kernels' segment table for segments from ``starts`` to ``ends`` ((S, 2), m; a
    point where they are equal), belonging to walls ``walls`` (S,), all edges of the boundary or
    none."""
    starts, ends = np.atleast_2d(starts), np.atleast_2d(ends)
    table = np.zeros((len(starts), segment_kernels.SEGMENT_COLUMNS))
    s = segment_kernels
    table[:, [s.X0, s.Y0]] = starts
    table[:, [s.X1, s.Y1]] = ends
    length = np.linalg.norm(ends - starts, axis=1)
    table[:, s.LENGTH] = length
    with np.errstate(invalid="ignore", divide="ignore"):
        tangent = np.where(length[:, None] > 0, (ends - starts) / length[:, None], 0.0)
    table[:, [s.TX, s.TY]] = tangent
    table[:, s.WALL] = walls
    table[:, s.BOUNDARY] = 1.0 if boundary else 0.0
    return table


def distances(points: FloatArray, table: FloatArray) -> FloatArray:
    """Distance in m from each point (N, 2) to each segment of a table, shape (N, S)."""
    s = segment_kernels
    start = table[:, [s.X0, s.Y0]]
    tangent = table[:, [s.TX, s.TY]]
    offset = points[:, None, :] - start[None, :, :]
    along = np.clip(np.einsum("nsk,sk->ns", offset, tangent), 0.0, table[:, s.LENGTH])
    nearest = start[None, :, :] + along[..., None] * tangent[None, :, :]
    return np.asarray(np.linalg.norm(points[:, None, :] - nearest, axis=2))
