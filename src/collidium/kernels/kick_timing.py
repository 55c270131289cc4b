"""The kick timing of contacts under forces, corrected to second order.

A kick-drift-kick substep h gives each particle the forces' impulse at its ends, ``a0 h / 2``
before the drift and ``aH h / 2`` after it. A contact at ``tau`` into the drift changes the
velocities in between, by a map C (a reflection of the normal velocity, for a pair its relative
one), although the particles physically received only part of the impulse before it. The exact
engine's response takes out the first-order error, ``v' = C(v - delta) + delta`` with
``delta = a0 (h/2 - tau)`` (`collidium.kernels.events`): exact for a constant acceleration, it
leaves an error of O(h^2) per contact, which in a charged gas, where the pair in contact pulls
hardest, is most of the energy error.

`correct` adds the rest once the accelerations at the substep's end are known. It carries each
particle's velocity error, the impulse its acceleration gave beyond the kick's constant ``a0``,
from contact to contact in the order they happened: linear in time between ``a0`` at the
start, its accelerations ``a_c`` at its contacts and ``aH`` at the end, and through each
contact's map C (of a pair, on both particles' errors). At the end the velocity is the
kick-drift-kick one plus that error and ``(a0 - aH) h / 2``; for a single contact,

    X = C[(a_c - a0) tau / 2] + a_c (h - tau) / 2 - aH tau / 2 + a0 (tau - h / 2),

which is 0 for a constant acceleration. The acceleration at the contact ``a_c`` is the pair's
mutual inverse-distance forces at the contact separation, which peak there, plus the rest of
each particle's acceleration interpolated linearly over the substep; a wall contributes no
force of its own. Carrying the error, rather than adding each contact's ``X``, keeps a
particle in two contacts of a substep (a chain, or a pair that meets twice) at second order.

The modified energy. Between contacts kick-drift-kick keeps not the energy H but its modified
energy ``S = H + h^2/12 sum_pairs w . Hess(U) . w - h^2/24 sum |F|^2/m`` (w a pair's relative
velocity; to O(h^4)): H oscillates about S by O(h^2) and does not drift. A contact that keeps H
makes S jump, by (derived to leading order for a mirror under a quadratic potential, and
measured on the seed's charged gas)

    (h^2 - 3 tau (h - tau)) / 12 dQ - tau (h - tau) (h - 2 tau) / (4 h) dv . Hess_o . dv,

``dQ`` the change of ``sum_pairs w . Hess(U) . w`` by the contact's velocity changes ``dv``
and ``Hess_o`` the Hessian of the particles' pulls from the others (not the pair's own, whose
force at the contact is exact). Two contacts of a substep add ``t (h - tau) (tau + t - h) /
(2 h) dv_1 . Hess . dv_2`` (``t < tau`` their times). These jumps, of random sign, random-walk S
and H with it: in the seed's charged gas at 8 substeps a 0.01 s step they were the whole of
the energy's drift, the substeps between contacts keeping S to 1e-10 of the energy each.
`correct` takes each contact's jump from the kinetic energy of its normal motion (the pair's
relative one, momentum kept), so that S goes through it to O(h^3); a single contact's jump
then falls eightfold per halving of h, not fourfold. Only where the pair forces are summed as
their laws' gradients (directly, uncapped; `collidium.forces.base.PairLawForce.follows_law`):
a tree's or a limiter's forces have no such S. The Hessians are the pair laws'; a uniform field
has none, and a field map's is left out.

The positions after the contact, drifted with the first-order velocities, are off by O(h^3).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels.compilation import inlined, uncounted
from collidium.kernels.events import (
    LOG_BOUNCE,
    LOG_DROP,
    LOG_DVX,
    LOG_DVY,
    LOG_ERROR,
    LOG_NX,
    LOG_NY,
    LOG_PARTICLE,
    LOG_PARTNER,
    LOG_PULL,
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
    shadow: bool,
    latest: np.ndarray,
) -> None:
    """Add the second-order kick-timing correction of a substep's contacts to the velocities of
    their particles, in place, and with ``shadow`` take each contact's jump of the modified
    energy from its normal motion (module docstring).

    Parameters
    ----------
    contacts : ndarray, shape (K, `collidium.kernels.events.LOG_COLUMNS`)
        The substep's contacts in the order they happened, as the engine logs them, in the
        first ``count`` rows; the correction works in their last columns. One with a bounce
        factor of 0 (not corrected to first order) starts its particles' errors afresh, and a
        particle whose last contact it is is left alone.
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
    shadow : bool
        Whether the pair forces are their laws' gradients, summed directly (the modified
        energy's term needs it).
    latest : ndarray of int64, shape (N,)
        Work array, -1 everywhere on entry and again on return: each particle's latest contact
        row so far, so that the correction takes time linear in the contacts.
    """
    shadow = shadow and couplings.shape[0] > 0
    for c in range(count):
        _carry(c, contacts, start_time, h, start, position, before, after, mass, sources,
               couplings, softenings2, width, height, periodic, latest)  # fmt: skip
        _set_latest(c, c, contacts, latest)
        contacts[c, LOG_DROP] = 0.0
        if shadow and contacts[c, LOG_BOUNCE] != 0.0:
            contacts[c, LOG_DROP] = _shadow_jump(
                c, contacts, count, start_time, h, start, position, velocity, mass, sources,
                couplings, softenings2, width, height, periodic,
            )  # fmt: skip
    for c in range(count):  # each particle's error at the end, from its last contact
        if contacts[c, LOG_BOUNCE] == 0.0:
            continue
        partner = int(contacts[c, LOG_PARTNER])
        rest = h - (contacts[c, LOG_TIME] - start_time)
        for member in range(2 if partner >= 0 else 1):
            k = int(contacts[c, LOG_PARTICLE]) if member == 0 else partner
            if latest[k] != c:  # a later contact of k carries its error on
                continue
            for d in range(2):
                error = contacts[c, LOG_ERROR + 2 * member + d]
                pull = contacts[c, LOG_PULL + 2 * member + d]
                velocity[k, d] += (error + (0.5 * (pull + after[k, d]) - before[k, d]) * rest
                                   + 0.5 * h * (before[k, d] - after[k, d]))  # fmt: skip
    for c in range(count):
        drop = contacts[c, LOG_DROP]
        if drop != 0.0:
            _take_along_normal(int(contacts[c, LOG_PARTICLE]), int(contacts[c, LOG_PARTNER]),
                               drop, contacts[c, LOG_NX], contacts[c, LOG_NY], velocity,
                               mass)  # fmt: skip
    for c in range(count):
        _set_latest(c, -1, contacts, latest)


@inlined
def _set_latest(c, value, contacts, latest) -> None:
    """Set the ``latest`` entry of contact ``c``'s particle and partner (not a wall's)."""
    latest[int(contacts[c, LOG_PARTICLE])] = value
    partner = int(contacts[c, LOG_PARTNER])
    if partner >= 0:
        latest[partner] = value


@inlined
def _carry(c, contacts, start_time, h, start, position, before, after, mass, sources, couplings,
           softenings2, width, height, periodic, latest) -> None:  # fmt: skip
    """Carry the velocity errors of contact ``c``'s particles from their previous contacts (or
    the substep's start) to it and through its map C, and log them with their accelerations
    at the contact (``LOG_ERROR``, ``LOG_PULL``). An uncorrected contact (bounce factor 0)
    starts its particles' errors afresh."""
    i, partner = int(contacts[c, LOG_PARTICLE]), int(contacts[c, LOG_PARTNER])
    tau = contacts[c, LOG_TIME] - start_time
    nx, ny = contacts[c, LOG_NX], contacts[c, LOG_NY]
    share = tau / h
    if partner < 0:  # a mirror has no force of its own
        ix, iy = _at_contact(i, 0.0, 0.0, 0.0, 0.0, 0.0, share, before, after, mass, nx, ny)
        jx, jy = 0.0, 0.0
    else:
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
    eix, eiy = _error_at(i, latest[i], tau, ix, iy, contacts, start_time, before)
    ejx, ejy = 0.0, 0.0
    if partner >= 0:
        ejx, ejy = _error_at(partner, latest[partner], tau, jx, jy, contacts, start_time, before)
    bounce = contacts[c, LOG_BOUNCE]
    n2 = nx * nx + ny * ny
    if bounce == 0.0:
        eix, eiy, ejx, ejy = 0.0, 0.0, 0.0, 0.0
    elif partner < 0:
        along = bounce * (eix * nx + eiy * ny) / n2
        eix, eiy = eix - along * nx, eiy - along * ny
    else:
        along = bounce * ((eix - ejx) * nx + (eiy - ejy) * ny) / n2
        total = mass[i] + mass[partner]
        gi, gj = along * mass[partner] / total, along * mass[i] / total
        eix, eiy, ejx, ejy = eix - gi * nx, eiy - gi * ny, ejx + gj * nx, ejy + gj * ny
    row = contacts[c]
    row[LOG_ERROR], row[LOG_ERROR + 1], row[LOG_ERROR + 2], row[LOG_ERROR + 3] = eix, eiy, ejx, ejy
    row[LOG_PULL], row[LOG_PULL + 1], row[LOG_PULL + 2], row[LOG_PULL + 3] = ix, iy, jx, jy


