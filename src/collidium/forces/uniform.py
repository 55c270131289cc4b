"""What the uniform external fields share: a constant force ``F_i = s_i f`` on each particle,
``s_i`` its mass (`Gravity`) or its charge (`UniformField`).

The potential energy is ``U_i = -s_i f . x_i``, measured from the origin (the vessel's centre),
with the unwrapped position in a periodic vessel so that a particle crossing the period keeps
its energy. A uniform force has no pair virial, and leapfrog follows it exactly (its stiffness
is 0): under a uniform force alone the adaptive integrator takes one substep a step.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from collidium.forces.base import check_vector
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel


class UniformForce:
    """The behaviour of a uniform field, for a frozen dataclass whose one field, named
    `vector`, is the field (x, y) per unit of the particles' `source` ("mass" or "charge")."""

    name: ClassVar[str]
    vector: ClassVar[str]
    source: ClassVar[str]

    def __post_init__(self) -> None:
        field = check_vector(self.name, self.vector, getattr(self, self.vector))
        object.__setattr__(self, self.vector, field)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Any vessel will do."""

    def compute(
        self,
        particles: Particles,
        vessel: Vessel,
        force: FloatArray,
        energy: FloatArray,
        virial: FloatArray,
        work: dict[str, np.ndarray],
        energies: bool,
    ) -> None:
        """``s_i f`` on each particle, ``-s_i f . x_i`` its energy, no virial
        (`collidium.forces.base.Force.compute`)."""
        force[...] = self.uniform_force(particles)
        if not energies:
            return
        position = particles.position
        if vessel.periodic:
            position = position + particles.image * vessel.size
        energy[...] = -(position[:, 0] * force[:, 0] + position[:, 1] * force[:, 1])
        virial[...] = 0.0

    def uniform_force(self, particles: Particles) -> FloatArray:
        """``s_i f`` on each particle (N, 2), N
        (`collidium.forces.base.UniformPositionForce`)."""
        fx, fy = getattr(self, self.vector)
        strength = getattr(particles, self.source)
        force = np.empty((particles.n, 2))
        force[:, 0] = strength * fx
        force[:, 1] = strength * fy
        return force

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """0: leapfrog follows a uniform force exactly."""
        return 0.0

    @property
    def fall(self) -> tuple[float, float] | None:
        """The field itself when it acts on the mass (the same acceleration for all), else None
        (`collidium.forces.base.PositionForce.fall`)."""
        vector: tuple[float, float] = getattr(self, self.vector)
        return vector if self.source == "mass" else None

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file."""
        return {"type": self.name, self.vector: list(getattr(self, self.vector))}
