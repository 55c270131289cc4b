"""Event-driven drift of hard disks: exact free flight between exact elastic collisions.

Design (Rapaport; Donev, Torquato & Stillinger):

- Each particle keeps one next event: a pair contact, a wall contact or a crossing into the next
  cell of the grid. An indexed binary heap orders particles by that event time, ties by index.
- Positions are lazy: ``position[i]`` is where particle i was at its own time stamp
  ``stamp[i]``; at time t it is at ``position[i] + velocity[i] * (t - stamp[i])``.
- A pair event records the partner's collision count when it was predicted; if the partner has
  collided since, the event is stale and the particle is simply re-predicted.
- Cells are at least one largest diameter wide, so a particle's possible partners are in the
  9 cells around it; crossing into another cell re-predicts it against its new neighbours.

All state lives in arrays owned by the caller (`collidium.collisions.ExactCollisions`), so the queue
survives from one call to the next: with no forces, dt is only a reporting interval.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.cells import fill_cells
from collidium.kernels.collision import elastic_response

NO_EVENT = 0
PAIR = 1
WALL = 2
CELL = 3

#: Index of each entry of the ``tally`` array (counts) and of the ``impulse`` array (sums).
PAIR_COLLISIONS = 0  # tally: pair collisions; impulse: pair virial sum of r_ij . dp_i (kg m^2/s)
WALL_HITS = 1  # 4 entries: left, right, bottom, top wall (tally: hits; impulse: kg m/s received)


#: Relative size, against the particles' speeds, of an approach too slow to be anything but
#: round-off (see `contact_delay`).
CONTACT_SLACK = 1e-12


@numba.njit(cache=True, inline="always")
def contact_delay(
    dx: float, dy: float, dvx: float, dvy: float, sigma: float, slack: float = 0.0
) -> float:
    """Time until two disks touch, or inf.

    Parameters
    ----------
    dx, dy : float
        Separation ``x_j - x_i`` now, in m.
    dvx, dvy : float
        Relative velocity ``v_j - v_i`` in m/s.
    sigma : float
        Contact distance ``r_i + r_j`` in m.
    slack : float
        For a pair already in contact: the approach ``-(dx . dv)``, in m^2/s, below which it is
        taken for round-off. The elastic response reverses the normal velocity only up to
        round-off, so without this a touching cluster (a rack with no gaps) could collide again
        and again at the same instant.

    Returns
    -------
    float
        Delay in s (0 for a pair in contact that approaches by more than ``slack``), inf if the
        pair is not approaching or misses.
    """
    b = dx * dvx + dy * dvy
    if b >= 0.0:
        return math.inf
    gap = dx * dx + dy * dy - sigma * sigma
    if gap <= 0.0:
        return 0.0 if -b > slack else math.inf
    dv2 = dvx * dvx + dvy * dvy
    disc = b * b - dv2 * gap
    if disc <= 0.0:
        return math.inf
    # Stable root of dv2 t^2 + 2 b t + gap = 0 (no cancellation for grazing contacts).
    return gap / (-b + math.sqrt(disc))


@numba.njit(cache=True, inline="always")
def _before(key_a: float, a: int, key_b: float, b: int) -> bool:
    return key_a < key_b or (key_a == key_b and a < b)


@numba.njit(cache=True)
def _sift_up(slot: int, heap: np.ndarray, keys: np.ndarray, where: np.ndarray) -> int:
    item = heap[slot]
    key = keys[slot]
    while slot > 0:
        parent = (slot - 1) >> 1
        if not _before(key, item, keys[parent], heap[parent]):
            break
        heap[slot] = heap[parent]
        keys[slot] = keys[parent]
        where[heap[slot]] = slot
        slot = parent
    heap[slot] = item
    keys[slot] = key
    where[item] = slot
    return slot


@numba.njit(cache=True)
def _sift_down(slot: int, heap: np.ndarray, keys: np.ndarray, where: np.ndarray) -> None:
    n = heap.shape[0]
    item = heap[slot]
    key = keys[slot]
    while True:
        child = 2 * slot + 1
        if child >= n:
            break
        if child + 1 < n and _before(keys[child + 1], heap[child + 1], keys[child], heap[child]):
            child += 1
        if not _before(keys[child], heap[child], key, item):
            break
        heap[slot] = heap[child]
        keys[slot] = keys[child]
        where[heap[slot]] = slot
        slot = child
    heap[slot] = item
    keys[slot] = key
    where[item] = slot


@numba.njit(cache=True)
def heap_update(i: int, key: float, heap: np.ndarray, keys: np.ndarray, where: np.ndarray) -> None:
    """Give particle i the event time ``key`` and restore heap order (O(log N)).

    The heap keeps each key next to its particle index (``keys[slot]``) so that sifting reads
    contiguous memory instead of chasing ``event_time[heap[slot]]``.
    """
    slot = where[i]
    keys[slot] = key
    if _sift_up(slot, heap, keys, where) == slot:
        _sift_down(slot, heap, keys, where)


@numba.njit(cache=True)
def heap_build(event_time: np.ndarray, heap: np.ndarray, keys: np.ndarray, where: np.ndarray):
    """Heap of all particles ordered by ``event_time`` then index (O(N))."""
    n = heap.shape[0]
    for i in range(n):
        heap[i] = i
        keys[i] = event_time[i]
        where[i] = i
    for slot in range(n // 2 - 1, -1, -1):
        _sift_down(slot, heap, keys, where)


@numba.njit(cache=True)
def predict(
    i: int,
    now: float,
    position: np.ndarray,
    velocity: np.ndarray,
    stamp: np.ndarray,
    radius: np.ndarray,
    geometry: np.ndarray,
    grid: np.ndarray,
    cell_of: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    cells: np.ndarray,
    shifts: np.ndarray,
    collisions: np.ndarray,
    event_time: np.ndarray,
    event_kind: np.ndarray,
    event_other: np.ndarray,
    event_stamp: np.ndarray,
) -> None:
    """Find particle i's next event after time ``now`` and store it (not in the heap yet).

    ``geometry`` is ``[half_width, half_height, cell_width, cell_height]`` in m; ``grid`` is
    ``[ncx, ncy, periodic]``. Ties go to the first found in a fixed order (walls, cells, then the
    partner with the lowest index), so the outcome does not depend on the order of cell lists.

    """
    hw = geometry[0]
    hh = geometry[1]
    ncx = grid[0]
    ncy = grid[1]
    periodic = grid[2] != 0
    lag = now - stamp[i]
    xi = position[i, 0] + velocity[i, 0] * lag
    yi = position[i, 1] + velocity[i, 1] * lag
    vxi = velocity[i, 0]
    vyi = velocity[i, 1]
    ri = radius[i]
    best = math.inf
    kind = NO_EVENT
    other = -1

    if not periodic:
        for d in range(2):
            v = velocity[i, d]
            x = xi if d == 0 else yi
            half = hw if d == 0 else hh
            if v > 0.0:
                delay = max((half - ri - x) / v, 0.0)
                if delay < best:
                    best, kind, other = delay, WALL, 2 * d + 1
            elif v < 0.0:
                delay = max((-half + ri - x) / v, 0.0)
                if delay < best:
                    best, kind, other = delay, WALL, 2 * d

    c = cell_of[i]
    if c >= 0:
        cxy = (c % ncx, c // ncx)
        counts = (ncx, ncy)
        for d in range(2):
            v = velocity[i, d]
            x = xi if d == 0 else yi
            half = hw if d == 0 else hh
            size = geometry[2 + d]
            k = cxy[d]
            if v > 0.0 and (periodic or k < counts[d] - 1):
                delay = max((-half + (k + 1) * size - x) / v, 0.0)
                if delay < best:
                    best, kind, other = delay, CELL, 2 * d + 1
            elif v < 0.0 and (periodic or k > 0):
                delay = max((-half + k * size - x) / v, 0.0)
                if delay < best:
                    best, kind, other = delay, CELL, 2 * d

        if ri > 0.0:
            speed_i = abs(vxi) + abs(vyi)
            width = 2.0 * hw
            height = 2.0 * hh
            for q in range(9):
                cell = cells[c, q]
                if cell < 0:
                    continue
                ox = shifts[c, q, 0] * width
                oy = shifts[c, q, 1] * height
                j = head[cell]
                while j >= 0:
                    if j != i and radius[j] > 0.0:
                        lag_j = now - stamp[j]
                        dx = position[j, 0] + velocity[j, 0] * lag_j + ox - xi
                        dy = position[j, 1] + velocity[j, 1] * lag_j + oy - yi
                        sigma = ri + radius[j]
                        speeds = speed_i + abs(velocity[j, 0]) + abs(velocity[j, 1])
                        delay = contact_delay(
                            dx, dy, velocity[j, 0] - vxi, velocity[j, 1] - vyi, sigma,
                            CONTACT_SLACK * sigma * speeds,
                        )  # fmt: skip
                        if delay < best or (delay == best and kind == PAIR and j < other):
                            best, kind, other = delay, PAIR, j
                    j = next_[j]

    event_time[i] = now + best
    event_kind[i] = kind
    event_other[i] = other
    event_stamp[i] = collisions[other] if kind == PAIR else 0


@numba.njit(cache=True, inline="always")
def _advance(i: int, t: float, position: np.ndarray, velocity: np.ndarray, stamp: np.ndarray):
    lag = t - stamp[i]
    position[i, 0] += velocity[i, 0] * lag
    position[i, 1] += velocity[i, 1] * lag
    stamp[i] = t


@numba.njit(cache=True)
def _move_to_cell(i: int, new: int, cell_of, head, next_, prev) -> None:
    old = cell_of[i]
    if prev[i] >= 0:
        next_[prev[i]] = next_[i]
    else:
        head[old] = next_[i]
    if next_[i] >= 0:
        prev[next_[i]] = prev[i]
    first = head[new]
    next_[i] = first
    prev[i] = -1
    if first >= 0:
        prev[first] = i
    head[new] = i
    cell_of[i] = new


@numba.njit(cache=True)
def _cross_cell(i, direction, position, image, geometry, grid, cell_of, head, next_, prev):
    """Move particle i into the neighbouring cell; wrap it at a periodic edge."""
    ncx = grid[0]
    ncy = grid[1]
    d = direction // 2
    step = 1 if direction % 2 == 1 else -1
    c = cell_of[i]
    k = (c % ncx, c // ncx)[d]
    count = (ncx, ncy)[d]
    k += step
    if k == count or k < 0:  # periodic edge
        k %= count
        span = 2.0 * geometry[d]
        position[i, d] -= step * span
        image[i, d] += step
    cx = k if d == 0 else c % ncx
    cy = k if d == 1 else c // ncx
    _move_to_cell(i, cx + ncx * cy, cell_of, head, next_, prev)


@numba.njit(cache=True)
def rebuild(
    now: float,
    position: np.ndarray,
    velocity: np.ndarray,
    stamp: np.ndarray,
    radius: np.ndarray,
    geometry: np.ndarray,
    grid: np.ndarray,
    cell_of: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    prev: np.ndarray,
    cells: np.ndarray,
    shifts: np.ndarray,
    collisions: np.ndarray,
    event_time: np.ndarray,
    event_kind: np.ndarray,
    event_other: np.ndarray,
    event_stamp: np.ndarray,
    heap: np.ndarray,
    heap_keys: np.ndarray,
    heap_where: np.ndarray,
) -> None:
    """Start a fresh queue at time ``now`` from synchronised positions (all stamps = now)."""
    stamp[:] = now
    fill_cells(
        position, radius, geometry[0], geometry[1], grid[0], grid[1], cell_of, head, next_, prev
    )
    for i in range(position.shape[0]):
        predict(
            i, now, position, velocity, stamp, radius, geometry, grid, cell_of, head, next_,
            cells, shifts, collisions, event_time, event_kind, event_other, event_stamp,
        )  # fmt: skip
    heap_build(event_time, heap, heap_keys, heap_where)


@numba.njit(cache=True)
def run_events(
    until: float,
    position: np.ndarray,
    velocity: np.ndarray,
    stamp: np.ndarray,
    mass: np.ndarray,
    radius: np.ndarray,
    image: np.ndarray,
    geometry: np.ndarray,
    grid: np.ndarray,
    cell_of: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    prev: np.ndarray,
    cells: np.ndarray,
    shifts: np.ndarray,
    collisions: np.ndarray,
    event_time: np.ndarray,
    event_kind: np.ndarray,
    event_other: np.ndarray,
    event_stamp: np.ndarray,
    heap: np.ndarray,
    heap_keys: np.ndarray,
    heap_where: np.ndarray,
    tally: np.ndarray,
    impulse: np.ndarray,
    acceleration: np.ndarray,
    midpoint: float,
) -> int:
    """Process every event up to time ``until`` (inclusive) in time order.

    Parameters
    ----------
    until : float
        End of the drift, in s (absolute simulation time).
    tally : ndarray of int64, shape (5,)
        Incremented: pair collisions, then hits on the left, right, bottom, top wall.
    impulse : ndarray of float64, shape (5,)
        Incremented: the collision virial ``sum r_ij . dp_i`` (kg m^2/s, ``r_ij = x_i - x_j`` at
        contact, ``dp_i`` the impulse on i), then the momentum given to each wall (kg m/s).
    acceleration : ndarray, shape (N, 2) or (0, 2)
        With forces, the acceleration of the step's half kicks (m/s^2), and ``midpoint`` the
        middle of the step (s): see `_pair_response`. Empty without forces.
    (other arrays)
        Engine state as built by `rebuild`; updated in place.

    Returns
    -------
    int
        Number of events processed (including cell crossings and stale events), or ``-1 - i``
        if time stopped advancing at particle i: far more events at one instant than simultaneous
        contacts allow, which only a runaway state (huge or infinite velocities) produces.
    """
    processed = 0
    n = position.shape[0]
    if n == 0:
        return 0
    instant = -math.inf
    at_instant = 0
    while True:
        i = heap[0]
        t = heap_keys[0]
        if t > until:
            break
        processed += 1
        if t > instant:
            instant = t
            at_instant = 0
        at_instant += 1
        if at_instant > 100 * n + 10_000:
            return -1 - i
        kind = event_kind[i]
        if kind == PAIR:
            j = event_other[i]
            if collisions[j] == event_stamp[i]:
                _advance(i, t, position, velocity, stamp)
                _advance(j, t, position, velocity, stamp)
                # Contact normal x_i - x_j; in contact the pair is at most half a side apart,
                # so the minimum image is the one that touches.
                nx = position[i, 0] - position[j, 0]
                ny = position[i, 1] - position[j, 1]
                if grid[2] != 0:
                    nx -= 2.0 * geometry[0] * round(nx / (2.0 * geometry[0]))
                    ny -= 2.0 * geometry[1] * round(ny / (2.0 * geometry[1]))
                v1x, v1y, v2x, v2y = _pair_response(
                    i, j, nx, ny, midpoint - t, mass, velocity, acceleration
                )
                impulse[PAIR_COLLISIONS] += mass[i] * (
                    nx * (v1x - velocity[i, 0]) + ny * (v1y - velocity[i, 1])
                )
                velocity[i, 0] = v1x
                velocity[i, 1] = v1y
                velocity[j, 0] = v2x
                velocity[j, 1] = v2y
                collisions[i] += 1
                collisions[j] += 1
                tally[PAIR_COLLISIONS] += 1
                predict(
                    j, t, position, velocity, stamp, radius, geometry, grid, cell_of, head,
                    next_, cells, shifts, collisions, event_time, event_kind,
                    event_other, event_stamp,
                )  # fmt: skip
                heap_update(j, event_time[j], heap, heap_keys, heap_where)
        elif kind == WALL:
            _advance(i, t, position, velocity, stamp)
            wall = event_other[i]
            d = wall // 2
            half = geometry[d]
            # Snap to the contact point so round-off never leaves the disk past the wall.
            position[i, d] = (half - radius[i]) if wall % 2 == 1 else (radius[i] - half)
            before = velocity[i, d]
            velocity[i, d] = _wall_response(before, wall % 2 == 1, i, d, midpoint - t, acceleration)
            impulse[WALL_HITS + wall] += mass[i] * abs(velocity[i, d] - before)
            collisions[i] += 1
            tally[WALL_HITS + wall] += 1
        elif kind == CELL:
            _advance(i, t, position, velocity, stamp)
            _cross_cell(
                i, event_other[i], position, image, geometry, grid, cell_of, head, next_, prev
            )
        predict(
            i, t, position, velocity, stamp, radius, geometry, grid, cell_of, head, next_,
            cells, shifts, collisions, event_time, event_kind, event_other, event_stamp,
        )  # fmt: skip
        heap_update(i, event_time[i], heap, heap_keys, heap_where)
    return processed


@numba.njit(cache=True, inline="always")
def _pair_response(i, j, nx, ny, lead, mass, velocity, acceleration):
    """Velocities of i and j after their collision, with the kick timing corrected.

    In a kick-drift-kick step each particle got ``a dt/2`` before the drift, although, at a
    collision at time tau into the step, only ``a tau`` of that impulse was physically received
    before it. Plain reflection leaves an O(dt) energy error per collision; instead the surplus
    ``delta = a (dt/2 - tau)`` (``lead = dt/2 - tau``) is taken out, the elastic response applied,
    and the surplus put back: ``v' = C(v - delta) + delta``. Momentum is conserved exactly; the
    error per collision becomes O(dt^2). If that would leave the pair still approaching (a slow
    contact under strong attraction), the plain response ``C(v)`` is used.
    """
    v1x, v1y = velocity[i, 0], velocity[i, 1]
    v2x, v2y = velocity[j, 0], velocity[j, 1]
    if acceleration.shape[0] > 0:
        d1x, d1y = lead * acceleration[i, 0], lead * acceleration[i, 1]
        d2x, d2y = lead * acceleration[j, 0], lead * acceleration[j, 1]
        w1x, w1y, w2x, w2y = elastic_response(
            mass[i], mass[j], nx, ny, v1x - d1x, v1y - d1y, v2x - d2x, v2y - d2y
        )
        w1x, w1y, w2x, w2y = w1x + d1x, w1y + d1y, w2x + d2x, w2y + d2y
        if (w1x - w2x) * nx + (w1y - w2y) * ny > 0.0:
            return w1x, w1y, w2x, w2y
    return elastic_response(mass[i], mass[j], nx, ny, v1x, v1y, v2x, v2y)


@numba.njit(cache=True, inline="always")
def _wall_response(v, upper, i, d, lead, acceleration):
    """Normal velocity after a wall bounce, with the same kick-timing correction as pairs:
    ``v' = -(v - delta) + delta``, kept only if it moves away from the wall."""
    if acceleration.shape[0] > 0:
        corrected = -v + 2.0 * lead * acceleration[i, d]
        if (corrected < 0.0) if upper else (corrected > 0.0):
            return corrected
    return -v


@numba.njit(cache=True)
def synchronise(
    now: float, position: np.ndarray, velocity: np.ndarray, stamp: np.ndarray, out: np.ndarray
) -> None:
    """Write every particle's position at time ``now`` into ``out`` (shape (N, 2)), lazily kept
    state untouched so the queue stays valid."""
    for i in range(position.shape[0]):
        lag = now - stamp[i]
        out[i, 0] = position[i, 0] + velocity[i, 0] * lag
        out[i, 1] = position[i, 1] + velocity[i, 1] * lag
