"""The Langevin thermostat: `Langevin`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.forces.base import check_at_least, check_finite, register
from collidium.forces.velocity import damping_rate
from collidium.state import Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class Langevin:
    """A heat bath at temperature ``kT``: drag ``-gamma v_i`` and random kicks of strength
    ``sqrt(2 gamma kT)`` (fluctuation-dissipation), so that speeds settle to the
    Maxwell-Boltzmann distribution at ``kT`` with the time constant ``m / gamma``.

    The flow, an Ornstein-Uhlenbeck process, is drawn exactly
    (``v -> c v + sqrt((1 - c^2) kT / m) xi``, ``c = exp(-gamma h / m)``, ``xi`` standard
    normal from the simulation's generator); collisions stay exact in between. Both keep the
    Maxwell-Boltzmann distribution, so the thermostat samples it whatever the substep. The
    energy it gives and takes is kept as heat.

    Parameters
    ----------
    temperature : float
        kT of the bath in J (> 0; Boltzmann's constant is 1, as for thermal walls).
    gamma : float
        The friction coefficient in kg/s (>= 0).
    """

    name: ClassVar[str] = "langevin"

    temperature: float
    gamma: float = 1.0

    def __post_init__(self) -> None:
        check_finite(self.name, "temperature", self.temperature)
        if self.temperature <= 0.0:
            raise InputError(
                f"forces.{self.name}.temperature", f"must be > 0, got {self.temperature!r}"
            )
        check_at_least(self.name, "gamma", self.gamma)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Draw the velocities ``h`` seconds on; returns the energy the bath gave, J."""
        mass = particles.mass
        v = particles.velocity
        before = np.einsum("ij,ij->i", v, v)
        damping = np.exp(-self.gamma * h / mass)
        spread = np.sqrt((1.0 - damping * damping) * self.temperature / mass)
        v *= damping[:, None]
        v += spread[:, None] * rng.standard_normal(v.shape)
        return 0.5 * float(np.sum(mass * (np.einsum("ij,ij->i", v, v) - before)))

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """``gamma / m`` of the lightest particle, 1/s."""
        return damping_rate(self.gamma, particles)

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        return {"type": self.name, "temperature": self.temperature, "gamma": self.gamma}
