"""What a wall does to a disk that hits it, for every engine and every shape.

A vessel's walls are described by a table, one row per wall (`collidium.vessels.Vessel.wall_table`):
``[response code, parameter, key]``:

- `SPECULAR`: the normal velocity is reversed (parameter unused);
- `INELASTIC`: the normal velocity is reversed and multiplied by the restitution coefficient
  ``e`` in (0, 1] (the parameter);
- `THERMAL`: the disk is re-emitted with a fresh velocity from the wall's Maxwell flux
  distribution at temperature ``kT`` (the parameter, J): normal speed with density
  ``m v / kT exp(-m v^2 / 2 kT)``, tangential velocity normal with variance ``kT / m``;
- `PISTON`: a moving wall of mass M (`moving_wall`); the parameter is the restitution of its
  collisions. Its motion is the engine's (`collidium.kernels.vessels.piston`).

Random numbers for thermal walls come from a counter-based generator (SplitMix64) keyed by the
wall's key, the particle and the wall's hit count, so a run is the same whatever the engine's
order of work and resumes bit for bit from a checkpoint.
"""

from __future__ import annotations

import math

import numpy as np

from collidium.kernels.compilation import inlined

#: Response codes of the wall table.
SPECULAR, INELASTIC, THERMAL, PISTON = 0, 1, 2, 3

#: Columns of a wall table row.
RESPONSE, PARAMETER, KEY = range(3)
WALL_TABLE_COLUMNS = 3

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@inlined
def _mix(z: np.uint64) -> np.uint64:
    """SplitMix64's finaliser: a bijection of 64-bit words that scrambles every bit."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@inlined
def uniform(key: float, particle: int, hit: int, draw: int) -> float:
    """A uniform number in (0, 1], a function of its four arguments alone (``key`` a whole
    number below 2^53)."""
    z = _mix(np.uint64(key) + _GOLDEN * np.uint64(particle + 1))
    z = _mix(z + _GOLDEN * np.uint64(hit + 1))
    z = _mix(z + _GOLDEN * np.uint64(draw + 1))
    return (float(z >> np.uint64(11)) + 1.0) * 2.0**-53


@inlined
def respond(
    table: np.ndarray,
    wall: int,
    outward: float,
    along: float,
    mass: float,
    particle: int,
    hit: int,
) -> tuple[float, float]:
    """The velocity after a hit, in the wall's frame.

    Parameters
    ----------
    table : ndarray, shape (W, 3)
        The vessel's wall table.
    wall : int
        The wall hit.
    outward, along : float
        Velocity along the wall's outward normal (> 0: into the wall) and along the wall, m/s.
    mass : float
        The disk's mass, kg.
    particle, hit : int
        The particle and the wall's hit count before this hit (the thermal wall's random key).

    Returns
    -------
    tuple of float
        ``(outward, along)`` after the hit; ``outward < 0`` moves away from the wall.
    """
    code = table[wall, RESPONSE]
    if code == INELASTIC:
        return -table[wall, PARAMETER] * outward, along
    if code == THERMAL:
        kT = table[wall, PARAMETER]
        key = table[wall, KEY]
        normal = math.sqrt(-2.0 * kT / mass * math.log(uniform(key, particle, hit, 0)))
        radius = math.sqrt(-2.0 * math.log(uniform(key, particle, hit, 1)))
        angle = 2.0 * math.pi * uniform(key, particle, hit, 2)
        return -normal, math.sqrt(kT / mass) * radius * math.cos(angle)
    return -outward, along


@inlined
def bounce(
    table: np.ndarray,
    wall: int,
    vx: float,
    vy: float,
    nx: float,
    ny: float,
    mass: float,
    particle: int,
    hit: int,
) -> tuple[float, float, float, float]:
    """A hit on ``wall`` with outward unit normal (nx, ny) of a disk moving at (vx, vy) m/s:
    `respond` in the wall's frame. Returns the new velocity (m/s), the momentum the wall
    receives along its normal (kg m/s) and the energy it gives the disk (J)."""
    outward = vx * nx + vy * ny
    along = vy * nx - vx * ny  # along the tangent (-ny, nx)
    after, slide = respond(table, wall, outward, along, mass, particle, hit)
    wx = after * nx - slide * ny
    wy = after * ny + slide * nx
    heat = 0.5 * mass * ((wx * wx + wy * wy) - (vx * vx + vy * vy))
    return wx, wy, mass * abs(after - outward), heat


@inlined
def hit(table, wall, vx, vy, nx, ny, mass, particle, hits, impulse, heat, slot):
    """`bounce`, booked: counts the hit and adds the wall's impulse and heat at ``slot`` of
    ``hits``, ``impulse`` and ``heat`` (the wall's entry of the caller's tallies). Returns the
    new velocity (m/s)."""
    wx, wy, received, gained = bounce(table, wall, vx, vy, nx, ny, mass, particle, hits[slot])
    hits[slot] += 1
    impulse[slot] += received
    heat[slot] += gained
    return wx, wy


@inlined
def moving_wall(
    outward: float, wall: float, mass: float, wall_mass: float, restitution: float
) -> tuple[float, float]:
    """A disk meets a wall that moves along its normal (a piston): the normal velocities after.

    Parameters
    ----------
    outward, wall : float
        The disk's and the wall's velocity along the wall's outward normal, m/s (the disk
        approaches when ``outward > wall``).
    mass, wall_mass : float
        The disk's and the wall's mass, kg; an infinite ``wall_mass`` is a wall driven at a set
        velocity, which no hit changes.
    restitution : float
        The normal restitution e in (0, 1]: the relative normal velocity is reversed and scaled
        by e.

    Returns
    -------
    tuple of float
        ``(outward, wall)`` after the hit (m/s). Momentum is conserved for a finite wall mass.
    """
    approach = outward - wall
    if math.isinf(wall_mass):
        return outward - (1.0 + restitution) * approach, wall
    share = (1.0 + restitution) * approach / (mass + wall_mass)
    return outward - wall_mass * share, wall + mass * share
