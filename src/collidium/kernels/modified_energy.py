"""The substeps' modified energy, kept where the substep changes.

Kick-drift-kick with a substep h keeps not the energy H but its modified energy

    S_h = H + h^2 D,   D = Q / 12 - sum_i |F_i|^2 / (24 m_i),   Q = sum_pairs w . Hess(U) . w

(to O(h^4); w a pair's relative velocity, F the position forces): H oscillates about S_h by
O(h^2) and does not drift. The adaptive integrator changes h between reporting intervals, as
close approaches come and go; the state goes on unchanged, so S jumps by ``(h'^2 - h^2) D``.
Those jumps do not cancel: D at a switch to a finer substep (two charges closing in) is not D at
the switch back (the same charges flying apart), and each leaves its part in the energy for
good. In the seed's charged scenes they were most of the error: charged-opposite at tolerance
2e-3 erred 5.3e-6 over 60 s with them, 3.4e-7 without.

`keep_across_step` takes each jump out where it happens: it scales the velocities about the
centre of mass, ``v -> V + (1 + eps)(v - V)``, so that S goes on as it was (the kinetic energy
changes by ``(h^2 - h'^2) D``, to first order). The momentum is kept; an angular momentum
changes by the same small factor (a few 1e-7 a switch in the seed's scenes). Where that would
change the velocities by more than ``limit`` of themselves (the particles nearly at rest about
their centre of mass), the jump is left.

The forces are pair laws summed as their gradients (`collidium.forces.base.PairLawForce`) and
uniform fields, whose Hessian is 0 (`collidium.forces.base.ForceField.keeps_modified_energy`).
"""

from __future__ import annotations

import math
from typing import Any

import numba

from collidium.kernels.compilation import uncounted

#: Reassociation (partial sums per vector lane) and fused multiply-add, as in the pair sums
#: (`collidium.kernels.pairwise`): a row runs in vector lanes, six times faster.
_FASTMATH = {"reassoc", "contract"}
_u: Any = numba.uint64  # unsigned counting, as in the pair sums: no gathered loads


@uncounted(error_model="numpy", fastmath=_FASTMATH)
def _curvature_row(a, x, y, vx, vy, source, softening2, width, height, periodic) -> float:
    """``sum_b s_b w . Hess(1 / sqrt(r^2 + eps^2)) . w`` over the particles b after a, of
    contiguous coordinates ``x, y`` (m), velocities ``vx, vy`` (m/s) and sources ``s``: w and r
    the pair's relative velocity and separation (J/s^2 over ``c s_a``)."""
    xa, ya, ua, va = x[a], y[a], vx[a], vy[a]
    total = 0.0
    for b in range(_u(a + 1), _u(x.shape[0])):
        sx = xa - x[b]
        sy = ya - y[b]
        if periodic:  # the same every pass: LLVM takes it out of the loop
            sx -= width * round(sx / width)
            sy -= height * round(sy / height)
        wx = ua - vx[b]
        wy = va - vy[b]
        u = sx * sx + sy * sy + softening2
        along = wx * sx + wy * sy
        total += source[b] * (3.0 * along * along / u - (wx * wx + wy * wy)) / (u * math.sqrt(u))
    return total


@uncounted(error_model="numpy")
def curvature_and_pulls(position, velocity, acceleration, mass, sources, couplings, softenings2,
                        width, height, periodic, rows) -> tuple[float, float]:  # fmt: skip
    """``(Q, P)`` (J/s^2): ``Q = sum_pairs w . Hess(U) . w`` of the pair laws and
    ``P = sum_i m_i |a_i|^2``, so that ``D = Q / 12 - P / 24``.

    Parameters
    ----------
    position, velocity, acceleration : ndarray, shape (N, 2)
        In m, m/s and m/s^2 (the position forces over the masses).
    mass : ndarray, shape (N,)
        In kg.
    sources, couplings, softenings2 : ndarray, shapes (L, N), (L,), (L,)
        The pair laws (`collidium.forces.base.ForceField.pair_laws`), ``sources`` C-ordered.
    width, height : float
        Box sides in m, for the minimum image when ``periodic``.
    periodic : bool
        Whether the pairs are taken at their minimum image.
    rows : ndarray, shape (4, N)
        Work: the coordinates and velocities, gathered.
    """
    n = position.shape[0]
    for i in range(n):
        rows[0, i], rows[1, i] = position[i, 0], position[i, 1]
        rows[2, i], rows[3, i] = velocity[i, 0], velocity[i, 1]
    curvature = 0.0
    for law in range(couplings.shape[0]):
        source = sources[law]
        for a in range(n):
            coupled = couplings[law] * source[a]
            if coupled != 0.0:
                curvature += coupled * _curvature_row(a, rows[0], rows[1], rows[2], rows[3],
                                                      source, softenings2[law], width, height,
                                                      periodic)  # fmt: skip
    pulls = 0.0
    for i in range(n):
        pulls += mass[i] * (acceleration[i, 0] ** 2 + acceleration[i, 1] ** 2)
    return curvature, pulls


@uncounted(error_model="numpy")
def keep_across_step(position, velocity, acceleration, mass, sources, couplings, softenings2,
                     width, height, periodic, rows, h, following, limit) -> float:  # fmt: skip
    """Scale the ``velocity`` (N, 2) about the centre of mass, in place, so that the modified
    energy of substeps ``h`` (s) before equals that of substeps ``following`` after
    (`curvature_and_pulls`, whose arguments the others are).

    Q and the internal kinetic energy K both scale with the square of the factor f, so
    ``f^2 (K + following^2 Q / 12) = K + h^2 Q / 12 - (h^2 - following^2) P / 24``. Left as it
    is where f differs from 1 by more than ``limit``. Returns the energy given, J (0 where
    left)."""
    curvature, pulls = curvature_and_pulls(position, velocity, acceleration, mass, sources,
                                           couplings, softenings2, width, height, periodic,
                                           rows)  # fmt: skip
    change = (h * h - following * following) * (curvature / 12.0 - pulls / 24.0)
    n = mass.shape[0]
    total, px, py = 0.0, 0.0, 0.0
    for i in range(n):
        total += mass[i]
        px += mass[i] * velocity[i, 0]
        py += mass[i] * velocity[i, 1]
    cx, cy = px / total, py / total
    internal = 0.0
    for i in range(n):
        internal += 0.5 * mass[i] * ((velocity[i, 0] - cx) ** 2 + (velocity[i, 1] - cy) ** 2)
    scaled = internal + following * following * curvature / 12.0  # what f^2 multiplies
    if not (internal > 0.0 and scaled > 0.0):
        return 0.0
    # f^2 = 1 + x, and f - 1 = x / (1 + sqrt(1 + x)) without cancellation
    x = change / scaled
    eps = x / (1.0 + math.sqrt(1.0 + x))
    if not abs(eps) <= limit:  # also NaN
        return 0.0
    for i in range(n):
        velocity[i, 0] = cx + (1.0 + eps) * (velocity[i, 0] - cx)
        velocity[i, 1] = cy + (1.0 + eps) * (velocity[i, 1] - cy)
    return internal * x
