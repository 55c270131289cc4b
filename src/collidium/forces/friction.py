"""Sliding (kinetic) friction on a table: `Friction`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.forces.base import check_at_least, register
from collidium.forces.velocity import scale_speeds, speeds
from collidium.state import Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class Friction:
    """Sliding friction of disks on a table (the plane seen from above): ``F_i = -mu m_i g``
    along the velocity, until the disk stops. A disk sliding at ``s`` stops after the
    distance ``s^2 / (2 mu g)``, in the time ``s / (mu g)``.

    The flow is exact (speeds fall by ``mu g h``, and stay at rest once there); a disk at rest
    stays there while the other forces on it are weaker than ``mu m g`` (the kick they give in
    half a substep is taken back).

    Parameters
    ----------
    mu : float
        The coefficient of sliding friction (>= 0).
    g : float
        The acceleration of free fall pressing the disks on the table, m/s^2 (>= 0).
    """

    name: ClassVar[str] = "friction"

    mu: float
    g: float = 9.81

    def __post_init__(self) -> None:
        check_at_least(self.name, "mu", self.mu)
        check_at_least(self.name, "g", self.g)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Lower each speed by ``mu g h`` (to 0 at most); returns the (negative) energy given."""
        speed = speeds(particles)
        slower = np.maximum(speed - self.mu * self.g * h, 0.0)
        factor = np.divide(slower, speed, out=np.zeros_like(speed), where=speed > 0.0)
        return scale_speeds(particles, factor)

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """0: the flow is exact whatever the substep."""
        return 0.0

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        return {"type": self.name, "mu": self.mu, "g": self.g}
