"""Initial conditions: random non-overlapping positions, random velocities and charges, the rack.

Every generator that draws random numbers takes a `numpy.random.Generator` and is deterministic
given its state: the same generator state gives bitwise-identical arrays.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from collidium.errors import InputError
from collidium.kernels.placement import place_disks
from collidium.state import FloatArray
from collidium.vessels import Vessel

#: Candidate batches tried by `random_positions` before it gives up.
MAX_BATCHES = 200

#: Densest packing fraction of equal disks in the plane (hexagonal), pi / (2 sqrt(3)).
HEXAGONAL_PACKING = math.pi / (2.0 * math.sqrt(3.0))


def random_positions(
    n: int,
    radius: float | ArrayLike,
    vessel: Vessel,
    rng: np.random.Generator,
    *,
    existing: ArrayLike | None = None,
    existing_radius: ArrayLike | None = None,
    field: str = "particles.n",
    max_batches: int = MAX_BATCHES,
    region: ArrayLike | None = None,
) -> FloatArray:
    """Uniform random centres of ``n`` non-overlapping disks inside a vessel.

    Candidates are drawn in batches from ``rng`` in the vessel's bounding box, shrunk by the
    largest radius, those not inside the vessel are dropped, and the rest are accepted in order
    when they overlap no disk accepted before (random sequential adsorption,
    `collidium.kernels.placement.place_disks`). In a box every candidate is inside, so the draw
    is the box's own.

    Parameters
    ----------
    n : int
        Number of disks to place (>= 0).
    radius : float or array_like, shape (n,)
        Radii in m (>= 0). Every disk, at the largest radius, lies fully inside the vessel (also
        in a periodic box, where no disk then straddles the boundary).
    vessel : Vessel
        Where the disks go (`collidium.vessels`).
    rng : numpy.random.Generator
        Source of the candidates.
    existing : array_like, shape (M, 2), optional
        Centres in m of disks already in the vessel that the new ones must not overlap.
    existing_radius : float or array_like, shape (M,), optional
        Radii in m of the existing disks (default 0).
    field : str
        Field named in the error when the disks do not fit.
    max_batches : int
        Batches of candidates tried before giving up.
    region : array_like, shape (2, 2), optional
        Lower-left and upper-right corners (m) of a rectangle the disks must also lie in (one
        chamber of a partitioned vessel, say); the whole vessel if None.

    Returns
    -------
    ndarray, shape (n, 2)
        Centres in m.

    Raises
    ------
    InputError
        When the disks do not fit in the vessel, or ``n`` disks could not be placed after
        ``max_batches`` batches (too dense for random placement).
    """
    radii = _radii(radius, n, "particles.radius")
    old = np.zeros((0, 2)) if existing is None else np.asarray(existing, np.float64).reshape(-1, 2)
    m = old.shape[0]
    old_radii = _radii(0.0 if existing_radius is None else existing_radius, m, "existing_radius")
    r_max = float(radii.max(initial=0.0))
    if n == 0:
        return np.zeros((0, 2))
    width, height = (float(side) for side in vessel.size)
    if vessel.periodic and m:
        reach = r_max + float(old_radii.max())
        old, old_radii = _with_edge_images(old, old_radii, width, height, reach)
        m = old.shape[0]
    if 2.0 * r_max > min(width, height) or vessel.available_area(r_max) <= 0.0:
        fits = f"do not fit in the {vessel.describe()}"
        raise InputError(field, f"disks of radius {r_max:g} m {fits}")
    _check_density(n, radii, old_radii, vessel, field)

    all_radii = np.concatenate([old_radii, radii])
    position = np.zeros((m + n, 2))
    position[:m] = old
    low, high = _candidate_box(vessel, r_max, region, field)
    lo, cell, ncx, ncy = _placement_grid(old, low, high, float(all_radii.max()), m + n)
    head, next_ = _cell_lists(old, lo, cell, ncx, ncy, m + n)
    placed = m
    for _ in range(max_batches):
        batch = max(256, 2 * (m + n - placed))
        candidates = rng.uniform(low, high, size=(batch, 2))
        inside = np.ones(batch, dtype=bool)
        inside[vessel.outside(candidates, np.full(batch, r_max))] = False
        placed = place_disks(
            candidates[inside], all_radii, placed, position, lo, cell, ncx, ncy, head, next_
        )
        if placed == m + n:
            return position[m:].copy() if m else position
    raise InputError(
        field,
        f"too dense: placed only {placed - m} of {n} disks of radius {r_max:g} m in the "
        f"{vessel.describe()} after {max_batches} tries; use fewer or smaller disks or a "
        "larger vessel",
    )


def _placement_grid(
    existing: FloatArray, low: FloatArray, high: FloatArray, r_max: float, count: int
) -> tuple[FloatArray, float, int, int]:
    """``(lower-left corner, cell side, ncx, ncy)`` of the grid that finds overlaps: over the
    candidates' box and the existing disks (not the whole vessel, so that disks placed in a
    small region are not all in a few cells), cells at least a diameter wide, about one disk per
    cell, and never more than ~4 ``count`` cells even in a very elongated box."""
    if existing.shape[0]:
        low = np.minimum(low, existing.min(axis=0))
        high = np.maximum(high, existing.max(axis=0))
    width, height = (float(side) for side in high - low)
    cell = max(
        2.0 * r_max,
        math.sqrt(width * height / count),
        max(width, height) / (4 * count + 16),
    )
    return low, cell, max(1, math.ceil(width / cell)), max(1, math.ceil(height / cell))


def _candidate_box(
    vessel: Vessel, r_max: float, region: ArrayLike | None, field: str
) -> tuple[FloatArray, FloatArray]:
    """Corners (m) of the box candidate centres are drawn in: the vessel's bounding box, cut
    to ``region`` when given, shrunk by the largest radius."""
    low, high = vessel.bounds[0] + r_max, vessel.bounds[1] - r_max
    if region is None:
        return low, high
    corners = np.asarray(region, dtype=np.float64)
    low, high = np.maximum(low, corners[0] + r_max), np.minimum(high, corners[1] - r_max)
    if not (low < high).all():
        region_field = field.rsplit(".", 1)[0] + ".region"
        raise InputError(region_field, f"leaves no room for disks of radius {r_max:g} m in the "
                                       f"{vessel.describe()}")  # fmt: skip
    return low, high


def _with_edge_images(
    position: FloatArray, radius: FloatArray, width: float, height: float, reach: float
) -> tuple[FloatArray, FloatArray]:
    """Disks (M, 2) plus their periodic images that come within ``reach`` (m) of the box."""
    size = np.array([width, height])
    shifted = [position]
    radii = [radius]
    for sx in (-1, 0, 1):
        for sy in (-1, 0, 1):
            if sx == sy == 0:
                continue
            image = position + size * np.array([sx, sy])
            near = (np.abs(image) <= 0.5 * size + reach).all(axis=1)
            shifted.append(image[near])
            radii.append(radius[near])
    return np.concatenate(shifted), np.concatenate(radii)


def _radii(value: float | ArrayLike, n: int, field: str) -> FloatArray:
    """A fresh (n,) float64 array of radii, checked >= 0 and finite."""
    array = np.array(value, dtype=np.float64)
    array = np.full(n, float(array)) if array.ndim == 0 else array.reshape(-1)
    if array.shape != (n,):
        raise InputError(field, f"expected a scalar or {n} values, got {array.size}")
    if not np.isfinite(array).all() or (array < 0).any():
        raise InputError(field, "radii must be finite numbers >= 0")
    return array


def _check_density(
    n: int, radii: FloatArray, old_radii: FloatArray, vessel: Vessel, field: str
) -> None:
    """Refuse at once a covered area beyond the densest possible packing."""
    covered = math.pi * float(np.sum(radii**2) + np.sum(old_radii**2))
    room = HEXAGONAL_PACKING * vessel.area
    if covered > room:
        raise InputError(
            field,
            f"too dense: {n} disks cover {covered:g} m^2, more than the {room:g} m^2 that fit "
            f"in the {vessel.describe()}",
        )


def _cell_lists(
    position: FloatArray, lo: FloatArray, cell: float, ncx: int, ncy: int, capacity: int
) -> tuple[np.ndarray, np.ndarray]:
    """Linked cell lists ``head`` (ncx*ncy,) and ``next_`` (capacity,) holding ``position``."""
    head = np.full(ncx * ncy, -1, dtype=np.int64)
    next_ = np.full(capacity, -1, dtype=np.int64)
    m = position.shape[0]
    if m == 0:
        return head, next_
    cx = np.clip(np.floor((position[:, 0] - lo[0]) / cell).astype(np.int64), 0, ncx - 1)
    cy = np.clip(np.floor((position[:, 1] - lo[1]) / cell).astype(np.int64), 0, ncy - 1)
    cells = cx + ncx * cy
    order = np.argsort(cells, kind="stable")
    sorted_cells = cells[order]
    same = sorted_cells[1:] == sorted_cells[:-1]
    next_[order[:-1][same]] = order[1:][same]
    first = np.concatenate([[True], ~same])
    head[sorted_cells[first]] = order[first]
    return head, next_


def hexagonal_positions(vessel: Vessel, radius: float, packing: float) -> FloatArray:
    """Centres of a hexagonal lattice of disks at ``packing`` (the share of the plane they
    cover, at most pi / sqrt(12) = 0.9069), those whose disk lies inside the vessel: the way to
    start a gas denser than random placement reaches (about 0.55).

    Parameters
    ----------
    vessel : Vessel
        Where the disks go; the lattice starts at the lower-left corner of its bounding box.
    radius : float
        Disk radius in m (> 0).
    packing : float
        Share of the plane the lattice's disks cover (0 < packing <= 0.9069).

    Returns
    -------
    ndarray, shape (N, 2)
        Centres in m, row by row.
    """
    spacing = lattice_spacing(radius, packing)
    (x0, y0), (x1, y1) = vessel.bounds
    rows = np.arange(y0, y1, spacing * math.sqrt(3.0) / 2.0)
    columns = np.arange(x0, x1, spacing)
    x = columns[None, :] + (np.arange(rows.size) % 2)[:, None] * (spacing / 2.0)
    y = np.broadcast_to(rows[:, None], x.shape)
    centres = np.column_stack([x.ravel(), y.ravel()])
    # A hair more than the radius: no disk starts touching a wall.
    inside = np.ones(len(centres), dtype=bool)
    inside[vessel.outside(centres, np.full(len(centres), radius * (1.0 + 1e-6)))] = False
    return centres[inside]


#: The densest packing of equal disks, the hexagonal lattice's: pi / sqrt(12).
CLOSE_PACKING = math.pi / math.sqrt(12.0)


def lattice_spacing(radius: float, packing: float) -> float:
    """Distance between neighbouring centres (m) of a hexagonal lattice of disks of ``radius`` (m)
    covering the share ``packing`` of the plane: each disk has a cell of ``sqrt(3)/2 a^2``."""
    return radius * math.sqrt(2.0 * math.pi / (math.sqrt(3.0) * packing))


def hexagonal_block(
    columns: int, rows: int, radius: float, packing: float, low: tuple[float, float]
) -> FloatArray:
    """Centres of ``columns x rows`` disks on a hexagonal lattice at ``packing``, its block
    ``columns a`` wide and ``rows a sqrt(3)/2`` high from the corner ``low`` (m), ``a`` the
    `lattice_spacing`; odd rows shifted by ``a/2``. With ``rows`` even the block tiles the plane:
    a periodic box of its size holds a perfect lattice.

    Returns
    -------
    ndarray, shape (columns * rows, 2)
        Centres in m, row by row.
    """
    spacing = lattice_spacing(radius, packing)
    height = spacing * math.sqrt(3.0) / 2.0
    row = np.repeat(np.arange(rows), columns)
    column = np.tile(np.arange(columns), rows)
    x = low[0] + (column + 0.25 + 0.5 * (row % 2)) * spacing
    y = low[1] + (row + 0.5) * height
    return np.column_stack([x, y]).astype(np.float64)


def uniform_velocities(n: int, speed: float, rng: np.random.Generator) -> FloatArray:
    """Velocities with each component uniform in ``[-speed, speed]``.

    Parameters
    ----------
    n : int
        Number of particles.
    speed : float
        Largest component in m/s (>= 0).
    rng : numpy.random.Generator
        Source of the draws.

    Returns
    -------
    ndarray, shape (n, 2)
        Velocities in m/s.
    """
    if not math.isfinite(speed) or speed < 0:
        raise InputError("particles.speed", f"must be a finite number >= 0, got {speed!r}")
    # Scale draws in [-1, 1): rng.uniform(-speed, speed) would overflow for speed near 1e308.
    return speed * rng.uniform(-1.0, 1.0, size=(n, 2))


def balanced_charges(n: int, charge: float, rng: np.random.Generator) -> FloatArray:
    """Charges ``+charge`` and ``-charge`` in equal numbers, in random order.

    Parameters
    ----------
    n : int
        Number of particles; ``n // 2`` get ``-charge``, the rest (one more when n is odd)
        ``+charge``.
    charge : float
        Magnitude in C.
    rng : numpy.random.Generator
        Source of the permutation.

    Returns
    -------
    ndarray, shape (n,)
        Charges in C.
    """
    negative = n // 2
    values = np.concatenate(
        [np.full(n - negative, float(charge)), np.full(negative, -float(charge))]
    )
    return rng.permutation(values)


def rhombus_rack(
    apex: tuple[float, float],
    rows: int,
    radius: float,
    gap: float = 0.01,
    back_tip: bool = False,
) -> FloatArray:
    """Centres of a pool-break rack: a rhombus of disks in hexagonal packing, apex pointing left.

    Columns from the apex rightwards hold 1, 2, ..., ``rows``, ..., 2 (and 1 with ``back_tip``)
    disks, centred on the apex's y; ``rows**2 - 1`` disks (``rows**2`` with the back tip).

    Parameters
    ----------
    apex : (float, float)
        Centre of the leftmost disk in m.
    rows : int
        Disks in the widest column (>= 1).
    radius : float
        Disk radius r in m (> 0).
    gap : float
        Surface gap between neighbours as a fraction of r: neighbouring centres are
        ``r * (2 + gap)`` apart.
    back_tip : bool
        Keep the last single-disk column (the tip opposite the apex).

    Returns
    -------
    ndarray, shape (rows**2 - 1, 2) or (rows**2, 2)
        Centres in m, column by column from the apex, bottom to top within a column.
    """
    spacing = radius * (2.0 + gap)
    columns = 2 * rows - 1 if back_tip else 2 * rows - 2
    rows_per_column = [j + 1 if j < rows else 2 * rows - 1 - j for j in range(columns)]
    step_x = spacing * math.sqrt(3.0) / 2.0
    centres = [
        (apex[0] + j * step_x, apex[1] + (k - 0.5 * (count - 1)) * spacing)
        for j, count in enumerate(rows_per_column)
        for k in range(count)
    ]
    return np.array(centres, dtype=np.float64).reshape(-1, 2)
