"""Event-driven drift of hard disks: exact free flight between exact collisions (elastic, or
inelastic with a normal restitution).

Design (Rapaport; Donev, Torquato & Stillinger; Bannerman's DynamO for the memory layout):

- Each particle keeps one next event: a pair contact, a wall contact or a crossing into the next
  cell of the grid. The event queue (`collidium.kernels.event_queue`) gives the earliest.
- Positions are lazy: a particle's row holds where it was at its own time stamp; at time t it is
  at ``x + v (t - stamp)``, or under a uniform gravity ``g`` that every disk shares on the
  parabola ``x + v tau + g tau^2 / 2``, moving at ``v + g tau`` (``tau = t - stamp``). A pair's
  relative motion is then still a straight line, so pair contacts keep their closed form; walls
  and cell edges are met at roots of quadratics, a circle's rim and a segment's point at the
  first crossing of a quartic (`collidium.kernels.parabolas`). The energy is kept to round-off
  and the queue lives on from step to step, as without gravity.
- A pair event records the partner's collision count when it was predicted; if the partner has
  collided since, the event is stale and the particle is simply re-predicted.
- Cells are at least one largest diameter wide, so a particle's possible partners are in the
  9 cells around it (found arithmetically, with the periodic wrap); crossing into another cell
  re-predicts it against its new neighbours.
- A kick between drifts re-predicts only the particles whose velocity it changed (`refresh`), as
  a collision does.

Memory layout. At 1e5 particles and more the engine waits on memory, not arithmetic, so:

- Particles live in *slots* of the engine's own order, sorted by cell and re-sorted every few
  events per particle (`sort_slots`), so that neighbours sit close in memory; the cells are
  taken in square tiles (`TILE`), so that the rows above and below are close too. ``ident[k]``
  is the particle (its index in `collidium.state.Particles`) in slot k. Every tie between equal
  event times is broken by ident, never by slot, so the outcome does not depend on the slot
  order.
- Everything a prediction reads of a neighbour is one row of ``body``:
  ``x, y, vx, vy, stamp`` (m, m/s, s) and, when the disks differ, ``radius, mass`` (m, kg), 56
  bytes. When all disks share one radius and one mass, ``geometry`` holds them and the row is 40
  bytes (`SHARED_BODY_COLUMNS`): smaller rows mean more collisions per second at N = 1e5.
- An event is one int32 code: the partner's slot (>= 0), a wall (`FIRST_WALL_CODE`) or a cell
  crossing (`CELL_CODES`); indices are int32. The caller keeps all of a slot's integers in one
  24-byte row (`SLOT_COLUMNS`), so a slot is two rows.
- The queue keeps each slot's time in slot order, and the earliest of blocks of them, so that
  what an event's new time updates is known from its slot alone. Each event asks for what the
  next two will read first (`_prefetch_following`). The kernels are compiled without numba's
  reference counting (`collidium.kernels.compilation.uncounted`).
- Memory: about 87 bytes per disk of one radius and mass at packing 0.3 (``body`` 40, integers
  24, queue 9, cell lists 14), so a million disks fit in 300 MB with the interpreter and LLVM.
  So the contact kept for the short prediction after a crossing (`predict`) is its partner
  alone, 4 bytes, and its time is computed again when needed: storing it too would add 8.

All state lives in arrays owned by the caller (`collidium.collisions.ExactCollisions`), so the queue
survives from one call to the next: with no forces, dt is only a reporting interval.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels import event_queue, parabolas, wall_responses
from collidium.kernels.audit import fails_in_box
from collidium.kernels.cells import cell_index, neighbour_cell
from collidium.kernels.collision import bounce_factor, energy_change, pair_response
from collidium.kernels.compilation import inlined, prefetch, uncounted
from collidium.kernels.stepper import chunk_count
from collidium.kernels.vessels import BOX, contacts
from collidium.kernels.vessels import piston as pistons

#: Columns of the ``body`` rows. RADIUS and MASS exist only in rows of `BODY_COLUMNS`; rows of
#: `SHARED_BODY_COLUMNS` take them from ``geometry``.
X, Y, VX, VY, STAMP, RADIUS, MASS = range(7)
BODY_COLUMNS = 7  # 56 bytes
SHARED_BODY_COLUMNS = 5  # 40 bytes: every disk has the radius and mass in ``geometry``

#: Entries of ``geometry`` (m, and kg for SHARED_MASS): the half sides of the vessel's bounding
#: box, the cell sides, the radius and mass of every disk when the rows have no columns for them
#: (else NaN), the vessel's shape code (`collidium.kernels.vessels`) and, for a circle, its radius;
#: then the pair collisions' restitution and the approach speed (m/s) below which they are
#: elastic (`collidium.kernels.collision.pair_response`); then the lower-left corner of the
#: cells' window (`collidium.kernels.cells.grid_window`: the box itself when periodic); then the
#: uniform acceleration every disk falls with between events (m/s^2, `_at`).
HALF_WIDTH, HALF_HEIGHT, CELL_WIDTH, CELL_HEIGHT, SHARED_RADIUS, SHARED_MASS, SHAPE, RIM = range(8)
RESTITUTION, ELASTIC_BELOW, GRID_LEFT, GRID_BOTTOM, FALL_X, FALL_Y = range(8, 14)
GEOMETRY_SIZE = 14

#: Columns of the ``event`` rows (int32): the next event's code, the earliest pair contact found
#: (its partner's slot, or -1; the event itself if it comes first) and that partner's collision
#: count when it was predicted (a later count makes the contact stale).
CODE, KEPT, PARTNER_COUNT = range(3)
EVENT_COLUMNS = 3

#: Columns after the event's in the rows the caller allocates, so that one 24-byte row holds
#: every integer of a slot (a slot's state is then two rows): the arrays ``ident``,
#: ``cell_of`` and ``count`` that the kernels take must be views of these columns, as
#: `sort_slots` moves whole rows.
IDENT, CELL, COUNT = range(EVENT_COLUMNS, EVENT_COLUMNS + 3)
SLOT_COLUMNS = EVENT_COLUMNS + 3

#: Columns of the contact log that `run_events` writes in a drift under forces: the particle, its
#: partner (or ``-1 - wall``, `collidium.vessels.Vessel.wall_names` order), the time (s), the
#: contact normal (the line of centres ``x_i - x_j``, or the wall's outward unit normal, m), and
#: the factor by which the response changed the normal velocity, ``1 + e`` (0 where the kick-timing
#: correction was not applied: a wall that is not a mirror, a piston, a pair still approaching),
#: and the change of the particle's velocity (m/s; its partner's is the opposite impulse).
LOG_PARTICLE, LOG_PARTNER, LOG_TIME, LOG_NX, LOG_NY, LOG_BOUNCE, LOG_DVX, LOG_DVY = range(8)
#: Columns the kick-timing correction works in (`collidium.kernels.kick_timing.correct`): the
#: velocity errors of the particle and its partner just after the contact (4, m/s), their
#: accelerations at it (4, m/s^2), and the contact's jump of the modified energy (J).
LOG_ERROR, LOG_PULL, LOG_DROP = 8, 12, 16
LOG_COLUMNS = 17

#: Slots from which the event loop asks ahead for what the next events read
#: (`_prefetch_following`): the engine's rows, 4.5 MB at 2^16 disks, then lie outside a core's
#: own cache. With other programs sharing the machine's cache, 1e5 disks ran 7-77% more
#: collisions a second than with the requests from 2^18 (six rounds); 4e4 disks from 16% fewer to
#: 5% more, so not there.
PREFETCH_EVENTS_FROM = 1 << 16

#: Slots on either side of the next event's whose ``body`` rows the event loop asks for ahead
#: (`_prefetch_following`): with the slots sorted by cell in tiles (`TILE`), most of a disk's
#: neighbours lie there.
ROWS_AROUND = 4

#: Event codes below 0: a crossing into the neighbouring cell in direction d (0 -x, 1 +x, 2 -y,
#: 3 +y) is ``-1 - d``; contact c with the vessel (`collidium.kernels.vessels.contacts`: the
#: box's wall c, the rim, a segment) is ``FIRST_WALL_CODE - c``.
CELL_CODES = (-1, -4)
NO_EVENT = -5
FIRST_WALL_CODE = -6

#: Index of each entry of the ``tally`` array (counts) and of the ``impulse`` array (sums).
PAIR_COLLISIONS = 0  # tally: pair collisions; impulse: pair virial sum of r_ij . dp_i (kg m^2/s)
WALL_HITS = 1  # one entry per wall, `Vessel.wall_names` order (tally: hits; impulse: kg m/s)

#: Relative size, against the particles' speeds, of an approach too slow to be anything but
#: round-off (see `contact_delay`).
CONTACT_SLACK = 1e-12


@inlined
def _slot_views(event):
    """The slots' particles, cells and event counts: columns of ``event``, (N,).

    The engine's entry points take these views here, from ``event``, rather than as arguments:
    a lone disk's column would be contiguous, another array type to numba, and so another
    minute-long compilation of the whole engine.
    """
    return event[:, IDENT], event[:, CELL], event[:, COUNT]


#: Events per particle between two re-sorts of the slots by cell (sorting costs about as much as
#: one event per particle; neighbours drift apart in memory over tens of events).
SORT_INTERVAL = 16

#: Slots from which the slots are re-sorted every `SORT_INTERVAL_LARGE` events a particle: in a
#: gas that outgrows the caches, neighbours drifting apart in memory cost more than the sorts.
#: W1 at 1e6 disks (`benchmarks/bench_paired.py`, eighteen rounds) ran a median 4% faster with 4
#: than with 16, ahead in thirteen rounds; at 3e5 no faster, at 1e5 slower (ARCHITECTURE.md,
#: "What an event at 1e6 disks is made of, and the designs measured by it").
SORT_OFTEN_FROM = 1 << 19
SORT_INTERVAL_LARGE = 4


def sort_interval(n: int) -> int:
    """Events per particle between two re-sorts of the slots of n disks."""
    return SORT_INTERVAL_LARGE if n >= SORT_OFTEN_FROM else SORT_INTERVAL


#: Swaps ahead along a cycle of `sort_slots`'s permutation whose rows it asks for: a million
#: slots moved after some 4 events a particle took 62-78 ms rather than 98-171 (the counting,
#: links and queue 20-22 ms of it; a throwaway timing, asking 2, 4, 8 and 16 ahead).
SORT_AHEAD = 8

#: Cells along a side of the square tiles in whose order `sort_slots` puts the slots (cells in
#: rows within a tile). A disk's neighbours in the rows of cells above and below then mostly lie
#: within a few hundred bytes of its own row, not a whole row of cells away: W1 at 1e6 disks
#: (ARCHITECTURE.md, "The exact engine's steps in one call") ran about 5% faster than with rows
#: of cells (a tile of 1), ahead in seven rounds of eight.
TILE = 4


@inlined
def _radius(k, body, geometry) -> float:
    """Radius of slot k in m: its row's, or the one all disks share."""
    return body[k, RADIUS] if body.shape[1] > RADIUS else geometry[SHARED_RADIUS]


