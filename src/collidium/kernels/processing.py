"""The processed kick-drift-kick: the state shown at the end of each reporting interval.

Kick-drift-kick of substep h keeps the modified energy ``S_h = H + h^2 (Q / 12 - P / 24)``
(`collidium.kernels.modified_energy`): ``Q = sum_pairs w . Hess(U) . w`` and
``P = sum_i m_i |a_i|^2``. The energy H of its state swings about S by ``h^2`` times that
bracket, and at the seed's tolerances that swing, not a drift, is most of the error of the
two-body scenes (charged-opposite: 3.4e-7 over 60 s, S kept to 2.5e-10).

A processed method (a symplectic corrector, as Wisdom, Holman and Touma's for their maps, or
Blanes, Casas and Ros's processing) shows not the integrator's own state z but ``C(z)``, where
C is the flow for ``c = h^2 / 12`` of ``G = sum_i v_i . F_i``: to first order in c

    x -> x + c a,    v -> v + c Hess(U) v / m

(``Hess(U) v`` the rate at which the forces' pull changes along the motion, with a minus sign).
Then ``H(C(z)) = H + c (Q - P)``, so ``S_h - H(C(z)) = h^2 P / 24``: Q's share of the swing is
gone. As C is a flow, the shown states are those of a method ``C Phi C^-1`` whose modified
energy lacks the ``[T, [T, V]]`` term; the integrator goes on from z, so nothing else changes.
Both maps move the centre of mass and the momentum by nothing (the pair terms cancel).

Near a contact the shift has no meaning (the flow is the smooth forces'): a disk that the shift
would bring past a wall, or closer to another disk than both their contact and their distance
before, is shown at its own position (its velocity still processed). In the seed's charged gas
that happens at about one step in a thousand (tolerance 4e-3).
"""

from __future__ import annotations

import math
from typing import Any

import numba

from collidium.kernels.compilation import uncounted
from collidium.kernels.sorting import sort_nearly_sorted
from collidium.kernels.vessels import contacts

#: ``c / h^2``: the processing's time squared per squared substep (Q's share of the swing).
SHARE = 1.0 / 12.0

#: Reassociation (partial sums per vector lane) and fused multiply-add, as in the pair sums.
_FASTMATH = {"reassoc", "contract"}
_u: Any = numba.uint64  # unsigned counting, as in the pair sums: no gathered loads


@uncounted(error_model="numpy", fastmath=_FASTMATH)
def _curved_row(i, x, y, vx, vy, source, softening2, coupled, hx, hy) -> None:
    """The pairs of particle i with those after it, ``Hess(U_ij) (v_i - v_j)`` added to i's
    ``hx, hy`` and taken from j's; contiguous coordinates, velocities and sums (a row in vector
    lanes, as in the pair sums)."""
    xi, yi, ui, vi = x[i], y[i], vx[i], vy[i]
    sx = 0.0
    sy = 0.0
    for j in range(_u(i + 1), _u(x.shape[0])):
        dx = xi - x[j]
        dy = yi - y[j]
        wx = ui - vx[j]
        wy = vi - vy[j]
        inverse2 = 1.0 / (dx * dx + dy * dy + softening2)
        # Hess(k / sqrt(u)) w = k (3 d (d . w) / u - w) / u^(3/2)
        scale = coupled * source[j] * inverse2 * math.sqrt(inverse2)
        along = 3.0 * (dx * wx + dy * wy) * inverse2
        fx = scale * (along * dx - wx)
        fy = scale * (along * dy - wy)
        sx += fx
        sy += fy
        hx[j] -= fx
        hy[j] -= fy
    hx[i] += sx
    hy[i] += sy


@uncounted(error_model="numpy")
def curved_velocities(position, velocity, sources, couplings, softenings2, rows, out) -> None:
    """``out`` (N, 2) in N/s: ``sum_j Hess(U_ij) (v_i - v_j)`` over the pair laws, each pair
    once, ``U_ij = k s_i s_j / sqrt(r^2 + eps^2)``.

    Parameters
    ----------
    position, velocity : ndarray, shape (N, 2)
        In m and m/s.
    sources, couplings, softenings2 : ndarray, shapes (L, N), (L,), (L,)
        The pair laws (`collidium.forces.base.ForceField.pair_laws`), ``sources`` C-ordered.
    rows : ndarray, shape (6, N)
        Work: the coordinates and velocities gathered, and the sums.
    out : ndarray, shape (N, 2)
        Output.
    """
    n = position.shape[0]
    x, y, vx, vy, hx, hy = rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]
    for i in range(n):
        x[i], y[i] = position[i, 0], position[i, 1]
        vx[i], vy[i] = velocity[i, 0], velocity[i, 1]
        hx[i] = 0.0
        hy[i] = 0.0
    for law in range(couplings.shape[0]):
        source = sources[law]
        for i in range(n):
            coupled = couplings[law] * source[i]
            if coupled != 0.0:
                _curved_row(i, x, y, vx, vy, source, softenings2[law], coupled, hx, hy)
    for i in range(n):
        out[i, 0] = hx[i]
        out[i, 1] = hy[i]


