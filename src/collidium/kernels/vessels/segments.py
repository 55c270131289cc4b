"""Walls made of straight segments, for every engine: a polygon's edges and reflex corners, and
the partitions of any vessel. Time to contact, the contact point and normal, distances and the
polygon's inside test.

A vessel's segments are rows of a table (`collidium.vessels.Vessel.segments`), columns `X0` to
`BOUNDARY`: the ends (m), the unit tangent and the length (m, 0 for a corner, which is a point),
the wall it belongs to (its index in `collidium.vessels.Vessel.wall_names`) and whether it is an
edge of the polygon's boundary (1) rather than a partition or a corner (0).

A disk of radius r touches a segment when its centre is r from the segment's nearest point: on
either side of its line within its length, or r from a point. A polygon's convex corners need no
point of their own (a disk meets one of the two edges first); its reflex corners do.
"""

from __future__ import annotations

import math

from collidium.kernels import parabolas
from collidium.kernels.compilation import inlined, uncounted

#: Columns of a segment table.
X0, Y0, X1, Y1, TX, TY, LENGTH, WALL, BOUNDARY = range(9)
SEGMENT_COLUMNS = 9


@inlined
def point_delay(px: float, py: float, vx: float, vy: float, r: float) -> float:
    """Time until a disk of radius ``r`` whose centre is (px, py) from a point, moving at
    (vx, vy), touches the point; inf if it never does. A disk already within ``r`` that moves
    closer gets 0."""
    b = px * vx + py * vy
    if b >= 0.0:
        return math.inf
    c = px * px + py * py - r * r
    if c <= 0.0:
        return 0.0
    disc = b * b - (vx * vx + vy * vy) * c
    if disc < 0.0:
        return math.inf
    return c / (math.sqrt(disc) - b)  # the earlier root, without cancellation


@inlined
def element_delay(
    x: float,
    y: float,
    vx: float,
    vy: float,
    r: float,
    segments,
    e: int,
    gx: float = 0.0,
    gy: float = 0.0,
    horizon: float = math.inf,
) -> float:
    """Time until a disk of radius ``r`` at (x, y) moving at (vx, vy) under the acceleration
    (gx, gy) (m/s^2) touches segment ``e`` (its flat part, from either side; a point if its
    length is 0); inf if it never does. On a parabola a point is looked for up to ``horizon``
    (s; a contact after it may be reported as inf)."""
    px = x - segments[e, X0]
    py = y - segments[e, Y0]
    length = segments[e, LENGTH]
    falling = gx != 0.0 or gy != 0.0
    if length == 0.0:
        if falling:
            return parabolas.distance_crossing(px, py, vx, vy, gx, gy, r, False, horizon)
        return point_delay(px, py, vx, vy, r)
    tx = segments[e, TX]
    ty = segments[e, TY]
    if falling:
        return _flat_delay_on_parabola(px, py, vx, vy, gx, gy, r, tx, ty, length)
    distance = tx * py - ty * px  # along the normal (-ty, tx)
    approach = tx * vy - ty * vx
    if distance < 0.0:
        distance, approach = -distance, -approach
    if approach >= 0.0:
        return math.inf
    delay = max((distance - r) / -approach, 0.0)
    along = (px + vx * delay) * tx + (py + vy * delay) * ty
    if along < 0.0 or along > length:
        return math.inf  # past an end: the end's point (or the next edge) is met instead
    return delay


@uncounted()
def _flat_delay_on_parabola(px, py, vx, vy, gx, gy, r, tx, ty, length) -> float:
    """`element_delay` of a flat part for a disk on a parabola, from (px, py) off the segment's
    start: the first time its distance to the line, a quadratic in t, comes to r on the disk's
    side while closing, or to r on the far side while coming back (a pull across the line may
    carry a disk past an end and back under the segment), with the contact point within the
    segment. A call, not inlined: the engine inlines `element_delay`, and this arithmetic would
    only add to its compile time."""
    distance = tx * py - ty * px  # along the normal (-ty, tx)
    approach = tx * vy - ty * vx
    pull = tx * gy - ty * gx
    if distance < 0.0:
        distance, approach, pull = -distance, -approach, -pull
    near = parabolas.first_contact(distance - r, approach, pull)
    far = parabolas.first_root(0.5 * pull, approach, distance + r, True)
    best = math.inf
    for delay in (near, far):
        if not 0.0 <= delay < best:  # also NaN
            continue
        along = (px + (vx + 0.5 * gx * delay) * delay) * tx + (
            py + (vy + 0.5 * gy * delay) * delay
        ) * ty
        if 0.0 <= along <= length:
            best = delay
    return best