@inlined
def _mass(k, body, geometry) -> float:
    """Mass of slot k in kg: its row's, or the one all disks share."""
    return body[k, MASS] if body.shape[1] > MASS else geometry[SHARED_MASS]


@inlined
def _at(k, t, body, geometry):
    """Slot k's position (m) and velocity (m/s) at time t (s): ``(x, y, vx, vy)``. Without a
    gravity the fall's terms are left out: they are zero, and a prediction reads a position for
    every neighbour it tests (the same position but for the sign of a zero, which nothing
    compares)."""
    lag = t - body[k, STAMP]
    gx = geometry[FALL_X]
    gy = geometry[FALL_Y]
    vx = body[k, VX]
    vy = body[k, VY]
    if gx == 0.0 and gy == 0.0:
        return body[k, X] + vx * lag, body[k, Y] + vy * lag, vx, vy
    x = body[k, X] + (vx + 0.5 * gx * lag) * lag
    y = body[k, Y] + (vy + 0.5 * gy * lag) * lag
    return x, y, vx + gx * lag, vy + gy * lag


@inlined
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


# --- asking ahead ---------------------------------------------------------------------------------


@inlined
def _prefetch_following(queue, body, event, head, next_, grid) -> None:
    """Ask ahead for what the next two events will read first, from `PREFETCH_EVENTS_FROM` slots
    on, where each line would otherwise come only when an event waits for it.

    The queue tells which slots most likely come next and after it
    (`collidium.kernels.event_queue.likely_next`). Ask for the rows of both. The next one's,
    asked for at the event before, have mostly come; so ask for what its event reads too: the
    cell heads of the three rows of cells around it, the ``body`` rows of the slots within
    `ROWS_AROUND` of its own (the slots are sorted by cell, so there lie most of its neighbours),
    its line of ``next_``, the queue's lines its new time updates, and its partner's rows, queue
    lines and the rows within `ROWS_AROUND` of the partner's slot, if its event is a contact
    (the partner is predicted again too), or the heads of the three cells that come into reach,
    if it crosses into the next row of cells (its prediction then searches them; in the next
    column they are mostly on the lines asked for).
    """
    n = body.shape[0]
    if n >= PREFETCH_EVENTS_FROM:
        following, after = event_queue.likely_next(queue)
        prefetch(body, (following, 0))
        prefetch(event, (following, 0))
        prefetch(body, (after, 0))
        prefetch(event, (after, 0))
        c = event[following, CELL]
        ncx = grid[0]
        for row in (c - ncx - 1, c - 1, c + ncx - 1):
            _prefetch_head(head, row)
        _prefetch_rows_around(body, following)
        prefetch(next_, following)
        event_queue.prefetch_lines(following, queue)
        code = event[following, CODE]
        if code >= 0:  # a contact: its partner's rows, and those around its slot
            prefetch(body, (code, 0))
            prefetch(event, (code, 0))
            event_queue.prefetch_lines(code, queue)
            _prefetch_rows_around(body, code)
        elif CELL_CODES[1] <= code and (-1 - code) // 2 == 1:  # a crossing along y
            beyond = c + (2 * ncx if (-1 - code) % 2 == 1 else -2 * ncx)
            _prefetch_head(head, beyond - 1)
            _prefetch_head(head, beyond + 1)


@inlined
def _prefetch_rows_around(body, slot) -> None:
    """Ask for the ``body`` rows of the slots within `ROWS_AROUND` of ``slot``, its own again
    among them (asked for first, with the lines that matter most): sorted by cell in tiles
    (`TILE`), most of its neighbours lie there."""
    for near in range(max(slot - ROWS_AROUND, 0), min(slot + ROWS_AROUND + 1, body.shape[0])):
        prefetch(body, (near, 0))


@inlined
def _prefetch_head(head, cell) -> None:
    """Ask for the line of ``head`` holding ``cell``'s entry, the index clamped to the grid (a
    guess past its edge asks for a line that is of no use, never for one outside it)."""
    prefetch(head, min(max(cell, 0), head.shape[0] - 1))


# --- predictions --------------------------------------------------------------------------------


