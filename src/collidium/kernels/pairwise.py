"""Direct pair sums over all particles: one pair loop, small per-force evaluators.

The pair forces of `collidium.forces` have the same inverse-distance form, ``U_ij = c s_i s_j /
sqrt(r^2 + eps^2)``, with a per-particle source strength ``s`` and a coupling ``c``: Coulomb's
charges with ``c = k``, Newton's gravity the masses with ``c = -G``. The loop is written once and
takes the source and the coupling (`inverse_distance_pair` is the evaluator).

Each pair is evaluated once and its force added to both particles (``F_ji = -F_ij`` bit for
bit). The particles are cut into at most `MOST_BLOCKS` blocks, and the tiles of two blocks
into tasks of equal work; each task sums into a buffer of its own, and the buffers are added up
in task order, so every particle's sums come out the same whatever the number of threads
(bitwise reproducible), in one parallel loop. The pair loops are vectorised: ``fastmath`` lets
LLVM reassociate (partial sums in vector lanes, ``k q_i`` taken out of the loop) and fuse
multiply-adds, which changes the round-off of a sum, not its reproducibility. Nothing else is
relaxed (no approximate functions, no assumptions about infinities or NaN).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from collidium.kernels.compilation import uncounted
from collidium.kernels.floats import MAGNITUDE, bits, from_bits
from collidium.kernels.sorting import sort_nearly_sorted

#: Reassociation (partial sums per vector lane) and fused multiply-add, nothing else. The row
#: loops also use NumPy's error model (a division by zero gives inf, as in the parallel kernel),
#: without which a zero-division check in the loop would keep it from being vectorised.
_FASTMATH = {"reassoc", "contract"}

#: Loop counters of this type index without numba's wraparound of negative indices.
_u: Any = numba.uint64  # a cast the type checker cannot follow


@numba.njit(cache=True, inline="always")
def inverse_distance_pair(r2: float, kqq: float, softening2: float) -> tuple[float, float]:
    """Softened inverse-distance evaluator (Coulomb, seed eq. 9-10; Newton's gravity), with one
    square root and one division.

    Parameters
    ----------
    r2 : float
        Squared distance in m^2.
    kqq : float
        The coupling times the product of the sources: ``k q_i q_j`` (Coulomb) or
        ``-G m_i m_j`` (gravity), in N m^2.
    softening2 : float
        Squared softening length in m^2.

    Returns
    -------
    tuple of float
        ``(f, u)``: force on i is ``f * (x_i - x_j)`` in N; pair energy ``u`` in J.
    """
    s2 = r2 + softening2
    f = kqq / (s2 * math.sqrt(s2))
    return f, f * s2


def inverse_distance_direct(
    position: np.ndarray,
    source: np.ndarray,
    coupling: float,
    softening2: float,
    width: float,
    height: float,
    periodic: bool,
    force: np.ndarray,
    energy: np.ndarray | None = None,
    virial: np.ndarray | None = None,
) -> None:
    """Inverse-distance forces, and per-particle energies and virials when asked for, by direct
    summation, O(N^2), each pair once (`pair_sums`), in parallel from `PARALLEL_DIRECT_FROM`
    particles on, on the calling thread below: ``F_i = c s_i sum_j s_j r_ij / (r^2 +
    eps^2)^(3/2)``.

    Only particles with a source enter the sums (a neutral one feels and exerts no Coulomb
    force), read from contiguous copies of their coordinates and sources.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m.
    source : ndarray, shape (N,)
        Source strengths: charges in C (Coulomb) or masses in kg (gravity).
    coupling : float
        ``k`` in N m^2 / C^2 (Coulomb) or ``-G`` in N m^2 / kg^2 (gravity).
    softening2 : float
        Squared softening length in m^2.
    width, height : float
        Box sides in m, used for the minimum image when ``periodic``.
    periodic : bool
        Minimum-image convention.
    force : ndarray, shape (N, 2)
        Output: total force on each particle, N.
    energy : ndarray, shape (N,), optional
        Output: half the pair energy of each particle with all others, J (sum = total potential).
    virial : ndarray, shape (N,), optional
        Output: half of ``sum_j r_ij . F_ij`` for each particle, J (sum = the pair virial).
        Without both, they are not written (the loop sums them anyway: `_tile`); the forces
        are the same either way.
    """
    rows = direct_parallel if position.shape[0] >= PARALLEL_DIRECT_FROM else direct_serial
    energies = energy is not None and virial is not None
    if energy is None or virial is None:
        energy = virial = _UNWANTED
    rows(position, source, coupling, softening2, width, height, periodic, force, energy, virial,
         energies)  # fmt: skip


#: What the kernels get for energies and virials that are not asked for (never written).
_UNWANTED = np.empty(0)


#: Particles from which `inverse_distance_direct` and `inverse_distance_stiffness` run in
#: parallel: below, waking the second thread costs more than it brings, and far more when
#: another program keeps it busy (`benchmarks/bench_threads.py`). The sums are taken in the same
#: order either way, so the results are bitwise the same. The choice is made here, in Python: a
#: compiled kernel calling a parallel one breaks numba's cache (the caller, once cached against
#: a callee itself loaded from the cache, crashes the next process that loads it).
PARALLEL_DIRECT_FROM = 256


@numba.njit(cache=True, inline="always")
def _sources(position, source, force, energy, virial, energies):
    """Zero the outputs (the energies and virials only if ``energies``); the particles with a
    source as contiguous ``x, y, q`` and their ``index`` (work arrays of O(N) for O(N^2)
    work)."""
    n = position.shape[0]
    x = np.empty(n)
    y = np.empty(n)
    q = np.empty(n)
    index = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        if energies:
            energy[i] = 0.0
            virial[i] = 0.0
        if source[i] != 0.0:
            x[m] = position[i, 0]
            y[m] = position[i, 1]
            q[m] = source[i]
            index[m] = i
            m += 1
    return x[:m], y[:m], q[:m], index[:m]


#: Most blocks the pair sums cut the particles into (`_blocks`): the tasks, two rows of tiles
#: each, are half as many, and each has a buffer of 4 values per particle.
MOST_BLOCKS = 16


@numba.njit(cache=True, inline="always")
def _blocks(m: int) -> tuple[int, int, int]:
    """How the pair sums cut m particles into blocks: ``(block size, blocks, tasks)``. Blocks of
    64 particles, or of a multiple of 16 that makes at most `MOST_BLOCKS`; task t takes the
    tiles of block rows t and ``blocks - 1 - t``, as many tiles as every other task. All of it
    depends on m alone, never on the number of threads."""
    size = max(64, ((m + MOST_BLOCKS - 1) // MOST_BLOCKS + 15) // 16 * 16)
    blocks = (m + size - 1) // size
    return size, blocks, (blocks + 1) // 2


@numba.njit(cache=True, inline="always")  # compiled with each caller's flags
def _row(i, lo, hi, x, y, q, coupling, softening2, width, height, periodic, energies,
         sums) -> None:  # fmt: skip
    """The pairs of particle i with particles ``lo`` to ``hi - 1``, added to both particles'
    ``sums`` (4, m): force x, y, and if ``energies`` pair energy and ``r . F``; i's own in
    running sums first.

    A loop without the energies is a fifth faster, but its forces are bitwise the same as those
    of the loop with them only as long as LLVM splits both loops' reductions alike, which LLVM
    14 (numba 0.59) did not: where the energies are read (an observer's firing), they are
    summed whether or not the step needs them, or watching a run would change its bits. The
    compiled substeps leave them out where no reading depends on it
    (`collidium.kernels.substeps`).

    The pair loops count with unsigned integers: a signed j could be negative, which numba
    wraps around, and LLVM would then gather the loads, four times slower."""
    xi, yi, kqi = x[i], y[i], coupling * q[i]
    fx = 0.0
    fy = 0.0
    u = 0.0
    w = 0.0
    for j in range(_u(lo), _u(hi)):
        dx = xi - x[j]
        dy = yi - y[j]
        if periodic:  # the same every pass: LLVM takes it out of the loop
            dx -= width * round(dx / width)
            dy -= height * round(dy / height)
        r2 = dx * dx + dy * dy
        f, uij = inverse_distance_pair(r2, kqi * q[j], softening2)
        fx += f * dx
        fy += f * dy
        sums[0, j] -= f * dx
        sums[1, j] -= f * dy
        if energies:  # the same every pass: LLVM takes it out of the loop
            u += uij
            w += f * r2
            sums[2, j] += uij
            sums[3, j] += f * r2
    sums[0, i] += fx
    sums[1, i] += fy
    sums[2, i] += u
    sums[3, i] += w


@uncounted(fastmath=_FASTMATH, error_model="numpy")
def _tile(first, second, size, x, y, q, coupling, softening2, width, height, periodic, energies,
          sums):  # fmt: skip
    """The pairs of block ``first`` with block ``second`` (each pair of the block once when they
    are the same), added to both particles' ``sums`` (4, m) (`_row`); vectorised, the running
    sums in several lanes."""
    m = x.shape[0]
    for i in range(first * size, min(m, (first + 1) * size)):
        lo, hi = max(second * size, i + 1), min(m, (second + 1) * size)
        _row(i, lo, hi, x, y, q, coupling, softening2, width, height, periodic, energies, sums)


#: Particles with a source up to which the pair sums take a plain loop (`_few`) instead of the
#: tiles: a two-body substep spent a fifth of its time in the tiles' calls and vector set-up.
FEW = 8


@uncounted(forceinline=True, fastmath={"contract"}, error_model="numpy")
def _few(x, y, q, coupling, softening2, width, height, periodic, energies, sums) -> None:
    """The pair sums of a few particles into ``sums`` (4, m), zeroed first: each pair once, in
    `_tile`'s order (`_row`), one pair at a time (no reassociation: LLVM makes no vectors of so
    short a loop)."""
    _zero(sums)
    m = x.shape[0]
    for i in range(m):
        _row(i, i + 1, m, x, y, q, coupling, softening2, width, height, periodic, energies, sums)


@uncounted(forceinline=True)
def _one_task(blocks, size, x, y, q, coupling, softening2, width, height, periodic, energies,
              sums):  # fmt: skip
    """The pair sums when they make one task, into ``sums`` itself: `_few` for up to `FEW`
    particles, else the task's tiles (`_task`)."""
    if x.shape[0] <= FEW:
        _few(x, y, q, coupling, softening2, width, height, periodic, energies, sums)
    else:
        _task(0, blocks, size, x, y, q, coupling, softening2, width, height, periodic, energies,
              sums)  # fmt: skip


@uncounted()
def _task(t, blocks, size, x, y, q, coupling, softening2, width, height, periodic, energies,
          sums) -> None:  # fmt: skip
    """Task t of the pair sums: the tiles of block rows t and ``blocks - 1 - t`` (each tile of a
    row with itself and the blocks after it) into its own ``sums`` (4, m), zeroed first."""
    _zero(sums)
    mirror = blocks - 1 - t
    for first in range(t, mirror + 1, max(1, mirror - t)):  # rows t and mirror (once if one)
        for second in range(first, blocks):
            _tile(first, second, size, x, y, q, coupling, softening2, width, height, periodic,
                  energies, sums)  # fmt: skip


@numba.njit(cache=True, inline="always")
def _total(buffers, sums) -> None:
    """``sums`` (4, m): the tasks' ``buffers`` (tasks, 4, m) added up in task order."""
    _zero(sums)
    for t in range(buffers.shape[0]):
        for d in range(4):
            for c in range(sums.shape[1]):
                sums[d, c] += buffers[t, d, c]


@numba.njit(cache=True, inline="always")
def _zero(sums) -> None:
    """Zero ``sums`` (4, m) in a plain loop (an array expression costs a few hundred ns, which a
    scene of three bodies pays at every substep)."""
    for d in range(4):
        for c in range(sums.shape[1]):
            sums[d, c] = 0.0


@uncounted(forceinline=True)  # into the substeps' loop: a call there cost a fifth
def pair_sums(x, y, q, coupling, softening2, width, height, periodic, energies, sums,
              buffer) -> None:  # fmt: skip
    """Every pair's force x, y, and if ``energies`` its energy and ``r . F`` (`_row`; else 0),
    on both particles into ``sums`` (4, m),
    each pair once, on the calling thread: task by task, each in a buffer of its own, the
    buffers then added up in task order, as `direct_parallel` does on all threads, so both give
    the same bits.

    Parameters
    ----------
    x, y, q : ndarray, shape (m,)
        Contiguous coordinates (m) and sources of the particles with a source.
    coupling, softening2, width, height, periodic
        As in `inverse_distance_direct`.
    energies : bool
        Whether to sum the pair energies and ``r . F`` too.
    sums : ndarray, shape (4, m)
        Output: force x and y (N), the sum of the pair energies (J) and of ``r_ij . F_ij``.
    buffer : ndarray, shape (4 * m * tasks,) at least
        Work space for the tasks (`_blocks`: at most ``MOST_BLOCKS / 2``); one task, up to 128
        particles, sums into ``sums`` itself.
    """
    m = x.shape[0]
    size, blocks, tasks = _blocks(m)
    if tasks == 1:  # as `direct_parallel` does
        _one_task(blocks, size, x, y, q, coupling, softening2, width, height, periodic, energies,
                  sums)  # fmt: skip
        return
    buffers = buffer[: tasks * 4 * m].reshape((tasks, 4, m))
    for t in range(tasks):
        _task(t, blocks, size, x, y, q, coupling, softening2, width, height, periodic, energies,
              buffers[t])  # fmt: skip
    _total(buffers, sums)


@numba.njit(cache=True, inline="always")
def _scatter(sums, index, force, energy, virial, energies) -> None:
    """The sums of the particles with a source to their places (if ``energies``, halves of the
    pair energies and virials too: each pair's is shared by its two particles)."""
    for c in range(index.shape[0]):
        i = index[c]
        force[i, 0] = sums[0, c]
        force[i, 1] = sums[1, c]
        if energies:
            energy[i] = 0.5 * sums[2, c]
            virial[i] = 0.5 * sums[3, c]


@numba.njit(cache=True, parallel=True)
def direct_parallel(position, source, coupling, softening2, width, height, periodic, force,
                    energy, virial, energies) -> None:  # fmt: skip
    """`inverse_distance_direct` on all threads: `pair_sums`'s tasks side by side, in one
    parallel loop (each wakes every thread, which costs milliseconds on a busy machine). The
    loop is written out here: a compiled kernel calling a parallel one breaks numba's cache
    (`PARALLEL_DIRECT_FROM`)."""
    x, y, q, index = _sources(position, source, force, energy, virial, energies)
    m = x.shape[0]
    size, blocks, tasks = _blocks(m)
    sums = np.empty((4, m))
    if tasks == 1:  # one task sums into ``sums`` itself, as in `pair_sums`
        _one_task(blocks, size, x, y, q, coupling, softening2, width, height, periodic, True,
                  sums)  # fmt: skip
    else:
        buffers = np.empty((tasks, 4, m))
        for t in numba.prange(tasks):
            _task(t, blocks, size, x, y, q, coupling, softening2, width, height, periodic, True,
                  buffers[t])  # fmt: skip
        _total(buffers, sums)
    _scatter(sums, index, force, energy, virial, energies)


@numba.njit(cache=True)
def direct_serial(position, source, coupling, softening2, width, height, periodic, force,
                  energy, virial, energies) -> None:  # fmt: skip
    """`inverse_distance_direct` on the calling thread (`pair_sums`)."""
    x, y, q, index = _sources(position, source, force, energy, virial, energies)
    m = x.shape[0]
    sums = np.empty((4, m))
    tasks = _blocks(m)[2]
    buffer = np.empty(4 * m * tasks if tasks > 1 else 0)  # one task sums into ``sums``
    pair_sums(x, y, q, coupling, softening2, width, height, periodic, True, sums, buffer)
    _scatter(sums, index, force, energy, virial, energies)


@numba.njit(cache=True, inline="always")  # compiled with each caller's flags
def stiffness_row(
    c: int,
    x: np.ndarray,
    y: np.ndarray,
    vx: np.ndarray,
    vy: np.ndarray,
    q: np.ndarray,
    inverse_mass: np.ndarray,
    coupling: float,
    softening2: float,
    width: float,
    height: float,
    periodic: bool,
    end: int,
) -> float:
    """Largest ``(|U_ij| rate_ij^2)^2`` of row c against the rows after it up to ``end``
    (exclusive; `inverse_distance_stiffness`). A pair's value is the same bits whichever of
    its two particles is row c, so that the maximum does not depend on the particles' order
    (`pruned_stiffness`).

    Inlined into its callers, which compile it with NumPy's error model (a division by zero
    gives inf): called, with views of the callers' arrays, it cost a three-body scene 0.3 us of
    reference counting per substep."""
    xc, yc, vxc, vyc = x[c], y[c], vx[c], vy[c]
    k, qc, mc = abs(coupling), abs(q[c]), inverse_mass[c]
    # The maximum of non-negative floats as that of their bit patterns (`floats`): vectorised,
    # and a NaN is kept.
    largest = 0
    for j in range(_u(c + 1), _u(end)):  # unsigned: see `_tile`
        dx = xc - x[j]
        dy = yc - y[j]
        if periodic:  # the same every pass: LLVM takes it out of the loop
            dx -= width * round(dx / width)
            dy -= height * round(dy / height)
        inverse = 1.0 / math.sqrt(dx * dx + dy * dy + softening2)  # one division a pair
        dvx = vxc - vx[j]
        dvy = vyc - vy[j]
        u = k * (qc * abs(q[j])) * inverse
        w2 = dvx * dvx + dvy * dvy
        error = u * (w2 + u * (mc + inverse_mass[j])) * inverse * inverse
        largest = max(largest, bits(error * error) & MAGNITUDE)
    return from_bits(largest)


#: Particles with a source from which `pruned_stiffness` prunes the rows; below, the pruning's
#: sort and bounds cost more than the pairs they skip (the result is the same either way).
PRUNE_FROM = 32


@uncounted(error_model="numpy")  # that of the inlined rows; a call, compiled once
def pruned_stiffness(x, y, vx, vy, q, inverse_mass, coupling, softening2, order, rows) -> float:
    """The rows' largest ``(|U_ij| rate_ij^2)^2`` (`stiffness_row`, not periodic), the pairs
    too far apart along x to reach the largest found so far left out: the same value as every
    row in full, from `PRUNE_FROM` particles on, in a fraction of the pairs.

    The particles are taken in the order of x (``order`` (m,) sorted in place from its last
    order, ``rows`` (6, m) the coordinates, velocities, sources and inverse masses gathered in
    it), the neighbours in that order first. Row c then stops at the first particle whose x is
    more than ``R`` past its own, where a pair at least that far apart errs by at most
    ``A W s^-3 + A^2 M s^-4`` (``A = |c| max|q|^2``, ``W = (2 max|v|)^2``, ``M = 2 max 1/m``,
    ``s^2 = R^2 + eps^2``), half the largest each. ``R`` is the same for every row, found again
    only when the largest grows: its roots cost more than the few pairs a bound of each row's
    own would leave out. Any value that is not finite takes every row in full, where it is met."""
    m = x.shape[0]
    if m < PRUNE_FROM or not _all_finite(x, y, vx, vy):
        return every_row(x, y, vx, vy, q, inverse_mass, coupling, softening2)
    sort_nearly_sorted(order, x)
    charge = speed = lightest = 0.0
    for c in range(m):
        i = order[c]
        rows[0, c], rows[1, c], rows[2, c], rows[3, c] = x[i], y[i], vx[i], vy[i]
        rows[4, c], rows[5, c] = q[i], inverse_mass[i]
        charge = max(charge, abs(q[i]))
        speed = max(speed, math.sqrt(vx[i] * vx[i] + vy[i] * vy[i]))
        lightest = max(lightest, inverse_mass[i])
    sx, sy, svx, svy, sq, sm = rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]
    stiffness = 0.0
    for c in range(m - 1):  # each particle and its neighbour along x: a first largest
        row = stiffness_row(c, sx, sy, svx, svy, sq, sm, coupling, softening2, 0.0, 0.0, False,
                            c + 2)  # fmt: skip
        stiffness = larger(stiffness, row)
    pull, fastest, masses = abs(coupling) * charge * charge, 2.0 * speed, 2.0 * lightest
    reach = _pruning_reach(math.sqrt(stiffness), pull, fastest, masses, softening2)
    for c in range(m):
        end = _first_at_or_past(sx, c + 1, sx[c] + reach)
        row = stiffness_row(c, sx, sy, svx, svy, sq, sm, coupling, softening2, 0.0, 0.0, False,
                            end)  # fmt: skip
        if not row <= stiffness:  # larger, or NaN
            stiffness = larger(stiffness, row)
            reach = _pruning_reach(math.sqrt(stiffness), pull, fastest, masses, softening2)
    return stiffness


