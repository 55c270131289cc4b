"""Uniform cell grid: linked lists of particles per cell, neighbour cells, overlaps.

Cells are at least one largest diameter wide, so two disks in contact always sit in the same or
adjacent cells. Radius-0 particles are in the grid too (the event engine wraps particles through
cell crossings in a periodic box) but every pair loop skips them: they never collide.

A grid covers a window, `grid_window`: the periodic box itself (its cells wrap), else the disks'
bounding box within the vessel's, so that disks packed in a corner of a large vessel are not all
in a few cells (which makes every search over neighbours quadratic). The cells along the
window's edges reach on to infinity (indices are clamped): a disk outside the window is still in
the cell next to the window, and disks in contact are still in the same or adjacent cells.
"""

from __future__ import annotations

import math
import sys

import numba
import numpy as np
from numpy.typing import ArrayLike

from collidium.kernels.compilation import inlined


@inlined
def cell_index(x: float, low: float, cell: float, count: int) -> int:
    """Index along one axis of the cell holding coordinate ``x`` (clamped to the grid), for a
    grid starting at ``low`` with cells ``cell`` wide (m)."""
    k = math.floor((x - low) / cell)
    return min(max(k, 0), count - 1)


@numba.njit(cache=True)
def fill_cells(
    position: np.ndarray,
    radius: np.ndarray,
    low_x: float,
    low_y: float,
    cell_width: float,
    cell_height: float,
    ncx: int,
    ncy: int,
    cell_of: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    prev: np.ndarray,
) -> None:
    """Put every particle in its cell's doubly linked list.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m.
    radius : ndarray, shape (N,)
        Radii in m (unused; kept so all cell kernels take the same arrays).
    low_x, low_y : float
        Lower-left corner of the grid's window in m.
    cell_width, cell_height : float
        Cell sides in m.
    ncx, ncy : int
        Cells along x and y.
    cell_of, head, next_, prev : ndarray of int64
        Outputs: cell of each particle (N,), first particle of each cell (ncx*ncy,), and the
        next/previous particle in the same cell (N,); -1 ends a list.
    """
    head[:] = -1
    # Insert in reverse index order so each list reads in increasing index order.
    for i in range(position.shape[0] - 1, -1, -1):
        next_[i] = -1
        prev[i] = -1
        c = cell_index(position[i, 0], low_x, cell_width, ncx) + ncx * cell_index(
            position[i, 1], low_y, cell_height, ncy
        )
        cell_of[i] = c
        first = head[c]
        next_[i] = first
        if first >= 0:
            prev[first] = i
        head[c] = i


@inlined
def neighbour_cell(cx, cy, ox, oy, ncx, ncy, periodic, width, height):
    """The cell at offset ``(ox, oy)`` from cell ``(cx, cy)``, and the shift to add to the
    positions of its particles to reach the image next to ``(cx, cy)``.

    Returns
    -------
    tuple
        ``(cell, sx, sy)``: the cell index ``x + ncx * y``, or -1 past a reflecting wall, and the
        shift in m (a whole box side across a periodic edge, else 0).
    """
    nx = cx + ox
    ny = cy + oy
    sx = 0.0
    sy = 0.0
    if nx < 0 or nx >= ncx or ny < 0 or ny >= ncy:
        if not periodic:
            return -1, sx, sy
        if nx < 0 or nx >= ncx:
            sx = -width if nx < 0 else width
            nx = nx + ncx if nx < 0 else nx - ncx
        if ny < 0 or ny >= ncy:
            sy = -height if ny < 0 else height
            ny = ny + ncy if ny < 0 else ny - ncy
    return nx + ncx * ny, sx, sy


@numba.njit(cache=True)
def first_overlap(
    position: np.ndarray,
    radius: np.ndarray,
    width: float,
    height: float,
    periodic: bool,
    window: np.ndarray,
    ncx: int,
    ncy: int,
) -> tuple[int, int]:
    """The overlapping pair ``(i, j)``, i < j, with the smallest i then j, or ``(-1, -1)``.

    ``width`` and ``height`` are the box's sides (m), for the periodic images; ``window``,
    ``[[x0, y0], [x1, y1]]`` (m), is the rectangle the ``ncx`` by ``ncy`` cells cover (the box
    itself when periodic, `grid_window`). Two disks overlap when their centres are closer than
    the sum of their radii by more than a relative 1e-12 (round-off). Radius-0 particles never
    overlap anything. Grids under 3 cells wide see a cell under several periodic shifts, so every
    image within reach is considered.
    """
    n = position.shape[0]
    cell_of = np.empty(n, dtype=np.int32)
    head = np.empty(ncx * ncy, dtype=np.int32)
    next_ = np.empty(n, dtype=np.int32)
    prev = np.empty(n, dtype=np.int32)
    low_x, low_y = window[0, 0], window[0, 1]
    cell_width = (window[1, 0] - low_x) / ncx
    cell_height = (window[1, 1] - low_y) / ncy
    fill_cells(position, radius, low_x, low_y, cell_width, cell_height, ncx, ncy, cell_of, head,
               next_, prev)  # fmt: skip
    for i in range(n):
        if radius[i] <= 0.0:
            continue
        best_j = -1
        for oy in range(-1, 2):
            for ox in range(-1, 2):
                c, sx, sy = neighbour_cell(
                    cell_of[i] % ncx, cell_of[i] // ncx, ox, oy, ncx, ncy, periodic, width, height
                )
                if c < 0:
                    continue
                j = head[c]
                while j >= 0:
                    if j > i and radius[j] > 0.0 and (best_j < 0 or j < best_j):
                        dx = position[j, 0] + sx - position[i, 0]
                        dy = position[j, 1] + sy - position[i, 1]
                        sigma = radius[i] + radius[j]
                        if dx * dx + dy * dy < sigma * sigma * (1.0 - 1e-12):
                            best_j = j
                    j = next_[j]
        if best_j >= 0:
            return i, best_j
    return -1, -1