@inlined
def _walls_and_cells(x, y, vx, vy, r, c, geometry, grid, segments, piston, now):
    """Earliest wall contact or cell crossing of a disk at (x, y) moving at (vx, vy) in cell c at
    time ``now`` (s), falling with the acceleration in ``geometry``: ``(delay in s, code)``. Ties
    go to walls before cells, x before y. With a piston (a non-empty ``piston``,
    `collidium.kernels.vessels.piston`) its wall of the box moves."""
    hw = geometry[HALF_WIDTH]
    hh = geometry[HALF_HEIGHT]
    gx = geometry[FALL_X]
    gy = geometry[FALL_Y]
    periodic = grid[2] != 0
    if gx != 0.0 or gy != 0.0:
        best, code = _falling_cell_crossing(x, y, vx, vy, gx, gy, c, geometry, grid)
    else:
        best, code = _cell_crossing(x, y, vx, vy, c, geometry, grid)
    if piston.shape[0] > 0:
        wall, contact = pistons.earliest(x, y, vx, vy, r, hw, hh, piston, now, gx, gy)
        if wall <= best:
            best, code = wall, FIRST_WALL_CODE - contact
    elif not periodic and _walls_in_reach(c, geometry, grid, segments):
        wall, contact = contacts.earliest(x, y, vx, vy, r, geometry[SHAPE], hw, hh, geometry[RIM],
                                          segments, gx, gy, best)  # fmt: skip
        if contact >= 0 and wall <= best:
            best, code = wall, FIRST_WALL_CODE - contact
    return best, code


@inlined
def _walls_in_reach(c, geometry, grid, segments) -> bool:
    """Whether a disk in cell c may touch a wall before it leaves the cell: in a box without
    segments only from a cell at the grid's edge, as the cells are at least one diameter wide
    and the grid lies inside the box (`collidium.kernels.cells.event_grid_shape`,
    `grid_window`); a wall is at least a diameter away from any other, and the disk crosses
    into the next cell first."""
    if geometry[SHAPE] != BOX or segments.shape[0] > 0:
        return True
    ncx = grid[0]
    cx, cy = c % ncx, c // ncx
    return cx == 0 or cy == 0 or cx == ncx - 1 or cy == grid[1] - 1


@inlined
def _cell_crossing(x, y, vx, vy, c, geometry, grid):
    """``(delay in s, code)`` of a straight path's crossing out of cell c (code ``-1 - (2 d +
    upper)``; none out of the edge cells of a walled box). Ties go to x."""
    ncx = grid[0]
    periodic = grid[2] != 0
    best = math.inf
    code = NO_EVENT
    for d in range(2):
        v = vx if d == 0 else vy
        pos = x if d == 0 else y
        low = geometry[GRID_LEFT + d]
        size = geometry[CELL_WIDTH + d]
        at = c % ncx if d == 0 else c // ncx
        cells = grid[d]
        if v > 0.0 and (periodic or at < cells - 1):
            delay = max((low + (at + 1) * size - pos) / v, 0.0)
            if delay < best:
                best, code = delay, -2 - 2 * d
        elif v < 0.0 and (periodic or at > 0):
            delay = max((low + at * size - pos) / v, 0.0)
            if delay < best:
                best, code = delay, -1 - 2 * d
    return best, code


@uncounted()
def _falling_cell_crossing(x, y, vx, vy, gx, gy, c, geometry, grid):
    """`_cell_crossing` on a parabola: each edge's gap closes on a quadratic (a disk thrown up
    may cross its cell's lower edge on the way down). Ties go to x, then to the lower edge. A
    call, not inlined: only falling disks take it, and inlined it would add to LLVM's work on
    every engine."""
    ncx = grid[0]
    periodic = grid[2] != 0
    best = math.inf
    code = NO_EVENT
    for d in range(2):
        v = vx if d == 0 else vy
        g = gx if d == 0 else gy
        pos = x if d == 0 else y
        low = geometry[GRID_LEFT + d]
        size = geometry[CELL_WIDTH + d]
        at = c % ncx if d == 0 else c // ncx
        if periodic or at > 0:
            delay = parabolas.first_contact(pos - (low + at * size), v, g)
            if delay < best:
                best, code = delay, -1 - 2 * d
        if periodic or at < grid[d] - 1:
            delay = parabolas.first_contact((low + (at + 1) * size) - pos, -v, -g)
            if delay < best:
                best, code = delay, -2 - 2 * d
    return best, code


@inlined
def _delay_to(j, now, x, y, vx, vy, r, sx, sy, body, geometry) -> float:
    """Time (s) from ``now`` until slot j, shifted by (sx, sy) m, touches a disk of radius r at
    (x, y) moving at (vx, vy); inf if never or if j has radius 0."""
    rj = _radius(j, body, geometry)
    if rj <= 0.0:
        return math.inf
    # Under a gravity both share, the relative motion is a straight line.
    xj, yj, vjx, vjy = _at(j, now, body, geometry)
    dx = xj + sx - x
    dy = yj + sy - y
    sigma = r + rj
    slack = CONTACT_SLACK * sigma * (abs(vx) + abs(vy) + abs(vjx) + abs(vjy))
    return contact_delay(dx, dy, vjx - vx, vjy - vy, sigma, slack)


@inlined
def _delay_to_any_image(j, now, x, y, vx, vy, r, body, geometry, grid) -> float:
    """`_delay_to` slot j, or in a periodic box to the image of j that comes first."""
    if grid[2] == 0:
        return _delay_to(j, now, x, y, vx, vy, r, 0.0, 0.0, body, geometry)
    best = math.inf
    for sx in (-2.0 * geometry[HALF_WIDTH], 0.0, 2.0 * geometry[HALF_WIDTH]):
        for sy in (-2.0 * geometry[HALF_HEIGHT], 0.0, 2.0 * geometry[HALF_HEIGHT]):
            best = min(best, _delay_to(j, now, x, y, vx, vy, r, sx, sy, body, geometry))
    return best


@inlined
def _scan_cells(k, now, x, y, vx, vy, r, rows, columns, body, ident, geometry, grid, cell_of,
                head, next_):  # fmt: skip
    """Earliest contact of slot k, at (x, y) at time ``now``, with the disks in a block of cells
    around its own: ``rows`` and ``columns`` are ``(first, last)`` offsets from k's cell.

    Returns ``(delay in s, partner slot)``, ``(inf, -1)`` if none; ties go to the lowest ident.
    """
    hw = geometry[HALF_WIDTH]
    hh = geometry[HALF_HEIGHT]
    ncx = grid[0]
    ncy = grid[1]
    periodic = grid[2] != 0
    c = cell_of[k]
    cx = c % ncx
    cy = c // ncx
    best = math.inf
    best_slot = -1
    best_ident = -1
    for oy in range(rows[0], rows[1] + 1):
        for ox in range(columns[0], columns[1] + 1):
            cell, sx, sy = neighbour_cell(cx, cy, ox, oy, ncx, ncy, periodic, 2.0 * hw, 2.0 * hh)
            if cell < 0:
                continue
            j = head[cell]
            while j >= 0:
                if j != k:
                    delay = _delay_to(j, now, x, y, vx, vy, r, sx, sy, body, geometry)
                    if delay < best or (delay == best and best_slot >= 0 and ident[j] < best_ident):
                        best, best_slot, best_ident = delay, j, ident[j]
                j = next_[j]
    return best, best_slot