@inlined
def _error_at(k, previous, tau, ax, ay, contacts, start_time, before) -> tuple[float, float]:
    """Particle k's velocity error (m/s) just before a contact at ``tau`` s, where its
    acceleration is (ax, ay): the error after its ``previous`` contact (a row, or -1 for none:
    the substep's start), plus the impulse its acceleration, linear in between, gave beyond the
    kick's constant ``a0``."""
    ex, ey, t, px, py = 0.0, 0.0, 0.0, before[k, 0], before[k, 1]
    if previous >= 0:
        row = contacts[previous]
        slot = 0 if k == int(row[LOG_PARTICLE]) else 2
        ex, ey = row[LOG_ERROR + slot], row[LOG_ERROR + slot + 1]
        px, py = row[LOG_PULL + slot], row[LOG_PULL + slot + 1]
        t = row[LOG_TIME] - start_time
    span = tau - t
    return (ex + (0.5 * (px + ax) - before[k, 0]) * span,
            ey + (0.5 * (py + ay) - before[k, 1]) * span)  # fmt: skip


@inlined
def _in_rows(k, first, stop, contacts) -> bool:
    """Whether particle k is in one of the contacts logged in rows ``first`` to ``stop - 1``."""
    for row in range(first, stop):
        if k in (int(contacts[row, LOG_PARTICLE]), int(contacts[row, LOG_PARTNER])):
            return True
    return False


