"""One pass over the state to catch a non-finite value or a particle outside its vessel."""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.stepper import chunk_count


@numba.njit(cache=True, parallel=True)
def first_invalid(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    half_width: float,
    half_height: float,
    periodic: bool,
    tolerance: float,
) -> tuple[int, int]:
    """The first particle with a non-finite position or velocity, or outside the box.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        State in m and m/s.
    radius : ndarray, shape (N,)
        Radii in m.
    half_width, half_height : float
        Half sides of the box in m.
    periodic : bool
        Periodic: the centre must be in the primary cell. Reflecting: the whole disk must be inside.
    tolerance : float
        Relative round-off allowance on the half sides.

    Returns
    -------
    tuple of int
        ``(index, reason)``: reason 1 for non-finite, 2 for outside; ``(-1, 0)`` if all is well.
    """
    limit_x = half_width * (1.0 + tolerance)
    limit_y = half_height * (1.0 + tolerance)
    n = position.shape[0]
    chunks = chunk_count(n)
    first = np.full(chunks, n)  # each chunk's first invalid particle (n: none) and why
    reason = np.zeros(chunks, dtype=np.int64)
    for p in numba.prange(chunks):
        for i in range(p * n // chunks, (p + 1) * n // chunks):
            why = _invalid(position[i, 0], position[i, 1], velocity[i, 0], velocity[i, 1],
                           0.0 if periodic else radius[i], limit_x, limit_y)  # fmt: skip
            if why:
                first[p] = i
                reason[p] = why
                break
    for p in range(chunks):
        if first[p] < n:
            return first[p], reason[p]
    return -1, 0


@numba.njit(cache=True, inline="always")
def _invalid(x, y, vx, vy, reach, limit_x, limit_y) -> int:
    """1 if the position or velocity is not finite, 2 if the disk reaches past the limits, else
    0."""
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(vx) and math.isfinite(vy)):
        return 1
    if abs(x) + reach > limit_x or abs(y) + reach > limit_y:
        return 2
    return 0
