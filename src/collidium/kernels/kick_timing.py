"""The kick timing of contacts under forces, corrected to second order.

A kick-drift-kick substep h gives each particle the forces' impulse at its ends, ``a0 h / 2``
before the drift and ``aH h / 2`` after it. A contact at ``tau`` into the drift changes the
velocities in between, by a map C (a reflection of the normal velocity, for a pair its relative
one), although the particles physically received only part of the impulse before it. The exact
engine's response takes out the first-order error, ``v' = C(v - delta) + delta`` with
``delta = a0 (h/2 - tau)`` (`collidium.kernels.events`): exact for a constant acceleration, it
leaves an error of O(h^2) per contact, which in a charged gas, where the pair in contact pulls
hardest, is most of the energy error.

`correct` adds the rest once the accelerations at the substep's end are known: for a particle
whose acceleration goes linearly from ``a0`` to ``a_c`` at the contact and from there linearly to
``aH``, the velocity at the end is the kick-drift-kick one plus

    X = C[(a_c - a0) tau / 2] + a_c (h - tau) / 2 - aH tau / 2 + a0 (tau - h / 2),

which is 0 for a constant acceleration (C[.] of a pair acts on both particles' vectors). The
acceleration at the contact ``a_c`` is the pair's mutual inverse-distance forces at the contact
separation, which peak there, plus the rest of each particle's acceleration interpolated
linearly over the substep; a wall contributes no force of its own. A charged gas of 200 disks
(the seed's) with 16 substeps per 0.01 s drifts by 3e-6 of its energy over 60 s, against 1e-4
over 10 s with the first-order response alone.

The positions after the contact, drifted with the first-order velocities, are off by O(h^3).
"""

from __future__ import annotations

import numba
import numpy as np

from collidium.kernels.compilation import uncounted
from collidium.kernels.events import (
    LOG_BOUNCE,
    LOG_NX,
    LOG_NY,
    LOG_PARTICLE,
    LOG_PARTNER,
    LOG_TIME,
)
from collidium.kernels.pairwise import inverse_distance_pair


@uncounted(error_model="numpy")
def correct(
    contacts: np.ndarray,
    count: int,
    start_time: float,
    h: float,
    start: np.ndarray,
    position: np.ndarray,
    before: np.ndarray,
    after: np.ndarray,
    velocity: np.ndarray,
    mass: np.ndarray,
    sources: np.ndarray,
    couplings: np.ndarray,
    softenings2: np.ndarray,
    width: float,
    height: float,
    periodic: bool,
) -> None:
    """Add the second-order kick-timing correction ``X`` of each contact of a substep to the
    velocities of its particles, in place.

    Parameters
    ----------
    contacts : ndarray, shape (K, `collidium.kernels.events.LOG_COLUMNS`)
        The substep's contacts in the order they happened, as the engine logs them, in the
        first ``count`` rows; those with a bounce factor of 0 (not corrected to first order)
        are left out.
    start_time, h : float
        The substep's start and length, s.
    start, position : ndarray, shape (N, 2)
        Positions at the substep's start and end, m.
    before, after : ndarray, shape (N, 2)
        The accelerations of the kicks at the substep's start and end, m/s^2.
    velocity : ndarray, shape (N, 2)
        The velocities after the drift, before the closing kick, m/s; corrected in place.
    mass : ndarray, shape (N,)
        In kg.
    sources : ndarray, shape (L, N)
        The sources of the L inverse-distance pair forces
        (`collidium.kernels.pairwise.inverse_distance_pair`), with their ``couplings`` (L,) and
        squared softenings ``softenings2`` (L,), m^2.
    width, height, periodic
        The box's sides (m) and whether separations take the minimum image.
    """
    for c in range(count):
        bounce = contacts[c, LOG_BOUNCE]
        if bounce == 0.0:
            continue
        i = int(contacts[c, LOG_PARTICLE])
        partner = int(contacts[c, LOG_PARTNER])
        tau = contacts[c, LOG_TIME] - start_time
        nx, ny = contacts[c, LOG_NX], contacts[c, LOG_NY]
        share = tau / h
        if partner < 0:  # a mirror: C reflects the normal component
            cx, cy = _at_contact(i, 0.0, 0.0, 0.0, 0.0, 0.0, share, before, after, mass, nx, ny)
            px, py = (cx - before[i, 0]) * 0.5 * tau, (cy - before[i, 1]) * 0.5 * tau
            along = bounce * (px * nx + py * ny) / (nx * nx + ny * ny)
            _add(i, px - along * nx, py - along * ny, cx, cy, tau, h, before, after, velocity)
            continue
        j = partner
        f0 = _mutual(i, j, start, sources, couplings, softenings2, width, height, periodic)
        fh = _mutual(i, j, position, sources, couplings, softenings2, width, height, periodic)
        fc = _pull(nx * nx + ny * ny, i, j, sources, couplings, softenings2)
        s0x, s0y = _separation(i, j, start, width, height, periodic)
        shx, shy = _separation(i, j, position, width, height, periodic)
        # Mutual forces on i along the separations, f * s; on j, the opposite.
        ix, iy = _at_contact(i, f0 * s0x, f0 * s0y, fh * shx, fh * shy, fc, share, before, after,
                             mass, nx, ny)  # fmt: skip
        jx, jy = _at_contact(j, -f0 * s0x, -f0 * s0y, -fh * shx, -fh * shy, -fc, share, before,
                             after, mass, nx, ny)  # fmt: skip
        pix, piy = (ix - before[i, 0]) * 0.5 * tau, (iy - before[i, 1]) * 0.5 * tau
        pjx, pjy = (jx - before[j, 0]) * 0.5 * tau, (jy - before[j, 1]) * 0.5 * tau
        along = bounce * ((pix - pjx) * nx + (piy - pjy) * ny) / (nx * nx + ny * ny)
        total = mass[i] + mass[j]
        gi, gj = along * mass[j] / total, along * mass[i] / total
        _add(i, pix - gi * nx, piy - gi * ny, ix, iy, tau, h, before, after, velocity)
        _add(j, pjx + gj * nx, pjy + gj * ny, jx, jy, tau, h, before, after, velocity)