@numba.njit(cache=True, error_model="numpy", inline="always")  # that of the inlined rows
def every_row(x, y, vx, vy, q, inverse_mass, coupling, softening2) -> float:
    """The largest of every row in full (`stiffness_row`, not periodic): what
    `pruned_stiffness` gives, inlined where the particles are few."""
    stiffness = 0.0
    for c in range(x.shape[0]):
        row = stiffness_row(c, x, y, vx, vy, q, inverse_mass, coupling, softening2, 0.0, 0.0,
                            False, x.shape[0])  # fmt: skip
        stiffness = larger(stiffness, row)
    return stiffness


#: The relative margin of `_pruning_reach`, far above the round-off of its bounds.
_REACH_MARGIN = 1e-9


@numba.njit(cache=True, inline="always")
def _pruning_reach(largest, pull, speed, inverse_masses, softening2) -> float:
    """The distance along x (m) beyond which a pair errs by less than ``largest``
    (``|U| rate^2``, J/s^2; `pruned_stiffness`), given ``pull`` (``A``, N m^2), ``speed``
    (``sqrt W``, m/s) and ``inverse_masses`` (``M``, 1/kg); infinite when nothing is found yet."""
    error = largest * (1.0 - _REACH_MARGIN)
    fly_by = pull * speed * speed
    fall = pull * pull * inverse_masses
    # The inverse distance that keeps each term within half the largest.
    inverse = min(
        (0.5 * error / fly_by) ** (1.0 / 3.0) if fly_by > 0.0 else math.inf,
        (0.5 * error / fall) ** 0.25 if fall > 0.0 else math.inf,
    )
    reach2 = 1.0 / (inverse * inverse) - softening2
    return math.sqrt(reach2) * (1.0 + _REACH_MARGIN) if reach2 > 0.0 else 0.0


