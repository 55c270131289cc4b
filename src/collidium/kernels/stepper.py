"""The seed report's collision method: after a plain drift, resolve overlapping pairs.

Overlapping pairs are found through the cell grid, then handled one by one in index order
(i, then j): a pair is resolved only if it is still approaching with the velocities it has by then
(seed 4.1: the directional check, and pairwise handling in a fixed order).
"""

from __future__ import annotations

import numba
import numpy as np

from collidium.kernels.cells import fill_cells
from collidium.kernels.collision import elastic_response


@numba.njit(cache=True)
def overlapping_pairs(
    position: np.ndarray,
    radius: np.ndarray,
    width: float,
    height: float,
    ncx: int,
    ncy: int,
    cell_of: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    prev: np.ndarray,
    cells: np.ndarray,
    shifts: np.ndarray,
    out: np.ndarray,
) -> int:
    """Overlapping pairs, encoded ``i * N + j`` (i < j) and sorted, written to ``out``.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m, inside the box.
    radius : ndarray, shape (N,)
        Radii in m.
    width, height : float
        Box sides in m (used for periodic shifts).
    ncx, ncy : int
        Grid shape.
    cell_of, head, next_, prev : ndarray of int64
        Work arrays for the cell lists (N,), (ncx*ncy,), (N,), (N,).
    cells, shifts : ndarray of int64
        Neighbour table from `cells.neighbour_table`.
    out : ndarray of int64, shape (M,)
        Receives the first ``min(count, M)`` pairs.

    Returns
    -------
    int
        The number of overlapping pairs; if larger than M, call again with a larger ``out``.
    """
    n = position.shape[0]
    fill_cells(position, radius, 0.5 * width, 0.5 * height, ncx, ncy, cell_of, head, next_, prev)
    count = 0
    for i in range(n):
        ci = cell_of[i]
        if radius[i] <= 0.0:  # points take no part in collisions
            continue
        for k in range(9):
            c = cells[ci, k]
            if c < 0:
                continue
            j = head[c]
            while j >= 0:
                if j > i and radius[j] > 0.0:
                    dx = position[j, 0] + shifts[ci, k, 0] * width - position[i, 0]
                    dy = position[j, 1] + shifts[ci, k, 1] * height - position[i, 1]
                    sigma = radius[i] + radius[j]
                    if dx * dx + dy * dy < sigma * sigma:
                        if count < out.shape[0]:
                            out[count] = i * n + j
                        count += 1
                j = next_[j]
    if count <= out.shape[0]:
        out[:count].sort()
    return count


@numba.njit(cache=True)
def resolve_pairs(
    pairs: np.ndarray,
    position: np.ndarray,
    velocity: np.ndarray,
    mass: np.ndarray,
    width: float,
    height: float,
    periodic: bool,
    impulse: np.ndarray,
) -> int:
    """Apply the elastic response to each listed pair that is approaching, in list order.

    Parameters
    ----------
    pairs : ndarray of int64, shape (M,)
        Pairs encoded ``i * N + j``, as from `overlapping_pairs`.
    position : ndarray, shape (N, 2)
        Centres in m.
    velocity : ndarray, shape (N, 2)
        Velocities in m/s, updated in place.
    mass : ndarray, shape (N,)
        Masses in kg.
    width, height : float
        Box sides in m.
    periodic : bool
        Use the minimum image for the line of centres.
    impulse : ndarray of float64, shape (>=1,)
        ``impulse[0]`` is incremented by the collision virial ``sum r_ij . dp_i`` (kg m^2/s).

    Returns
    -------
    int
        Number of collisions applied.
    """
    n = position.shape[0]
    done = 0
    for p in range(pairs.shape[0]):
        i = pairs[p] // n
        j = pairs[p] % n
        nx = position[i, 0] - position[j, 0]
        ny = position[i, 1] - position[j, 1]
        if periodic:
            nx -= width * round(nx / width)
            ny -= height * round(ny / height)
        dvx = velocity[i, 0] - velocity[j, 0]
        dvy = velocity[i, 1] - velocity[j, 1]
        if nx * dvx + ny * dvy >= 0.0:  # separating already: leave it (seed's directional check)
            continue
        v1x, v1y, v2x, v2y = elastic_response(
            mass[i], mass[j], nx, ny, velocity[i, 0], velocity[i, 1], velocity[j, 0], velocity[j, 1]
        )
        impulse[0] += mass[i] * (nx * (v1x - velocity[i, 0]) + ny * (v1y - velocity[i, 1]))
        velocity[i, 0] = v1x
        velocity[i, 1] = v1y
        velocity[j, 0] = v2x
        velocity[j, 1] = v2y
        done += 1
    return done