@uncounted(error_model="numpy")
def _shadow_jump(c, contacts, count, start_time, h, start, position, velocity, mass, sources,
                 couplings, softenings2, width, height, periodic) -> float:  # fmt: skip
    """The jump (J) that contact ``c`` of particle i (and its partner j, or -1 for a wall) makes
    in the substep's modified energy (module docstring): from the change ``dQ`` of
    ``Q = sum_pairs w . Hess(U) . w`` by the contact's velocity changes ``dv`` and the others'
    pull's curvature along them, ``dv . Hess . dv``, at the contact (`_member_terms`; the pair's
    own separation is the logged normal), and the cross terms with the earlier contacts."""
    row = contacts[c]
    i, j = int(row[LOG_PARTICLE]), max(int(row[LOG_PARTNER]), -1)
    tau = row[LOG_TIME] - start_time
    dix, diy = row[LOG_DVX], row[LOG_DVY]
    djx, djy = 0.0, 0.0
    if j >= 0:
        djx, djy = -dix * mass[i] / mass[j], -diy * mass[i] / mass[j]
    change, bend = 0.0, 0.0
    for one in range(2 if j >= 0 else 1):
        a = i if one == 0 else j
        dx, dy = (dix, diy) if one == 0 else (djx, djy)
        dc, db = _member_terms(a, dx, dy, c, i, j, tau, count, contacts, start_time, h, start,
                               position, velocity, mass, sources, couplings, softenings2, width,
                               height, periodic)  # fmt: skip
        change, bend = change + dc, bend + db
    if j >= 0:
        vix, viy = _after_contact(i, c, count, contacts, velocity, mass)
        vjx, vjy = _after_contact(j, c, count, contacts, velocity, mass)
        wx, wy = vix - 0.5 * dix - vjx + 0.5 * djx, viy - 0.5 * diy - vjy + 0.5 * djy
        change += 2.0 * _hessian_form(i, j, row[LOG_NX], row[LOG_NY], dix - djx, diy - djy, wx,
                                      wy, sources, couplings, softenings2)  # fmt: skip
    jump = (h * h - 3.0 * tau * (h - tau)) / 12.0 * change
    jump -= tau * (h - tau) * (h - 2.0 * tau) / (4.0 * h) * bend
    for other in range(c):  # with each earlier contact, its changes against this one's
        if contacts[other, LOG_BOUNCE] != 0.0:
            t = contacts[other, LOG_TIME] - start_time
            form = _cross_form(c, other, tau, count, contacts, start_time, h, start, position,
                               mass, sources, couplings, softenings2, width, height,
                               periodic)  # fmt: skip
            jump += t * (h - tau) * (tau + t - h) / (2.0 * h) * form
    return jump


