"""Plain NumPy twins of the compiled kernels, written for clarity, not speed; tests compare them.

Each function here computes what its kernel computes, by the most direct method (all pairs, one
event at a time), so an optimisation in a kernel can always be checked against it.
"""

from __future__ import annotations

import math

import numpy as np

from collidium.kernels.substeps import RATE_SPACING
from collidium.kernels.vessels import BOX, CIRCLE, segments
from collidium.state import FloatArray, IntArray


def pair_response(
    m1: float,
    m2: float,
    x1: FloatArray,
    x2: FloatArray,
    v1: FloatArray,
    v2: FloatArray,
    restitution: float = 1.0,
) -> tuple[FloatArray, FloatArray]:
    """Seed eq. 7, in the centre-of-mass frame: velocities (2,) after a collision of disks at x1,
    x2 whose normal relative velocity is reversed and scaled by ``restitution`` (1: elastic)."""
    n = (x1 - x2) / np.linalg.norm(x1 - x2)
    centre = (m1 * v1 + m2 * v2) / (m1 + m2)
    u1, u2 = v1 - centre, v2 - centre
    u1 = u1 - (1 + restitution) * np.dot(u1, n) * n
    u2 = u2 - (1 + restitution) * np.dot(u2, n) * n
    return centre + u1, centre + u2


def fold(x: float, v: float, lo: float, hi: float) -> tuple[float, float, int]:
    """Reflect a coordinate back into ``[lo, hi]`` one bounce at a time (twin of
    `vessels.box.fold`)."""
    bounces = 0
    while x < lo or x > hi:
        x = 2 * lo - x if x < lo else 2 * hi - x
        v = -v
        bounces += 1
    return x, v, bounces


