"""A vessel's contacts, whatever its shape: its shape's own walls (a box's four, a circle's rim;
a polygon has none) and its segments (`segments`: a polygon's edges and corners, partitions).

Contact ``c`` is the shape's wall ``c`` for ``c < SEGMENTS_FROM``, else segment
``c - SEGMENTS_FROM``. The exact engine, the hit-by-hit flight of the step and off modes and the
audit ask here, so that none of them knows a shape.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels import wall_responses
from collidium.kernels.compilation import inlined
from collidium.kernels.vessels import BOX, CIRCLE, box, circle, segments

#: The first contact that is a segment: shapes have at most this many walls of their own.
SEGMENTS_FROM = 4


@inlined
def earliest(
    x, y, vx, vy, r, shape, half_width, half_height, rim, table, gx=0.0, gy=0.0, horizon=math.inf
) -> tuple[float, int]:
    """``(delay in s, contact)`` of the first wall a disk of radius ``r`` at (x, y) moving at
    (vx, vy) under the acceleration (gx, gy) (m/s^2) touches; ``(inf, -1)`` if none. ``table``
    is the vessel's segment table. Ties go to the shape's walls. On a parabola, curved contacts
    (the rim, a segment's point) are looked for up to ``horizon`` (s) only."""
    if shape == CIRCLE:
        best, contact = circle.wall_delay(x, y, vx, vy, r, rim, gx, gy, horizon)
    elif shape == BOX:
        best, contact = box.wall_delay(x, y, vx, vy, r, half_width, half_height, gx, gy)
    else:
        best, contact = math.inf, -1
    if table.shape[0] > 0:
        delay, e = segments.earliest(x, y, vx, vy, r, table, gx, gy, min(best, horizon))
        if delay < best:
            best, contact = delay, SEGMENTS_FROM + e
    return best, contact


@inlined
def touch(contact, x, y, vx, vy, r, shape, half_width, half_height, rim, table):
    """A disk of radius ``r`` at (x, y) moving at (vx, vy) touching ``contact``:
    ``(x, y, nx, ny, wall)``, its centre snapped onto the contact line (so that round-off never
    leaves it past the wall), the wall's outward unit normal there and the wall's index
    (`Vessel.wall_names` order)."""
    if contact >= SEGMENTS_FROM:
        e = contact - SEGMENTS_FROM
        x, y, nx, ny = segments.touch(x, y, vx, vy, r, table, e)
        return x, y, nx, ny, int(table[e, segments.WALL])
    if shape == CIRCLE:
        x, y = circle.contact_point(x, y, r, rim)
        nx, ny = circle.outward_normal(x, y)
        return x, y, nx, ny, contact
    touching = box.contact_coordinate(contact, r, half_width, half_height)
    sign = 1.0 if contact % 2 == 1 else -1.0
    if contact < 2:
        return touching, y, sign, 0.0, contact
    return x, touching, 0.0, sign, contact


@inlined
def reaches_outside(x, y, reach, shape, limit_x, limit_y, slack, table) -> bool:
    """Whether a disk at (x, y) reaching ``reach`` m from its centre passes the shape's limits
    (`collidium.vessels.Vessel.audit_arguments`, round-off allowance included) or comes closer than
    ``reach - slack`` to a segment."""
    if shape == CIRCLE:
        outside = circle.reaches_outside(x, y, reach, limit_x)
    elif shape == BOX:
        outside = box.reaches_outside(x, y, reach, limit_x, limit_y)
    else:
        outside = False
    return outside or (table.shape[0] > 0 and segments.reaches_outside(x, y, reach, slack, table))


@numba.njit(cache=True)
def drift_responding(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    dt: float,
    shape: int,
    half_width: float,
    half_height: float,
    rim: float,
    table: np.ndarray,
    responses: np.ndarray,
    wall_hits: np.ndarray,
    wall_impulse: np.ndarray,
    wall_heat: np.ndarray,
) -> None:
    """Move every particle for ``dt`` in straight lines; at each exact time one meets a wall,
    the wall's response (`collidium.kernels.wall_responses`), in index order (so the tallies do
    not depend on threads). The step and off modes' flight wherever the box's fold does not
    apply.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        Updated in place (m, m/s).
    radius, mass : ndarray, shape (N,)
        Radii (m) and masses (kg).
    dt : float
        Time step, s.
    shape, half_width, half_height, rim : int, float, float, float
        The shape's code and size (m): the box's half sides, the circle's radius.
    table : ndarray, shape (S, `segments.SEGMENT_COLUMNS`)
        The vessel's segments.
    responses : ndarray, shape (W, 3)
        The vessel's wall table.
    wall_hits, wall_impulse, wall_heat : ndarray, shape (W,) or more
        Incremented per hit on each wall: hits, momentum received along the normal (kg m/s),
        energy given to the disk (J).
    """
    for i in range(position.shape[0]):
        left = dt
        x, y = position[i, 0], position[i, 1]
        vx, vy = velocity[i, 0], velocity[i, 1]
        r = radius[i]
        while True:
            delay, contact = earliest(x, y, vx, vy, r, shape, half_width, half_height, rim, table)
            if contact < 0 or delay >= left:
                x += vx * left
                y += vy * left
                break
            x, y, nx, ny, wall = touch(contact, x + vx * delay, y + vy * delay, vx, vy, r, shape,
                                       half_width, half_height, rim, table)  # fmt: skip
            left -= delay
            if vx * nx + vy * ny > 0.0:  # respond to what moves into the wall
                vx, vy = wall_responses.hit(responses, wall, vx, vy, nx, ny, mass[i], i,
                                            wall_hits, wall_impulse, wall_heat, wall)  # fmt: skip
            elif delay == 0.0:
                # Exactly tangent to the rim (only round-off makes it): nothing to respond to;
                # go on along the tangent and stay on the rim.
                x += vx * left
                y += vy * left
                if shape == CIRCLE and contact < SEGMENTS_FROM:
                    x, y = circle.contact_point(x, y, r, rim)
                break
        position[i, 0], position[i, 1] = x, y
        velocity[i, 0], velocity[i, 1] = vx, vy