@uncounted(error_model="numpy")
def _member_terms(a, dx, dy, c, i, j, tau, count, contacts, start_time, h, start, position,
                  velocity, mass, sources, couplings, softenings2, width, height,
                  periodic) -> tuple[float, float]:  # fmt: skip
    """Member a's pairs with every particle outside contact ``c`` (i, j): their parts of ``dQ``
    and of the curvature (`_terms`) for a's velocity change ``d`` (m/s), at the contact. The
    velocities there are the ones after the drift less the later contacts' changes, the
    positions those interpolated over the substep, put back on their paths for the particles
    that met contacts."""
    vx, vy = _after_contact(a, c, count, contacts, velocity, mass)
    # Halfway through the change, where a quadratic form's difference is exact.
    wx, wy = vx - 0.5 * dx, vy - 0.5 * dy
    ax, ay = _on_path(a, tau, count, contacts, start_time, h, start, position, mass, width,
                      height, periodic)  # fmt: skip
    change, bend = 0.0, 0.0
    for k in range(position.shape[0]):
        if k in (i, j):
            continue
        kx, ky = _at_share(k, tau / h, start, position, width, height, periodic)
        dc, db = _terms(a, k, ax - kx, ay - ky, dx, dy, wx - velocity[k, 0], wy - velocity[k, 1],
                        sources, couplings, softenings2, width, height, periodic)  # fmt: skip
        change, bend = change + dc, bend + db
    # The others that met contacts: their terms again, at their places and velocities then.
    for other in range(count):
        p, q = int(contacts[other, LOG_PARTICLE]), int(contacts[other, LOG_PARTNER])
        for member in range(2 if q >= 0 else 1):
            k = p if member == 0 else q
            if k in (i, j) or _in_rows(k, 0, other, contacts):
                continue
            kx, ky = _at_share(k, tau / h, start, position, width, height, periodic)
            dc, db = _terms(a, k, ax - kx, ay - ky, dx, dy, wx - velocity[k, 0],
                            wy - velocity[k, 1], sources, couplings, softenings2, width, height,
                            periodic)  # fmt: skip
            change, bend = change - dc, bend - db
            kx, ky = _on_path(k, tau, count, contacts, start_time, h, start, position, mass,
                              width, height, periodic)  # fmt: skip
            ux, uy = _after_contact(k, c, count, contacts, velocity, mass)
            dc, db = _terms(a, k, ax - kx, ay - ky, dx, dy, wx - ux, wy - uy, sources, couplings,
                            softenings2, width, height, periodic)  # fmt: skip
            change, bend = change + dc, bend + db
    return change, bend


