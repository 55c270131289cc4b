"""Direct pair sums over all particles: one pair loop, small per-force evaluators.

The pair forces of `collidium.forces` have the same inverse-distance form, ``U_ij = c s_i s_j /
sqrt(r^2 + eps^2)``, with a per-particle source strength ``s`` and a coupling ``c``: Coulomb's
charges with ``c = k``, Newton's gravity the masses with ``c = -G``. The loop is written once and
takes the source and the coupling (`inverse_distance_pair` is the evaluator).

Each row i is summed by one thread, always in the same way, so results do not depend on the
number of threads (bitwise reproducible). The row loops are vectorised: ``fastmath`` lets LLVM
reassociate (partial sums in vector lanes, ``k q_i`` taken out of the loop) and fuse
multiply-adds. That changes the round-off of a row (not its reproducibility): ``F_ij = -F_ji``
holds to round-off, not bit for bit. Nothing else is relaxed (no approximate functions, no
assumptions about infinities or NaN).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, cast

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

#: Reassociation (partial sums per vector lane) and fused multiply-add, nothing else. The row
#: loops also use NumPy's error model (a division by zero gives inf, as in the parallel kernel),
#: without which a zero-division check in the loop would keep it from being vectorised.
_FASTMATH = {"reassoc", "contract"}


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


@numba.njit(cache=True, inline="always")
def _window(x, y, q, lo, hi):
    """The slices ``lo:hi`` of the arrays (views, no copy). A loop over ``range(lo, hi)`` would
    index with a possibly negative ``j``, which numba wraps around: LLVM then vectorises the
    loads as gathers, four times slower than a loop from 0 over views."""
    return x[lo:hi], y[lo:hi], q[lo:hi]


@numba.njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def _row(
    lo: int,
    hi: int,
    xi: float,
    yi: float,
    kqi: float,
    x: np.ndarray,
    y: np.ndarray,
    q: np.ndarray,
    softening2: float,
) -> tuple[float, float, float, float]:
    """Sums over ``j`` in ``lo:hi`` of the force on i (x, y), the pair energy and ``r . F``."""
    x, y, q = _window(x, y, q, lo, hi)
    fx = 0.0
    fy = 0.0
    u = 0.0
    w = 0.0
    for j in range(x.shape[0]):
        dx = xi - x[j]
        dy = yi - y[j]
        r2 = dx * dx + dy * dy
        f, uij = inverse_distance_pair(r2, kqi * q[j], softening2)
        fx += f * dx
        fy += f * dy
        u += uij
        w += f * r2
    return fx, fy, u, w


@numba.njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def _row_periodic(
    lo: int,
    hi: int,
    xi: float,
    yi: float,
    kqi: float,
    x: np.ndarray,
    y: np.ndarray,
    q: np.ndarray,
    softening2: float,
    width: float,
    height: float,
) -> tuple[float, float, float, float]:
    """`_row` with the minimum image."""
    x, y, q = _window(x, y, q, lo, hi)
    fx = 0.0
    fy = 0.0
    u = 0.0
    w = 0.0
    for j in range(x.shape[0]):
        dx = xi - x[j]
        dy = yi - y[j]
        dx -= width * round(dx / width)
        dy -= height * round(dy / height)
        r2 = dx * dx + dy * dy
        f, uij = inverse_distance_pair(r2, kqi * q[j], softening2)
        fx += f * dx
        fy += f * dy
        u += uij
        w += f * r2
    return fx, fy, u, w


def inverse_distance_direct(
    position: np.ndarray,
    source: np.ndarray,
    coupling: float,
    softening2: float,
    width: float,
    height: float,
    periodic: bool,
    force: np.ndarray,
    energy: np.ndarray,
    virial: np.ndarray,
) -> None:
    """Inverse-distance forces and per-particle energies by direct summation, O(N^2), parallel
    over rows from `PARALLEL_DIRECT_FROM` particles on, on the calling thread below:
    ``F_i = c s_i sum_j s_j r_ij / (r^2 + eps^2)^(3/2)``.

    Only particles with a source enter the sums (a neutral one feels and exerts no Coulomb
    force), read from contiguous copies of their coordinates and sources. Each row is summed
    over ``j < i`` then ``j > i``, with no branch in the loops, which LLVM vectorises.

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
    energy : ndarray, shape (N,)
        Output: half the pair energy of each particle with all others, J (sum = total potential).
    virial : ndarray, shape (N,)
        Output: half of ``sum_j r_ij . F_ij`` for each particle, J (sum = the pair virial).
    """
    rows = direct_parallel if position.shape[0] >= PARALLEL_DIRECT_FROM else direct_serial
    rows(position, source, coupling, softening2, width, height, periodic, force, energy, virial)


#: Particles from which `inverse_distance_direct` and `inverse_distance_stiffness` run their rows
#: in parallel: below, waking the second thread costs more than the rows bring, and far more when
#: another program keeps it busy (`benchmarks/bench_threads.py`). A row is summed alike either
#: way, so the results are bitwise the same. The choice is made here, in Python: a compiled
#: kernel calling a parallel one breaks numba's cache (the caller, once cached against a callee
#: itself loaded from the cache, crashes the next process that loads it).
PARALLEL_DIRECT_FROM = 256


@numba.njit(cache=True, inline="always")
def _sources(position, source, force, energy, virial):
    """Zero the outputs; the particles with a source as contiguous ``x, y, q`` and their
    ``index`` (work arrays of O(N) for O(N^2) work)."""
    n = position.shape[0]
    x = np.empty(n)
    y = np.empty(n)
    q = np.empty(n)
    index = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        energy[i] = 0.0
        virial[i] = 0.0
        if source[i] != 0.0:
            x[m] = position[i, 0]
            y[m] = position[i, 1]
            q[m] = source[i]
            index[m] = i
            m += 1
    return x[:m], y[:m], q[:m], index[:m]


@numba.njit(cache=True, inline="always")
def direct_row(c, x, y, q, index, coupling, softening2, width, height, periodic, force, energy,
                virial) -> None:  # fmt: skip
    """Row c of `inverse_distance_direct`: the sums over ``j < c`` then ``j > c``, written to
    the particle ``index[c]``."""
    m = x.shape[0]
    xi, yi, kqi = x[c], y[c], coupling * q[c]
    if periodic:
        below = _row_periodic(0, c, xi, yi, kqi, x, y, q, softening2, width, height)
        above = _row_periodic(c + 1, m, xi, yi, kqi, x, y, q, softening2, width, height)
    else:
        below = _row(0, c, xi, yi, kqi, x, y, q, softening2)
        above = _row(c + 1, m, xi, yi, kqi, x, y, q, softening2)
    i = index[c]
    force[i, 0] = below[0] + above[0]
    force[i, 1] = below[1] + above[1]
    energy[i] = 0.5 * (below[2] + above[2])
    virial[i] = 0.5 * (below[3] + above[3])


@numba.njit(cache=True, parallel=True)
def direct_parallel(position, source, coupling, softening2, width, height, periodic, force,
                    energy, virial) -> None:  # fmt: skip
    """`inverse_distance_direct`'s rows in parallel."""
    x, y, q, index = _sources(position, source, force, energy, virial)
    for c in numba.prange(x.shape[0]):
        direct_row(c, x, y, q, index, coupling, softening2, width, height, periodic, force,
                    energy, virial)  # fmt: skip


