"""Random sequential placement of non-overlapping disks."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def place_disks(
    candidates: np.ndarray,
    radius: np.ndarray,
    placed: int,
    position: np.ndarray,
    lo: np.ndarray,
    cell: float,
    ncx: int,
    ncy: int,
    head: np.ndarray,
    next_: np.ndarray,
) -> int:
    """Accept candidate centres, in order, that overlap no disk placed so far.

    Parameters
    ----------
    candidates : ndarray, shape (M, 2)
        Proposed centres in m (already inside the allowed region).
    radius : ndarray, shape (N,)
        Radius of each disk to place, in m; all at most ``cell / 2``.
    placed : int
        Disks already placed (``position[:placed]``).
    position : ndarray, shape (N, 2)
        Output, filled from index ``placed`` on.
    lo : ndarray, shape (2,)
        Lower-left corner of the grid in m.
    cell : float
        Grid cell side in m (>= largest diameter).
    ncx, ncy : int
        Grid shape.
    head, next_ : ndarray of int64
        Cell lists of placed disks, (ncx*ncy,) and (N,), updated in place.

    Returns
    -------
    int
        Number of disks placed in total.
    """
    n = position.shape[0]
    for m in range(candidates.shape[0]):
        if placed >= n:
            break
        x = candidates[m, 0]
        y = candidates[m, 1]
        r = radius[placed]
        cx = min(max(math.floor((x - lo[0]) / cell), 0), ncx - 1)
        cy = min(max(math.floor((y - lo[1]) / cell), 0), ncy - 1)
        free = True
        for oy in range(max(cy - 1, 0), min(cy + 2, ncy)):
            for ox in range(max(cx - 1, 0), min(cx + 2, ncx)):
                j = head[ox + ncx * oy]
                while j >= 0 and free:
                    dx = position[j, 0] - x
                    dy = position[j, 1] - y
                    sigma = r + radius[j]
                    if dx * dx + dy * dy < sigma * sigma:
                        free = False
                    j = next_[j]
        if free:
            position[placed, 0] = x
            position[placed, 1] = y
            c = cx + ncx * cy
            next_[placed] = head[c]
            head[c] = placed
            placed += 1
    return placed