@inlined
def _cross_form(c, other, tau, count, contacts, start_time, h, start, position, mass, sources,
                couplings, softenings2, width, height, periodic) -> float:  # fmt: skip
    """``dv_c . Hess(U) . dv_other`` (J/s^2): the Hessian of every pair law between the
    velocity changes of contacts ``c`` and ``other``, at the positions ``tau`` s into the
    substep: over the pairs among their particles, and a particle in both with every other."""
    ids = (
        int(contacts[c, LOG_PARTICLE]),
        int(contacts[c, LOG_PARTNER]),
        int(contacts[other, LOG_PARTICLE]),
        int(contacts[other, LOG_PARTNER]),
    )
    form = 0.0
    for x in range(4):
        a = ids[x]
        if a < 0 or _listed(a, ids, x):
            continue
        ax, ay = _on_path(a, tau, count, contacts, start_time, h, start, position, mass, width,
                          height, periodic)  # fmt: skip
        ux, uy = _change_of(a, c, contacts, mass)
        wx, wy = _change_of(a, other, contacts, mass)
        for y in range(x + 1, 4):
            b = ids[y]
            if b < 0 or b == a or _listed(b, ids, y):
                continue
            bx, by = _on_path(b, tau, count, contacts, start_time, h, start, position, mass,
                              width, height, periodic)  # fmt: skip
            vx, vy = _change_of(b, c, contacts, mass)
            zx, zy = _change_of(b, other, contacts, mass)
            sx, sy = _image(ax - bx, ay - by, width, height, periodic)
            form += _hessian_form(a, b, sx, sy, ux - vx, uy - vy, wx - zx, wy - zy, sources,
                                  couplings, softenings2)  # fmt: skip
        if (ux == 0.0 and uy == 0.0) or (wx == 0.0 and wy == 0.0):
            continue
        for k in range(position.shape[0]):  # a is in both: its pairs with the rest
            if k in ids:
                continue
            kx, ky = _at_share(k, tau / h, start, position, width, height, periodic)
            sx, sy = _image(ax - kx, ay - ky, width, height, periodic)
            form += _hessian_form(a, k, sx, sy, ux, uy, wx, wy, sources, couplings, softenings2)
    return form


@inlined
def _listed(a, ids, before) -> bool:
    """Whether ``a`` is among the first ``before`` of ``ids``."""
    for x in range(before):  # noqa: SIM110 (numba compiles no generator)
        if ids[x] == a:
            return True
    return False


@inlined
def _terms(a, k, sx, sy, dx, dy, wx, wy, sources, couplings, softenings2, width, height,
           periodic) -> tuple[float, float]:  # fmt: skip
    """Pair (a, k)'s part of ``dQ``, ``2 d . Hess . w``, and of the curvature, ``d . Hess . d``
    (J/s^2), at separation ``s`` (m, its minimum image taken here)."""
    sx, sy = _image(sx, sy, width, height, periodic)
    form, bend = _hessian_forms(a, k, sx, sy, dx, dy, wx, wy, sources, couplings, softenings2)
    return 2.0 * form, bend


@inlined
def _change_of(a, row, contacts, mass) -> tuple[float, float]:
    """The change of particle a's velocity (m/s) at contact ``row``: 0 if it is not in it."""
    p, q = int(contacts[row, LOG_PARTICLE]), int(contacts[row, LOG_PARTNER])
    scale = 1.0 if p == a else (-mass[p] / mass[a] if q == a else 0.0)
    return scale * contacts[row, LOG_DVX], scale * contacts[row, LOG_DVY]


@inlined
def _after_contact(a, c, count, contacts, velocity, mass) -> tuple[float, float]:
    """Particle a's velocity just after contact ``c`` (m/s): its ``velocity`` less the changes
    of the contacts logged after ``c``."""
    vx, vy = velocity[a, 0], velocity[a, 1]
    for later in range(c + 1, count):
        dx, dy = _change_of(a, later, contacts, mass)
        vx, vy = vx - dx, vy - dy
    return vx, vy


