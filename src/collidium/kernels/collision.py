"""Collision of two disks (seed eq. 7), for any masses: elastic, or inelastic with a normal
restitution coefficient (granular matter)."""

from __future__ import annotations

import math

from collidium.kernels.compilation import inlined


@inlined
def pair_response(
    m1: float,
    m2: float,
    nx: float,
    ny: float,
    v1x: float,
    v1y: float,
    v2x: float,
    v2y: float,
    restitution: float,
    elastic_below: float,
) -> tuple[float, float, float, float]:
    """Post-collision velocities of two disks in contact.

    Parameters
    ----------
    m1, m2 : float
        Masses in kg.
    nx, ny : float
        Line of centres ``x1 - x2`` in m (need not be normalised).
    v1x, v1y, v2x, v2y : float
        Velocities before the collision in m/s.
    restitution : float
        Normal restitution coefficient e in (0, 1]: the normal relative velocity is reversed and
        scaled by e (1: elastic).
    elastic_below : float
        Normal approach speed (m/s) below which the collision is elastic whatever e: the guard
        against inelastic collapse (infinitely many collisions in a finite time).

    Returns
    -------
    tuple of float
        ``(v1x', v1y', v2x', v2y')``: momentum is conserved; only the component along the line
        of centres changes; the kinetic energy drops by ``(1 - e^2) mu g_n^2 / 2`` (``mu`` the
        reduced mass, ``g_n`` the normal approach speed), nothing when elastic.
    """
    n2 = nx * nx + ny * ny
    along = ((v1x - v2x) * nx + (v1y - v2y) * ny) / n2
    total = m1 + m2
    bounce = bounce_factor(along, n2, restitution, elastic_below)
    f1 = bounce * m2 / total * along
    f2 = bounce * m1 / total * along
    return v1x - f1 * nx, v1y - f1 * ny, v2x + f2 * nx, v2y + f2 * ny


@inlined
def bounce_factor(along: float, n2: float, restitution: float, elastic_below: float) -> float:
    """``1 + e`` of a collision whose normal relative velocity is ``along`` times the line of
    centres of squared length ``n2`` (m^2): the normal relative velocity changes by that factor
    times itself, 2 when elastic (`pair_response`)."""
    if restitution != 1.0 and -along * math.sqrt(n2) > elastic_below:
        return 1.0 + restitution
    return 2.0


@inlined
def energy_change(m1, m2, u1x, u1y, u2x, u2y, v1x, v1y, v2x, v2y) -> float:
    """Kinetic energy (J) two disks of masses m1, m2 (kg) gain when their velocities go from
    u1, u2 to v1, v2 (m/s): what an inelastic collision takes, negative."""
    before = m1 * (u1x * u1x + u1y * u1y) + m2 * (u2x * u2x + u2y * u2y)
    after = m1 * (v1x * v1x + v1y * v1y) + m2 * (v2x * v2x + v2y * v2y)
    return 0.5 * (after - before)
