"""A uniform magnetic field normal to the plane: `MagneticField`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.forces.base import check_finite, check_rectangle, register
from collidium.state import Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class MagneticField:
    """A uniform magnetic field ``B`` along z, out of the plane: the Lorentz force
    ``F_i = q_i v_i x B`` turns each charge's velocity at the cyclotron frequency
    ``omega_i = q_i B / m_i`` (clockwise for ``q B > 0``) and does no work.

    Its flow is applied as a rotation of the velocities (the Boris push's rotation), so a
    speed is kept to round-off whatever the substep; a free charge circles with radius
    ``m v / (|q| B)`` and period ``2 pi m / (|q| B)``, to O((omega h)^2) with substeps h.

    Parameters
    ----------
    B : float
        The field in T (N s / (C m)); positive out of the plane.
    region : pair of (x, y), optional
        The lower-left and upper-right corners (m) of the rectangle the field fills (the whole
        plane by default), as between the poles of a mass spectrometer's magnet. A charge is in
        it or not at the ends of each substep, so an edge is crossed to O(omega h).
    """

    name: ClassVar[str] = "magnetic_field"

    B: float
    region: tuple[tuple[float, float], tuple[float, float]] | None = None

    def __post_init__(self) -> None:
        check_finite(self.name, "B", self.B)
        if self.region is not None:
            object.__setattr__(self, "region", check_rectangle(self.name, "region", self.region))

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def cyclotron(self, particles: Particles) -> np.ndarray:
        """Each particle's signed cyclotron frequency ``q B / m`` (N,), rad/s, inside the
        `region` (`collidium.forces.base.TurningForce`)."""
        return np.asarray(particles.charge * self.B / particles.mass)

    def bounds(self) -> np.ndarray:
        """The `region` as ``(left, bottom, right, top)`` in m, infinite for the whole plane."""
        if self.region is None:
            return np.array([-np.inf, -np.inf, np.inf, np.inf])
        (left, bottom), (right, top) = self.region
        return np.array([left, bottom, right, top])

    def frequency(self, particles: Particles) -> np.ndarray:
        """Each particle's signed cyclotron frequency ``q B / m`` (N,), rad/s, where it is
        (0 outside the `region`)."""
        omega = self.cyclotron(particles)
        if self.region is None:
            return omega
        left, bottom, right, top = self.bounds()
        x, y = particles.position[:, 0], particles.position[:, 1]
        inside = (x >= left) & (x <= right) & (y >= bottom) & (y <= top)
        return np.where(inside, omega, 0.0)

    def advance(
        self, particles: Particles, vessel: Vessel, h: float, rng: np.random.Generator
    ) -> float:
        """Turn each velocity by ``-q B h / m`` (`collidium.forces.base.VelocityForce`); no
        energy is given."""
        angle = -self.frequency(particles) * h
        cos, sin = np.cos(angle), np.sin(angle)
        v = particles.velocity
        vx = v[:, 0].copy()
        v[:, 0] = cos * vx - sin * v[:, 1]
        v[:, 1] = sin * vx + cos * v[:, 1]
        return 0.0

    def rate(self, particles: Particles, vessel: Vessel) -> float:
        """The fastest cyclotron frequency ``|q B| / m`` (inside the region or not), rad/s."""
        return float(np.max(np.abs(particles.charge * self.B / particles.mass), initial=0.0))

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file (the region omitted when it is the whole plane)."""
        region = {} if self.region is None else {"region": [list(c) for c in self.region]}
        return {"type": self.name, "B": self.B} | region
