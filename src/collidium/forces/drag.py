"""Drag of a surrounding fluid: linear (`LinearDrag`, Stokes) and quadratic (`QuadraticDrag`).

Both slow each particle along its velocity. Their flows are solved exactly and applied as a
factor on the speeds (`collidium.forces.velocity`); the energy they take is kept as heat.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.forces.base import check_at_least, register
from collidium.forces.velocity import damping_rate, scale_speeds, speeds
from collidium.state import Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class LinearDrag:
    """Linear (Stokes) drag ``F_i = -gamma v_i``: a speed decays as ``exp(-gamma t / m)``, and
    under gravity a particle reaches the terminal velocity ``m g / gamma``.

    Parameters
    ----------
    gamma : float
        The drag coefficient in kg/s (>= 0).
    """

    name: ClassVar[str] = "linear_drag"

    gamma: float

    def __post_init__(self) -> None:
        check_at_least(self.name, "gamma", self.gamma)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Scale each velocity by ``exp(-gamma h / m)``; returns the (negative) energy given."""
        return scale_speeds(particles, np.exp(-self.gamma * h / particles.mass))

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """``gamma / m`` of the lightest particle, 1/s."""
        return damping_rate(self.gamma, particles)

    def damping(self, particles: Particles) -> np.ndarray:
        """Each particle's ``gamma / m`` (N,), 1/s (`collidium.forces.base.DampingForce`)."""
        return np.asarray(self.gamma / particles.mass)

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        return {"type": self.name, "gamma": self.gamma}


@register
@dataclass(frozen=True)
class QuadraticDrag:
    """Quadratic drag ``F_i = -c |v_i| v_i`` (a fast body in air): a speed falls as
    ``s / (1 + c s t / m)``, and under gravity a particle reaches the terminal speed
    ``sqrt(m g / c)``.

    Parameters
    ----------
    c : float
        The drag coefficient in kg/m (>= 0; ``rho C_d A / 2`` of a body in a fluid).
    """

    name: ClassVar[str] = "quadratic_drag"

    c: float

    def __post_init__(self) -> None:
        check_at_least(self.name, "c", self.c)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Scale each velocity by ``1 / (1 + c s h / m)``; returns the (negative) energy given."""
        return scale_speeds(
            particles, 1.0 / (1.0 + self.c * speeds(particles) * h / particles.mass)
        )

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """The fastest ``c s / m``, 1/s."""
        return float(np.max(self.c * speeds(particles) / particles.mass, initial=0.0))

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        return {"type": self.name, "c": self.c}