@numba.njit(cache=True, inline="always")
def _first_at_or_past(sorted_x, first, limit) -> int:
    """The first index from ``first`` whose value in ``sorted_x`` (ascending) is at least
    ``limit``, or its length: a binary search."""
    lo, hi = first, sorted_x.shape[0]
    while lo < hi:
        middle = (lo + hi) // 2
        if sorted_x[middle] < limit:
            lo = middle + 1
        else:
            hi = middle
    return lo


@numba.njit(cache=True, inline="always")
def _all_finite(x, y, vx, vy) -> bool:
    """Whether every coordinate and velocity is finite."""
    for i in range(x.shape[0]):
        if not (math.isfinite(x[i]) and math.isfinite(y[i]) and math.isfinite(vx[i])
                and math.isfinite(vy[i])):  # fmt: skip
            return False
    return True


@numba.njit(cache=True, inline="always")
def larger(a: float, b: float) -> float:
    """The larger of two stiffnesses, NaN if either is (Python's ``max`` keeps a NaN only as
    its first argument)."""
    return a if a >= b or a != a else b


@numba.njit(cache=True, inline="always")
def _moving_sources(position, velocity, source, mass):
    """The particles with a source as contiguous ``x, y, vx, vy, q`` and inverse masses."""
    n = position.shape[0]
    m = 0
    for i in range(n):
        if source[i] != 0.0:
            m += 1
    x, y = np.empty(m), np.empty(m)
    vx, vy = np.empty(m), np.empty(m)
    q, inverse_mass = np.empty(m), np.empty(m)
    c = 0
    for i in range(n):
        if source[i] != 0.0:
            x[c], y[c] = position[i, 0], position[i, 1]
            vx[c], vy[c] = velocity[i, 0], velocity[i, 1]
            q[c], inverse_mass[c] = source[i], 1.0 / mass[i]
            c += 1
    return x, y, vx, vy, q, inverse_mass


