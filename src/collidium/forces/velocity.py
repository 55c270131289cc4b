"""What the velocity forces share: a velocity scaled along itself by a factor per particle.

Drag, friction and the thermostat change each particle's speed and not (apart from the
thermostat's noise) its direction. `scale_speeds` applies such a factor and returns the kinetic
energy it gave the particles, which the integrators keep as the forces' heat.
"""

from __future__ import annotations

import numpy as np

from collidium.state import FloatArray, Particles


def speeds(particles: Particles) -> FloatArray:
    """Each particle's speed (N,), m/s."""
    return np.hypot(particles.velocity[:, 0], particles.velocity[:, 1])


def damping_rate(gamma: float, particles: Particles) -> float:
    """``gamma / m`` of the lightest particle, 1/s: the fastest rate at which a drag
    coefficient ``gamma`` (kg/s) damps a velocity."""
    return float(gamma / np.min(particles.mass, initial=np.inf))


def scale_speeds(particles: Particles, factor: FloatArray) -> float:
    """Multiply each velocity by ``factor`` (N,) in place; returns the kinetic energy this gave
    the particles, J (negative: what it took)."""
    v = particles.velocity
    speed2 = np.einsum("ij,ij->i", v, v)
    v *= factor[:, None]
    return 0.5 * float(np.sum(particles.mass * speed2 * (factor * factor - 1.0)))