@numba.njit(cache=True)
def bounding_box(position: np.ndarray) -> tuple[float, float, float, float]:
    """``(x0, y0, x1, y1)`` (m): the smallest rectangle holding every point of ``position``
    (N, 2), N >= 1."""
    x0 = x1 = position[0, 0]
    y0 = y1 = position[0, 1]
    for i in range(1, position.shape[0]):
        x, y = position[i, 0], position[i, 1]
        x0, x1 = min(x0, x), max(x1, x)
        y0, y1 = min(y0, y), max(y1, y)
    return x0, y0, x1, y1


#: Disks from which a grid covers only their surroundings: fewer are searched quickly whatever
#: the grid, and a small scene keeps the whole vessel's few cells (and so the same round-off as
#: ever: no cell crossings where there were none).
WINDOW_FROM = 4096

#: The window of a grid reaches past the disks' bounding box by this share of its larger side
#: (and at least a diameter): disks that spread out leave it only after moving that far, and
#: each new window is larger by that much (`collidium.collisions` makes a new one then).
WINDOW_MARGIN = 0.25


def grid_window(
    position: np.ndarray, diameter: float, extent: ArrayLike, periodic: bool
) -> np.ndarray:
    """The rectangle ``[[x0, y0], [x1, y1]]`` (m) a cell grid covers.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Disk centres in m.
    diameter : float
        Largest diameter in m.
    extent : array_like, shape (2,)
        Sides (m) of the vessel's bounding box, centred on the origin.
    periodic : bool
        A periodic box: the grid then covers the box, whose cells wrap.

    Returns
    -------
    ndarray, shape (2, 2)
        The disks' bounding box grown by `WINDOW_MARGIN` of its larger side and a diameter on
        every side, within the vessel's bounding box; that box itself when periodic, for fewer
        than `WINDOW_FROM` disks, or when that leaves no area (point particles in a line).
    """
    half = 0.5 * np.asarray(extent, dtype=np.float64)
    box = np.array([-half, half])
    if periodic or position.shape[0] < WINDOW_FROM:
        return box
    x0, y0, x1, y1 = bounding_box(position)
    reach = diameter + WINDOW_MARGIN * max(x1 - x0, y1 - y0)
    low = np.maximum(np.array([x0, y0]) - reach, -half)
    high = np.minimum(np.array([x1, y1]) + reach, half)
    return np.array([low, high]) if (high > low).all() else box


def window_sides(window: np.ndarray) -> tuple[float, float]:
    """Width and height (m) of a window ``[[x0, y0], [x1, y1]]``."""
    return float(window[1, 0] - window[0, 0]), float(window[1, 1] - window[0, 1])


def grid_shape(width: float, height: float, max_diameter: float, n: int) -> tuple[int, int]:
    """Cells along x and y of a window ``width`` by ``height`` (m): at least one diameter wide,
    at most about 2 cells per particle."""
    if max_diameter <= 0.0:
        return 1, 1
    # A subnormal diameter overflows the ratio to inf: any count past the budget ends the same.
    ncx = max(1, int(min(width // max_diameter, sys.float_info.max)))
    ncy = max(1, int(min(height // max_diameter, sys.float_info.max)))
    budget = max(16, 2 * n)
    while ncx * ncy > budget:
        ncx = max(1, ncx // 2)
        ncy = max(1, ncy // 2)
    return ncx, ncy


#: Cells per particle at most in the event engine's grid (a dilute gas gets cells wider than a
#: diameter, so the grid's memory stays about that many int32 per particle).
EVENT_CELLS_PER_PARTICLE = 3

#: Cells per particle at most in the grid of a scene of fewer than `SMALL_SCENE` particles,
#: whose arrays stay in the caches, with no gravity: smaller cells there leave fewer pairs to
#: test at each prediction (pool-break 7-11% faster than with 3, piston 3-4%, the other presets
#: within 2%). From about 1e4 particles on, the grid's own memory traffic costs more than the
#: pairs it spares. Where a crossing costs more, the extra crossings cost more than they spare:
#: under a gravity the engine carries, where a disk meets a cell's edge at a root of a
#: quadratic (atmosphere 10% slower), and in a vessel with segments, which every prediction
#: tests (effusion 3% slower).
SMALL_SCENE_CELLS_PER_PARTICLE = 6

#: Particles from which the event grid takes `EVENT_CELLS_PER_PARTICLE`.
SMALL_SCENE = 16_384


def event_grid_shape(
    width: float,
    height: float,
    max_diameter: float,
    n: int,
    falls: bool = False,
    segments: int = 0,
) -> tuple[int, int]:
    """Cells along x and y of a window (m) for the event engine: as small as one largest
    diameter (the fewest neighbours to test per prediction; measured fastest at packing 0.3), at
    most `SMALL_SCENE_CELLS_PER_PARTICLE` cells per particle below `SMALL_SCENE` particles that
    do not fall (under a gravity the engine carries: ``falls``) in a vessel without
    ``segments``, and `EVENT_CELLS_PER_PARTICLE` otherwise."""
    if max_diameter <= 0.0:
        return 1, 1
    small = n < SMALL_SCENE and not falls and segments == 0
    per_particle = SMALL_SCENE_CELLS_PER_PARTICLE if small else EVENT_CELLS_PER_PARTICLE
    size = max(max_diameter, math.sqrt(width * height / (per_particle * max(n, 1))))
    return max(1, int(width // size)), max(1, int(height // size))
