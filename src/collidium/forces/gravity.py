"""Gravity: Newton's attraction between masses (`Newton`) and a uniform field (`Gravity`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.forces.base import check_at_least, register
from collidium.forces.pair import (
    DEFAULT_THETA,
    SumMethod,
    check_sum,
    check_vessel,
    pair_stiffness,
    pair_sum,
)
from collidium.forces.uniform import UniformForce
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class Newton:
    """Newton's gravitation between every pair of particles, softened.

    ``F = -G m_i m_j r / (r^2 + eps^2)^(3/2)`` (attractive) and
    ``U = -G m_i m_j / sqrt(r^2 + eps^2)``: Coulomb's form with the masses as charges and ``-G``
    as ``k``, summed by the same kernels (`collidium.forces.pair`).

    Parameters
    ----------
    G : float
        Gravitational constant in N m^2 / kg^2 (>= 0; 1 by default, simulation units).
    softening : float
        Softening length eps in m (>= 0).
    method : {"auto", "direct", "tree"}
        How the pair sum is done, as for `collidium.forces.Coulomb`.
    theta : float
        The tree's opening angle (0 < theta < 1).
    """

    name: ClassVar[str] = "newton"

    G: float = 1.0
    softening: float = 0.0
    method: SumMethod = "auto"
    theta: float = DEFAULT_THETA

    def __post_init__(self) -> None:
        check_at_least(self.name, "G", self.G)
        check_sum(self.name, self.softening, self.method, self.theta)

    def check(self, particles: Particles, vessel: Vessel) -> None:
        """Refuse the tree in a periodic vessel (it cannot follow the minimum image)."""
        check_vessel(self.name, self.method, vessel)

    def compute(
        self,
        particles: Particles,
        vessel: Vessel,
        force: FloatArray,
        energy: FloatArray,
        virial: FloatArray,
        work: dict[str, np.ndarray],
    ) -> None:
        """The pair sum of the masses (`collidium.forces.base.Force.compute`)."""
        pair_sum(
            particles.mass, -self.G, self.softening, self.method, self.theta, particles, vessel,
            (force, energy, virial), work,
        )  # fmt: skip

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """How fast the pair energies change (`collidium.forces.pair.pair_stiffness`)."""
        return pair_stiffness(
            particles.mass, -self.G, self.softening, self.method, particles, vessel, acceleration
        )

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file (the default method and angle omitted)."""
        out: dict[str, object] = {"type": self.name, "G": self.G, "softening": self.softening}
        if self.method != "auto":
            out["method"] = self.method
        if self.theta != DEFAULT_THETA:
            out["theta"] = self.theta
        return out


@register
@dataclass(frozen=True)
class Gravity(UniformForce):
    """Uniform gravity: ``F_i = m_i g``, ``U_i = -m_i g . x_i`` (`collidium.forces.uniform`).

    Parameters
    ----------
    g : tuple of float
        Acceleration of free fall (x, y) in m/s^2; ``(0, -9.81)`` by default.
    """

    name: ClassVar[str] = "gravity"
    vector: ClassVar[str] = "g"
    source: ClassVar[str] = "mass"

    g: tuple[float, float] = (0.0, -9.81)
