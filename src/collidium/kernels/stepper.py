"""The seed report's collision method: after a plain drift, resolve overlapping pairs.

Overlapping pairs are found through a cell grid, then handled one by one in index order (i, then j):
a pair is resolved only if it is still approaching with the velocities it has by then (seed 4.1:
the directional check, and pairwise handling in a fixed order).

Finding the pairs is parallel, yet its result does not depend on the number of threads. The
particles are kept sorted into cells, with copies of their centres (and radii) side by side in cell
order: a counting sort the first time (`sort_into_cells`), then from one step to the next only the
few particles that changed cell are moved (`update_cells`). Each pair of neighbouring cells is
searched once, by one thread (`overlapping_pairs`), and the pairs found are sorted by their code
``i * N + j``, which also makes the order of the particles within a cell irrelevant. Only the
resolution, which touches the few overlapping pairs, is sequential.

Work arrays of particle indices and cells may be int32 or int64 (int32 halves their memory
traffic, which is most of the cost).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.cells import grid_shape
from collidium.kernels.collision import energy_change, pair_response
from collidium.kernels.sorting import radix_sort, sort_nearly_sorted

#: Cast to an unsigned index. Numba wraps negative indices around; with an unsigned one it need
#: not check, which makes the random reads of a gather about twice as fast.
_u = numba.uint64

#: Cells per particle the grid aims at (cells are never narrower than the largest diameter).
#: Measured fastest at packing fraction 0.3 (cells about two diameters wide there): fewer cells
#: mean fewer particles changing cell and less to sort, more mean fewer pairs to test.
CELLS_PER_PARTICLE = 0.65

#: Cells are this much wider than the largest diameter, so that round-off in the cell index can
#: never put two touching disks two cells apart.
_CELL_MARGIN = 1e-9


def step_grid(
    width: float, height: float, max_diameter: float, n: int, periodic: bool
) -> tuple[int, int, bool]:
    """Grid for `sort_into_cells` and `overlapping_pairs`.

    Parameters
    ----------
    width, height : float
        Sides of the grid's window in m (`cells.grid_window`: the box itself when periodic).
    max_diameter : float
        Largest disk diameter in m.
    n : int
        Number of particles.
    periodic : bool
        Periodic box.

    Returns
    -------
    tuple
        ``(ncx, ncy, general)``. ``general`` asks for the search that visits every neighbour cell
        under every periodic shift, as the seed's method did on its own grid: in a periodic box
        of fewer than three cells a side, a pair can be met under two shifts and is then listed
        twice, so that grid (`cells.grid_shape`) is kept there to list exactly the same pairs.
    """
    if max_diameter <= 0.0 or n < 2:
        return 1, 1, True  # no pairs: every point is skipped, a lone disk meets none

    old = grid_shape(width, height, max_diameter, n)
    if periodic and min(old) < 3:
        return old[0], old[1], True
    cell = max(
        max_diameter * (1.0 + _CELL_MARGIN), math.sqrt(width * height / (CELLS_PER_PARTICLE * n))
    )
    ncx = max(1, int(width // cell))
    ncy = max(1, int(height // cell))
    if periodic and min(ncx, ncy) < 3:
        return old[0], old[1], True
    return ncx, ncy, False


@numba.njit(cache=True, inline="always")
def _cell(x: float, low: float, cell: float, count: int) -> int:
    """Index along one axis of the cell holding ``x`` (clamped), as `cells.cell_index`."""
    k = math.floor((x - low) / cell)
    return min(max(k, 0), count - 1)


@numba.njit(cache=True)
def chunk_count(n: int) -> int:
    """Chunks of particles handled in parallel: a fixed number, whatever the thread count."""
    return max(1, min(64, n // 4096))


@numba.njit(cache=True, inline="always")
def _share_starts(counts: np.ndarray, starts: np.ndarray) -> None:
    """Turn ``counts[p, b]``, how many of chunk p's items go to bucket b, into where chunk p's
    share of bucket b begins (buckets in order, chunks in order within a bucket); ``starts``
    (B + 1,) gets where each bucket begins, and the total."""
    filled = 0
    for b in range(counts.shape[1]):
        starts[b] = filled
        for p in range(counts.shape[0]):
            count = counts[p, b]
            counts[p, b] = filled
            filled += count
    starts[counts.shape[1]] = filled


@numba.njit(cache=True, parallel=True)
def radius_summary(radius: np.ndarray, copy: np.ndarray) -> tuple[bool, bool, float]:
    """Compare the radii with ``copy`` (made equal if they differ) and summarise them.

    Parameters
    ----------
    radius, copy : ndarray of float64, shape (N,)
        Radii in m, and those seen last time.

    Returns
    -------
    tuple
        ``(changed, uniform, largest)``: whether they differ from ``copy``, whether all are equal,
        and the largest radius in m (0 if none).
    """
    n = radius.shape[0]
    chunks = chunk_count(n)
    differs = np.zeros(chunks, dtype=np.bool_)
    varies = np.zeros(chunks, dtype=np.bool_)
    largest = np.zeros(chunks)
    first = radius[0] if n > 0 else 0.0
    for p in numba.prange(chunks):
        big = 0.0
        other = False
        unequal = False
        for i in range(_u(p * n // chunks), _u((p + 1) * n // chunks)):
            r = radius[i]
            big = max(big, r)
            other |= r != copy[i]
            unequal |= r != first
        # Written once per chunk: entries of one cache line written by several threads in a loop
        # would bounce the line between their caches.
        largest[p] = big
        differs[p] = other
        varies[p] = unequal
    changed = differs.any()
    if changed:
        copy[:] = radius
    return bool(changed), not varies.any(), float(largest.max())


@numba.njit(cache=True, parallel=True)
def sort_into_cells(
    position: np.ndarray,
    radius: np.ndarray,
    uniform: bool,
    window: np.ndarray,
    ncx: int,
    ncy: int,
    band_index: np.ndarray,
    band_xy: np.ndarray,
    band_r: np.ndarray,
    cursor: np.ndarray,
    order: np.ndarray,
    key: np.ndarray,
    start: np.ndarray,
    cell_xy: np.ndarray,
    cell_r: np.ndarray,
) -> None:
    """Stable counting sort of the particles into cells ``c = cx + ncx * cy``, in two passes.

    First into rows of cells (in parallel over chunks of particles, each chunk with its own row
    counts), then each row into its cells (in parallel over rows). The result is unique, so it
    does not depend on the number of threads. For a first sort; `update_cells` then follows the
    particles from step to step.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m, inside the box.
    radius : ndarray, shape (N,)
        Radii in m.
    uniform : bool
        All radii are equal: ``cell_r`` is left alone (it holds that radius in every entry, in
        any order).
    window : ndarray, shape (2, 2)
        Lower-left and upper-right corners (m) of the rectangle the cells cover
        (`cells.grid_window`); particles outside it are in its edge cells.
    ncx, ncy : int
        Grid shape.
    band_index : ndarray of int, shape (N,)
        Work array (particles by row).
    band_xy, band_r : ndarray of float64, shapes (N, 2) and (N,)
        Work arrays (their centres and radii).
    cursor : ndarray of int, shape (ncx * ncy,)
        Work array.
    order : ndarray of int, shape (N,)
        Output: particle indices by cell, increasing within a cell.
    key : ndarray of int, shape (N,)
        Output: the cell of ``order[s]`` in entry ``s`` (non-decreasing).
    start : ndarray of int, shape (ncx * ncy + 1,)
        Output: the particles of cell ``c`` are at ``start[c]:start[c + 1]`` of ``order``.
    cell_xy, cell_r : ndarray of float64, shapes (N, 2) and (N,)
        Output: centre and radius of ``order[s]`` in entry ``s`` (m), read contiguously by the
        search.
    """
    n = position.shape[0]
    low_x, low_y = window[0, 0], window[0, 1]
    cw = (window[1, 0] - low_x) / ncx
    ch = (window[1, 1] - low_y) / ncy
    chunks = chunk_count(n)
    rows = np.zeros((chunks, ncy), dtype=np.int64)
    # Row of each particle (kept in `order` for now), counted per chunk.
    for p in numba.prange(chunks):
        for i in range(_u(p * n // chunks), _u((p + 1) * n // chunks)):
            row = _cell(position[i, 1], low_y, ch, ncy)
            order[i] = row
            rows[p, row] += 1
    # Where each chunk's share of each row begins: rows in order, chunks in order within a row.
    row_start = np.empty(ncy + 1, dtype=np.int64)
    _share_starts(rows, row_start)
    for p in numba.prange(chunks):
        for i in range(_u(p * n // chunks), _u((p + 1) * n // chunks)):
            row = order[i]
            s = _u(rows[p, row])
            rows[p, row] += 1
            band_index[s] = i
            band_xy[s, 0] = position[i, 0]
            band_xy[s, 1] = position[i, 1]
            if not uniform:
                band_r[s] = radius[i]
    # Each row into its cells (rows hold particles in index order, so cells do too).
    for row in numba.prange(ncy):
        base = row * ncx
        lo = _u(row_start[row])
        hi = _u(row_start[row + 1])
        for cx in range(ncx):
            cursor[base + cx] = 0
        for s in range(lo, hi):
            cursor[base + _cell(band_xy[s, 0], low_x, cw, ncx)] += 1
        at = row_start[row]
        for cx in range(ncx):
            count = cursor[base + cx]
            start[base + cx] = at
            cursor[base + cx] = at
            at += count
        for s in range(lo, hi):
            c = base + _cell(band_xy[s, 0], low_x, cw, ncx)
            t = _u(cursor[c])
            cursor[c] += 1
            order[t] = band_index[s]
            key[t] = c
            cell_xy[t, 0] = band_xy[s, 0]
            cell_xy[t, 1] = band_xy[s, 1]
            if not uniform:
                cell_r[t] = band_r[s]
    start[ncx * ncy] = n


@numba.njit(cache=True, error_model="numpy")  # no zero-division check on the cell widths
def _gather_chunk(
    position: np.ndarray,
    radius: np.ndarray,
    fresh_radius: bool,
    uniform: bool,
    low_x: float,
    low_y: float,
    cw: float,
    ch: float,
    ncx: int,
    ncy: int,
    order: np.ndarray,
    key: np.ndarray,
    cell_r: np.ndarray,
    data_xy: np.ndarray,
    data_r: np.ndarray,
    new_key: np.ndarray,
    movers: np.ndarray,
    lo: int,
    hi: int,
) -> int:
    """`gather_movers` for slots ``lo:hi``: returns the number of movers listed from
    ``movers[lo]``."""
    # The random reads alone first, so that many are in flight at once.
    for s in range(_u(lo), _u(hi)):
        i = _u(order[s])
        data_xy[s, 0] = position[i, 0]
        data_xy[s, 1] = position[i, 1]
    if fresh_radius and not uniform:
        for s in range(_u(lo), _u(hi)):
            data_r[s] = radius[_u(order[s])]
    elif not uniform:
        for s in range(_u(lo), _u(hi)):
            data_r[s] = cell_r[s]
    count = 0
    for s in range(lo, hi):
        us = _u(s)
        x = data_xy[us, 0]
        y = data_xy[us, 1]
        c = _cell(x, low_x, cw, ncx) + ncx * _cell(y, low_y, ch, ncy)
        new_key[us] = c
        if c != key[us]:
            movers[_u(lo + count)] = s
            count += 1
    return count


@numba.njit(cache=True, parallel=True)
def gather_movers(
    position: np.ndarray,
    radius: np.ndarray,
    fresh_radius: bool,
    uniform: bool,
    window: np.ndarray,
    ncx: int,
    ncy: int,
    order: np.ndarray,
    key: np.ndarray,
    cell_r: np.ndarray,
    data_xy: np.ndarray,
    data_r: np.ndarray,
    new_key: np.ndarray,
    movers: np.ndarray,
    moved: np.ndarray,
) -> None:
    """Centres (and radii) and cells of the particles in last step's cell order; list movers.

    Chunk ``p`` of the slots lists the slots whose particle changed cell from ``movers[lo_p]``
    on, and their number in ``moved[p]``. Radii are taken from last step's ``cell_r`` unless
    ``fresh_radius``, and not at all if ``uniform``. `update_cells` goes on from here.

    Parameters
    ----------
    position, radius, window, ncx, ncy
        As `sort_into_cells`.
    fresh_radius : bool
        The radii changed since the step before: read them from ``radius``, not ``cell_r``.
    uniform : bool
        All radii are equal: no radius is gathered.
    order, key : ndarray of int, shape (N,)
        Last step's `order_out` and `key_out` (or the output of `sort_into_cells`).
    cell_r : ndarray of float64, shape (N,)
        Last step's radii by slot.
    data_xy, data_r : ndarray of float64, shapes (N, 2) and (N,)
        Output: centre and radius of ``order[s]`` in entry ``s``.
    new_key, movers : ndarray of int, shape (N,)
        Output: each slot's new cell; the slots that changed cell, by chunk.
    moved : ndarray of int64, shape (P,)
        Output: the movers of each chunk, ``P = chunk_count(N)``.
    """
    n = order.shape[0]
    chunks = moved.shape[0]
    low_x, low_y = window[0, 0], window[0, 1]
    cw = (window[1, 0] - low_x) / ncx
    ch = (window[1, 1] - low_y) / ncy
    for p in numba.prange(chunks):
        moved[p] = _gather_chunk(
            position, radius, fresh_radius, uniform, low_x, low_y, cw, ch, ncx, ncy,
            order, key, cell_r, data_xy, data_r, new_key, movers, p * n // chunks,
            (p + 1) * n // chunks,
        )  # fmt: skip


@numba.njit(cache=True)
def _range_of(cell: int, cell_at: np.ndarray, guess: int) -> int:
    """The merge range ``p`` with ``cell_at[p] <= cell < cell_at[p + 1]``, searched from
    ``guess`` (a mover's own range, which it has seldom left)."""
    p = numba.int64(guess)  # signed: a prange index may come unsigned
    while cell < cell_at[p]:
        p -= 1
    while cell >= cell_at[p + 1]:
        p += 1
    return int(p)


@numba.njit(cache=True)
def _merge_range(
    order: np.ndarray,
    key: np.ndarray,
    data_xy: np.ndarray,
    data_r: np.ndarray,
    uniform: bool,
    new_key: np.ndarray,
    movers: np.ndarray,
    slot_lo: int,
    slot_hi: int,
    mover_lo: int,
    mover_hi: int,
    out: int,
    cell_lo: int,
    cell_hi: int,
    order_out: np.ndarray,
    key_out: np.ndarray,
    start: np.ndarray,
    cell_xy: np.ndarray,
    cell_r: np.ndarray,
) -> None:
    """Merge the stayers of slots ``slot_lo:slot_hi`` with ``movers[mover_lo:mover_hi]`` into
    the slots from ``out`` on, and write ``start`` for cells ``cell_lo:cell_hi``."""
    s = slot_lo
    m = mover_lo
    t = out
    while True:
        while s < slot_hi and new_key[_u(s)] != key[_u(s)]:  # a mover: merged from the list
            s += 1
        if s < slot_hi and (m == mover_hi or new_key[_u(s)] <= new_key[_u(movers[_u(m)])]):
            src = _u(s)
            s += 1
        elif m < mover_hi:
            src = _u(movers[_u(m)])
            m += 1
        else:
            break
        ut = _u(t)
        order_out[ut] = order[src]
        key_out[ut] = new_key[src]
        cell_xy[ut, 0] = data_xy[src, 0]
        cell_xy[ut, 1] = data_xy[src, 1]
        if not uniform:
            cell_r[ut] = data_r[src]
        t += 1
    _fill_start(key_out, out, t, cell_lo, cell_hi, start)


@numba.njit(cache=True)
def _fill_start(
    key: np.ndarray, lo: int, hi: int, cell_lo: int, cell_hi: int, start: np.ndarray
) -> None:
    """``start[c]`` for cells ``cell_lo:cell_hi``, whose particles are slots ``lo:hi`` (sorted
    by cell in ``key``). Without branches on the cell sizes, which vary at random."""
    for c in range(_u(cell_lo), _u(cell_hi)):
        start[c] = hi
    for t in range(hi - 1, lo - 1, -1):  # backwards: the first slot of a cell is written last
        start[_u(key[_u(t)])] = t
    following = hi
    for c in range(cell_hi - 1, cell_lo - 1, -1):  # empty cells start where the next one does
        following = min(start[_u(c)], following)
        start[_u(c)] = following


@numba.njit(cache=True, parallel=True)
def update_cells(
    uniform: bool,
    ncx: int,
    ncy: int,
    order: np.ndarray,
    key: np.ndarray,
    data_xy: np.ndarray,
    data_r: np.ndarray,
    new_key: np.ndarray,
    movers: np.ndarray,
    grouped: np.ndarray,
    moved: np.ndarray,
    order_out: np.ndarray,
    key_out: np.ndarray,
    start: np.ndarray,
    cell_xy: np.ndarray,
    cell_r: np.ndarray,
) -> bool:
    """Sort the particles into cells again, starting from the order of the step before.

    Particles move little in one step: the ones still in the same cell keep their order, the
    few that changed cell are sorted and merged in, in parallel over ranges of cells (each range
    takes the movers bound for its cells, in slot order, and sorts them by cell). Within a cell
    the order then depends on the history, which the pair search does not see (it sorts the
    pairs it finds); the result does not depend on the number of threads.

    The centres, radii and new cells come from `gather_movers`, called just before (from
    Python: a compiled kernel calling a parallel one breaks numba's cache,
    `pairwise.PARALLEL_DIRECT_FROM`).

    Parameters
    ----------
    uniform : bool
        All radii are equal: ``cell_r`` is left alone (it holds that radius in every entry, in
        any order).
    ncx, ncy : int
        Grid shape.
    order, key : ndarray of int, shape (N,)
        Last step's `order_out` and `key_out` (or the output of `sort_into_cells`).
    data_xy, data_r, new_key, movers, moved : ndarray
        What `gather_movers` wrote.
    grouped : ndarray of int, shape (N,)
        Work array.
    order_out, key_out : ndarray of int, shape (N,)
        Output: particle index and cell in each slot, by cell.
    start : ndarray of int, shape (ncx * ncy + 1,)
        Output: the particles of cell ``c`` are at ``start[c]:start[c + 1]`` of ``order_out``.
    cell_xy, cell_r : ndarray of float64, shapes (N, 2) and (N,)
        Output: centre and radius of ``order_out[s]`` in entry ``s`` (m). On entry, ``cell_r``
        holds last step's radii.

    Returns
    -------
    bool
        False (outputs unset) if so many particles changed cell that `sort_into_cells` is the
        faster way.
    """
    n = order.shape[0]
    ncells = ncx * ncy
    chunks = moved.shape[0]
    if moved.sum() > n // 8:
        return False
    # Ranges merged in parallel: the slots of whole cells, about n / chunks of them each.
    slot_at = np.empty(chunks + 1, dtype=np.int64)
    cell_at = np.empty(chunks + 1, dtype=np.int64)
    for p in range(chunks + 1):
        s = p * n // chunks
        while 0 < s < n and key[s - 1] == key[s]:
            s -= 1
        slot_at[p] = s
        cell_at[p] = 0 if p == 0 else (ncells if p == chunks else key[s])
    # The movers grouped by the range they are bound for, in slot order within a group.
    bound = np.zeros((chunks, chunks), dtype=np.int64)  # [chunk of slots, range]
    for q in numba.prange(chunks):
        lo = q * n // chunks
        for k in range(moved[q]):
            bound[q, _range_of(new_key[_u(movers[lo + k])], cell_at, q)] += 1
    group_at = np.empty(chunks + 1, dtype=np.int64)
    _share_starts(bound, group_at)
    for q in numba.prange(chunks):
        lo = q * n // chunks
        for k in range(moved[q]):
            s = movers[lo + k]
            p = _range_of(new_key[_u(s)], cell_at, q)
            grouped[bound[q, p]] = s
            bound[q, p] += 1
    # Each range's output starts after the stayers and movers of the cells before it.
    below = np.zeros(chunks + 1, dtype=np.int64)  # movers from slots before slot_at[p]
    for p in range(chunks + 1):
        for q in range(chunks):
            lo = q * n // chunks
            if (q + 1) * n // chunks <= slot_at[p]:
                below[p] += moved[q]
            elif lo < slot_at[p]:
                below[p] += np.searchsorted(movers[lo : lo + moved[q]], slot_at[p])
    for p in numba.prange(chunks):
        # By their new cell: they come by their old one, and most moved to a neighbouring cell.
        sort_nearly_sorted(grouped[group_at[p] : group_at[p + 1]], new_key)
        out = slot_at[p] - below[p] + group_at[p]
        if uniform:  # a constant argument: numba compiles each case on its own
            _merge_range(
                order, key, data_xy, data_r, True, new_key, grouped, slot_at[p],
                slot_at[p + 1], group_at[p], group_at[p + 1], out, cell_at[p], cell_at[p + 1],
                order_out, key_out, start, cell_xy, cell_r,
            )  # fmt: skip
        else:
            _merge_range(
                order, key, data_xy, data_r, False, new_key, grouped, slot_at[p],
                slot_at[p + 1], group_at[p], group_at[p + 1], out, cell_at[p], cell_at[p + 1],
                order_out, key_out, start, cell_xy, cell_r,
            )  # fmt: skip
    start[ncells] = n
    return True


@numba.njit(cache=True)
def _scan_shifted(
    a: int, lo: int, hi: int, sx: float, sy: float, width: float, height: float,
    order: np.ndarray, cell_xy: np.ndarray, cell_r: np.ndarray, found: np.ndarray, base: int,
    cap: int, count: int,
) -> int:  # fmt: skip
    """Pairs of slot ``a`` with slots ``lo:hi`` of a cell whose particles are seen shifted by
    ``(sx * width, sy * height)`` (across a periodic edge).

    The separation is computed as the seed's search did, from the lower index i to the image of
    j, so that the overlap test rounds exactly as it did.
    """
    n = order.shape[0]
    ia = order[a]
    xa = cell_xy[a, 0]
    ya = cell_xy[a, 1]
    ra = cell_r[a]
    for b in range(lo, hi):
        ib = order[b]
        xb = cell_xy[b, 0]
        yb = cell_xy[b, 1]
        rb = cell_r[b]
        if ia < ib:
            dx = (xb + sx * width) - xa
            dy = (yb + sy * height) - ya
        else:
            dx = (xa - sx * width) - xb
            dy = (ya - sy * height) - yb
        sigma = ra + rb
        if dx * dx + dy * dy < sigma * sigma and rb > 0.0:
            if count < cap:
                found[base + count] = min(ia, ib) * n + max(ia, ib)
            count += 1
    return count


@numba.njit(cache=True)
def _search_rows(
    rows: tuple[int, int], start: np.ndarray, order: np.ndarray, cell_xy: np.ndarray,
    cell_r: np.ndarray, uniform: bool, r0: float, ncx: int, ncy: int, width: float,
    height: float, periodic: bool, found: np.ndarray, base: int, cap: int,
) -> int:  # fmt: skip
    """Overlapping pairs met from rows ``rows[0]:rows[1]``: each cell against itself, its east
    neighbour and the three cells above (a half shell, so each pair of neighbour cells is
    searched once). With ``uniform``, every radius is ``r0`` (m) and ``cell_r`` is not read.

    Pairs are written to ``found[base:base + cap]`` (counted even when they do not fit); returns
    their number. (Narrowing the neighbours to those within reach of each particle was measured
    slower: it adds unpredictable branches per particle.)
    """
    n = order.shape[0]
    count = 0
    for cy in range(rows[0], rows[1]):
        row = cy * ncx
        above = cy + 1
        wrapped_above = above == ncy  # the row above lies across the periodic edge
        if wrapped_above:
            above = 0
        up = above * ncx
        has_above = periodic or not wrapped_above
        for cx in range(ncx):
            c = row + cx
            # Unshifted neighbours, in two contiguous runs of slots: the rest of this cell with
            # the east cell, and the cells above (those across a periodic edge: see below).
            east_end = start[_u(c + 2)] if cx + 1 < ncx else start[_u(c + 1)]
            above_lo = 0
            above_hi = 0
            if has_above and not wrapped_above:
                above_lo = start[_u(up + max(cx - 1, 0))]
                above_hi = start[_u(up + min(cx + 1, ncx - 1) + 1)]
            edge = periodic and (cx == 0 or cx + 1 == ncx or wrapped_above)
            for a in range(start[_u(c)], start[_u(c + 1)]):
                ua = _u(a)
                xa = cell_xy[ua, 0]
                ya = cell_xy[ua, 1]
                ra = r0 if uniform else cell_r[ua]
                if ra <= 0.0:  # points take no part in collisions
                    continue
                # One loop over both runs (fewer mispredicted loop exits than two loops).
                skip = above_lo - east_end  # from the end of the first run to the second
                for k in range(a + 1, east_end + above_hi - above_lo):
                    b = _u(k if k < east_end else k + skip)
                    # Computed from a's side whatever the index order: the square is the same.
                    dx = cell_xy[b, 0] - xa
                    dy = cell_xy[b, 1] - ya
                    rb = r0 if uniform else cell_r[b]
                    sigma = ra + rb
                    if dx * dx + dy * dy < sigma * sigma and rb > 0.0:
                        i = min(order[ua], order[b])
                        j = max(order[ua], order[b])
                        if count < cap:
                            found[base + count] = i * n + j
                        count += 1
                if edge:
                    count = _search_edges(
                        a, cx, cy, start, order, cell_xy, cell_r, ncx, width, height, up,
                        wrapped_above, found, base, cap, count,
                    )  # fmt: skip
    return count


@numba.njit(cache=True)
def _search_edges(
    a: int, cx: int, cy: int, start: np.ndarray, order: np.ndarray, cell_xy: np.ndarray,
    cell_r: np.ndarray, ncx: int, width: float, height: float, up: int, wrapped_above: bool,
    found: np.ndarray, base: int, cap: int, count: int,
) -> int:  # fmt: skip
    """The half-shell neighbours of slot ``a`` (cell ``cx, cy``) across a periodic edge."""
    sy = 1.0 if wrapped_above else 0.0
    if cx + 1 == ncx:  # east, across the right edge
        row = cy * ncx
        count = _scan_shifted(
            a, start[row], start[row + 1], 1.0, 0.0, width, height, order, cell_xy, cell_r, found,
            base, cap, count,
        )  # fmt: skip
    for ox in range(-1, 2):
        nx = cx + ox
        sx = 0.0
        if nx < 0:
            nx += ncx
            sx = -1.0
        elif nx >= ncx:
            nx -= ncx
            sx = 1.0
        if sx != 0.0 or sy != 0.0:
            count = _scan_shifted(
                a, start[up + nx], start[up + nx + 1], sx, sy, width, height, order, cell_xy,
                cell_r, found, base, cap, count,
            )  # fmt: skip
    return count


@numba.njit(cache=True)
def _search_row_general(
    cy: int, start: np.ndarray, order: np.ndarray, cell_xy: np.ndarray, cell_r: np.ndarray,
    ncx: int, ncy: int, width: float, height: float, periodic: bool, found: np.ndarray,
    base: int, cap: int, count: int,
) -> int:  # fmt: skip
    """Overlapping pairs ``(i, j)``, j > i, met from each i of row ``cy`` in its 9 neighbour
    cells, under the periodic shift of each (a cell may appear under several shifts)."""
    n = order.shape[0]
    for cx in range(ncx):
        c = cx + ncx * cy
        for a in range(start[c], start[c + 1]):
            i = order[a]
            xi = cell_xy[a, 0]
            yi = cell_xy[a, 1]
            ri = cell_r[a]
            if ri <= 0.0:
                continue
            for oy in range(-1, 2):
                ny = cy + oy
                if not periodic and (ny < 0 or ny >= ncy):
                    continue
                sy = (ny - ny % ncy) // ncy
                for ox in range(-1, 2):
                    nx = cx + ox
                    if not periodic and (nx < 0 or nx >= ncx):
                        continue
                    sx = (nx - nx % ncx) // ncx
                    nc = nx % ncx + ncx * (ny % ncy)
                    for b in range(start[nc], start[nc + 1]):
                        j = order[b]
                        rj = cell_r[b]
                        if j > i and rj > 0.0:
                            dx = cell_xy[b, 0] + sx * width - xi
                            dy = cell_xy[b, 1] + sy * height - yi
                            sigma = ri + rj
                            if dx * dx + dy * dy < sigma * sigma:
                                if count < cap:
                                    found[base + count] = i * n + j
                                count += 1
    return count


@numba.njit(cache=True, parallel=True)
def overlapping_pairs(
    start: np.ndarray,
    order: np.ndarray,
    cell_xy: np.ndarray,
    cell_r: np.ndarray,
    uniform: bool,
    r0: float,
    ncx: int,
    ncy: int,
    width: float,
    height: float,
    periodic: bool,
    general: bool,
    chunks: int,
    found: np.ndarray,
    scratch: np.ndarray,
) -> int:
    """Overlapping pairs, encoded ``i * N + j`` (i < j) and sorted, written to ``found``.

    Parameters
    ----------
    start, order : ndarray of int
        The particles sorted into cells, as from `sort_into_cells` or `update_cells`.
    cell_xy, cell_r : ndarray of float64, shapes (N, 2) and (N,)
        Their centres and radii in m, in the same order.
    uniform : bool
        Every radius is ``r0``, in m (``cell_r`` must hold it too, for the periodic edges).
    r0 : float
        The radius when ``uniform``.
    ncx, ncy : int
        Grid shape.
    width, height : float
        Box sides in m (for periodic shifts).
    periodic : bool
        Periodic box: neighbour cells wrap around.
    general : bool
        Use the search that visits every neighbour cell under every shift (see `step_grid`).
    chunks : int
        Number of bands of rows searched in parallel, 1 to ``ncy``; each fills its own
        ``found.shape[0] // chunks`` entries of ``found``.
    found : ndarray of int64, shape (M,)
        Output: the sorted pair codes at ``found[:count]`` when the return value is ``count >= 0``.
    scratch : ndarray of int64, shape (M,)
        Work array for the sort.

    Returns
    -------
    int
        The number of overlapping pairs, or ``-need`` if a band found ``need`` pairs, more than
        its share: call again with ``found`` of at least ``chunks * need`` entries.
    """
    cap = found.shape[0] // chunks
    counts = np.zeros(chunks, dtype=np.int64)
    for k in numba.prange(chunks):
        base = k * cap
        rows = (k * ncy // chunks, (k + 1) * ncy // chunks)
        if general:
            count = 0
            for cy in range(rows[0], rows[1]):
                count = _search_row_general(
                    cy, start, order, cell_xy, cell_r, ncx, ncy, width, height, periodic, found,
                    base, cap, count,
                )  # fmt: skip
        # Constant flags: numba compiles each case on its own, without tests in the loops.
        elif periodic and uniform:
            count = _search_rows(
                rows, start, order, cell_xy, cell_r, True, r0, ncx, ncy, width, height, True,
                found, base, cap,
            )  # fmt: skip
        elif periodic:
            count = _search_rows(
                rows, start, order, cell_xy, cell_r, False, r0, ncx, ncy, width, height, True,
                found, base, cap,
            )  # fmt: skip
        elif uniform:
            count = _search_rows(
                rows, start, order, cell_xy, cell_r, True, r0, ncx, ncy, width, height, False,
                found, base, cap,
            )  # fmt: skip
        else:
            count = _search_rows(
                rows, start, order, cell_xy, cell_r, False, r0, ncx, ncy, width, height, False,
                found, base, cap,
            )  # fmt: skip
        counts[k] = count
    need = counts.max()
    if need > cap:
        return -need
    # Gather the bands' pairs at the front (moving left only), then put them in index order.
    total = 0
    for k in range(chunks):
        for m in range(counts[k]):
            found[total + m] = found[k * cap + m]
        total += counts[k]
    _sort_pairs(found[:total], scratch[:total], order.shape[0])
    return total


@numba.njit(cache=True)
def _sort_pairs(codes: np.ndarray, scratch: np.ndarray, n: int) -> None:
    """Sort pair codes ``i * n + j`` in place (a radix sort above a few hundred)."""
    if codes.shape[0] < 256:
        codes.sort()
        return
    bits = 1
    while (1 << bits) < n * n:
        bits += 1
    radix_sort(codes, scratch, bits, codes[:0], scratch[:0])


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
    restitution: float,
    elastic_below: float,
    heat: np.ndarray,
) -> int:
    """Apply the collision response to each listed pair that is approaching, in list order.

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
    restitution, elastic_below : float
        The pairs' restitution and the approach speed (m/s) below which they bounce elastically
        (`collidium.kernels.collision.pair_response`).
    heat : ndarray of float64, shape (>=1,)
        ``heat[0]`` is incremented by the kinetic energy inelastic collisions take (J, < 0).

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
        u1x, u1y, u2x, u2y = velocity[i, 0], velocity[i, 1], velocity[j, 0], velocity[j, 1]
        v1x, v1y, v2x, v2y = pair_response(
            mass[i], mass[j], nx, ny, u1x, u1y, u2x, u2y, restitution, elastic_below
        )
        impulse[0] += mass[i] * (nx * (v1x - u1x) + ny * (v1y - u1y))
        if restitution != 1.0:
            heat[0] += energy_change(mass[i], mass[j], u1x, u1y, u2x, u2y, v1x, v1y, v2x, v2y)
        velocity[i, 0] = v1x
        velocity[i, 1] = v1y
        velocity[j, 0] = v2x
        velocity[j, 1] = v2y
        done += 1
    return done