@inlined
def earliest(
    x: float,
    y: float,
    vx: float,
    vy: float,
    r: float,
    segments,
    gx: float = 0.0,
    gy: float = 0.0,
    horizon: float = math.inf,
) -> tuple[float, int]:
    """``(delay in s, segment)`` of the first segment a disk touches (`element_delay`);
    ``(inf, -1)`` if none. Ties go to the first row."""
    best = math.inf
    found = -1
    for e in range(segments.shape[0]):
        delay = element_delay(x, y, vx, vy, r, segments, e, gx, gy, min(horizon, best))
        if delay < best:
            best, found = delay, e
    return best, found


@inlined
def nearest_point(x: float, y: float, segments, e: int) -> tuple[float, float]:
    """The point of segment ``e`` nearest to (x, y), m."""
    along = (x - segments[e, X0]) * segments[e, TX] + (y - segments[e, Y0]) * segments[e, TY]
    along = min(max(along, 0.0), segments[e, LENGTH])
    return segments[e, X0] + along * segments[e, TX], segments[e, Y0] + along * segments[e, TY]


@inlined
def distance(x: float, y: float, segments, e: int) -> float:
    """Distance in m from (x, y) to segment ``e``."""
    qx, qy = nearest_point(x, y, segments, e)
    return math.hypot(qx - x, qy - y)


@inlined
def touch(
    x: float, y: float, vx: float, vy: float, r: float, segments, e: int
) -> tuple[float, float, float, float]:
    """A disk of radius ``r`` at (x, y) moving at (vx, vy) touching segment ``e``:
    ``(x, y, nx, ny)``, its centre put exactly ``r`` from the nearest point (the snap that keeps
    round-off from leaving it on the wall's far side) and the unit normal from the centre
    towards that point: the line's normal along a flat part, the direction to an end or a
    corner. A centre that round-off alone puts on one side (radius 0) goes by the velocity."""
    tx, ty = segments[e, TX], segments[e, TY]
    along = (x - segments[e, X0]) * tx + (y - segments[e, Y0]) * ty
    if 0.0 < along < segments[e, LENGTH]:
        qx, qy = segments[e, X0] + along * tx, segments[e, Y0] + along * ty
        nx, ny = ty, -tx
        side = (x - qx) * nx + (y - qy) * ny  # > 0: the wall is along -n
        by_side = r > 0.0 and abs(side) > 0.5 * r
        moving_in = side < 0.0 if by_side else vx * nx + vy * ny > 0.0
        if not moving_in:
            nx, ny = -nx, -ny
        return qx - r * nx, qy - r * ny, nx, ny
    qx, qy = nearest_point(x, y, segments, e)
    dx, dy = qx - x, qy - y
    gap = math.hypot(dx, dy)
    if r > 0.0 and gap > 0.5 * r:
        nx, ny = dx / gap, dy / gap
    else:  # head on
        speed = math.hypot(vx, vy)
        nx, ny = (vx / speed, vy / speed) if speed > 0.0 else (1.0, 0.0)
    return qx - r * nx, qy - r * ny, nx, ny


@inlined
def inside_boundary(x: float, y: float, segments) -> bool:
    """Whether (x, y) is inside the polygon the boundary rows make (crossing number); True when
    there are none (the vessel's shape is not a polygon)."""
    crossings = 0
    edges = 0
    for e in range(segments.shape[0]):
        if segments[e, BOUNDARY] == 0.0:
            continue
        edges += 1
        ay, by = segments[e, Y0], segments[e, Y1]
        if (ay > y) != (by > y):
            ax, bx = segments[e, X0], segments[e, X1]
            if x < ax + (y - ay) * (bx - ax) / (by - ay):
                crossings += 1
    return edges == 0 or crossings % 2 == 1


@inlined
def reaches_outside(x: float, y: float, reach: float, slack: float, segments) -> bool:
    """Whether a disk at (x, y) reaching ``reach`` m from its centre comes closer than
    ``reach - slack`` (m, the round-off allowance) to any segment, or has its centre outside the
    boundary by more than ``slack`` (a point on the boundary is inside).

    By squared distances: ``math.hypot``, a careful root, was most of a 1000-disk audit's time
    in a box with a partition."""
    nearest2 = math.inf
    for e in range(segments.shape[0]):
        qx, qy = nearest_point(x, y, segments, e)
        nearest2 = min(nearest2, (qx - x) * (qx - x) + (qy - y) * (qy - y))
    close = reach - slack
    return (close > 0.0 and nearest2 < close * close) or (
        nearest2 > slack * slack and not inside_boundary(x, y, segments)
    )