def inverse_distance_direct(
    position: FloatArray,
    charge: FloatArray,
    k: float,
    softening2: float,
    size: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Inverse-distance forces (N, 2) of sources ``charge`` (N,) with coupling ``k`` (Coulomb, or
    masses and ``-G``), per-particle half pair energies (N,) and half pair virials
    ``r_ij . F_ij`` (N,) over all pairs at once. ``size`` (the box sides) turns on the minimum
    image.
    """
    d = position[:, None, :] - position[None, :, :]
    if size is not None:
        d -= size * np.round(d / size)
    distance2 = np.einsum("ijk,ijk->ij", d, d)
    r2 = distance2 + softening2
    np.fill_diagonal(r2, np.inf)
    qq = charge[:, None] * charge[None, :]
    inv = 1.0 / np.sqrt(r2)
    force = np.einsum("ij,ijk->ik", k * qq * inv**3, d)
    virial = 0.5 * np.sum(k * qq * inv**3 * distance2, axis=1)
    return force, 0.5 * np.sum(k * qq * inv, axis=1), virial


def inverse_distance_on(
    position: FloatArray, charge: FloatArray, k: float, softening2: float, targets: IntArray
) -> FloatArray:
    """Inverse-distance forces (M, 2) in N on the particles ``targets`` (M,) from all others,
    one target at a time (O(M N) time, O(N) memory: for checking large systems on a sample)."""
    force = np.empty((len(targets), 2))
    for row, i in enumerate(targets):
        d = position[i] - position
        r2 = np.einsum("ij,ij->i", d, d) + softening2
        r2[i] = np.inf
        force[row] = k * charge[i] * ((charge / r2**1.5) @ d)
    return force


def inverse_distance_stiffness(
    position: FloatArray,
    velocity: FloatArray,
    charge: FloatArray,
    mass: FloatArray,
    k: float,
    softening2: float,
    size: FloatArray | None = None,
) -> float:
    """The largest ``(|U_ij| rate_ij^2)^2`` (J^2/s^4) over charged pairs, all pairs at once, with
    ``|U_ij| = |k q_i q_j| / s``, ``rate_ij^2 = (|v_ij|^2 + |U_ij| (1/m_i + 1/m_j)) / s^2`` and
    ``s^2 = r^2 + eps^2``. ``size`` (the box sides) turns on the minimum image."""
    charged = charge != 0.0
    x, v, q, m = position[charged], velocity[charged], charge[charged], mass[charged]
    d = x[:, None, :] - x[None, :, :]
    if size is not None:
        d -= size * np.round(d / size)
    s2 = np.einsum("ijk,ijk->ij", d, d) + softening2
    np.fill_diagonal(s2, np.inf)  # no pair: U = 0 there
    w = v[:, None, :] - v[None, :, :]
    u = np.abs(k) * np.abs(q[:, None] * q[None, :]) / np.sqrt(s2)
    error = u * (np.einsum("ijk,ijk->ij", w, w) + u * (1 / m[:, None] + 1 / m[None, :])) / s2
    return float(np.max(error[np.triu_indices(q.size, 1)] ** 2, initial=0.0))


def acceleration_stiffness(
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    softening: float,
    spacing: float,
) -> float:
    """Twin of `tree.acceleration_stiffness`: the largest ``(m_i |a_i| l_i rate_i^2)^2`` with
    ``rate_i^2 = (|v_i|^2 / l_i + |a_i|) / l_i`` and ``l_i`` the diameter or the softening,
    whichever is larger, else ``spacing``."""
    length = np.maximum(2.0 * radius, softening)
    length = np.where(length > 0.0, length, spacing)
    pull = np.hypot(acceleration[:, 0], acceleration[:, 1])
    speed2 = np.einsum("ij,ij->i", velocity, velocity)
    error = mass * pull * (speed2 / length + pull)
    return float(np.max(error * error, initial=0.0))


def kick_timing_correction(
    contacts: FloatArray,
    start_time: float,
    h: float,
    start: FloatArray,
    position: FloatArray,
    before: FloatArray,
    after: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    laws: list[tuple[FloatArray, float, float]],
    size: FloatArray | None = None,
    shadow: bool = True,
) -> None:
    """Twin of `kick_timing.correct`, with vectors: each particle's velocity error carried from
    contact to contact (the impulse of its acceleration, linear between the substep's start,
    its contacts and the end, beyond the kick's constant ``a0``; through each contact's map C;
    afresh after a contact of bounce factor 0) added at the end with ``(a0 - aH) h / 2``; with
    ``shadow`` the modified energy's jump
    ``(h^2 - 3 tau (h - tau)) / 12 dQ - tau (h - tau) (h - 2 tau) / (4 h) dv.Hess.dv`` taken from
    its normal motion; ``laws`` the pair forces'
    (sources, coupling, squared softening); ``size`` the box sides for the minimum image."""

    def image(d: FloatArray) -> FloatArray:
        return d if size is None else d - size * np.round(d / size)

    def pull(d: FloatArray, i: int, j: int) -> FloatArray:  # the force on i, N
        r2 = float(d @ d)
        return sum((c * q[i] * q[j] / (r2 + e2) ** 1.5 * d for q, c, e2 in laws), np.zeros(2))

    def changes(row: FloatArray) -> dict[int, FloatArray]:  # each member's velocity change
        i, partner, dv = int(row[0]), int(row[1]), row[6:8]
        return {i: dv} if partner < 0 else {i: dv, partner: -dv * mass[i] / mass[partner]}

    def hessian_form(sep: FloatArray, d: FloatArray, w: FloatArray, a: int, b: int) -> float:
        u = [sep @ sep + e2 for _, _, e2 in laws]
        return sum(
            c * q[a] * q[b] / uk**1.5 * (3.0 * (d @ sep) * (w @ sep) / uk - d @ w)
            for (q, c, _), uk in zip(laws, u, strict=True)
        )

    def jump(index: int) -> float:  # of the modified energy, J
        row = contacts[index]
        tau = row[2] - start_time
        then = velocity.copy()  # the velocities just after the contact
        for later in contacts[index + 1 :]:
            for k, dv in changes(later).items():
                then[k] -= dv
        at = on_path(tau)
        members = changes(row)
        mean = {a: then[a] - 0.5 * d for a, d in members.items()}
        dq = bend = 0.0
        for a, d in members.items():
            for k in range(len(mass)):
                if k not in members:
                    dq += 2.0 * hessian_form(image(at[a] - at[k]), d, mean[a] - then[k], a, k)
                    bend += hessian_form(image(at[a] - at[k]), d, d, a, k)
        if len(members) == 2:
            i, j = members
            dq += 2.0 * hessian_form(row[3:5], members[i] - members[j], mean[i] - mean[j], i, j)
        total = (h * h - 3.0 * tau * (h - tau)) / 12.0 * dq
        total -= tau * (h - tau) * (h - 2.0 * tau) / (4.0 * h) * bend
        straight = start + tau / h * image(position - start)
        for other in contacts[:index]:
            if other[5] != 0.0:
                t = other[2] - start_time
                total += t * (h - tau) * (tau + t - h) / (2.0 * h) * cross(row, other, at, straight)
        return total

    def on_path(tau: float) -> FloatArray:  # every position tau into the substep, m
        at = start + tau / h * image(position - start)
        for other in contacts:
            for k, dv in changes(other).items():
                t = other[2] - start_time
                at[k] += dv * (max(tau - t, 0.0) - tau / h * (h - t))
        return at

    def cross(row: FloatArray, other: FloatArray, at: FloatArray, straight: FloatArray) -> float:
        u, w = changes(row), changes(other)
        listed = list(dict.fromkeys([*u, *w]))
        form = 0.0
        for x, a in enumerate(listed):
            ua, wa = u.get(a, np.zeros(2)), w.get(a, np.zeros(2))
            for b in listed[x + 1 :]:
                ub, wb = u.get(b, np.zeros(2)), w.get(b, np.zeros(2))
                form += hessian_form(image(at[a] - at[b]), ua - ub, wa - wb, a, b)
            if a in u and a in w:
                for k in range(len(mass)):
                    if k not in listed:
                        form += hessian_form(image(at[a] - straight[k]), ua, wa, a, k)
        return form

    def take(members: list[int], drop: float, n: FloatArray) -> None:
        unit = n / np.linalg.norm(n)
        if len(members) == 1:
            reduced, normal = mass[members[0]], velocity[members[0]] @ unit
        else:
            i, j = members
            reduced = mass[i] * mass[j] / (mass[i] + mass[j])
            normal = (velocity[i] - velocity[j]) @ unit
        left = normal * normal - 2.0 * drop / reduced
        if not left > 0.0:
            return
        change = np.copysign(np.sqrt(left), normal) - normal
        if len(members) == 1:
            velocity[members[0]] += change * unit
        else:
            i, j = members
            velocity[i] += change * mass[j] / (mass[i] + mass[j]) * unit
            velocity[j] -= change * mass[i] / (mass[i] + mass[j]) * unit

    def accelerations_at(index: int) -> dict[int, FloatArray]:  # m/s^2
        row = contacts[index]
        i, partner, tau, n = int(row[0]), int(row[1]), row[2] - start_time, row[3:5]
        members = [i] if partner < 0 else [i, partner]
        at_contact = {}
        for k, sign in zip(members, [1.0, -1.0], strict=False):
            if partner < 0:
                mutual0 = mutualh = mutualc = np.zeros(2)
            else:
                mutual0 = sign * pull(image(start[i] - start[partner]), i, partner)
                mutualh = sign * pull(image(position[i] - position[partner]), i, partner)
                mutualc = sign * pull(n, i, partner)
            rest0 = before[k] - mutual0 / mass[k]
            resth = after[k] - mutualh / mass[k]
            at_contact[k] = rest0 + (resth - rest0) * tau / h + mutualc / mass[k]
        return at_contact

    state: dict[int, tuple[FloatArray, float, FloatArray, bool]] = {}  # error, time, pull, kept
    drops = []
    for index, row in enumerate(contacts):
        tau, n, bounce = row[2] - start_time, row[3:5], row[5]
        at_contact = accelerations_at(index)
        error = {}
        for k, a_c in at_contact.items():
            e, t, a, _ = state.get(k, (np.zeros(2), 0.0, before[k], True))
            error[k] = e + ((a + a_c) / 2 - before[k]) * (tau - t)
        members = list(error)
        if bounce == 0.0:
            error = {k: np.zeros(2) for k in members}
        elif len(members) == 1:
            e = error[members[0]]
            error[members[0]] = e - bounce * (e @ n) / (n @ n) * n
        else:
            i, j = members
            along = bounce * ((error[i] - error[j]) @ n) / (n @ n)
            error[i] = error[i] - along * mass[j] / (mass[i] + mass[j]) * n
            error[j] = error[j] + along * mass[i] / (mass[i] + mass[j]) * n
        for k in members:
            state[k] = (error[k], tau, at_contact[k], bounce != 0.0)
        drops.append(jump(index) if shadow and laws and bounce != 0.0 else 0.0)
    for k, (e, t, a, kept) in state.items():
        if kept:
            velocity[k] += e + ((a + after[k]) / 2 - before[k]) * (h - t)
            velocity[k] += (before[k] - after[k]) * h / 2
    for row, drop in zip(contacts, drops, strict=True):
        if drop != 0.0:
            partner = int(row[1])
            take([int(row[0])] if partner < 0 else [int(row[0]), partner], drop, row[3:5])


def modified_energy_terms(
    position: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    laws: tuple[FloatArray, FloatArray, FloatArray],
    size: FloatArray | None = None,
) -> tuple[float, float]:
    """Twin of `modified_energy.curvature_and_pulls`: ``(Q, P)``, ``Q`` the quadratic form
    ``w . Hess(U) . w`` of every pair's relative velocity, all pairs at once, ``P`` the sum of
    ``m |a|^2``, of the pair ``laws`` (sources (L, N), couplings and squared softenings (L,));
    ``size`` (the box sides) turns on the minimum image."""
    sources, couplings, softenings2 = laws
    d = position[:, None, :] - position[None, :, :]
    if size is not None:
        d -= size * np.round(d / size)
    w = velocity[:, None, :] - velocity[None, :, :]
    curvature = 0.0
    for q, k, eps2 in zip(sources, couplings, softenings2, strict=True):
        u = np.einsum("ijk,ijk->ij", d, d) + eps2
        np.fill_diagonal(u, np.inf)
        along = np.einsum("ijk,ijk->ij", d, w)
        # Hess(k q_i q_j / sqrt(u)) = k q_i q_j (3 d d^T / u^(5/2) - I / u^(3/2))
        square = np.einsum("ijk,ijk->ij", w, w)
        form = k * np.outer(q, q) * (3.0 * along**2 / u**2.5 - square / u**1.5)
        curvature += 0.5 * float(form.sum())  # each pair twice
    return curvature, float(np.sum(mass * np.sum(acceleration**2, axis=1)))


def modified_energy_keep(
    position: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    laws: tuple[FloatArray, FloatArray, FloatArray],
    steps: tuple[float, float],
    limit: float,
    size: FloatArray | None = None,
) -> float:
    """Twin of `modified_energy.keep_across_step`: the velocities about the centre of mass
    scaled, in place, by the factor f with ``KE + U + h^2 (Q / 12 - P / 24)`` the same before
    and after ``steps``, the substep (s) before and after, unless f is further than ``limit``
    from 1; returns the energy given (J, 0 where left)."""
    substep, following = steps
    curvature, pulls = modified_energy_terms(position, velocity, acceleration, mass, laws, size)
    centre = mass @ velocity / mass.sum()
    internal = 0.5 * float(np.sum(mass * np.sum((velocity - centre) ** 2, axis=1)))
    if not internal > 0.0:
        return 0.0
    before = internal + substep**2 * (curvature / 12.0 - pulls / 24.0)
    factor = math.sqrt(
        (before + following**2 * pulls / 24.0) / (internal + following**2 * curvature / 12.0)
    )
    if not abs(factor - 1.0) <= limit:
        return 0.0
    velocity[...] = centre + factor * (velocity - centre)
    return internal * (factor**2 - 1.0)


def curved_velocities(
    position: FloatArray,
    velocity: FloatArray,
    laws: tuple[FloatArray, FloatArray, FloatArray],
) -> FloatArray:
    """Twin of `processing.curved_velocities`: ``sum_j Hess(U_ij) (v_i - v_j)`` (N, 2), N/s, of
    the pair ``laws`` (sources (L, N), couplings and squared softenings (L,)), all pairs at
    once."""
    sources, couplings, softenings2 = laws
    d = position[:, None, :] - position[None, :, :]
    w = velocity[:, None, :] - velocity[None, :, :]
    out = np.zeros_like(position)
    for q, k, eps2 in zip(sources, couplings, softenings2, strict=True):
        u = np.einsum("ijk,ijk->ij", d, d) + eps2
        np.fill_diagonal(u, np.inf)
        along = np.einsum("ijk,ijk->ij", d, w)[..., None]
        scale = (k * np.outer(q, q) / u**1.5)[..., None]
        out += np.sum(scale * (3.0 * along * d / u[..., None] - w), axis=1)
    return out


def processed_state(
    position: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    curved: FloatArray,
    scale: float,
    radius: FloatArray,
    vessel: tuple[int, float, float, float, FloatArray],
) -> tuple[FloatArray, FloatArray, int]:
    """Twin of `processing.shown`: ``(x + scale a, v + scale curved / m, disks put back)``, a
    disk put back to its own position while its shift brings it past a wall (`first_invalid`
    on it alone) or closer to another disk (both radii > 0) than both their contact and their
    distance before."""
    shape, limit_x, limit_y, slack, table = vessel
    shifted = position + scale * acceleration
    moving = velocity + scale * curved / mass[:, None]
    moved = np.ones(len(position), dtype=bool)
    before = np.sum((position[:, None, :] - position[None, :, :]) ** 2, axis=2)
    contact = (radius[:, None] + radius[None, :]) ** 2
    disks = (radius[:, None] > 0.0) & (radius[None, :] > 0.0)
    np.fill_diagonal(disks, False)
    kept = 0
    while True:
        outside = [
            first_invalid(shifted[i : i + 1], moving[i : i + 1], radius[i : i + 1], shape,
                          limit_x, limit_y, slack, False, table)[1] == 2
            for i in range(len(position))
        ]  # fmt: skip
        back = moved & np.array(outside, dtype=bool)
        now = np.sum((shifted[:, None, :] - shifted[None, :, :]) ** 2, axis=2)
        close = disks & (now < np.minimum(contact, before)) & (moved[:, None] | moved[None, :])
        back |= moved & close.any(axis=1)
        if not back.any():
            return shifted, moving, kept
        shifted[back] = position[back]
        moved &= ~back
        kept += int(back.sum())


def first_overlap(position: FloatArray, radius: FloatArray) -> tuple[int, int]:
    """The overlapping pair with the smallest (i, j), or (-1, -1); all pairs, reflecting box."""
    d = np.linalg.norm(position[:, None] - position[None, :], axis=2)
    sigma = radius[:, None] + radius[None, :]
    bad = (d < sigma * (1 - 1e-12)) & np.triu(np.ones_like(d, dtype=bool), 1)
    bad &= (radius[:, None] > 0) & (radius[None, :] > 0)
    pairs = np.argwhere(bad)
    return (int(pairs[0, 0]), int(pairs[0, 1])) if len(pairs) else (-1, -1)


def step_collisions(
    position: FloatArray, velocity: FloatArray, mass: FloatArray, radius: FloatArray
) -> tuple[int, float]:
    """Seed method, resolution part: every overlapping pair (i < j, index order) that is approaching
    gets the elastic response. Velocities updated in place (reflecting box). Radius-0 particles take
    no part. Returns the count and the collision virial ``sum r_ij . dp_i``."""
    done, virial = 0, 0.0
    n = len(position)
    for i in range(n):
        for j in range(i + 1, n):
            if radius[i] == 0 or radius[j] == 0:
                continue
            sep = position[i] - position[j]
            if np.dot(sep, sep) >= (radius[i] + radius[j]) ** 2:
                continue
            if np.dot(sep, velocity[i] - velocity[j]) >= 0:
                continue
            before = velocity[i].copy()
            velocity[i], velocity[j] = pair_response(
                mass[i], mass[j], position[i], position[j], velocity[i], velocity[j]
            )
            virial += mass[i] * np.dot(sep, velocity[i] - before)
            done += 1
    return done, virial


def event_drift(
    position: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    half: FloatArray,
    duration: float,
    periodic: bool = False,
    rim: float | None = None,
    table: FloatArray | None = None,
    box_walls: bool = True,
    fall: FloatArray | None = None,
) -> tuple[int, int, float, FloatArray]:
    """Event-driven hard disks, all pairs (and, if periodic, all 9 images) checked at every event,
    in a box of half sides ``half`` or, with ``rim``, in a circle of that radius (m), and against
    the segments of ``table`` (`segments`; without ``box_walls``, they are the only walls), all
    falling with the acceleration ``fall`` (2,) m/s^2 (none by default): the pairs' relative
    motion stays straight, the walls are met on parabolas.

    Positions and velocities (N, 2) are updated in place (periodic positions are left unwrapped).
    Returns (pair collisions, wall hits, collision virial ``sum r_ij . dp_i``, momentum received
    by the left, right, bottom and top wall, or by the rim, then by each segment).
    """
    now = 0.0
    pairs = walls = 0
    virial = 0.0
    table = np.empty((0, segments.SEGMENT_COLUMNS)) if table is None else table
    g = np.zeros(2) if fall is None else np.asarray(fall, dtype=float)
    own = 1 if rim is not None else 4 if box_walls and not periodic else 0
    wall_impulse = np.zeros(own + len(table))
    while True:
        t_pair, i, j = _next_contact(position, velocity, radius, 2 * half, periodic)
        if periodic:
            t_wall, k, d = math.inf, -1, -1
        elif rim is not None:
            t_wall, k, d = _next_rim(position, velocity, radius, rim, g)
        elif box_walls:
            t_wall, k, d = _next_wall(position, velocity, radius, half, g)
        else:
            t_wall, k, d = math.inf, -1, -1
        t_segment, s, e = _next_segment(position, velocity, radius, table, g)
        best = min(t_pair, t_wall, t_segment)
        if now + best > duration:
            _fly(position, velocity, g, duration - now)
            return pairs, walls, virial, wall_impulse
        _fly(position, velocity, g, best)
        now += best
        if t_segment < min(t_pair, t_wall):
            normal = _nearest_on_segment(position[s], table[e]) - position[s]
            normal /= np.linalg.norm(normal)
            outward = float(velocity[s] @ normal)
            wall_impulse[own + e] += 2 * mass[s] * abs(outward)
            velocity[s] -= 2 * outward * normal
            walls += 1
        elif t_wall < t_pair and rim is not None:
            normal = position[k] / np.linalg.norm(position[k])
            outward = float(velocity[k] @ normal)
            wall_impulse[0] += 2 * mass[k] * abs(outward)
            velocity[k] -= 2 * outward * normal
            walls += 1
        elif t_wall < t_pair:
            wall_impulse[2 * d + (1 if velocity[k, d] > 0 else 0)] += (
                2 * mass[k] * abs(velocity[k, d])
            )
            velocity[k, d] = -velocity[k, d]
            walls += 1
        else:
            sep = position[i] - position[j]
            if periodic:
                sep -= 2 * half * np.round(sep / (2 * half))
            before = velocity[i].copy()
            velocity[i], velocity[j] = pair_response(
                mass[i], mass[j], sep, np.zeros(2), velocity[i], velocity[j]
            )
            virial += mass[i] * np.dot(sep, velocity[i] - before)
            pairs += 1


def event_intervals(
    position: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    half: FloatArray,
    dt: float,
    count: int,
    rim: float | None = None,
    fall: FloatArray | None = None,
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Twin of `event_flights.event_intervals`: `event_drift` for ``count`` steps of ``dt`` (s)
    in a box of half sides ``half`` or a circle of radius ``rim`` (m), falling with ``fall``
    (2,) m/s^2 (none by default), in place, recording at each step's end the kinetic energy,
    the potential energy of the fall ``-sum m g . x``, the pair virial (0), momentum, total
    speed (K, 6); the pair collisions and wall hits (K, 2); the collision virial and the
    momentum each wall received (K, 1 + W)."""
    g = np.zeros(2) if fall is None else np.asarray(fall, dtype=float)
    values, counts, impulses = [], [], []
    pairs = walls = 0
    virial = 0.0
    received = np.zeros(1 if rim is not None else 4)
    for _ in range(count):
        more = event_drift(position, velocity, mass, radius, half, dt, rim=rim, fall=g)
        pairs, walls, virial = pairs + more[0], walls + more[1], virial + more[2]
        received = received + more[3]
        px, py = mass @ velocity
        kinetic = 0.5 * float(np.sum(mass * np.sum(velocity**2, axis=1)))
        speeds = float(np.sum(np.hypot(velocity[:, 0], velocity[:, 1])))
        potential = -float(np.sum(mass * (position @ g)))
        values.append((kinetic, potential, 0.0, float(px), float(py), speeds))
        counts.append((pairs, walls))
        impulses.append((virial, *received))
    return np.array(values), np.array(counts, dtype=np.int64), np.array(impulses)


def _fly(position: FloatArray, velocity: FloatArray, fall: FloatArray, t: float) -> None:
    """Every disk along its parabola for t seconds, in place."""
    position += velocity * t + 0.5 * fall * t * t
    velocity += fall * t


def _nearest_on_segment(point: FloatArray, row: FloatArray) -> FloatArray:
    """The point of a segment (a row of a segment table) nearest to ``point``, m."""
    start = row[[segments.X0, segments.Y0]]
    end = row[[segments.X1, segments.Y1]]
    span = end - start
    if not span.any():
        return start
    along = np.clip((point - start) @ span / (span @ span), 0.0, 1.0)
    return start + along * span


def segment_delay(position: FloatArray, velocity: FloatArray, radius: float, row: FloatArray,
                  fall: FloatArray | None = None) -> float:  # fmt: skip
    """Twin of `segments.element_delay`: when a disk first comes ``radius`` from a segment while
    approaching it, from the signed distance to its line (or the squared distance to a point:
    `distance_crossing`), inf if never. Under a ``fall`` (2,) m/s^2, the signed distance is a
    quadratic whose roots at +-r come from `numpy.roots`."""
    g = np.zeros(2) if fall is None else np.asarray(fall, dtype=float)
    start = row[[segments.X0, segments.Y0]]
    end = row[[segments.X1, segments.Y1]]
    span = end - start
    offset = position - start
    if not span.any():
        return distance_crossing(offset, velocity, g, radius, outward=False)
    normal = np.array([-span[1], span[0]]) / np.linalg.norm(span)
    d0, w, pull = float(offset @ normal), float(velocity @ normal), float(g @ normal)
    side = math.copysign(1.0, d0)
    times = []
    if abs(d0) <= radius and side * w < 0:
        times.append(0.0)  # within r of the line by round-off, and closing
    # This side's face, met moving towards the line; the far one's, met coming back to it.
    for level, toward in ((radius, -1.0), (-radius, 1.0)):
        roots = np.roots([0.5 * pull, w, d0 - side * level]) if pull or w else np.array([])
        for root in np.atleast_1d(roots):
            t = float(root.real)
            slope = w + pull * t
            if abs(root.imag) <= 1e-12 * max(1.0, abs(t)) and t >= 0 and toward * side * slope > 0:
                times.append(t)
    for t in sorted(times):
        along = (offset + velocity * t + 0.5 * g * t * t) @ span / (span @ span)
        if 0.0 <= along <= 1.0:
            return t
    return math.inf


def _next_segment(
    position: FloatArray,
    velocity: FloatArray,
    radius: FloatArray,
    table: FloatArray,
    fall: FloatArray,
) -> tuple[float, int, int]:
    """Earliest contact with a segment: (delay, particle, segment)."""
    best, particle, segment = math.inf, -1, -1
    for i in range(len(position)):
        for e in range(len(table)):
            delay = segment_delay(position[i], velocity[i], radius[i], table[e], fall)
            if delay < best:
                best, particle, segment = delay, i, e
    return best, particle, segment


def _next_rim(
    position: FloatArray, velocity: FloatArray, radius: FloatArray, rim: float, fall: FloatArray
) -> tuple[float, int, int]:
    """Earliest contact with a circle's rim: (delay, particle, 0)."""
    delays = [
        circle_wall_delay(x, v, r, rim, fall)[0]
        for x, v, r in zip(position, velocity, radius, strict=True)
    ]
    k = int(np.argmin(delays))
    return float(delays[k]), k, 0


def _next_wall(
    position: FloatArray,
    velocity: FloatArray,
    radius: FloatArray,
    half: FloatArray,
    fall: FloatArray | None = None,
) -> tuple[float, int, int]:
    """Earliest wall contact: (delay, particle, axis); under a ``fall``, from `first_contact`
    for each wall."""
    if fall is not None and fall.any():
        delay = np.array([[min(first_contact(position[k, d] + half[d] - radius[k],
                                             velocity[k, d], fall[d]),
                               first_contact(half[d] - radius[k] - position[k, d],
                                             -velocity[k, d], -fall[d]))
                           for d in range(2)] for k in range(len(position))])  # fmt: skip
        k, d = np.unravel_index(np.argmin(delay), delay.shape)
        return float(delay[k, d]), int(k), int(d)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        target = np.where(velocity > 0, half - radius[:, None], radius[:, None] - half)
        delay = np.where(velocity != 0, (target - position) / velocity, np.inf)
    delay = np.maximum(delay, 0.0)
    k, d = np.unravel_index(np.argmin(delay), delay.shape)
    return float(delay[k, d]), int(k), int(d)


def box_wall_delay(
    position: FloatArray,
    velocity: FloatArray,
    radius: float,
    half: FloatArray,
    fall: FloatArray | None = None,
) -> tuple[float, int]:
    """Twin of `vessels.box.wall_delay` for one disk: ``(delay, wall)`` (walls 0 left, 1 right,
    2 bottom, 3 top), ``(inf, -1)`` if none; ties to the x walls, then the lower wall. Under a
    ``fall`` each wall's gap closes on a parabola (`first_contact`)."""
    g = np.zeros(2) if fall is None else np.asarray(fall, dtype=float)
    delays = [
        first_contact((half[d] - radius) - sign * position[d], -sign * velocity[d], -sign * g[d])
        for d in range(2)
        for sign in (-1.0, 1.0)
    ]  # fmt: skip
    wall = int(np.argmin(delays))
    return (delays[wall], wall) if math.isfinite(delays[wall]) else (math.inf, -1)


def circle_wall_delay(
    position: FloatArray,
    velocity: FloatArray,
    radius: float,
    rim: float,
    fall: FloatArray | None = None,
) -> tuple[float, int]:
    """Twin of `vessels.circle.wall_delay`: the largest root of ``|x + v t|^2 = (rim - r)^2``
    from NumPy's polynomial roots, ``(delay, 0)``, or ``(inf, -1)`` at rest; under a ``fall``,
    `distance_crossing`."""
    if fall is not None and np.any(fall):
        delay = distance_crossing(position, velocity, fall, rim - radius, outward=True)
        return (delay, 0) if math.isfinite(delay) else (math.inf, -1)
    a = float(velocity @ velocity)
    if a == 0.0:
        return math.inf, -1
    reach = rim - radius
    roots = np.roots([a, 2.0 * float(position @ velocity), float(position @ position) - reach**2])
    return max(float(np.max(roots.real)), 0.0), 0


def circle_drift_reflecting(
    position: FloatArray, velocity: FloatArray, radius: FloatArray, rim: float, dt: float
) -> int:
    """Twin of `vessels.circle.drift_reflecting`: each disk flies to the rim (`circle_wall_delay`),
    has the normal component of its velocity reversed there, and flies on; in place. Returns the
    bounces."""
    bounces = 0
    for i in range(len(position)):
        left = dt
        while True:
            delay, _ = circle_wall_delay(position[i], velocity[i], radius[i], rim)
            if delay >= left:
                position[i] += velocity[i] * left
                break
            position[i] += velocity[i] * delay
            normal = position[i] / np.linalg.norm(position[i])
            velocity[i] -= 2.0 * (velocity[i] @ normal) * normal
            left -= delay
            bounces += 1
    return bounces


_MASK64 = (1 << 64) - 1


def _mix64(z: int) -> int:
    """SplitMix64's finaliser on Python integers (twin of `wall_responses._mix`)."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK64
    return z ^ (z >> 31)


def wall_uniform(key: int, particle: int, hit: int, draw: int) -> float:
    """Twin of `wall_responses.uniform` in exact integer arithmetic."""
    golden = 0x9E3779B97F4A7C15
    z = _mix64((key + golden * (particle + 1)) & _MASK64)
    z = _mix64((z + golden * (hit + 1)) & _MASK64)
    z = _mix64((z + golden * (draw + 1)) & _MASK64)
    return ((z >> 11) + 1) * 2.0**-53


def wall_respond(
    table: FloatArray, wall: int, outward: float, along: float, mass: float, particle: int, hit: int
) -> tuple[float, float]:
    """Twin of `wall_responses.respond`: mirror, restitution, or thermal re-emission (flux
    Maxwell normal speed by inversion, Box-Muller tangential velocity)."""
    code, parameter, key = table[wall]
    if code == 1:
        return -parameter * outward, along
    if code == 2:
        u = [wall_uniform(int(key), particle, hit, draw) for draw in range(3)]
        normal = math.sqrt(-2.0 * parameter / mass * math.log(u[0]))
        slide = math.sqrt(parameter / mass) * math.sqrt(-2.0 * math.log(u[1]))
        return -normal, slide * math.cos(2.0 * math.pi * u[2])
    return -outward, along


def _next_contact(
    position: FloatArray, velocity: FloatArray, radius: FloatArray, size: FloatArray, periodic: bool
) -> tuple[float, int, int]:
    """Earliest pair contact over all pairs i < j (and the 9 nearest images): (delay, i, j)."""
    n = len(position)
    base = position[None, :, :] - position[:, None, :]  # x_j - x_i
    shifts = [np.zeros(2)]
    if periodic:
        base -= size * np.round(base / size)
        shifts = [size * np.array([a, b]) for a in (-1, 0, 1) for b in (-1, 0, 1)]
    dv = velocity[None, :, :] - velocity[:, None, :]
    a = np.einsum("ijk,ijk->ij", dv, dv)
    sigma2 = (radius[:, None] + radius[None, :]) ** 2
    takes_part = np.triu(np.ones((n, n), dtype=bool), 1) & (radius[:, None] > 0) & (radius > 0)
    best, pair = math.inf, (-1, -1)
    for shift in shifts:
        dx = base + shift
        b = np.einsum("ijk,ijk->ij", dx, dv)
        disc = b * b - a * (np.einsum("ijk,ijk->ij", dx, dx) - sigma2)
        hits = takes_part & (b < 0) & (disc > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            delay = np.where(hits, np.maximum((-b - np.sqrt(disc)) / a, 0.0), np.inf)
        if n > 1 and delay.min() < best:
            i, j = np.unravel_index(np.argmin(delay), delay.shape)
            best, pair = float(delay[i, j]), (int(i), int(j))
    return best, pair[0], pair[1]


def drift_reflecting(
    position: FloatArray,
    velocity: FloatArray,
    radius: FloatArray,
    mass: FloatArray,
    half: FloatArray,
    dt: float,
) -> tuple[np.ndarray, FloatArray]:
    """Twin of `vessels.box.drift_reflecting`: straight drift, then bounce-by-bounce folding per
    coordinate. Updates position and velocity (N, 2) in place; returns hits per wall
    (left, right, bottom, top) and the momentum each wall received."""
    hits = np.zeros(4, dtype=np.int64)
    impulse = np.zeros(4)
    for i in range(len(position)):
        for d in range(2):
            lo, hi = radius[i] - half[d], half[d] - radius[i]
            x = position[i, d] + velocity[i, d] * dt
            v = velocity[i, d]
            while x < lo or x > hi:
                wall = 2 * d + (1 if x > hi else 0)
                hits[wall] += 1
                impulse[wall] += 2 * mass[i] * abs(v)
                x, v = (2 * lo - x, -v) if x < lo else (2 * hi - x, -v)
            position[i, d], velocity[i, d] = x, v
    return hits, impulse


def drift_periodic(
    position: FloatArray, velocity: FloatArray, image: np.ndarray, size: FloatArray, dt: float
) -> None:
    """Twin of `vessels.box.drift_periodic`: drift, wrap into ``[-L/2, L/2)``, count the images."""
    moved = position + velocity * dt
    shift = np.floor((moved + size / 2) / size)
    position[...] = moved - shift * size
    image += shift.astype(np.int64)


def place_disks(
    candidates: FloatArray, radius: FloatArray, position: FloatArray, placed: int
) -> int:
    """Twin of `placement.place_disks` without a grid: accept, in order, each candidate that
    overlaps none of the disks placed so far. Fills ``position`` (N, 2); returns the count."""
    for x in candidates:
        if placed == len(position):
            break
        gaps = np.linalg.norm(position[:placed] - x, axis=1)
        if np.all(gaps >= radius[:placed] + radius[placed]):
            position[placed] = x
            placed += 1
    return placed


def first_past_face(
    position: FloatArray, radius: FloatArray, axis: int, sign: float, face: float, allowance: float
) -> int:
    """Twin of `audit.first_past_face`: the first disk with ``sign (x[axis] - face) + r`` above
    the allowance, or -1."""
    past = np.flatnonzero(sign * (position[:, axis] - face) + radius > allowance)
    return int(past[0]) if past.size else -1


def first_invalid(
    position: FloatArray,
    velocity: FloatArray,
    radius: FloatArray,
    shape: int,
    limit_x: float,
    limit_y: float,
    slack: float,
    periodic: bool,
    table: FloatArray,
) -> tuple[int, int]:
    """Twin of `audit.first_invalid`: (index, 1) for a non-finite value, (index, 2) for a particle
    outside the vessel (a box of half sides ``limit_x, limit_y``, or a circle of radius
    ``limit_x``, or outside the polygon the boundary rows of ``table`` make, or closer than its
    radius less ``slack`` to a segment), whichever index comes first; (-1, 0) if none."""
    finite = np.asarray(np.isfinite(position).all(axis=1) & np.isfinite(velocity).all(axis=1))
    reach = 0.0 if periodic else radius
    if shape == CIRCLE:
        inside = np.hypot(position[:, 0], position[:, 1]) + reach <= limit_x
    elif shape == BOX:
        inside = (np.abs(position) + np.asarray(reach)[..., None] <= [limit_x, limit_y]).all(axis=1)
    else:
        inside = np.ones(len(position), dtype=bool)
    edges = table[table[:, segments.BOUNDARY] == 1.0]
    for k in np.flatnonzero(finite) if len(table) else []:
        point = position[k]
        gap = min(np.linalg.norm(point - _nearest_on_segment(point, row)) for row in table)
        if gap < radius[k] - slack or (
            gap > slack and len(edges) and not _winds_around(point, edges)
        ):
            inside[k] = False
    bad = np.flatnonzero(~finite | ~inside)
    if bad.size == 0:
        return -1, 0
    i = int(bad[0])
    return i, 1 if not finite[i] else 2


def _winds_around(point: FloatArray, edges: FloatArray) -> bool:
    """Whether the closed chain of edges winds around ``point`` (its winding number is not 0):
    the sum of the angles the edges subtend there."""
    start = edges[:, [segments.X0, segments.Y0]] - point
    end = edges[:, [segments.X1, segments.Y1]] - point
    angles = np.arctan2(start[:, 0] * end[:, 1] - start[:, 1] * end[:, 0], (start * end).sum(1))
    return bool(abs(angles.sum()) > math.pi)


def inverse_distance_tree(
    position: FloatArray,
    charge: FloatArray,
    k: float,
    softening2: float,
    theta: float,
    leaf_size: int,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Twin of `tree.inverse_distance_tree`: forces (N, 2), half pair energies (N,) and half pair
    virials (N,) by the same Barnes-Hut quadtree (same Morton cells, leaves, node radii and opening
    test), with each accepted node's order-4 Taylor expansion written out from its particles:
    ``sum_n sum_k (-1)^n / (2^k k! (n-2k)!) D_(n-k)(R) sum_j q_j |d_j|^2k (d_j . R)^(n-2k)``,
    ``D_m = 2^m g^(m)`` for the kernel g of each output."""
    n = len(position)
    force, energy, virial = np.zeros((n, 2)), np.zeros(n), np.zeros(n)
    if n == 0:
        return force, energy, virial
    bits = 21
    lo = position.min(axis=0)
    side = float(np.max(position.max(axis=0) - lo))
    side = side if side > 0 else 1.0
    cell = np.clip(((position - lo) * ((1 << bits) / side)).astype(np.int64), 0, (1 << bits) - 1)
    code = np.zeros(n, dtype=np.int64)
    for b in range(bits):
        code |= ((cell[:, 0] >> b) & 1) << (2 * b) | ((cell[:, 1] >> b) & 1) << (2 * b + 1)
    order = np.argsort(code, kind="stable")

    def build(members: np.ndarray) -> dict:
        """Node of the smallest quadtree cell holding ``members`` (Morton-sorted indices)."""
        level = bits - (int(code[members[0]] ^ code[members[-1]]).bit_length() + 1) // 2
        size = side / (1 << level)
        centre = lo + ((cell[members[0]] >> (bits - level)) + 0.5) * size
        node = {"members": members, "centre": centre, "children": []}
        if len(members) <= leaf_size or level == bits:
            node["radius"] = np.sqrt(np.max(np.sum((position[members] - centre) ** 2, axis=1)))
            return node
        digit = (code[members] >> (2 * (bits - level - 1))) & 3
        node["children"] = [build(members[digit == d]) for d in range(4) if np.any(digit == d)]
        offsets = [c["centre"] - centre for c in node["children"]]
        reach = max(
            math.sqrt(o[0] * o[0] + o[1] * o[1]) + c["radius"]
            for o, c in zip(offsets, node["children"], strict=True)
        )
        node["radius"] = min(reach, math.sqrt(2.0) * 0.5 * size)
        return node

    def leaves(node: dict) -> list[dict]:
        return [node] if not node["children"] else [g for c in node["children"] for g in leaves(c)]

    root = build(order)
    for group in leaves(root):
        targets = group["members"]
        box_lo, box_hi = position[targets].min(axis=0), position[targets].max(axis=0)
        near_members, far = [], []
        pending = [root]
        while pending:
            node = pending.pop()
            if not np.any(charge[node["members"]] != 0):
                continue
            gap = np.maximum(np.maximum(box_lo - node["centre"], 0.0), node["centre"] - box_hi)
            if node["radius"] ** 2 < theta**2 * np.sum(gap**2):
                far.append(node)
            elif node["children"]:
                pending.extend(node["children"])
            else:
                near_members.extend(node["members"])
        near = np.array([j for j in near_members if charge[j] != 0], dtype=np.int64)
        field, phi, w = np.zeros((len(targets), 2)), np.zeros(len(targets)), np.zeros(len(targets))
        for t, i in enumerate(targets):
            sources = near[near != i]
            d = position[i] - position[sources]
            r2 = np.sum(d**2, axis=1)
            inv = 1.0 / np.sqrt(r2 + softening2)
            field[t] = np.sum((charge[sources] * inv**3)[:, None] * d, axis=0)
            phi[t] = np.sum(charge[sources] * inv)
            w[t] = np.sum(charge[sources] * inv**3 * r2)
        for node in far:
            f, p, v = _expansion(position[targets] - node["centre"], node, position, charge,
                                 softening2)  # fmt: skip
            field, phi, w = field + f, phi + p, w + v
        charged = charge[targets] != 0  # neutral targets keep exact zeros, as in the direct sum
        kq = k * charge[targets[charged]]
        force[targets[charged]] = kq[:, None] * field[charged]
        energy[targets[charged]] = 0.5 * kq * phi[charged]
        virial[targets[charged]] = 0.5 * kq * w[charged]
    return force, energy, virial


def _expansion(
    r: FloatArray, node: dict, position: FloatArray, charge: FloatArray, softening2: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Order-4 expansion about a node's centre at the targets' offsets ``r`` (M, 2): field
    ``-grad Phi`` (M, 2), potential ``Phi`` (M,) and virial sum (M,), per unit charge. With
    ``g(s) = (s + eps^2)^(-1/2)``, ``D_m = 2^m g^(m) = (-1)^m (2m-1)!! h^(2m+1)``; the virial
    kernel ``s (s+eps^2)^(-3/2)`` is ``g + 2 eps^2 g'``, whose ``D_m`` is ``D_m + eps^2 D_m+1``."""
    d = position[node["members"]] - node["centre"]
    q = charge[node["members"]]
    h = 1.0 / np.sqrt(np.sum(r**2, axis=1) + softening2)

    def big_d(m: int) -> FloatArray:
        return (-1) ** m * math.prod(range(1, 2 * m, 2)) * h ** (2 * m + 1)

    field, phi, w = np.zeros_like(r), np.zeros(len(r)), np.zeros(len(r))
    projection = r @ d.T  # (M, members): d_j . R
    for order in range(5):
        for traces in range(order // 2 + 1):
            rank = order - 2 * traces
            c = (-1) ** order / (2**traces * math.factorial(traces) * math.factorial(rank))
            weight = q * np.sum(d**2, axis=1) ** traces
            t = (weight * projection**rank).sum(axis=1)
            grad_t = rank * ((weight * projection ** max(rank - 1, 0)) @ d)
            m = order - traces
            phi += c * big_d(m) * t
            w += c * (big_d(m) + softening2 * big_d(m + 1)) * t
            field -= c * ((big_d(m + 1) * t)[:, None] * r + big_d(m)[:, None] * grad_t)
    return field, phi, w


def first_contact(gap: float, rate: float, pull: float) -> float:
    """Twin of `parabolas.first_contact`: the least root t >= 0 of
    ``gap + rate t + pull t^2 / 2`` at which the gap is closing (a touch, later on, counts; at
    t = 0 a gap that only starts to open does not), by `numpy.roots`; inf if none."""
    gap = max(gap, 0.0)
    if pull == 0.0:  # a straight path: one division (np.roots overflows for tiny rates)
        with np.errstate(over="ignore"):  # a tiny rate: inf, as the kernel gives
            return gap / -rate if rate < 0.0 else math.inf
    roots = np.roots([0.5 * pull, rate, gap])
    closing = []
    for root in np.atleast_1d(roots):
        t = float(root.real)
        if abs(root.imag) > 1e-12 * max(1.0, abs(t)) or t < 0.0:
            continue
        slope = rate + pull * t
        if slope < 0.0 or (slope == 0.0 and (t > 0.0 or pull < 0.0)):
            closing.append(t)
    return min(closing, default=math.inf)


def distance_crossing(
    position: FloatArray, velocity: FloatArray, fall: FloatArray, reach: float, outward: bool
) -> float:
    """Twin of `parabolas.distance_crossing` (no horizon): the least root t >= 0 of the quartic
    ``|p + v t + g t^2 / 2|^2 - reach^2`` at which the distance crosses ``reach`` outwards (or
    inwards), by `numpy.roots`; 0 for a body already across and moving on across; inf if none."""
    p, v, g = (np.asarray(a, dtype=float) for a in (position, velocity, fall))
    sense = 1.0 if outward else -1.0
    if sense * (np.linalg.norm(p) - reach) >= 0 and sense * (p @ v) > 0:
        return 0.0
    quartic = [g @ g / 4, v @ g, v @ v + p @ g, 2 * p @ v, p @ p - reach**2]
    crossings = []
    for root in np.roots(quartic):
        t = float(root.real)
        x, u = p + v * t + 0.5 * g * t * t, v + g * t
        if abs(root.imag) <= 1e-9 * max(1.0, abs(t)) and t >= 0 and sense * (x @ u) > 0:
            crossings.append(t)
    return min(crossings, default=math.inf)


def moving_wall(
    outward: float, wall: float, mass: float, wall_mass: float, restitution: float
) -> tuple[float, float]:
    """Twin of `wall_responses.moving_wall`, in the centre-of-mass frame: each normal velocity
    relative to the centre of mass is reversed and scaled by e (the wall's own frame when it is
    driven, of infinite mass)."""
    if math.isinf(wall_mass):
        return wall - restitution * (outward - wall), wall
    centre = (mass * outward + wall_mass * wall) / (mass + wall_mass)
    return centre - restitution * (outward - centre), centre - restitution * (wall - centre)


def piston_drift(
    position: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    half: FloatArray,
    duration: float,
    wall: int,
    piston: dict[str, float],
) -> tuple[int, int, FloatArray, float]:
    """Event-driven hard disks in a box of half sides ``half`` (m) whose wall ``wall`` (0 left,
    1 right, 2 bottom, 3 top) is a piston, all pairs checked at every event.

    ``piston`` holds ``height`` and ``speed`` along the outward normal (m, m/s; updated in
    place), ``pull`` (m/s^2), ``mass`` (kg, inf when driven), ``restitution``, ``low`` and
    ``high`` (the ends of its travel, m) and ``driven`` (1: it stops at an end; 0: bounces).
    Positions and velocities (N, 2) are updated in place. Returns (pair collisions, wall hits,
    momentum received by each of the four walls, work done by the piston on the disks).
    """
    axis, sign = wall // 2, (1.0 if wall % 2 == 1 else -1.0)
    now, pairs, hits, work = 0.0, 0, 0, 0.0
    impulse = np.zeros(4)
    p = piston

    def piston_at(t: float) -> tuple[float, float]:
        return p["height"] + p["speed"] * t + 0.5 * p["pull"] * t * t, p["speed"] + p["pull"] * t

    while True:
        t_pair, i, j = _next_contact(position, velocity, radius, 2 * half, False)
        with np.errstate(divide="ignore", invalid="ignore"):
            target = np.where(velocity > 0, half - radius[:, None], radius[:, None] - half)
            delays = np.where(velocity != 0, np.maximum((target - position) / velocity, 0), np.inf)
        towards = 2 * np.arange(2)[None, :] + (velocity > 0)
        delays[towards == wall] = np.inf  # the piston's wall is where the piston is
        k, d = np.unravel_index(np.argmin(delays), delays.shape)
        t_wall = float(delays[k, d])
        gaps = [p["height"] - sign * position[q, axis] - radius[q] for q in range(len(radius))]
        t_disks = [
            first_contact(g, p["speed"] - sign * velocity[q, axis], p["pull"])
            for q, g in enumerate(gaps)
        ]
        q = int(np.argmin(t_disks)) if t_disks else -1
        t_piston = t_disks[q] if t_disks else math.inf
        t_end = min(
            first_contact(p["high"] - p["height"], -p["speed"], -p["pull"]),
            first_contact(p["height"] - p["low"], p["speed"], p["pull"]),
        )
        best = min(t_pair, t_wall, t_piston, t_end)
        if now + best > duration:
            left = duration - now
            position += velocity * left
            p["height"], p["speed"] = piston_at(left)
            return pairs, hits, impulse, work
        position += velocity * best
        now += best
        p["height"], p["speed"] = piston_at(best)
        if t_end == best:
            upper = abs(p["height"] - p["high"]) <= abs(p["height"] - p["low"])
            p["height"] = p["high"] if upper else p["low"]
            p["speed"] = 0.0 if p["driven"] else -p["speed"]
        elif t_wall == best:
            impulse[2 * d + int(velocity[k, d] > 0)] += 2 * mass[k] * abs(velocity[k, d])
            velocity[k, d] = -velocity[k, d]
            hits += 1
        elif t_piston == best:
            outward = sign * velocity[q, axis]
            after, p["speed"] = moving_wall(outward, p["speed"], mass[q], p["mass"],
                                            p["restitution"])  # fmt: skip
            impulse[wall] += mass[q] * (outward - after)
            work += 0.5 * mass[q] * (after * after - outward * outward)
            velocity[q, axis] = sign * after
            hits += 1
        else:
            sep = position[i] - position[j]
            velocity[i], velocity[j] = pair_response(
                mass[i], mass[j], sep, np.zeros(2), velocity[i], velocity[j]
            )
            pairs += 1


def smooth_substeps(
    position: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    source: FloatArray,
    coupling: float,
    softening2: float,
    uniform: FloatArray,
    fall: FloatArray,
    turn: FloatArray,
    region: FloatArray,
    damp: FloatArray,
    shape: int,
    half: FloatArray,
    rim: float,
    table: FloatArray,
    now: float,
    dt: float,
    first: int,
    count: int,
    t: float,
    fastest: float,
    total: float,
    energy_floor: float,
    margin: float,
    tolerance: float = math.inf,
    most: int = 2**30,
) -> tuple[int, float, float, float]:
    """Twin of `substeps.smooth_substeps` in a box of half sides ``half`` (``shape`` `BOX`), a
    circle of radius ``rim`` (`CIRCLE`) or neither, and against the segments of ``table``.

    Each substep: the velocity forces' flow (`flowed`) and the kick (with the carried
    ``fall``, if any); the contact test on all pairs and walls at once (contacts within
    ``margin`` of a radius, or of the substep); the straight flight; the force
    (`inverse_distance_direct` and the ``uniform`` field's, unless carried); the kick and the
    flow; at every `rate_stride` substeps and the last, the squared rate from the ``total``
    energy (`squared_rate`), which stops the substeps once it needs more than ``count``
    (`needed`; never with an infinite ``tolerance``, which reads it at every substep). Updates
    the motion in place and returns ``(substep not taken, its start, fastest, energy the drag
    gave)``.
    """
    zero = np.zeros(2)
    stride = rate_stride(tolerance)
    given = 0.0
    carried = fall if fall.size else zero
    if fastest < 0.0:
        fastest = squared_rate(position, velocity, mass, source, coupling, softening2, turn,
                               damp, total, energy_floor)  # fmt: skip
    for s in range(first, count + 1):
        end = now + dt * s / count
        h = end - t
        flowed_in, before = flowed(position, velocity, mass, turn, region, damp, 0.5 * h)
        kicked = flowed_in + 0.5 * h * (acceleration + carried)
        wide = radius * (1.0 + margin)
        wall = math.inf
        if shape == CIRCLE:
            wall = _next_rim(position, kicked, wide, rim, zero)[0]
        elif shape == BOX:
            wall = _next_wall(position, kicked, wide, half)[0]
        wall = min(wall, _next_segment(position, kicked, wide, table, zero)[0])
        d = position[None, :, :] - position[:, None, :]  # x_j - x_i
        w = kicked[None, :, :] - kicked[:, None, :]
        w2 = np.einsum("ijk,ijk->ij", w, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            along = np.clip(-np.einsum("ijk,ijk->ij", d, w) / w2, 0.0, h * (1.0 + margin))
        closest = d + w * np.nan_to_num(along)[:, :, None]
        sigma = (radius[:, None] + radius[None, :]) * (1.0 + margin)
        meets = (np.einsum("ijk,ijk->ij", closest, closest) <= sigma**2) & (sigma > 0)
        if not np.isfinite(kicked).all() or wall <= h * (1.0 + margin) or np.triu(meets, 1).any():
            return s, t, fastest, given
        flown = position + kicked * h
        force = inverse_distance_direct(flown, source, coupling, softening2)[0]
        pull = (force + uniform if uniform.size and not fall.size else force) / mass[:, None]
        if not np.isfinite(pull).all():
            return s, t, fastest, given
        position[...] = flown
        velocity[...], after = flowed(flown, kicked + 0.5 * h * (pull + carried), mass, turn,
                                      region, damp, 0.5 * h)  # fmt: skip
        acceleration[...] = pull
        given += before + after
        t = end
        if s % stride == 0 or s == count:
            rate2 = squared_rate(position, velocity, mass, source, coupling, softening2, turn,
                                 damp, total + given, energy_floor)  # fmt: skip
            fastest = max(fastest, rate2)
            if needed(fastest, dt, tolerance, most) > count:
                break
    return count + 1, t, fastest, given


def rate_stride(tolerance: float) -> int:
    """Twin of `substeps.rate_stride`: the largest power of two n with ``n tolerance <=
    RATE_SPACING``, at least 1."""
    ratio = RATE_SPACING / tolerance
    return 1 if ratio < 2.0 else 2 ** math.floor(math.log2(ratio))


def flowed(
    position: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    turn: FloatArray,
    region: FloatArray,
    damp: FloatArray,
    lag: float,
) -> tuple[FloatArray, float]:
    """Twin of the substeps' velocity flows: the velocities (N, 2) damped by ``exp(-damp lag)``
    and, inside ``region`` (left, bottom, right, top), turned by ``-turn lag`` (a new array),
    and the kinetic energy that gave (J)."""
    factor = np.exp(-damp * lag) if damp.size else np.ones(len(velocity))
    damped = velocity * factor[:, None]
    given = 0.5 * float(np.sum(mass * np.sum(velocity**2, axis=1) * (factor**2 - 1.0)))
    if turn.size == 0:
        return damped, given
    x, y = position[:, 0], position[:, 1]
    inside = (x >= region[0]) & (x <= region[2]) & (y >= region[1]) & (y <= region[3])
    angle = np.where(inside, -turn * lag, 0.0)
    cos, sin = np.cos(angle), np.sin(angle)
    vx, vy = damped[:, 0], damped[:, 1]
    return np.stack([cos * vx - sin * vy, sin * vx + cos * vy], axis=1), given


def squared_rate(
    position: FloatArray,
    velocity: FloatArray,
    mass: FloatArray,
    source: FloatArray,
    coupling: float,
    softening2: float,
    turn: FloatArray,
    damp: FloatArray,
    total: float,
    energy_floor: float,
) -> float:
    """Twin of the substeps' rate: the square root of the stiffness
    (`inverse_distance_stiffness`) over the energy scale, ``|E|`` (``total``) but at least
    ``(KE + |U|) / energy_floor`` with ``U = E - KE``; or the fastest rate of the velocity
    forces (cyclotron frequencies ``turn``, damping rates ``damp``) squared, if larger."""
    stiffness = inverse_distance_stiffness(position, velocity, source, mass, coupling, softening2)
    kinetic = 0.5 * float(np.sum(mass * np.sum(velocity**2, axis=1)))
    scale = max(abs(total), (kinetic + abs(total - kinetic)) / energy_floor)
    energy = math.sqrt(stiffness) / scale if scale > 0.0 else 0.0
    rates = np.concatenate([np.abs(turn), damp])
    return max(energy, float(np.max(rates, initial=0.0)) ** 2)


def needed(rate2: float, dt: float, tolerance: float, most: int) -> int:
    """Twin of `substeps.needed`: the smallest power of two n >= ``dt sqrt(rate2) /
    tolerance``, at most ``most``."""
    ratio = dt * math.sqrt(rate2) / tolerance
    if not ratio <= most:
        return most
    return 1 if ratio <= 1.0 else 2 ** math.ceil(math.log2(ratio))


def smooth_intervals(
    position: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    mass: FloatArray,
    radius: FloatArray,
    source: FloatArray,
    coupling: float,
    softening2: float,
    uniform: FloatArray,
    fall: FloatArray,
    turn: FloatArray,
    region: FloatArray,
    damp: FloatArray,
    shape: int,
    half: FloatArray,
    rim: float,
    table: FloatArray,
    origin: float,
    elapsed: int,
    dt: float,
    count: int,
    substeps: int,
    tolerance: float,
    most: int,
    energy_floor: float,
    given: float,
    margin: float,
    substep: float = math.nan,
    keep: bool = False,
) -> tuple[int, int, FloatArray, float]:
    """Twin of `substeps.smooth_intervals`: interval by interval, the substep count from the
    rate at its start (`needed`), the modified energy kept where the substep changes from the
    last (``substep`` s before the first, NaN for none) if ``keep`` (`modified_energy_keep`),
    `smooth_substeps` from its first substep, taken again with more substeps while a boundary
    needs more; the first interval that meets a contact is put back as it began. Returns
    ``(intervals taken, the next count, the record of each: kinetic and potential energy, pair
    virial, momentum x and y, total speed, the energy the drag has given since ``given`` J
    before the first; the last interval's substep, s)``."""
    record: list[tuple[float, ...]] = []

    def energies() -> tuple[float, float, float]:
        moving = 0.5 * float(np.sum(mass * np.sum(velocity**2, axis=1)))
        _, energy, virial = inverse_distance_direct(position, source, coupling, softening2)
        field = -float(np.sum(position * uniform)) if uniform.size else 0.0
        return moving, float(energy.sum()) + field, float(virial.sum())

    def table_row() -> tuple[float, ...]:
        px, py = mass @ velocity
        speeds = float(np.sum(np.hypot(velocity[:, 0], velocity[:, 1])))
        return (*energies(), float(px), float(py), speeds, given)

    for k in range(count):
        now = origin + (elapsed + k) * dt
        total = sum(energies()[:2])
        rate2 = squared_rate(position, velocity, mass, source, coupling, softening2, turn, damp,
                             total, energy_floor)  # fmt: skip
        if not dt * math.sqrt(rate2) <= most * tolerance:
            return k, substeps, np.array(record).reshape(-1, 7), substep
        taken = max(substeps, needed(rate2, dt, tolerance, most))
        start = [a.copy() for a in (position, velocity, acceleration)]
        while True:
            if keep and not math.isnan(substep) and dt / taken != substep:
                laws = (source[None, :], np.array([coupling]), np.array([softening2]))
                modified_energy_keep(
                    position, velocity, acceleration, mass, laws, (substep, dt / taken), tolerance
                )
            reached, _, fastest, drag = smooth_substeps(
                position, velocity, acceleration, mass, radius, source, coupling, softening2,
                uniform, fall, turn, region, damp, shape, half, rim, table, now, dt, 1, taken,
                now, rate2, total, energy_floor, margin, tolerance, most,
            )  # fmt: skip
            met = reached <= taken
            required = needed(fastest, dt, tolerance, most)
            if met or required > taken:
                for array, kept in zip((position, velocity, acceleration), start, strict=True):
                    array[...] = kept
            if met:
                return k, substeps, np.array(record).reshape(-1, 7), substep
            if required <= taken:
                break
            taken = max(required, 2 * taken)
        substeps = max(1, taken // 2) if required <= taken // 2 else taken
        substep = dt / taken
        given += drag
        record.append(table_row())
    return count, substeps, np.array(record).reshape(-1, 7), substep
