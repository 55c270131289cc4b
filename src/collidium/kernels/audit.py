"""One pass over the state to catch a non-finite value or a particle outside its vessel."""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.compilation import inlined, uncounted
from collidium.kernels.stepper import chunk_count
from collidium.kernels.vessels import BOX, box, contacts

#: Particles from which the audit runs in parallel chunks; below, starting the threads would cost
#: more than the pass (a two-disk scene took twice as long a step).
PARALLEL_FROM = 16_384


def first_invalid(
    position: np.ndarray,
    velocity: np.ndarray,
    radius: np.ndarray,
    shape: int,
    limit_x: float,
    limit_y: float,
    slack: float,
    periodic: bool,
    segments: np.ndarray,
) -> tuple[int, int]:
    """The first particle with a non-finite position or velocity, or outside the vessel.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        State in m and m/s.
    radius : ndarray, shape (N,)
        Radii in m.
    shape : int
        The vessel's shape code (`collidium.kernels.vessels`).
    limit_x, limit_y, slack : float
        The shape's limits with their round-off allowance (`Vessel.audit_arguments`): the box's
        half sides, the circle's radius twice (m); how much closer than its radius a disk may
        come to a segment (m).
    periodic : bool
        Periodic: the centre must be in the primary cell. Else the whole disk must be inside.
    segments : ndarray, shape (S, 9)
        The vessel's segments (`collidium.kernels.vessels.segments`).

    Returns
    -------
    tuple of int
        ``(index, reason)``: reason 1 for non-finite, 2 for outside; ``(-1, 0)`` if all is well.
    """
    audit = _in_chunks if position.shape[0] >= PARALLEL_FROM else in_order
    index, reason = audit(
        position, velocity, radius, shape, limit_x, limit_y, slack, periodic, segments
    )
    return int(index), int(reason)


@uncounted()
def first_past_face(position, radius, axis, sign, face, allowance) -> int:
    """The first disk reaching past a piston's face by more than ``allowance`` (m), or -1: past
    when ``sign (position[i, axis] - face) + radius[i]`` exceeds it
    (`collidium.vessels.Vessel.piston_face`). A centre that is not finite is not past
    (`first_invalid` finds it)."""
    for i in range(position.shape[0]):
        if sign * (position[i, axis] - face) + radius[i] > allowance:
            return i
    return -1


@uncounted()
def in_order(position, velocity, radius, shape, limit_x, limit_y, slack, periodic, segments):
    """`first_invalid` in one pass, particle by particle, compiled: ``(index, reason)``."""
    return _first_between(0, position.shape[0], position, velocity, radius, shape, limit_x,
                          limit_y, slack, periodic, segments)  # fmt: skip


@uncounted()
def all_valid(position, velocity, radius, shape, limit_x, limit_y, slack, periodic, segments):
    """Whether no particle fails the audit (`first_invalid`; its arguments), compiled, for the
    steps a run flies (`collidium.kernels.event_flights`). In a box without segments one pass
    without branches, which LLVM vectorises (0.5 against 3.5 us for 200 disks); `in_order`
    otherwise (a circle's branch-free pass, tried, was no faster)."""
    if shape != BOX or segments.shape[0] > 0:
        return in_order(position, velocity, radius, shape, limit_x, limit_y, slack, periodic,
                        segments)[0] < 0  # fmt: skip
    bad = False
    for i in range(position.shape[0]):
        reach = 0.0 if periodic else radius[i]
        bad |= fails_in_box(position[i, 0], position[i, 1], velocity[i, 0], velocity[i, 1], reach,
                            limit_x, limit_y)  # fmt: skip
    return not bad


@inlined
def fails_in_box(x, y, vx, vy, reach, limit_x, limit_y) -> bool:
    """Whether a disk at (x, y) moving at (vx, vy) fails the audit of a box without segments:
    a value not finite, or reaching ``reach`` m (its radius; 0 in a periodic box) past the half
    sides ``limit_x, limit_y`` (m). Without branches (`all_valid`,
    `collidium.kernels.events.audit_in_box`). `collidium.kernels.vessels.box.reaches_outside`
    finds the coordinates that are not finite too, which spares testing them apart (a tenth of
    a microsecond a step of a 200-disk gas)."""
    moving = (vx - vx == 0.0) & (vy - vy == 0.0)  # NaN else
    return box.reaches_outside(x, y, reach, limit_x, limit_y) | (not moving)


@numba.njit(cache=True, parallel=True, nogil=True)
def _in_chunks(position, velocity, radius, shape, limit_x, limit_y, slack, periodic, segments):
    """`first_invalid` in parallel chunks: each finds its first, the earliest chunk's wins."""
    n = position.shape[0]
    chunks = chunk_count(n)
    first = np.full(chunks, -1)
    reason = np.zeros(chunks, dtype=np.int64)
    for p in numba.prange(chunks):
        start, stop = p * n // chunks, (p + 1) * n // chunks
        first[p], reason[p] = _first_between(start, stop, position, velocity, radius, shape,
                                             limit_x, limit_y, slack, periodic,
                                             segments)  # fmt: skip
    for p in range(chunks):
        if first[p] >= 0:
            return first[p], reason[p]
    return -1, 0


@numba.njit(cache=True, inline="always")
def _first_between(start, stop, position, velocity, radius, shape, limit_x, limit_y, slack,
                   periodic, segments):  # fmt: skip
    """The first invalid particle among ``start`` to ``stop - 1`` and why, or ``(-1, 0)``."""
    for i in range(start, stop):
        why = _invalid(position[i, 0], position[i, 1], velocity[i, 0], velocity[i, 1],
                       0.0 if periodic else radius[i], shape, limit_x, limit_y, slack,
                       segments)  # fmt: skip
        if why:
            return i, why
    return -1, 0


@numba.njit(cache=True, inline="always")
def _invalid(x, y, vx, vy, reach, shape, limit_x, limit_y, slack, segments) -> int:
    """1 if the position or velocity is not finite, 2 if the disk reaches past the vessel's
    walls, else 0."""
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(vx) and math.isfinite(vy)):
        return 1
    outside = contacts.reaches_outside(x, y, reach, shape, limit_x, limit_y, slack, segments)
    return 2 if outside else 0