@inlined
def _on_path(a, tau, count, contacts, start_time, h, start, position, mass, width, height,
             periodic) -> tuple[float, float]:  # fmt: skip
    """Particle a's position ``tau`` s into the substep (m): the straight interpolation
    (`_at_share`) put back on its path, bent at each of its contacts."""
    x, y = _at_share(a, tau / h, start, position, width, height, periodic)
    for row in range(count):
        dx, dy = _change_of(a, row, contacts, mass)
        t = contacts[row, LOG_TIME] - start_time
        lead = max(tau - t, 0.0) - tau / h * (h - t)
        x, y = x + dx * lead, y + dy * lead
    return x, y


@inlined
def _hessian_form(a, b, sx, sy, dx, dy, wx, wy, sources, couplings, softenings2) -> float:
    """``d . Hess(U_ab) . w`` of the pair laws at separation ``s`` (m): ``d``, ``w`` in m/s,
    the result in J/s^2."""
    return _hessian_forms(a, b, sx, sy, dx, dy, wx, wy, sources, couplings, softenings2)[0]


@inlined
def _hessian_forms(a, b, sx, sy, dx, dy, wx, wy, sources, couplings, softenings2):
    """``(d . Hess(U_ab) . w, d . Hess(U_ab) . d)`` (J/s^2) of the pair laws at separation ``s``
    (m), in one pass over the laws: ``d``, ``w`` in m/s."""
    form, bend = 0.0, 0.0
    for law in range(couplings.shape[0]):
        kqq = couplings[law] * sources[law, a] * sources[law, b]
        if kqq != 0.0:
            u = sx * sx + sy * sy + softenings2[law]
            scale = kqq / (u * math.sqrt(u))
            along = 3.0 * (dx * sx + dy * sy) / u
            form += scale * (along * (wx * sx + wy * sy) - dx * wx - dy * wy)
            bend += scale * (along * (dx * sx + dy * sy) - dx * dx - dy * dy)
    return form, bend


@inlined
def _take_along_normal(i, j, drop, nx, ny, velocity, mass) -> None:
    """Take ``drop`` (J) from the kinetic energy of the contact's normal motion, the pair's
    relative one (momentum kept) or a wall's particle's, where there is that much."""
    norm = math.sqrt(nx * nx + ny * ny)
    ux, uy = nx / norm, ny / norm
    if j >= 0:
        reduced = mass[i] * mass[j] / (mass[i] + mass[j])
        normal = (velocity[i, 0] - velocity[j, 0]) * ux + (velocity[i, 1] - velocity[j, 1]) * uy
    else:
        reduced = mass[i]
        normal = velocity[i, 0] * ux + velocity[i, 1] * uy
    left = normal * normal - 2.0 * drop / reduced
    if not left > 0.0:
        return
    change = math.copysign(math.sqrt(left), normal) - normal
    if j >= 0:
        total = mass[i] + mass[j]
        velocity[i, 0] += change * mass[j] / total * ux
        velocity[i, 1] += change * mass[j] / total * uy
        velocity[j, 0] -= change * mass[i] / total * ux
        velocity[j, 1] -= change * mass[i] / total * uy
    else:
        velocity[i, 0] += change * ux
        velocity[i, 1] += change * uy


@inlined
def _at_share(k, share, start, position, width, height, periodic) -> tuple[float, float]:
    """Particle k's position ``share`` of the way through the substep (m), straight from its
    start to its end (the minimum image of the way when ``periodic``)."""
    dx, dy = _image(position[k, 0] - start[k, 0], position[k, 1] - start[k, 1], width, height,
                    periodic)  # fmt: skip
    return start[k, 0] + share * dx, start[k, 1] + share * dy


@inlined
def _image(sx, sy, width, height, periodic) -> tuple[float, float]:
    """The minimum image of a separation (m) when ``periodic``."""
    if periodic:
        sx -= width * round(sx / width)
        sy -= height * round(sy / height)
    return sx, sy


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
def _separation(i, j, position, width, height, periodic) -> tuple[float, float]:
    """``x_i - x_j`` (m), the minimum image when ``periodic``."""
    return _image(position[i, 0] - position[j, 0], position[i, 1] - position[j, 1], width, height,
                  periodic)  # fmt: skip


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
