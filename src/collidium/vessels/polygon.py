"""`Polygon`: any simple polygon, convex or not (an L, a funnel, a star), with one wall per edge.

Its walls are segments (`kernels/vessels/segments.py`): a disk meets an edge along the edge's
normal and, at a reflex (inward) corner, the corner point itself, along the line from the point
to its centre. Convex corners need nothing of their own: a disk meets one of their edges first.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.kernels.vessels import POLYGON
from collidium.state import BoolArray, FloatArray
from collidium.vessels.base import MAX_EXTENT, Vessel
from collidium.vessels.partitions import Partition, distances, segment_table
from collidium.vessels.walls import WallResponse


class Polygon(Vessel):
    """The inside of a closed chain of straight edges, in either orientation.

    Parameters
    ----------
    vertices : sequence of (x, y)
        Its corners in m, at least 3, in order around it (clockwise or not), the last joined to
        the first. The edges must not cross or touch but at the corners they share.
    walls : dict of str to WallResponse, optional
        Responses of edges that are not mirrors, by name: edge ``i`` (``"edge0"``, ...) runs from
        vertex i to vertex i + 1.
    partitions : sequence of Partition, optional
        Straight walls inside.
    """

    kind: ClassVar[str] = "polygon"
    shape_code: ClassVar[int] = POLYGON

    def __init__(
        self,
        vertices: Any,
        walls: dict[str, WallResponse] | None = None,
        partitions: tuple[Partition, ...] | list[Partition] = (),
    ) -> None:
        self.vertices = _checked_vertices(vertices)
        following = np.roll(self.vertices, -1, axis=0)
        self._edges = following - self.vertices  # edge i: vertex i to vertex i + 1
        doubled = float(np.sum(self.vertices[:, 0] * following[:, 1]
                               - following[:, 0] * self.vertices[:, 1]))  # fmt: skip
        self._orientation = 1.0 if doubled > 0 else -1.0  # counter-clockwise: +1
        self._area = 0.5 * abs(doubled)
        before = np.roll(self._edges, 1, axis=0)  # the edge that ends at each vertex
        cross = before[:, 0] * self._edges[:, 1] - before[:, 1] * self._edges[:, 0]
        turn = self._orientation * cross  # > 0 where the boundary turns inwards (convex)
        cosine = np.einsum("ij,ij->i", before, self._edges)
        #: Interior angle at each vertex, rad (above pi at a reflex corner).
        self.angles = math.pi - np.arctan2(turn, cosine)
        count = len(self.vertices)
        self._edge_rows = segment_table(self.vertices, following, np.arange(count), boundary=True)
        super().__init__(walls, partitions)

    @property
    def shape_walls(self) -> tuple[str, ...]:
        """``("edge0", "edge1", ...)``: edge i runs from vertex i to vertex i + 1."""
        return tuple(f"edge{i}" for i in range(len(self.vertices)))

    @property
    def reflex(self) -> BoolArray:
        """Which corners point inwards (interior angle above pi), shape (M,)."""
        return np.asarray(self.angles > math.pi + 1e-12)

    @property
    def bounds(self) -> FloatArray:
        """The corners' smallest and largest coordinates, ``[[x_min, y_min], [x_max, y_max]]``."""
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    @property
    def area(self) -> float:
        """Area enclosed (shoelace formula), m^2."""
        return self._area

    def outline(self) -> FloatArray:
        """The corners, counter-clockwise, m, shape (M, 2)."""
        return self.vertices if self._orientation > 0 else self.vertices[::-1].copy()

    def _shape_segments(self) -> FloatArray:
        """Each edge (wall i), then each reflex corner as a point of the edge that ends there."""
        corners = np.flatnonzero(self.reflex)
        points = self.vertices[corners]
        ending = (corners - 1) % len(self.vertices)
        corner_rows = segment_table(points, points, ending, boundary=False)
        return np.concatenate([self._edge_rows, corner_rows])

    def _corner_terms(self, radius: float) -> tuple[FloatArray, FloatArray]:
        """Per corner, how much shorter its two edges' contact lines are at it (convex corners,
        ``r cot(angle / 2)`` each) and the arc around it (reflex corners, ``r (angle - pi)``),
        m."""
        convex = ~self.reflex
        with np.errstate(divide="ignore"):
            cut = np.where(convex, radius / np.tan(0.5 * self.angles), 0.0)
        arc = np.where(convex, 0.0, radius * (self.angles - math.pi))
        return cut, arc

    def _open_area(self, radius: float) -> float:
        """``A - r P + r^2 sum cot(angle / 2)`` over convex corners ``- r^2 sum (angle - pi) / 2``
        over reflex ones (m^2): the inner parallel polygon's area (Steiner), exact while every
        edge keeps a contact line of positive length."""
        perimeter = float(np.linalg.norm(self._edges, axis=1).sum())
        cut, arc = self._corner_terms(radius)
        return (
            self._area
            - radius * perimeter
            + radius * float(cut.sum())
            - 0.5 * radius * float(arc.sum())
        )

    def _shape_contact_lengths(self, radius: float) -> FloatArray:
        """Edge i: its length less the cuts at its two convex corners, with the arc around the
        reflex corner it ends at (where its hits are counted), m."""
        cut, arc = self._corner_terms(radius)
        length = np.linalg.norm(self._edges, axis=1)
        return np.asarray(length - cut - np.roll(cut, -1) + np.roll(arc, -1))

    def _outside_shape(self, position: FloatArray, radius: FloatArray) -> BoolArray:
        """Disks closer than their radius to an edge by more than round-off, or whose centre is
        outside the polygon by more than round-off (a centre on the boundary is inside)."""
        if len(position) == 0:
            return np.zeros(0, dtype=bool)
        near = distances(np.nan_to_num(position), self._edge_rows).min(axis=1)
        return np.asarray((near < radius - self._slack) | (
            (near > self._slack) & ~self._winds_around(position)
        ))  # fmt: skip

    def _winds_around(self, position: FloatArray) -> BoolArray:
        """Whether each point is inside (crossing number), shape (N,)."""
        start = self.vertices
        end = np.roll(self.vertices, -1, axis=0)
        x, y = position[:, :1], position[:, 1:]
        straddles = (start[:, 1] > y) != (end[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            crossing_x = start[:, 0] + (y - start[:, 1]) * (end[:, 0] - start[:, 0]) / (
                end[:, 1] - start[:, 1]
            )
        return np.asarray(np.sum(straddles & (x < crossing_x), axis=1) % 2 == 1)

    def check_fits(self, radius: FloatArray) -> None:
        """Refuse disks for whose centres no room is left (the inner parallel polygon)."""
        if radius.size and self._open_area(float(radius.max())) <= 0.0:
            diameter = 2.0 * float(radius.max())
            room = f"leaves no room in the {self.describe()}"
            raise InputError("radius", f"diameter {diameter} {room}")

    def _shape_limits(self, tolerance: float) -> tuple[float, float]:
        """None: the audit tests a polygon through its segments."""
        return math.inf, math.inf

    def describe(self) -> str:
        """``'polygon of 12 corners (area 314 m^2)'``."""
        return f"polygon of {len(self.vertices)} corners (area {self._area:g} m^2)"

    def parameters(self) -> dict[str, Any]:
        """``{"vertices"}``, as in a scenario file (the walls apart)."""
        return {"vertices": self.vertices.tolist()}

    def __repr__(self) -> str:
        return f"Polygon({self.vertices.tolist()!r})"


def regular_polygon(corners: int, circumradius: float) -> Polygon:
    """A regular polygon of ``corners`` corners ``circumradius`` m from the origin, the first on
    the x axis."""
    angle = 2.0 * math.pi * np.arange(corners) / corners
    return Polygon(circumradius * np.column_stack([np.cos(angle), np.sin(angle)]))


def _checked_vertices(vertices: Any) -> FloatArray:
    """The corners as an (M, 2) array, or `InputError` naming ``vessel.vertices``."""
    field = "vessel.vertices"
    try:
        points = np.array(vertices, dtype=float)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a list of [x, y] points, got {vertices!r}") from None
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise InputError(field, f"must be at least 3 [x, y] points, got {vertices!r}")
    if not np.isfinite(points).all():
        raise InputError(field, "must be finite numbers")
    if np.ptp(points, axis=0).max() > MAX_EXTENT:
        raise InputError(field, f"must span at most {MAX_EXTENT:g} m")
    following = np.roll(points, -1, axis=0)
    if (points == following).all(axis=1).any():
        raise InputError(field, "has two equal consecutive points")
    crossing = _first_crossing(points)
    if crossing is not None:
        i, j = crossing
        raise InputError(field, f"must be a simple polygon: edges {i} and {j} cross or touch")
    doubled = np.sum(points[:, 0] * following[:, 1] - following[:, 0] * points[:, 1])
    if doubled == 0.0:
        raise InputError(field, "encloses no area")
    return points


def _first_crossing(points: FloatArray) -> tuple[int, int] | None:
    """The first pair of edges that cross or touch other than at the corner they share (or fold
    back onto each other there), or None for a simple polygon."""
    count = len(points)
    a, b = points, np.roll(points, -1, axis=0)

    def side(p: FloatArray, q: FloatArray, r: FloatArray) -> FloatArray:
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))  # fmt: skip

    i, j = np.triu_indices(count, 1)
    adjacent = (j == i + 1) | ((i == 0) & (j == count - 1))
    pi_, pj = a[i], b[i]
    qi, qj = a[j], b[j]
    d1, d2 = side(qi, qj, pi_), side(qi, qj, pj)
    d3, d4 = side(pi_, pj, qi), side(pi_, pj, qj)
    proper = (d1 * d2 < 0) & (d3 * d4 < 0)

    def on(p: FloatArray, q: FloatArray, r: FloatArray, s: FloatArray) -> BoolArray:
        """r lies on segment pq, given they are collinear (s == 0)."""
        within = (np.minimum(p, q) <= r) & (r <= np.maximum(p, q))
        return (s == 0) & within.all(axis=-1)

    touching = on(qi, qj, pi_, d1) | on(qi, qj, pj, d2) | on(pi_, pj, qi, d3) | on(pi_, pj, qj, d4)
    bad = ~adjacent & (proper | touching)
    # Adjacent edges share a corner; they only fail by folding back along each other.
    first, second = b[i] - a[i], b[j] - a[j]
    folded = adjacent & (d1 == 0) & (d2 == 0) & (d3 == 0) & (d4 == 0)
    folded &= np.einsum("ij,ij->i", first, second) < 0
    hits = np.flatnonzero(bad | folded)
    return None if hits.size == 0 else (int(i[hits[0]]), int(j[hits[0]]))
