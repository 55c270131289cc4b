"""Direct pair sums over all particles: one pair loop, small per-force evaluators.

Each row i is summed by one thread in a fixed order, so results do not depend on the number of
threads (bitwise reproducible), and ``F_ij = -F_ji`` exactly.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def coulomb_pair(r2: float, qq: float, k: float, softening2: float) -> tuple[float, float]:
    """Coulomb evaluator (seed eq. 9-10, softened).

    Parameters
    ----------
    r2 : float
        Squared distance in m^2.
    qq : float
        Product of the charges in C^2.
    k : float
        Coulomb constant in N m^2 / C^2.
    softening2 : float
        Squared softening length in m^2.

    Returns
    -------
    tuple of float
        ``(f, u)``: force on i is ``f * (x_i - x_j)`` in N; pair energy ``u`` in J.
    """
    inv = 1.0 / math.sqrt(r2 + softening2)
    u = k * qq * inv
    return u * inv * inv, u


@numba.njit(cache=True, parallel=True)
def coulomb_direct(
    position: np.ndarray,
    charge: np.ndarray,
    k: float,
    softening2: float,
    width: float,
    height: float,
    periodic: bool,
    force: np.ndarray,
    energy: np.ndarray,
    virial: np.ndarray,
) -> None:
    """Coulomb forces and per-particle energies by direct summation, O(N^2), parallel over rows.

    Parameters
    ----------
    position : ndarray, shape (N, 2)
        Centres in m.
    charge : ndarray, shape (N,)
        Charges in C.
    k : float
        Coulomb constant in N m^2 / C^2.
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
    n = position.shape[0]
    for i in numba.prange(n):
        fx = 0.0
        fy = 0.0
        u = 0.0
        w = 0.0
        qi = charge[i]
        if qi != 0.0:
            xi = position[i, 0]
            yi = position[i, 1]
            for j in range(n):
                qj = charge[j]
                if j == i or qj == 0.0:
                    continue
                dx = xi - position[j, 0]
                dy = yi - position[j, 1]
                if periodic:
                    dx -= width * round(dx / width)
                    dy -= height * round(dy / height)
                f, uij = coulomb_pair(dx * dx + dy * dy, qi * qj, k, softening2)
                fx += f * dx
                fy += f * dy
                u += uij
                w += f * (dx * dx + dy * dy)
        force[i, 0] = fx
        force[i, 1] = fy
        energy[i] = 0.5 * u
        virial[i] = 0.5 * w