@numba.njit(cache=True, inline="always")
def _at_contact(i, f0x, f0y, fhx, fhy, fc, share, before, after, mass, nx, ny):
    """Particle i's acceleration at the contact (m/s^2): the rest of its acceleration, without the
    mutual force ``f0`` at the start and ``fh`` at the end (N), interpolated by ``share`` of the
    substep, plus the mutual force at the contact, ``fc`` times the normal (nx, ny)."""
    m = mass[i]
    rest_x = before[i, 0] - f0x / m + (after[i, 0] - fhx / m - before[i, 0] + f0x / m) * share
    rest_y = before[i, 1] - f0y / m + (after[i, 1] - fhy / m - before[i, 1] + f0y / m) * share
    return rest_x + fc * nx / m, rest_y + fc * ny / m


@numba.njit(cache=True, inline="always")
def _add(i, cx, cy, ax, ay, tau, h, before, after, velocity) -> None:
    """Add ``X`` to particle i's velocity: ``C[P]`` (cx, cy), then the accelerations' terms,
    ``a`` (ax, ay) at the contact."""
    for d in range(2):
        at = ax if d == 0 else ay
        velocity[i, d] += ((cx if d == 0 else cy) + at * 0.5 * (h - tau)
                           - after[i, d] * 0.5 * tau + before[i, d] * (tau - 0.5 * h))  # fmt: skip


@numba.njit(cache=True, inline="always")
def _separation(i, j, position, width, height, periodic) -> tuple[float, float]:
    """``x_i - x_j`` (m), the minimum image when ``periodic``."""
    sx = position[i, 0] - position[j, 0]
    sy = position[i, 1] - position[j, 1]
    if periodic:
        sx -= width * round(sx / width)
        sy -= height * round(sy / height)
    return sx, sy


@numba.njit(cache=True, inline="always")
def _mutual(i, j, position, sources, couplings, softenings2, width, height, periodic) -> float:
    """The pair forces between i and j at ``position``: the force on i is this times
    ``x_i - x_j`` (N/m)."""
    sx, sy = _separation(i, j, position, width, height, periodic)
    return _pull(sx * sx + sy * sy, i, j, sources, couplings, softenings2)


@numba.njit(cache=True, inline="always")
def _pull(r2, i, j, sources, couplings, softenings2) -> float:
    """The pair forces of particles i and j at squared distance ``r2`` (m^2), summed over the
    laws: the force on i is this times ``x_i - x_j`` (N/m)."""
    total = 0.0
    for law in range(couplings.shape[0]):
        kqq = couplings[law] * sources[law, i] * sources[law, j]
        if kqq != 0.0:
            f, _ = inverse_distance_pair(r2, kqq, softenings2[law])
            total += f
    return total