@numba.njit(cache=True, parallel=True, error_model="numpy")  # that of the inlined rows
def stiffness_parallel(position, velocity, source, mass, coupling, softening2, width, height,
                       periodic) -> float:  # fmt: skip
    """`inverse_distance_stiffness`'s rows in parallel, row c with row m - 1 - c: the rows
    shorten down the triangle, and numba gives each thread a run of the loop's passes."""
    x, y, vx, vy, q, inverse_mass = _moving_sources(position, velocity, source, mass)
    m = x.shape[0]
    rows = np.zeros(m)
    for c in numba.prange((m + 1) // 2):
        for row in range(c, m - c, max(1, m - 1 - 2 * c)):  # c and m - 1 - c (once if one)
            rows[row] = stiffness_row(row, x, y, vx, vy, q, inverse_mass, coupling, softening2,
                                      width, height, periodic, m)  # fmt: skip
    stiffness = 0.0
    for c in range(m):
        stiffness = larger(stiffness, rows[c])
    return stiffness


@numba.njit(cache=True, error_model="numpy")  # that of the inlined rows
def stiffness_serial(position, velocity, source, mass, coupling, softening2, width, height,
                     periodic) -> float:  # fmt: skip
    """`inverse_distance_stiffness`'s rows on the calling thread, pruned where not periodic
    (`pruned_stiffness`)."""
    x, y, vx, vy, q, inverse_mass = _moving_sources(position, velocity, source, mass)
    m = x.shape[0]
    if not periodic:
        return pruned_stiffness(x, y, vx, vy, q, inverse_mass, coupling, softening2,
                                np.argsort(x), np.empty((6, m)))  # fmt: skip
    stiffness = 0.0
    for c in range(m):
        row = stiffness_row(c, x, y, vx, vy, q, inverse_mass, coupling, softening2, width, height,
                             periodic, m)  # fmt: skip
        stiffness = larger(stiffness, row)
    return stiffness


def inverse_distance_stiffness(
    position: np.ndarray,
    velocity: np.ndarray,
    source: np.ndarray,
    mass: np.ndarray,
    coupling: float,
    softening2: float,
    width: float,
    height: float,
    periodic: bool,
) -> float:
    """How fast the inverse-distance pair energies change, for the adaptive integrator's substeps
    (rows in parallel from `PARALLEL_DIRECT_FROM` particles on).

    For each pair of particles with sources, with ``s^2 = r^2 + eps^2`` (minimum image when
    ``periodic``), ``|U_ij| = |c q_i q_j| / s`` and the squared rate
    ``rate_ij^2 = (|v_i - v_j|^2 + |U_ij| (1/m_i + 1/m_j)) / s^2``: fly-by plus free fall, the
    inverse square of the time in which the pair's force turns or grows appreciably. A leapfrog
    step h errs on the pair's energy by about ``|U_ij| rate_ij^2 h^2``: the result is the largest
    ``(|U_ij| rate_ij^2)^2`` over pairs, the pair whose energy is the hardest to follow
    (`collidium.integrators`). A maximum does not depend on the number of threads.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        In m and m/s.
    source, mass : ndarray, shape (N,)
        Source strengths (C or kg, `inverse_distance_direct`) and masses in kg.
    coupling : float
        ``k`` or ``-G`` (`inverse_distance_direct`).
    softening2 : float
        Squared softening length in m^2.
    width, height : float
        Box sides in m (minimum image when ``periodic``).
    periodic : bool
        Minimum-image convention.

    Returns
    -------
    float
        The largest ``(|U_ij| rate_ij^2)^2`` over pairs, in J^2/s^4 (0 with fewer than two
        sources).
    """
    rows = stiffness_parallel if position.shape[0] >= PARALLEL_DIRECT_FROM else stiffness_serial
    return float(rows(position, velocity, source, mass, coupling, softening2, width, height,
                      periodic))  # fmt: skip
