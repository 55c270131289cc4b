"""One pass over the state to catch a non-finite value or a particle outside its vessel."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
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
    for i in range(position.shape[0]):
        x = position[i, 0]
        y = position[i, 1]
        if not (
            math.isfinite(x)
            and math.isfinite(y)
            and math.isfinite(velocity[i, 0])
            and math.isfinite(velocity[i, 1])
        ):
            return i, 1
        reach = 0.0 if periodic else radius[i]
        if abs(x) + reach > limit_x or abs(y) + reach > limit_y:
            return i, 2
    return -1, 0