@numba.njit(cache=True)
def direct_serial(position, source, coupling, softening2, width, height, periodic, force,
                  energy, virial) -> None:  # fmt: skip
    """`inverse_distance_direct`'s rows on the calling thread."""
    x, y, q, index = _sources(position, source, force, energy, virial)
    for c in range(x.shape[0]):
        direct_row(c, x, y, q, index, coupling, softening2, width, height, periodic, force,
                    energy, virial)  # fmt: skip


@numba.njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
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
) -> float:
    """Largest ``(|U_ij| rate_ij^2)^2`` of row c against the rows after it
    (`inverse_distance_stiffness`)."""
    xc, yc, vxc, vyc = x[c], y[c], vx[c], vy[c]
    kqc, mc = abs(coupling * q[c]), inverse_mass[c]
    # Views from 0 (see `_window`).
    x, y, vx, vy = x[c + 1 :], y[c + 1 :], vx[c + 1 :], vy[c + 1 :]
    q, inverse_mass = q[c + 1 :], inverse_mass[c + 1 :]
    # The maximum of non-negative floats as that of their bit patterns, which order alike: LLVM
    # vectorises an integer maximum, not a float one. Without the sign bit a NaN is the largest
    # pattern, and is kept.
    largest = 0
    for j in range(x.shape[0]):
        dx = xc - x[j]
        dy = yc - y[j]
        if periodic:  # the same every pass: LLVM takes it out of the loop
            dx -= width * round(dx / width)
            dy -= height * round(dy / height)
        inverse = 1.0 / math.sqrt(dx * dx + dy * dy + softening2)  # one division a pair
        dvx = vxc - vx[j]
        dvy = vyc - vy[j]
        u = kqc * abs(q[j]) * inverse
        w2 = dvx * dvx + dvy * dvy
        error = u * (w2 + u * (mc + inverse_mass[j])) * inverse * inverse
        largest = max(largest, _bits(error * error) & _MAGNITUDE)
    return _float(largest)


@numba.njit(cache=True, inline="always")
def larger(a: float, b: float) -> float:
    """The larger of two stiffnesses, NaN if either is (Python's ``max`` keeps a NaN only as
    its first argument)."""
    return a if a >= b or a != a else b


#: All bits of a float64 but its sign.
_MAGNITUDE = (1 << 63) - 1


def _bitcast(source: types.Type, target: types.Type) -> Callable[[Any], Any]:
    """A compiled function that reads a value of one 64-bit type as another (no conversion)."""

    def typer(typingctx: Any, value: Any) -> Any:
        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            return builder.bitcast(args[0], context.get_value_type(target))

        return target(source), codegen

    return cast(Callable[[Any], Any], intrinsic(typer))


#: The bit pattern of a float64 as an int64, and back.
_bits = _bitcast(types.float64, types.int64)
_float = _bitcast(types.int64, types.float64)


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


@numba.njit(cache=True, parallel=True)
def stiffness_parallel(position, velocity, source, mass, coupling, softening2, width, height,
                       periodic) -> float:  # fmt: skip
    """`inverse_distance_stiffness`'s rows in parallel."""
    x, y, vx, vy, q, inverse_mass = _moving_sources(position, velocity, source, mass)
    m = x.shape[0]
    rows = np.zeros(m)
    for c in numba.prange(m):
        rows[c] = stiffness_row(
            c, x, y, vx, vy, q, inverse_mass, coupling, softening2, width, height, periodic
        )
    stiffness = 0.0
    for c in range(m):
        stiffness = larger(stiffness, rows[c])
    return stiffness


@numba.njit(cache=True)
def stiffness_serial(position, velocity, source, mass, coupling, softening2, width, height,
                     periodic) -> float:  # fmt: skip
    """`inverse_distance_stiffness`'s rows on the calling thread."""
    x, y, vx, vy, q, inverse_mass = _moving_sources(position, velocity, source, mass)
    stiffness = 0.0
    for c in range(x.shape[0]):
        row = stiffness_row(c, x, y, vx, vy, q, inverse_mass, coupling, softening2, width, height,
                             periodic)  # fmt: skip
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