@uncounted(error_model="numpy")
def shown(position, velocity, acceleration, mass, curved, scale, radius, vessel, order, work,
          out_position, out_velocity) -> int:  # fmt: skip
    """The processed state into ``out_position`` and ``out_velocity`` (N, 2): ``x + scale a``
    and ``v + scale curved / m`` (`curved_velocities`; ``scale = h^2 / 12`` s^2, negative for
    the inverse), each disk whose shift would bring it past a wall or closer to another disk than
    both their contact and their distance before shown at its own position. Returns how many.

    Parameters
    ----------
    position, velocity, acceleration, curved : ndarray, shape (N, 2)
        The state (m, m/s), the position forces over the masses (m/s^2) and `curved_velocities`.
    mass, radius : ndarray, shape (N,)
        In kg and m.
    scale : float
        s^2.
    vessel : tuple
        ``(shape, limit_x, limit_y, slack, segments)`` as the audit takes them
        (`collidium.vessels.Vessel.audit_arguments`; not periodic).
    order : ndarray of int, shape (N,)
        The disks by the low end of their x-extent, kept from call to call (nearly sorted).
    work : ndarray, shape (3, N)
        Work: the x-extents and whether each disk is shifted.
    """
    n = position.shape[0]
    low, high, moved = work[0], work[1], work[2]
    for i in range(n):
        out_position[i, 0] = position[i, 0] + scale * acceleration[i, 0]
        out_position[i, 1] = position[i, 1] + scale * acceleration[i, 1]
        out_velocity[i, 0] = velocity[i, 0] + scale * curved[i, 0] / mass[i]
        out_velocity[i, 1] = velocity[i, 1] + scale * curved[i, 1] / mass[i]
        moved[i] = 1.0
    kept = 0
    while True:  # rounds: each puts back, at once, every disk its positions find at fault
        _mark_outside(radius, vessel, moved, out_position)
        _mark_close(position, radius, order, low, high, moved, out_position)
        left = 0
        for i in range(n):
            if moved[i] < 0.0:
                out_position[i, 0] = position[i, 0]
                out_position[i, 1] = position[i, 1]
                moved[i] = 0.0
                left += 1
        if left == 0:
            return kept
        kept += left


@numba.njit(cache=True, inline="always")
def _mark_outside(radius, vessel, moved, out) -> None:
    """Mark (-1 in ``moved``) each shifted disk that reaches past a wall."""
    shape, limit_x, limit_y, slack, segments = vessel
    for i in range(out.shape[0]):
        x, y = out[i, 0], out[i, 1]
        if moved[i] > 0.0 and contacts.reaches_outside(x, y, radius[i], shape, limit_x, limit_y,
                                                       slack, segments):  # fmt: skip
            moved[i] = -1.0


@numba.njit(cache=True, inline="always")
def _mark_close(position, radius, order, low, high, moved, out) -> None:
    """Mark (-1 in ``moved``) the shifted disks of each pair (radii > 0) that the shift brings
    closer than both their contact and their distance before; pairs swept along x."""
    n = position.shape[0]
    for i in range(n):
        low[i] = out[i, 0] - radius[i]
        high[i] = out[i, 0] + radius[i]
    sort_nearly_sorted(order, low)
    for a in range(n):
        i = order[a]
        if radius[i] == 0.0:
            continue
        for b in range(a + 1, n):
            j = order[b]
            if low[j] > high[i]:
                break
            if radius[j] == 0.0 or (moved[i] == 0.0 and moved[j] == 0.0):
                continue
            contact = radius[i] + radius[j]
            if _distance2(out, i, j) < min(contact * contact, _distance2(position, i, j)):
                if moved[i] != 0.0:
                    moved[i] = -1.0
                if moved[j] != 0.0:
                    moved[j] = -1.0


@numba.njit(cache=True, inline="always")
def _distance2(position, i, j) -> float:
    """Squared distance of disks i and j, m^2."""
    dx = position[i, 0] - position[j, 0]
    dy = position[i, 1] - position[j, 1]
    return dx * dx + dy * dy