@inlined
def predict(k, now, crossed, body, ident, geometry, grid, cell_of, head, next_, count, event,
            segments, piston):  # fmt: skip
    """Find slot k's next event after time ``now`` (s), store it, return its time (s).

    The earliest pair contact found is kept (``event[k, KEPT]``): after a cell crossing in
    direction ``crossed`` (0 -x, 1 +x, 2 -y, 3 +y; -1 for none) only the 3 cells newly in reach are
    searched, and compared with the kept contact, recomputed, if its partner has not collided
    since. That is exact: k's velocity did not change, the neighbours that did not change cannot
    come earlier than the kept contact, and any neighbour that changed or arrived since has
    predicted against k itself.

    ``geometry`` holds the half sides of the grid's box, the cell sides, any shared radius and
    mass and the vessel's shape (`HALF_WIDTH` to `RIM`); ``grid`` is ``[ncx, ncy, periodic]``;
    ``segments`` is the vessel's segment table (`collidium.kernels.vessels.segments`) and
    ``piston`` its piston (`collidium.kernels.vessels.piston`; empty for none). Ties go
    to the first found in a fixed order (walls, cells, then the partner with the lowest ident),
    so the outcome does not depend on the slot order.
    """
    x, y, vx, vy = _at(k, now, body, geometry)
    r = _radius(k, body, geometry)
    when, code = _walls_and_cells(x, y, vx, vy, r, cell_of[k], geometry, grid, segments, piston,
                                  now)  # fmt: skip
    when += now
    pair = -1
    if r > 0.0:
        rows = (-1, 1)
        columns = (-1, 1)
        kept = event[k, KEPT]
        # In a grid under 3 cells wide, periodic neighbours repeat under several shifts.
        partial = (
            crossed >= 0
            and (kept < 0 or count[kept] == event[k, PARTNER_COUNT])
            and grid[0] >= 3
            and grid[1] >= 3
        )
        if partial:
            edge = 1 if crossed % 2 == 1 else -1
            if crossed < 2:
                columns = (edge, edge)
            else:
                rows = (edge, edge)
        found, pair = _scan_cells(k, now, x, y, vx, vy, r, rows, columns, body, ident, geometry,
                                  grid, cell_of, head, next_)  # fmt: skip
        if partial and kept >= 0:
            again = _delay_to_any_image(kept, now, x, y, vx, vy, r, body, geometry, grid)
            if pair < 0 or again < found or (again == found and ident[kept] < ident[pair]):
                found, pair = again, kept
        if pair >= 0 and now + found < when:
            when, code = now + found, pair
    event[k, CODE] = code
    event[k, KEPT] = pair
    event[k, PARTNER_COUNT] = count[pair] if pair >= 0 else 0
    return when


@uncounted()
def _predict_not_inlined(k, now, body, ident, geometry, grid, cell_of, head, next_, count, event,
                         segments, piston):  # fmt: skip
    """`predict` of slot k, which crossed no cell edge, as a call rather than an inlined copy,
    for the passes over every slot (`rebuild`, `_piston_moved`): each copy adds to LLVM's work
    at the first compilation, and saves nothing there, where the prediction dwarfs the call.
    The event loop keeps its inlined copies: a call there costs 7 to 10% of the collisions per
    second. The slot and the crossing are typed as the event loop's are (int32, and int64 not
    the literal -1): numba compiles `predict` once for every other combination of types, a
    second apiece at the first run."""
    return predict(np.int32(k), now, np.int64(-1), body, ident, geometry, grid, cell_of, head,
                   next_, count, event, segments, piston)  # fmt: skip


# --- cells and slots ----------------------------------------------------------------------------


@inlined
def _push_front(k, c, head, next_) -> None:
    """Put slot k first in cell c's list."""
    next_[k] = head[c]
    head[c] = k


@uncounted()
def _link_cells(cell_of, head, next_) -> None:
    """Rebuild the per-cell linked lists from ``cell_of``, each in increasing slot order."""
    head[:] = -1
    for k in range(cell_of.shape[0] - 1, -1, -1):
        _push_front(k, cell_of[k], head, next_)


@inlined
def _move_to_cell(k, new, cell_of, head, next_) -> None:
    """Take slot k out of its cell's list and put it first in cell ``new``'s. A cell holds a
    few disks: walking its list is as fast as keeping back links, and takes no memory."""
    j = head[cell_of[k]]
    if j == k:
        head[cell_of[k]] = next_[k]
    else:
        while next_[j] != k:
            j = next_[j]
        next_[j] = next_[k]
    _push_front(k, new, head, next_)
    cell_of[k] = new


