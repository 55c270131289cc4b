"""The circle's wall arithmetic, for every engine: the time to the rim and the contact point
(exact engine), exact straight flight with the rim's response at each hit (step and off modes)
and the outside test (audit).

The circle is centred on the origin with radius ``rim`` (m); its one wall, the rim, is wall 0.
A disk of radius r touches it when its centre is ``rim - r`` from the origin; the outward
normal there is the centre's direction.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels import wall_responses


@numba.njit(cache=True, inline="always")
def wall_delay(x: float, y: float, vx: float, vy: float, r: float, rim: float) -> tuple[float, int]:
    """Time until a disk of radius ``r`` at (x, y) moving at (vx, vy) touches the rim.

    The later root of ``|x + v t| = rim - r`` (the disk is inside). Returns ``(delay in s, 0)``,
    or ``(inf, -1)`` at rest; a disk at or past the rim moving outwards gets 0.
    """
    speed2 = vx * vx + vy * vy
    if speed2 == 0.0:
        return math.inf, -1
    reach = rim - r
    b = x * vx + y * vy
    c = x * x + y * y - reach * reach
    if c >= 0.0 and b >= 0.0:
        return 0.0, 0
    root = math.sqrt(max(b * b - speed2 * c, 0.0))
    # Stable forms of (-b + root) / speed2: no cancellation whatever the sign of b.
    delay = (root - b) / speed2 if b <= 0.0 else -c / (b + root)
    return max(delay, 0.0), 0


@numba.njit(cache=True, inline="always")
def outward_normal(x: float, y: float) -> tuple[float, float]:
    """Unit outward normal of the rim at the direction of (x, y) (x axis at the centre)."""
    length = math.hypot(x, y)
    if length == 0.0:
        return 1.0, 0.0
    return x / length, y / length


@numba.njit(cache=True, inline="always")
def contact_point(x: float, y: float, r: float, rim: float) -> tuple[float, float]:
    """(x, y) moved along its direction to ``rim - r`` from the centre: where a disk of radius
    ``r`` touching the rim there is (the snap that keeps round-off from leaving it outside)."""
    nx, ny = outward_normal(x, y)
    reach = rim - r
    return nx * reach, ny * reach


@numba.njit(cache=True, inline="always")
def reaches_outside(x: float, y: float, reach: float, limit: float) -> bool:
    """Whether a disk at (x, y) reaching ``reach`` m from its centre passes ``limit`` m from the
    origin (the rim with its round-off allowance)."""
    return math.hypot(x, y) + reach > limit


@numba.njit(cache=True)
def drift_responding(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    rim: float,
    dt: float,
    table: np.ndarray,
    wall_hits: np.ndarray,
    wall_impulse: np.ndarray,
    wall_heat: np.ndarray,
) -> None:
    """Move every particle for ``dt`` in straight lines; at each exact time one meets the rim,
    the rim's response (`collidium.kernels.wall_responses`; a mirror by default), in index order
    (so the tallies do not depend on threads).

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        Updated in place (m, m/s).
    radius, mass : ndarray, shape (N,)
        Radii (m) and masses (kg).
    rim : float
        The circle's radius, m.
    dt : float
        Time step, s.
    table : ndarray, shape (1, 3)
        The rim's response.
    wall_hits, wall_impulse, wall_heat : ndarray, shape (1,) or more
        Incremented per hit on the rim: hits, momentum received along the normal (kg m/s),
        energy given to the disk (J).
    """
    for i in range(position.shape[0]):
        left = dt
        x, y = position[i, 0], position[i, 1]
        vx, vy = velocity[i, 0], velocity[i, 1]
        while True:
            delay, wall = wall_delay(x, y, vx, vy, radius[i], rim)
            if wall < 0 or delay >= left:
                x += vx * left
                y += vy * left
                break
            x, y = contact_point(x + vx * delay, y + vy * delay, radius[i], rim)
            left -= delay
            nx, ny = outward_normal(x, y)
            if vx * nx + vy * ny > 0.0:  # respond to what moves outwards
                vx, vy = wall_responses.hit(table, 0, vx, vy, nx, ny, mass[i], i, wall_hits,
                                            wall_impulse, wall_heat, 0)  # fmt: skip
            elif delay == 0.0:
                # Exactly tangent at the rim (only round-off makes it): nothing to respond to;
                # go on along the tangent and keep the centre on the circle.
                x, y = contact_point(x + vx * left, y + vy * left, radius[i], rim)
                break
        position[i, 0], position[i, 1] = x, y
        velocity[i, 0], velocity[i, 1] = vx, vy
