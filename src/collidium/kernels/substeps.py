"""The adaptive leapfrog's contact-free substeps under inverse-distance pair forces, compiled.

The adaptive integrator (`collidium.integrators.AdaptiveLeapfrog`) cuts a reporting interval
into n equal kick-drift-kick substeps. In a small charged scene most substeps meet no contact,
and their drift is then a straight flight; a Python call per substep (kick, drift, force sum,
substep rate) costs a hundred times the arithmetic. `smooth_substeps` flies a run of such
substeps in one call, with the pair sums of `collidium.kernels.pairwise`, and stops before the
first substep whose flight would bring a disk near a wall or another disk, or whose values stop
being finite: the integrator takes that one in Python, where the collision modes and the error
messages are (the divisions here follow NumPy: an overflow gives inf, which stops the
substeps). The two paths differ by round-off only: the exact engine advances a disk at each
cell crossing, in two roundings where the straight flight here takes one.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.pairwise import MOST_BLOCKS, larger, pair_sums, stiffness_row
from collidium.kernels.sorting import sort_nearly_sorted
from collidium.kernels.vessels import contacts

#: Relative margin of the contact test: a disk that comes within this fraction of its radius (or
#: of a pair's contact distance) of a contact, within this fraction past the substep, counts as
#: meeting it. The engine finds contacts from the same numbers but at other instants (after a
#: cell crossing), so round-off could otherwise part the two on a grazing contact.
CONTACT_MARGIN = 1e-6


@numba.njit(cache=True)
def kinetic_energy(mass: np.ndarray, velocity: np.ndarray) -> float:
    """``sum m v^2 / 2`` in J of masses (N,) in kg and velocities (N, 2) in m/s, summed in
    particle order (the substep rate's, alike in both paths of the integrator)."""
    total = 0.0
    for i in range(mass.shape[0]):
        total += mass[i] * (velocity[i, 0] * velocity[i, 0] + velocity[i, 1] * velocity[i, 1])
    return 0.5 * total


@numba.njit(cache=True)
def energy_scale(kinetic: float, total: float, floor: float) -> float:
    """The energy (J) the substep rate judges the energy error against: ``|E|``, but at least
    ``(KE + |U|) / floor``, with the potential ``U = E - KE`` (``total`` E and ``kinetic`` KE in
    J); 0 only when there is no energy at all."""
    return max(abs(total), (kinetic + abs(total - kinetic)) / floor)


@numba.njit(cache=True, error_model="numpy")
def smooth_substeps(
    position, velocity, acceleration, mass, radius, sources, couplings, softening2,
    shape, half_width, half_height, rim, segments, now, dt, first, count, t, fastest, total,
    energy_floor,
) -> tuple[int, float, float]:  # fmt: skip
    """Regular substeps ``first, first + 1, ...`` of ``count`` in the interval from ``now`` of
    ``dt`` (s), in place, up to the first that may meet a contact.

    Substep s ends at ``now + dt s / count``; it is a kick ``v += a h / 2``, the straight flight
    over h, the accelerations at the new positions and the kick ``v += a h / 2``. After each,
    the squared rate of the forces weighted by energy (`collidium.integrators._squared_rate`)
    raises ``fastest``. No energy is summed: the rate's energy scale takes the potential as the
    ``total`` energy less the kinetic (the forces conserve the total to the tolerance).

    Parameters
    ----------
    position, velocity, acceleration : ndarray, shape (N, 2)
        In m, m/s and m/s^2, at time ``t``, which is substep ``first``'s start; updated.
    mass, radius : ndarray, shape (N,)
        In kg and m.
    sources : ndarray, shape (F, N)
        Each pair force's sources (`collidium.kernels.pairwise.inverse_distance_direct`).
    couplings, softening2 : ndarray, shape (F,)
        Each pair force's coupling (N m^2 per source squared) and squared softening (m^2).
    shape, half_width, half_height, rim, segments
        The vessel as the exact engine has it (`collidium.kernels.vessels.contacts.earliest`).
    now, dt : float
        The interval's start and length, s.
    first, count : int
        The substep to start with (1 to ``count``) and the interval's number of substeps.
    t : float
        Substep ``first``'s start, s.
    fastest : float
        Largest squared rate so far, 1/s^2; if negative, the rate of the state given (with
        ``first > count``, the call returns just that: the rate of an interval's start).
    total : float
        The total energy (kinetic and potential) at the interval's start, J.
    energy_floor : float
        The rate's energy scale is ``|KE + U|`` but at least ``(KE + |U|) / energy_floor``
        (`energy_scale`).

    Returns
    -------
    tuple
        ``(substep, time, fastest)``: the substep not taken (``count + 1`` when all were), its
        start (s) and the largest squared rate.
    """
    n = position.shape[0]
    kicked = np.empty((n, 2))
    flown = np.empty((n, 2))
    pull = np.empty((n, 2))
    # Each force's particles with a source, in a row of (index, source, 1 / mass), and work
    # rows for their coordinates and velocities: the pair rows read contiguous arrays.
    index, charged, inverse_mass, counts = _with_sources(sources, mass)
    moving = np.empty((4, n))
    sums = np.empty(4 * n * (1 + MOST_BLOCKS // 2))  # the pair sums' work (`_accelerations`)
    order, low, high = np.arange(n), np.empty(n), np.empty(n)  # the sweep (`_meets_contact`)
    walls = (shape, half_width, half_height, rim, segments)
    if fastest < 0.0:
        fastest = _squared_rate(position, velocity, mass, index, charged, inverse_mass, counts,
                                couplings, softening2, moving, total, energy_floor)  # fmt: skip
    for s in range(first, count + 1):
        end = now + dt * s / count
        h = end - t
        for i in range(n):
            for d in range(2):
                kicked[i, d] = velocity[i, d] + (0.5 * h) * acceleration[i, d]
        if not _finite(kicked) or _meets_contact(position, kicked, radius, h, *walls, order, low,
                                                 high):  # fmt: skip
            return s, t, fastest
        for i in range(n):
            for d in range(2):
                flown[i, d] = position[i, d] + kicked[i, d] * h
        _accelerations(flown, mass, index, charged, counts, couplings, softening2, moving, sums,
                       pull)  # fmt: skip
        if not _finite(pull):
            return s, t, fastest
        for i in range(n):
            for d in range(2):
                position[i, d] = flown[i, d]
                velocity[i, d] = kicked[i, d] + (0.5 * h) * pull[i, d]
                acceleration[i, d] = pull[i, d]
        t = end
        rate2 = _squared_rate(position, velocity, mass, index, charged, inverse_mass, counts,
                              couplings, softening2, moving, total, energy_floor)  # fmt: skip
        if rate2 > fastest:
            fastest = rate2
    return count + 1, t, fastest


@numba.njit(cache=True)
def _finite(values: np.ndarray) -> bool:
    """Whether every entry of ``values`` (N, 2) is finite."""
    for i in range(values.shape[0]):
        if not (math.isfinite(values[i, 0]) and math.isfinite(values[i, 1])):
            return False
    return True


@numba.njit(cache=True, error_model="numpy")
def _with_sources(sources, mass):
    """For each force f (a row of ``sources`` (F, N)), its particles with a source: their
    indices, sources and inverse masses in the first ``counts[f]`` places of row f."""
    forces, n = sources.shape
    index = np.empty((forces, n), dtype=np.int64)
    charged = np.empty((forces, n))
    inverse_mass = np.empty((forces, n))
    counts = np.zeros(forces, dtype=np.int64)
    for f in range(forces):
        for i in range(n):
            if sources[f, i] != 0.0:
                c = counts[f]
                index[f, c] = i
                charged[f, c] = sources[f, i]
                inverse_mass[f, c] = 1.0 / mass[i]
                counts[f] = c + 1
    return index, charged, inverse_mass, counts


@numba.njit(cache=True, error_model="numpy")
def _accelerations(position, mass, index, charged, counts, couplings, softening2, work, buffer,
                   out):  # fmt: skip
    """The accelerations (N, 2) of the pair forces into ``out`` (the sum of the forces over the
    masses, as `collidium.forces.base.ForceField.evaluate` forms them), by the pair sums of
    `collidium.kernels.pairwise.inverse_distance_direct` in ``buffer`` (4 N (1 + MOST_BLOCKS /
    2)); their energies are not used."""
    n = position.shape[0]
    out[:, :] = 0.0
    for f in range(counts.shape[0]):
        m = counts[f]
        x, y = work[0, :m], work[1, :m]
        for c in range(m):
            x[c] = position[index[f, c], 0]
            y[c] = position[index[f, c], 1]
        sums = buffer[: 4 * m].reshape((4, m))  # contiguous, as `pair_sums` is compiled for
        pair_sums(x, y, charged[f, :m], couplings[f], softening2[f], 0.0, 0.0, False, sums,
                  buffer[4 * m :])  # fmt: skip
        for c in range(m):
            i = index[f, c]
            out[i, 0] += sums[0, c]
            out[i, 1] += sums[1, c]
    for i in range(n):
        out[i, 0] /= mass[i]
        out[i, 1] /= mass[i]


@numba.njit(cache=True, error_model="numpy")  # that of the inlined rows
def _stiffness(position, velocity, index, charged, inverse_mass, counts, couplings, softening2,
               work) -> float:  # fmt: skip
    """The largest ``(|U_ij| rate_ij^2)^2`` over the pairs of every force, J^2/s^4
    (`collidium.kernels.pairwise.inverse_distance_stiffness`, by its rows)."""
    stiffness = 0.0
    for f in range(counts.shape[0]):
        m = counts[f]
        x, y, vx, vy = work[0, :m], work[1, :m], work[2, :m], work[3, :m]
        for c in range(m):
            i = index[f, c]
            x[c], y[c] = position[i, 0], position[i, 1]
            vx[c], vy[c] = velocity[i, 0], velocity[i, 1]
        for c in range(m):
            row = stiffness_row(c, x, y, vx, vy, charged[f, :m], inverse_mass[f, :m],
                                 couplings[f], softening2[f], 0.0, 0.0, False)  # fmt: skip
            stiffness = larger(stiffness, row)
    return stiffness


@numba.njit(cache=True, error_model="numpy")
def _squared_rate(position, velocity, mass, index, charged, inverse_mass, counts, couplings,
                  softening2, work, total, floor) -> float:  # fmt: skip
    """`collidium.integrators._squared_rate` of pair forces alone, 1/s^2, given the total
    energy (J): the stiffness (`_stiffness`) over the energy scale."""
    stiffness = _stiffness(position, velocity, index, charged, inverse_mass, counts, couplings,
                           softening2, work)  # fmt: skip
    scale = energy_scale(kinetic_energy(mass, velocity), total, floor)
    return math.sqrt(stiffness) / scale if scale > 0.0 else 0.0


@numba.njit(cache=True)
def _meets_contact(position, velocity, radius, lag, shape, half_width, half_height, rim,
                   segments, order, low, high) -> bool:  # fmt: skip
    """Whether a straight flight of ``lag`` seconds may bring a disk to a wall or another disk
    (within `CONTACT_MARGIN`).

    Pairs are swept and pruned along x: ``low`` and ``high`` (N,) get the x-interval each disk
    sweeps, and ``order`` (N,) lists the disks by its low end, kept from the last call (a nearly
    sorted list); a pair is tested only if their intervals overlap, which two disks that meet
    must do."""
    n = position.shape[0]
    horizon = lag * (1.0 + CONTACT_MARGIN)
    for i in range(n):
        delay, _ = contacts.earliest(position[i, 0], position[i, 1], velocity[i, 0],
                                     velocity[i, 1], radius[i] * (1.0 + CONTACT_MARGIN), shape,
                                     half_width, half_height, rim, segments)  # fmt: skip
        if delay <= horizon:
            return True
    for i in range(n):
        reach = radius[i] * (1.0 + 2.0 * CONTACT_MARGIN)  # wider than the test: never prunes a hit
        x, travel = position[i, 0], velocity[i, 0] * horizon
        low[i] = min(x, x + travel) - reach
        high[i] = max(x, x + travel) + reach
    sort_nearly_sorted(order, low)
    for a in range(n):
        i = order[a]
        for b in range(a + 1, n):
            j = order[b]
            if low[j] > high[i]:
                break
            sigma = (radius[i] + radius[j]) * (1.0 + CONTACT_MARGIN)
            if sigma > 0.0 and _closest(position, velocity, i, j, horizon) <= sigma * sigma:
                return True
    return False


@numba.njit(cache=True, inline="always")
def _closest(position, velocity, i, j, horizon) -> float:
    """The smallest squared distance (m^2) of disks i and j on straight paths within
    ``horizon`` seconds."""
    dx = position[j, 0] - position[i, 0]
    dy = position[j, 1] - position[i, 1]
    wx = velocity[j, 0] - velocity[i, 0]
    wy = velocity[j, 1] - velocity[i, 1]
    w2 = wx * wx + wy * wy
    approach = -(dx * wx + dy * wy)
    s = 0.0 if approach <= 0.0 or w2 == 0.0 else min(approach / w2, horizon)
    cx = dx + wx * s
    cy = dy + wy * s
    return cx * cx + cy * cy
