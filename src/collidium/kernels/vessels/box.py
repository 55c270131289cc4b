"""The box's wall arithmetic, for every engine: the time to a wall and the contact point (exact
engine), the exact fold of straight flight between mirror walls (step and off modes; other
responses fly hit by hit in `contacts`), the wrap of a periodic box and the outside test (audit).

The box is centred on the origin with half sides ``half_width, half_height`` (m); its walls are
numbered 0 left, 1 right, 2 bottom, 3 top (wall ``w`` is on axis ``w // 2``, at the upper end when
``w`` is odd), the order of `collidium.vessels.Box.wall_names`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels import parabolas
from collidium.kernels.compilation import inlined, uncounted


@inlined
def wall_delay(
    x: float,
    y: float,
    vx: float,
    vy: float,
    r: float,
    half_width: float,
    half_height: float,
    gx: float = 0.0,
    gy: float = 0.0,
) -> tuple[float, int]:
    """Time until a disk of radius ``r`` at (x, y) moving at (vx, vy) under the acceleration
    (gx, gy) (m/s^2) touches a wall.

    Returns
    -------
    tuple
        ``(delay in s, wall)``; ``(inf, -1)`` if it never does. A disk already at or past a wall
        it moves towards gets 0. Ties go to the x walls, then to the lower wall.
    """
    if gx != 0.0 or gy != 0.0:
        return _falling_wall_delay(x, y, vx, vy, r, half_width, half_height, gx, gy)
    best = math.inf
    wall = -1
    for d in range(2):
        v = vx if d == 0 else vy
        position = x if d == 0 else y
        half = half_width if d == 0 else half_height
        if v > 0.0:
            delay = max((half - r - position) / v, 0.0)
            if delay < best:
                best, wall = delay, 2 * d + 1
        elif v < 0.0:
            delay = max((-half + r - position) / v, 0.0)
            if delay < best:
                best, wall = delay, 2 * d
    return best, wall


@uncounted()
def _falling_wall_delay(x, y, vx, vy, r, half_width, half_height, gx, gy) -> tuple[float, int]:
    """`wall_delay` on a parabola: each wall's gap closes on a quadratic. A call, not inlined:
    the engine inlines `wall_delay`, and this arithmetic would only add to its compile time."""
    best = math.inf
    wall = -1
    for d in range(2):
        v = vx if d == 0 else vy
        g = gx if d == 0 else gy
        position = x if d == 0 else y
        half = half_width if d == 0 else half_height
        lower = parabolas.first_contact(position - (r - half), v, g)
        upper = parabolas.first_contact((half - r) - position, -v, -g)
        if lower < best:
            best, wall = lower, 2 * d
        if upper < best:
            best, wall = upper, 2 * d + 1
    return best, wall


@inlined
def contact_coordinate(wall: int, r: float, half_width: float, half_height: float) -> float:
    """Where the centre of a disk of radius ``r`` touching ``wall`` is along the wall's axis
    (``wall // 2``), in m: the snap that keeps round-off from leaving a disk past the wall."""
    half = half_width if wall < 2 else half_height
    return (half - r) if wall % 2 == 1 else (r - half)


@inlined
def reaches_outside(x: float, y: float, reach: float, limit_x: float, limit_y: float) -> bool:
    """Whether a disk at (x, y) reaching ``reach`` m from its centre (its radius; 0 for the
    centre alone) passes the half sides ``limit_x, limit_y`` (m, round-off allowance included),
    or has a coordinate that is not finite: a NaN is within no sides. Without branches."""
    return not ((abs(x) + reach <= limit_x) & (abs(y) + reach <= limit_y))


@inlined
def fold(x: float, v: float, lo: float, hi: float) -> tuple[float, float, int]:
    """Reflect a free-flight coordinate back into ``[lo, hi]``.

    Unfolding a path that bounces between two mirrors gives a straight line; folding it back is
    exact however many bounces happened in one step.

    Parameters
    ----------
    x : float
        Coordinate after a straight drift (may lie outside), in m.
    v : float
        Velocity component in m/s.
    lo, hi : float
        Allowed range of the coordinate (wall minus/plus the radius), in m.

    Returns
    -------
    tuple
        ``(x', v', bounces)``: the folded coordinate, the velocity component (sign flipped once
        per bounce) and the number of bounces.
    """
    if lo <= x <= hi:
        return x, v, 0
    span = hi - lo
    above = x > hi
    if span <= 0.0:
        return lo, -v, 1
    # Distance travelled past the first wall met; every further span is one more bounce.
    overshoot = x - hi if above else lo - x
    bounces = math.ceil(overshoot / span)
    rest = overshoot - (bounces - 1) * span
    back_from_first = bounces % 2 == 1
    x = hi - rest if above == back_from_first else lo + rest
    if back_from_first:
        v = -v
    return min(max(x, lo), hi), v, bounces


#: Particles per chunk of the parallel drift. A chunk runs in parallel up to its first particle
#: that meets a wall; the rest of it is finished afterwards, in index order, so that the sums of
#: the wall tallies are the same whatever the number of threads.
DRIFT_CHUNK = 1024


@numba.njit(cache=True)
def _drift_free(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    half_width: float,
    half_height: float,
    dt: float,
    lo: int,
    hi: int,
) -> int:
    """Drift particles ``lo:hi`` until the first that would meet a wall; return its index (or
    ``hi``). That particle and the ones after it are left untouched."""
    for i in range(lo, hi):
        x = position[i, 0] + velocity[i, 0] * dt
        y = position[i, 1] + velocity[i, 1] * dt
        inside_x = -half_width + radius[i] <= x <= half_width - radius[i]
        if not (inside_x and -half_height + radius[i] <= y <= half_height - radius[i]):
            return i
        position[i, 0] = x
        position[i, 1] = y
    return hi


@numba.njit(cache=True)
def _drift_folding(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    half_width: float,
    half_height: float,
    dt: float,
    wall_hits: np.ndarray,
    wall_impulse: np.ndarray,
    lo: int,
    hi: int,
) -> None:
    """Drift particles ``lo:hi`` in index order, folding them back and tallying wall hits."""
    half = (half_width, half_height)
    for i in range(lo, hi):
        for d in range(2):
            x = position[i, d] + velocity[i, d] * dt
            low = -half[d] + radius[i]
            high = half[d] - radius[i]
            moving_up = velocity[i, d] > 0.0
            x, v, bounces = fold(x, velocity[i, d], low, high)
            position[i, d] = x
            velocity[i, d] = v
            if bounces > 0:
                # Bounces alternate between the two walls, starting with the one moved towards.
                first = 2 * d + (1 if moving_up else 0)
                other = 2 * d + (0 if moving_up else 1)
                kick = 2.0 * mass[i] * abs(v)
                wall_hits[first] += (bounces + 1) // 2
                wall_hits[other] += bounces // 2
                wall_impulse[first] += kick * ((bounces + 1) // 2)
                wall_impulse[other] += kick * (bounces // 2)


@numba.njit(cache=True, parallel=True)
def drift_reflecting(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    mass: np.ndarray,
    half_width: float,
    half_height: float,
    dt: float,
    wall_hits: np.ndarray,
    wall_impulse: np.ndarray,
) -> None:
    """Move every particle by ``velocity * dt`` and fold it back inside the walls.

    Parallel over chunks of `DRIFT_CHUNK` particles; the (few) particles from the first one of a
    chunk that meets a wall are drifted afterwards, in index order, so the wall tallies are summed
    in index order and the result does not depend on the number of threads.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        Updated in place (m, m/s).
    radius : ndarray, shape (N,)
        Radii in m (a disk bounces when its rim touches a wall).
    mass : ndarray, shape (N,)
        Masses in kg (for the momentum given to the walls).
    half_width, half_height : float
        Half sides of the box in m.
    dt : float
        Time step in s.
    wall_hits : ndarray of int64, shape (4,)
        Incremented per bounce on the left, right, bottom, top wall.
    wall_impulse : ndarray of float64, shape (4,)
        Incremented by the momentum each wall receives, ``2 m |v|`` per bounce (kg m/s).
    """
    n = position.shape[0]
    chunks = (n + DRIFT_CHUNK - 1) // DRIFT_CHUNK
    stopped = np.empty(chunks, dtype=np.int64)
    for k in numba.prange(chunks):
        hi = min(n, (k + 1) * DRIFT_CHUNK)
        stopped[k] = _drift_free(
            position, velocity, radius, half_width, half_height, dt, k * DRIFT_CHUNK, hi
        )
    for k in range(chunks):
        hi = min(n, (k + 1) * DRIFT_CHUNK)
        if stopped[k] < hi:
            _drift_folding(
                position, velocity, radius, mass, half_width, half_height, dt, wall_hits,
                wall_impulse, stopped[k], hi,
            )  # fmt: skip


@numba.njit(cache=True, parallel=True)
def drift_periodic(
    position: np.ndarray,
    velocity: np.ndarray,
    image: np.ndarray,
    width: float,
    height: float,
    dt: float,
) -> None:
    """Move every particle by ``velocity * dt`` and wrap it into the primary cell (in parallel).

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        Position updated in place (m).
    image : ndarray of int64, shape (N, 2)
        Image counts, updated so that ``position + image * size`` stays unwrapped.
    width, height : float
        Box sides in m.
    dt : float
        Time step in s.
    """
    size = (width, height)
    for i in numba.prange(position.shape[0]):
        for d in range(2):
            x = position[i, d] + velocity[i, d] * dt
            shift = math.floor((x + 0.5 * size[d]) / size[d])
            if shift != 0:
                x -= shift * size[d]
                image[i, d] += int(shift)
            position[i, d] = x