@inlined
def _cross_cell(k, direction, body, ident, image, geometry, grid, cell_of, head, next_):
    """Move slot k into the neighbouring cell; wrap it at a periodic edge."""
    ncx = grid[0]
    d = direction // 2
    step = 1 if direction % 2 == 1 else -1
    c = cell_of[k]
    at = (c % ncx if d == 0 else c // ncx) + step
    cells = grid[d]
    if at == cells or at < 0:  # periodic edge
        at %= cells
        body[k, d] -= step * 2.0 * geometry[HALF_WIDTH + d]
        image[ident[k], d] += step
    cx = at if d == 0 else c % ncx
    cy = at if d == 1 else c // ncx
    _move_to_cell(k, cx + ncx * cy, cell_of, head, next_)


@inlined
def _swap_rows(array, a, b) -> None:
    """Exchange rows a and b of a 2-d array."""
    for column in range(array.shape[1]):
        array[a, column], array[b, column] = array[b, column], array[a, column]


@inlined
def _starts_by_tile(head, ncx) -> None:
    """Turn the count of slots in each cell (``head``, cells ``x + ncx * y``) into the first new
    slot of each: the cells taken tile by tile (`TILE`), both row by row."""
    ncy = head.shape[0] // ncx
    start = 0
    for ty in range(0, ncy, TILE):
        for tx in range(0, ncx, TILE):
            for cy in range(ty, min(ty + TILE, ncy)):
                for cx in range(tx, min(tx + TILE, ncx)):
                    c = cx + ncx * cy
                    size = head[c]
                    head[c] = start
                    start += size


@uncounted()
def sort_slots(body, cell_of, event, head, next_, keys, items, grid) -> None:
    """Renumber the slots in cell order, tile by tile (`TILE`; a counting sort), keeping every
    reference consistent, and order the queue (``keys``, ``items``:
    `collidium.kernels.event_queue`) again."""
    _sort_rows(body, cell_of, event, head, next_, keys, grid)
    event_queue.build(keys, items, event[:, IDENT])


@inlined
def _sort_rows(body, cell_of, event, head, next_, keys, grid) -> None:
    """`sort_slots` but for the queue's order: the slots' rows and times (the first entries of
    ``keys``) are moved.

    ``head`` doubles as the counting array and ``next_`` as each slot's new number before both
    are rebuilt.
    """
    n = body.shape[0]
    head[:] = 0
    for k in range(n):
        head[cell_of[k]] += 1
    _starts_by_tile(head, grid[0])
    moved_to = next_
    for k in range(n):  # stable: slots keep their relative order within a cell
        c = cell_of[k]
        moved_to[k] = head[c]
        head[c] += 1
    # References first, while the rows are still in place ...
    for k in range(n):
        for column in (CODE, KEPT):
            if event[k, column] >= 0:
                event[k, column] = moved_to[event[k, column]]
    # ... then the rows.
    for first in range(n):
        if moved_to[first] != first:
            _move_cycle(first, body, event, keys, moved_to)
    _link_cells(cell_of, head, next_)


@inlined
def _move_cycle(first, body, event, keys, moved_to) -> None:
    """Move the rows of the cycle of the permutation ``moved_to`` through slot ``first`` in
    place, each swap putting the row at ``first`` in its place, and mark them moved.

    The rows of a gas larger than the caches lie anywhere in memory: ask for those of the slot
    `SORT_AHEAD` swaps ahead along the cycle, so that several come at once rather than each
    waiting for the one before.
    """
    ahead = moved_to[first]
    for _ in range(SORT_AHEAD):
        if ahead != first:
            ahead = moved_to[ahead]
    while moved_to[first] != first:
        if ahead != first:
            prefetch(body, (ahead, 0))
            prefetch(event, (ahead, 0))
            prefetch(keys, ahead)
            ahead = moved_to[ahead]
        to = moved_to[first]
        _swap_rows(body, first, to)
        _swap_rows(event, first, to)
        keys[first], keys[to] = keys[to], keys[first]
        moved_to[first] = moved_to[to]
        moved_to[to] = to


@uncounted(nogil=True)
def rebuild(now, body, geometry, grid, head, next_, event, keys, items, segments, piston) -> None:
    """Start a fresh queue at time ``now`` (s) from positions synchronised at ``now``.

    ``body``'s positions, velocities, radii and masses are filled by the caller (see `load`);
    this sets the stamps, sorts the slots by cell and predicts every event.
    """
    n = body.shape[0]
    _restart_between(0, n, now, body, geometry, grid, event)
    _sort_restarted(body, event, head, next_, keys, grid)
    _predict_between(0, n, now, body, geometry, grid, head, next_, event, keys, segments, piston)
    event_queue.build(keys, items, event[:, IDENT])


@uncounted()
def rebuild_near(now, body, geometry, grid, head, next_, event, keys, items, segments, piston,
                 near) -> None:  # fmt: skip
    """`rebuild` for a drift of which every disk but the ``near`` ones (by particle, (N,) bool)
    is known to meet no other disk before its end (`collidium.kernels.substeps`, where the
    drift is a substep's): those predict their walls and cells alone (`_predict_alone`), a
    tenth of the cost of a search of the cells around. The events before the drift's end are
    the same: a disk that meets one of them after a contact of its own searches the cells
    around it then, as after any contact."""
    n = body.shape[0]
    _restart_between(0, n, now, body, geometry, grid, event)
    _sort_restarted(body, event, head, next_, keys, grid)
    ident, cell_of, count = event[:, IDENT], event[:, CELL], event[:, COUNT]
    for k in range(n):
        if near[ident[k]]:
            keys[k] = _predict_not_inlined(k, now, body, ident, geometry, grid, cell_of, head,
                                           next_, count, event, segments, piston)  # fmt: skip
        else:
            keys[k] = _predict_alone(k, now, body, geometry, grid, cell_of, event, segments,
                                     piston)  # fmt: skip
    event_queue.build(keys, items, ident)


@inlined
def _predict_alone(k, now, body, geometry, grid, cell_of, event, segments, piston) -> float:
    """`predict` of slot k without a search for partners: its next wall contact or cell
    crossing (s), no partner kept (after a cell crossing `predict` searches the cells newly in
    reach, which is exact where no partner was there before)."""
    x, y, vx, vy = _at(k, now, body, geometry)
    r = _radius(k, body, geometry)
    when, code = _walls_and_cells(x, y, vx, vy, r, cell_of[k], geometry, grid, segments, piston,
                                  now)  # fmt: skip
    event[k, CODE] = code
    event[k, KEPT] = -1
    event[k, PARTNER_COUNT] = 0
    return now + when


@numba.njit(cache=True, parallel=True, nogil=True)
def rebuild_in_chunks(
    now, body, geometry, grid, head, next_, event, keys, items, segments, piston
) -> None:
    """`rebuild` with its passes over every slot in parallel chunks, for many particles
    (`audit.PARALLEL_FROM`). Each slot's prediction is its own, so any number of threads builds
    the same queue."""
    n = body.shape[0]
    chunks = chunk_count(n)
    for p in numba.prange(chunks):
        _restart_between(p * n // chunks, (p + 1) * n // chunks, now, body, geometry, grid,
                         event)  # fmt: skip
    _sort_restarted(body, event, head, next_, keys, grid)
    for p in numba.prange(chunks):
        _predict_between(p * n // chunks, (p + 1) * n // chunks, now, body, geometry, grid, head,
                         next_, event, keys, segments, piston)  # fmt: skip
    event_queue.build(keys, items, event[:, IDENT])


@inlined
def _restart_between(start, stop, now, body, geometry, grid, event) -> None:
    """Stamp the slots ``start`` to ``stop - 1`` at ``now`` (s), find their cells and forget their
    events and collision counts."""
    ncx = grid[0]
    for k in range(start, stop):
        body[k, STAMP] = now
        event[k, CELL] = cell_index(
            body[k, X], geometry[GRID_LEFT], geometry[CELL_WIDTH], ncx
        ) + ncx * cell_index(body[k, Y], geometry[GRID_BOTTOM], geometry[CELL_HEIGHT], grid[1])
        event[k, COUNT] = 0
        event[k, CODE] = NO_EVENT
        event[k, KEPT] = -1
        event[k, PARTNER_COUNT] = 0


@inlined
def _sort_restarted(body, event, head, next_, keys, grid) -> None:
    """`sort_slots` after `_restart_between`, but for the queue, which has no times yet. The
    slots keep the order of the queue before (`load`), sorted by the cells of a little earlier,
    so few rows move."""
    _sort_rows(body, event[:, CELL], event, head, next_, keys, grid)


@inlined
def _predict_between(start, stop, now, body, geometry, grid, head, next_, event, keys, segments,
                     piston) -> None:  # fmt: skip
    """Predict the events of the slots ``start`` to ``stop - 1`` into ``event`` and their times
    into ``keys`` (the queue's first entries, `collidium.kernels.event_queue`)."""
    ident, cell_of, count = event[:, IDENT], event[:, CELL], event[:, COUNT]
    for k in range(start, stop):
        keys[k] = _predict_not_inlined(k, now, body, ident, geometry, grid, cell_of, head, next_,
                                       count, event, segments, piston)  # fmt: skip


# --- the drift ----------------------------------------------------------------------------------


@uncounted(nogil=True)
def run_events(
    until: float,
    body: np.ndarray,
    image: np.ndarray,
    geometry: np.ndarray,
    grid: np.ndarray,
    head: np.ndarray,
    next_: np.ndarray,
    event: np.ndarray,
    keys: np.ndarray,
    items: np.ndarray,
    tally: np.ndarray,
    impulse: np.ndarray,
    acceleration: np.ndarray,
    midpoint: float,
    sort_every: int,
    log: np.ndarray,
    logged: np.ndarray,
    walls: np.ndarray,
    heat: np.ndarray,
    segments: np.ndarray,
    piston: np.ndarray,
) -> int:
    """Process every event up to time ``until`` (inclusive) in time order.

    Parameters
    ----------
    until : float
        End of the drift, in s (absolute simulation time).
    image : ndarray of int64, shape (N, 2)
        Periodic image counters, by particle (not slot); updated at wraps.
    tally : ndarray of int64, shape (1 + W,)
        Incremented: pair collisions, then hits on each wall (`Vessel.wall_names` order).
    impulse : ndarray of float64, shape (1 + W,)
        Incremented: the collision virial ``sum r_ij . dp_i`` (kg m^2/s, ``r_ij = x_i - x_j`` at
        contact, ``dp_i`` the impulse on i), then the momentum given to each wall (kg m/s).
    acceleration : ndarray, shape (N, 2) or (0, 2)
        With forces, the acceleration of the step's half kicks (m/s^2), by particle, and
        ``midpoint`` the middle of the step (s): see `_pair_response`. Empty without forces.
    sort_every : int
        Events between two re-sorts of the slots (`sort_slots`); the outcome does not depend on
        it, only the speed.
    log : ndarray of float64, shape (K, `LOG_COLUMNS`)
        With forces (``acceleration`` not empty), each contact of the drift in turn, as long as
        there is room (`_log_contact`), for the integrator's correction of its kick timing
        (`collidium.kernels.kick_timing`).
    logged : ndarray of int64, shape (1,)
        Incremented by each contact logged, also those that found no room.
    walls : ndarray, shape (W, 3)
        The vessel's wall table (`collidium.kernels.wall_responses`): how each wall responds.
    heat : ndarray of float64, shape (1 + W,)
        Incremented like ``impulse``'s wall entries by the energy each wall gives the disks (J).
    segments : ndarray, shape (S, 9)
        The vessel's segments (`collidium.kernels.vessels.segments`).
    piston : ndarray, shape (`pistons.PISTON_SIZE`,) or (0,)
        The vessel's piston, moved in place (`collidium.kernels.vessels.piston`); its hits add
        the work it does on the gas to its wall's ``heat``. Empty without one.
    (other arrays)
        Engine state as built by `rebuild`; updated in place.

    Returns
    -------
    int
        Number of events processed (including cell crossings and stale events), or ``-1 - i``
        if time stopped advancing at particle i: far more events at one instant than simultaneous
        contacts allow, which only a runaway state (huge or infinite velocities) produces.
    """
    ident, cell_of, count = _slot_views(event)
    queue = event_queue.views(keys, items)
    processed = 0
    n = body.shape[0]
    if n == 0:
        return 0
    instant = -math.inf
    at_instant = 0
    since_sort = 0
    while True:
        if since_sort >= sort_every:
            sort_slots(body, cell_of, event, head, next_, keys, items, grid)
            since_sort = 0
        t = event_queue.first_time(queue)
        if piston.shape[0] > 0 and piston[pistons.NEXT] < t:
            # The piston reaches an end of its travel first.
            if piston[pistons.NEXT] > until:
                break
            pistons.arrive(piston)
            _piston_moved(piston[pistons.STAMP], body, ident, geometry, grid, cell_of, head,
                          next_, count, event, queue, segments, piston)  # fmt: skip
            processed += 1
            continue
        if t > until:
            break
        k = event_queue.earliest(queue, ident)
        _prefetch_following(queue, body, event, head, next_, grid)
        processed += 1
        since_sort += 1
        if t > instant:
            instant = t
            at_instant = 0
        at_instant += 1
        if at_instant > 100 * n + 10_000:
            return -1 - ident[k]
        code = event[k, CODE]
        crossed = -1
        pushed = False
        if code >= 0:
            j = code
            if count[j] == event[k, PARTNER_COUNT]:
                _collide(k, j, t, body, ident, geometry, grid, tally, impulse, acceleration,
                         midpoint, heat, log, logged)  # fmt: skip
                count[k] += 1
                count[j] += 1
                # Not the literal -1, which numba would compile a second `predict` for.
                t_j = predict(j, t, np.int64(-1), body, ident, geometry, grid, cell_of, head, next_,
                              count, event, segments, piston)  # fmt: skip
                event_queue.update(j, t_j, queue, ident)
        elif piston.shape[0] > 0 and code == FIRST_WALL_CODE - piston[pistons.WALL]:
            old_x, old_y = body[k, VX], body[k, VY]
            _push_piston(k, t, body, ident, geometry, tally, impulse, heat, piston)
            if acceleration.shape[0] > 0:
                _log_contact(log, logged, ident[k], -1 - piston[pistons.WALL], t, 0.0, 0.0, 0.0,
                             body[k, VX] - old_x, body[k, VY] - old_y)  # fmt: skip
            count[k] += 1
            pushed = True
        elif code <= FIRST_WALL_CODE:
            _bounce(k, FIRST_WALL_CODE - code, t, body, ident, geometry, tally, impulse,
                    acceleration, midpoint, walls, heat, segments, log, logged)  # fmt: skip
            count[k] += 1
        elif code >= CELL_CODES[1]:
            crossed = -1 - code
            _advance(k, t, body, geometry)
            _cross_cell(k, crossed, body, ident, image, geometry, grid, cell_of, head, next_)
        t_k = predict(k, t, crossed, body, ident, geometry, grid, cell_of, head, next_, count,
                      event, segments, piston)  # fmt: skip
        event_queue.update(k, t_k, queue, ident)
        if pushed:
            _piston_moved(t, body, ident, geometry, grid, cell_of, head, next_, count, event,
                          queue, segments, piston)  # fmt: skip
    return processed


@uncounted()
def _push_piston(k, t, body, ident, geometry, tally, impulse, heat, piston):
    """Slot k hits the piston at time t (s): snapped onto its face, both respond
    (`collidium.kernels.vessels.piston.hit`); the hit, the momentum and the work done on the gas
    are booked on the piston's wall."""
    _advance(k, t, body, geometry)
    x, y, _, _ = pistons.touch(piston, t, body[k, X], body[k, Y], _radius(k, body, geometry))
    body[k, X] = x
    body[k, Y] = y
    m = _mass(k, body, geometry)
    vx, vy, received, work = pistons.hit(piston, t, body[k, VX], body[k, VY], m,
                                         geometry[ELASTIC_BELOW])  # fmt: skip
    body[k, VX] = vx
    body[k, VY] = vy
    pistons.schedule(piston)
    wall = WALL_HITS + int(piston[pistons.WALL])
    tally[wall] += 1
    impulse[wall] += received
    heat[wall] += work


@uncounted()
def _piston_moved(now, body, ident, geometry, grid, cell_of, head, next_, count, event, queue,
                  segments, piston) -> None:  # fmt: skip
    """The piston's path changed at time ``now`` (s): every disk whose next event was a contact
    with it is predicted again, and every other that now meets it sooner than its next event
    takes that contact. O(N) per change of the piston's path, a few ns per disk."""
    code = FIRST_WALL_CODE - int(piston[pistons.WALL])
    for k in range(body.shape[0]):
        if event[k, CODE] == code:
            t_k = _predict_not_inlined(k, now, body, ident, geometry, grid, cell_of, head, next_,
                                       count, event, segments, piston)  # fmt: skip
            event_queue.update(k, t_k, queue, ident)
            continue
        x, y, vx, vy = _at(k, now, body, geometry)
        when = now + pistons.delay(piston, now, x, y, vx, vy, _radius(k, body, geometry),
                                   geometry[FALL_X], geometry[FALL_Y])  # fmt: skip
        if when < event_queue.time_of(k, queue):
            event[k, CODE] = code
            event_queue.update(k, when, queue, ident)


@inlined
def _log_contact(log, logged, particle, partner, t, nx, ny, bounce, dvx, dvy) -> None:
    """Write a contact into the next row of ``log`` if there is one (`run_events`): ``dvx``,
    ``dvy`` the change of the particle's velocity (m/s; the partner's is the opposite impulse)."""
    row = logged[0]
    if row < log.shape[0]:
        log[row, LOG_PARTICLE] = particle
        log[row, LOG_PARTNER] = partner
        log[row, LOG_TIME] = t
        log[row, LOG_NX] = nx
        log[row, LOG_NY] = ny
        log[row, LOG_BOUNCE] = bounce
        log[row, LOG_DVX] = dvx
        log[row, LOG_DVY] = dvy
    logged[0] = row + 1


@inlined
def _advance(k: int, t: float, body: np.ndarray, geometry: np.ndarray) -> None:
    """Bring slot k's row to time t (s)."""
    body[k, X], body[k, Y], body[k, VX], body[k, VY] = _at(k, t, body, geometry)
    body[k, STAMP] = t


@inlined
def _collide(k, j, t, body, ident, geometry, grid, tally, impulse, acceleration, midpoint, heat,
             log, logged):  # fmt: skip
    """Collision of slots k and j at time t (s); an inelastic one books the kinetic energy it
    takes in ``heat[PAIR_COLLISIONS]`` (J, negative); under forces it is logged."""
    _advance(k, t, body, geometry)
    _advance(j, t, body, geometry)
    # Contact normal x_k - x_j; in contact the pair is at most half a side apart, so the
    # minimum image is the one that touches.
    nx = body[k, X] - body[j, X]
    ny = body[k, Y] - body[j, Y]
    if grid[2] != 0:
        nx -= 2.0 * geometry[HALF_WIDTH] * round(nx / (2.0 * geometry[HALF_WIDTH]))
        ny -= 2.0 * geometry[HALF_HEIGHT] * round(ny / (2.0 * geometry[HALF_HEIGHT]))
    v1x, v1y, v2x, v2y, bounce = _pair_response(
        k, j, nx, ny, midpoint - t, body, ident, geometry, acceleration
    )
    if acceleration.shape[0] > 0:
        _log_contact(log, logged, ident[k], ident[j], t, nx, ny, bounce, v1x - body[k, VX],
                     v1y - body[k, VY])  # fmt: skip
    m1, m2 = _mass(k, body, geometry), _mass(j, body, geometry)
    impulse[PAIR_COLLISIONS] += m1 * (nx * (v1x - body[k, VX]) + ny * (v1y - body[k, VY]))
    if geometry[RESTITUTION] != 1.0:
        heat[PAIR_COLLISIONS] += energy_change(m1, m2, body[k, VX], body[k, VY], body[j, VX],
                                               body[j, VY], v1x, v1y, v2x, v2y)  # fmt: skip
    body[k, VX] = v1x
    body[k, VY] = v1y
    body[j, VX] = v2x
    body[j, VY] = v2y
    tally[PAIR_COLLISIONS] += 1


@inlined
def _bounce(k, contact, t, body, ident, geometry, tally, impulse, acceleration, midpoint, walls,
            heat, segments, log, logged):  # fmt: skip
    """Slot k meets the vessel at ``contact`` (`collidium.kernels.vessels.contacts`) at time t
    (s). The disk is first snapped onto the contact line, so that round-off never leaves it past
    the wall; then the wall responds (``walls``, the vessel's wall table). Under forces the hit
    is logged."""
    _advance(k, t, body, geometry)
    r = _radius(k, body, geometry)
    m = _mass(k, body, geometry)
    x, y, nx, ny, wall = contacts.touch(contact, body[k, X], body[k, Y], body[k, VX],
                                        body[k, VY], r, geometry[SHAPE], geometry[HALF_WIDTH],
                                        geometry[HALF_HEIGHT], geometry[RIM],
                                        segments)  # fmt: skip
    body[k, X] = x
    body[k, Y] = y
    old_x, old_y = body[k, VX], body[k, VY]
    if walls[wall, wall_responses.RESPONSE] != wall_responses.SPECULAR:
        vx, vy = wall_responses.hit(walls, wall, body[k, VX], body[k, VY], nx, ny, m, ident[k],
                                    tally, impulse, heat, WALL_HITS + wall)  # fmt: skip
        body[k, VX] = vx
        body[k, VY] = vy
        if acceleration.shape[0] > 0:
            _log_contact(log, logged, ident[k], -1 - wall, t, nx, ny, 0.0, vx - old_x, vy - old_y)
        return
    forced = acceleration.shape[0] > 0
    if geometry[SHAPE] == BOX and contact < contacts.SEGMENTS_FROM:
        # A mirror of the box: the normal is an axis, so the response is exact.
        d = contact // 2
        sign = 1.0 if contact % 2 == 1 else -1.0
        before = body[k, VX + d]
        pull = acceleration[ident[k], d] if forced else 0.0
        normal, corrected = _wall_response(sign * before, sign * pull, midpoint - t, forced)
        after = sign * normal
        body[k, VX + d] = after
        impulse[WALL_HITS + wall] += m * abs(after - before)
    else:
        outward = body[k, VX] * nx + body[k, VY] * ny
        pull = 0.0
        if forced:
            pull = acceleration[ident[k], 0] * nx + acceleration[ident[k], 1] * ny
        normal, corrected = _wall_response(outward, pull, midpoint - t, forced)
        change = normal - outward
        body[k, VX] += change * nx
        body[k, VY] += change * ny
        impulse[WALL_HITS + wall] += m * abs(change)
    tally[WALL_HITS + wall] += 1
    if forced:
        _log_contact(log, logged, ident[k], -1 - wall, t, nx, ny, 2.0 if corrected else 0.0,
                     body[k, VX] - old_x, body[k, VY] - old_y)  # fmt: skip


@inlined
def _pair_response(k, j, nx, ny, lead, body, ident, geometry, acceleration):
    """Velocities of k and j after their collision, with the kick timing corrected.

    In a kick-drift-kick step each particle got ``a dt/2`` before the drift, although, at a
    collision at time tau into the step, only ``a tau`` of that impulse was physically received
    before it. Plain reflection leaves an O(dt) energy error per collision; instead the surplus
    ``delta = a (dt/2 - tau)`` (``lead = dt/2 - tau``) is taken out, the elastic response applied,
    and the surplus put back: ``v' = C(v - delta) + delta``. Momentum is conserved exactly; the
    error per collision becomes O(dt^2). If that would leave the pair still approaching (a slow
    contact under strong attraction), the plain response ``C(v)`` is used.

    Returns the four velocity components and the factor ``1 + e`` by which the corrected
    response changed the normal relative velocity (`collision.bounce_factor`), 0 where it was
    not corrected (no forces, or the plain response).
    """
    m1 = _mass(k, body, geometry)
    m2 = _mass(j, body, geometry)
    e, below = geometry[RESTITUTION], geometry[ELASTIC_BELOW]
    v1x, v1y = body[k, VX], body[k, VY]
    v2x, v2y = body[j, VX], body[j, VY]
    if acceleration.shape[0] > 0:
        a, b = ident[k], ident[j]
        d1x, d1y = lead * acceleration[a, 0], lead * acceleration[a, 1]
        d2x, d2y = lead * acceleration[b, 0], lead * acceleration[b, 1]
        w1x, w1y, w2x, w2y = pair_response(
            m1, m2, nx, ny, v1x - d1x, v1y - d1y, v2x - d2x, v2y - d2y, e, below
        )
        w1x, w1y, w2x, w2y = w1x + d1x, w1y + d1y, w2x + d2x, w2y + d2y
        if (w1x - w2x) * nx + (w1y - w2y) * ny > 0.0:
            n2 = nx * nx + ny * ny
            along = ((v1x - d1x - v2x + d2x) * nx + (v1y - d1y - v2y + d2y) * ny) / n2
            return w1x, w1y, w2x, w2y, bounce_factor(along, n2, e, below)
    w1x, w1y, w2x, w2y = pair_response(m1, m2, nx, ny, v1x, v1y, v2x, v2y, e, below)
    return w1x, w1y, w2x, w2y, 0.0


@inlined
def _wall_response(outward, pull, lead, forced):
    """Velocity along a wall's outward normal after a bounce, from ``outward`` before it (m/s),
    with the kick-timing correction of pairs when ``forced``: ``pull`` is the acceleration along
    the normal (m/s^2), ``lead`` as in `_pair_response`; ``v' = -(v - delta) + delta`` is kept
    only if it leaves the wall, else ``-v``. Returns it and whether it was corrected."""
    if forced:
        corrected = -outward + 2.0 * lead * pull
        if corrected < 0.0:
            return corrected, True
    return -outward, False


# --- between the engine and the particles -------------------------------------------------------


@uncounted()
def load(position, velocity, radius, mass, body, event) -> None:
    """Fill ``body`` (N, 7), or (N, 5) without radius and mass, from the particles: slot k from
    particle ``event[k, IDENT]``.

    The slots keep their particles from queue to queue (a fresh engine's slot k holds particle
    k): a queue built again where the particles moved since the last (a drift that left disks
    outside the cells' window, the compiled substeps' flights) finds the slots still nearly in
    cell order (`rebuild`).

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        In m and m/s.
    radius, mass : ndarray, shape (N,)
        In m and kg.
    """
    for k in range(position.shape[0]):
        i = event[k, IDENT]
        body[k, X] = position[i, 0]
        body[k, Y] = position[i, 1]
        body[k, VX] = velocity[i, 0]
        body[k, VY] = velocity[i, 1]
        if body.shape[1] > MASS:
            body[k, RADIUS] = radius[i]
            body[k, MASS] = mass[i]


@uncounted(nogil=True)
def synchronise(now, body, event, geometry, grid, position, velocity) -> int:
    """Write every particle's position at time ``now`` (s) and velocity into ``position`` and
    ``velocity`` (N, 2), by particle; the lazily kept state is untouched so the queue stays
    valid. Returns how many particles are outside the cells' window (they share its edge cells:
    right, but slow when they are many)."""
    return _synchronise_between(0, body.shape[0], now, body, event, geometry, grid, position,
                                velocity)  # fmt: skip


@uncounted(nogil=True)
def audit_in_box(now, body, geometry, grid, limit_x, limit_y, periodic,
                 window_is_vessel) -> tuple[bool, int, float]:  # fmt: skip
    """What `synchronise` and then the audit in a box without segments
    (`collidium.kernels.audit.all_valid`) find at time ``now`` (s), read from the slots, the
    particles not written: whether every particle is finite and inside the half sides
    ``limit_x, limit_y`` (m; its centre alone if ``periodic``), how many are outside the cells'
    window (counted only where the window is not the vessel, ``window_is_vessel``: a disk inside
    the vessel is inside it), and their largest velocity component (m/s; as
    `collidium.kernels.floats.largest_magnitude` takes it from the velocities written). The
    positions are `synchronise`'s, bit for bit: the verdicts are those of the particles that it
    would write."""
    x0, y0, x1, y1 = _window(geometry, grid)
    count = not window_is_vessel  # a disk inside the vessel is inside the window
    shared = periodic or body.shape[1] == SHARED_BODY_COLUMNS
    radius = 0.0 if periodic else geometry[SHARED_RADIUS]  # read once, where the disks share it
    strays = 0
    bad = False
    largest = 0.0
    for k in range(body.shape[0]):
        x, y, vx, vy = _at(k, now, body, geometry)
        bad |= fails_in_box(x, y, vx, vy, radius if shared else body[k, RADIUS], limit_x, limit_y)
        if count:
            strays += not (x0 <= x <= x1 and y0 <= y <= y1)
        largest = max(largest, abs(vx), abs(vy))
    return not bad, strays, largest


@inlined
def _window(geometry, grid) -> tuple[float, float, float, float]:
    """The cells' window: its left, bottom, right and top (m)."""
    x0, y0 = geometry[GRID_LEFT], geometry[GRID_BOTTOM]
    return x0, y0, x0 + grid[0] * geometry[CELL_WIDTH], y0 + grid[1] * geometry[CELL_HEIGHT]


@numba.njit(cache=True, parallel=True, nogil=True)
def synchronise_in_chunks(now, body, event, geometry, grid, position, velocity) -> int:
    """`synchronise` in parallel chunks of slots, for many particles (`audit.PARALLEL_FROM`): each
    particle is written once, so any number of threads writes the same."""
    n = body.shape[0]
    chunks = chunk_count(n)
    strays = np.zeros(chunks, dtype=np.int64)
    for p in numba.prange(chunks):
        strays[p] = _synchronise_between(p * n // chunks, (p + 1) * n // chunks, now, body,
                                         event, geometry, grid, position, velocity)  # fmt: skip
    return strays.sum()


@inlined
def _synchronise_between(start, stop, now, body, event, geometry, grid, position, velocity):
    """`synchronise` for the slots ``start`` to ``stop - 1``: their strays."""
    x0, y0, x1, y1 = _window(geometry, grid)
    strays = 0
    for k in range(start, stop):
        i = event[k, IDENT]
        x, y, vx, vy = _at(k, now, body, geometry)
        position[i, 0] = x
        position[i, 1] = y
        velocity[i, 0] = vx
        velocity[i, 1] = vy
        strays += not (x0 <= x <= x1 and y0 <= y <= y1)
    return strays


#: ``event[k, KEPT]`` of a slot whose velocity changed (`_take_in_between`) until `refresh`
#: predicts it again.
REPREDICT = -2


@uncounted(nogil=True)
def refresh(now, body, geometry, grid, head, next_, event, keys, items, segments, piston,
            position, velocity, radius, mass) -> int:  # fmt: skip
    """Bring the queue up to date with the particles at ``now`` (s), the time `synchronise` last
    wrote them, where only velocities changed since (a kick, a user's edit): each slot whose
    velocity changed starts again at ``now`` with the new one and is predicted again; the others
    keep their rows and events.

    That is exact, as after a collision: the changed slot's collision count goes up, so that
    events predicted against it are stale when they come, and its own prediction searches every
    neighbour, so that it finds any contact that comes before their own next events. The queue is
    then ordered again (`collidium.kernels.event_queue.build`).

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        The particles' positions (m) and velocities (m/s), by particle.
    radius, mass : ndarray, shape (N,)
        In m and kg.

    Returns
    -------
    int
        How many slots changed (0: the queue was up to date), or -1 where a position, radius or
        mass is not the engine's: the queue must then be built again (`load`, `rebuild`, which
        set every row: some may have been changed here).
    """
    n = body.shape[0]
    changed = _take_in_between(0, n, now, body, event, geometry, position, velocity, radius,
                               mass)  # fmt: skip
    if changed > 0:
        _predict_marked_between(0, n, now, body, geometry, grid, head, next_, event, keys,
                                segments, piston)  # fmt: skip
        event_queue.build(keys, items, event[:, IDENT])
    return changed


@numba.njit(cache=True, parallel=True, nogil=True)
def refresh_in_chunks(now, body, geometry, grid, head, next_, event, keys, items, segments,
                      piston, position, velocity, radius, mass) -> int:  # fmt: skip
    """`refresh` with its passes over every slot in parallel chunks, for many particles
    (`audit.PARALLEL_FROM`). Each slot's row and prediction are its own, so any number of
    threads leaves the same queue."""
    n = body.shape[0]
    chunks = chunk_count(n)
    changed = np.zeros(chunks, dtype=np.int64)
    for p in numba.prange(chunks):
        changed[p] = _take_in_between(p * n // chunks, (p + 1) * n // chunks, now, body, event,
                                      geometry, position, velocity, radius, mass)  # fmt: skip
    if (changed < 0).any():
        return -1
    total = changed.sum()
    if total > 0:
        for p in numba.prange(chunks):
            _predict_marked_between(p * n // chunks, (p + 1) * n // chunks, now, body, geometry,
                                    grid, head, next_, event, keys, segments, piston)  # fmt: skip
        event_queue.build(keys, items, event[:, IDENT])
    return total


@inlined
def _take_in_between(start, stop, now, body, event, geometry, position, velocity, radius, mass):
    """Start the slots ``start`` to ``stop - 1`` whose particle's velocity is no longer the one
    `synchronise` wrote at ``now`` (s) again there with the new one, marked `REPREDICT`, their
    collision counts raised. Returns how many, or -1 at the first whose position, radius or mass
    is not the engine's. Radii and masses that the disks share are checked apart, for the
    particles ``start`` to ``stop - 1`` in their own order: read from each slot's particle they
    would be two more reads at random, which cost more than the rest of the pass."""
    shared = body.shape[1] == SHARED_BODY_COLUMNS
    if shared:
        for i in range(start, stop):
            if radius[i] != geometry[SHARED_RADIUS] or mass[i] != geometry[SHARED_MASS]:
                return -1
    changed = 0
    for k in range(start, stop):
        i = event[k, IDENT]
        x, y, vx, vy = _at(k, now, body, geometry)
        if position[i, 0] != x or position[i, 1] != y:
            return -1
        if not shared and (radius[i] != body[k, RADIUS] or mass[i] != body[k, MASS]):
            return -1
        if velocity[i, 0] != vx or velocity[i, 1] != vy:
            body[k, X] = x
            body[k, Y] = y
            body[k, VX] = velocity[i, 0]
            body[k, VY] = velocity[i, 1]
            body[k, STAMP] = now
            event[k, COUNT] += 1
            event[k, KEPT] = REPREDICT
            changed += 1
    return changed


@inlined
def _predict_marked_between(start, stop, now, body, geometry, grid, head, next_, event, keys,
                            segments, piston) -> None:  # fmt: skip
    """Predict the slots ``start`` to ``stop - 1`` marked `REPREDICT` again, each event time
    written into ``keys`` (the queue's first entries), whose order the caller then restores."""
    ident, cell_of, count = _slot_views(event)
    for k in range(start, stop):
        if event[k, KEPT] == REPREDICT:
            keys[k] = _predict_not_inlined(k, now, body, ident, geometry, grid, cell_of, head,
                                           next_, count, event, segments, piston)  # fmt: skip
