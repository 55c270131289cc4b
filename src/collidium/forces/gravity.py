"""Gravity: Newton's attraction between masses (`Newton`) and a uniform field (`Gravity`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from collidium.forces.base import check_at_least, register
from collidium.forces.pair import DEFAULT_THETA, InverseDistanceForce, SumMethod
from collidium.forces.uniform import UniformForce


@register
@dataclass(frozen=True)
class Newton(InverseDistanceForce):
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
    source: ClassVar[str] = "mass"

    G: float = 1.0
    softening: float = 0.0
    method: SumMethod = "auto"
    theta: float = DEFAULT_THETA

    def __post_init__(self) -> None:
        check_at_least(self.name, "G", self.G)
        super().__post_init__()

    @property
    def coupling(self) -> float:
        """``-G``: the masses attract."""
        return -self.G

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file (the default method and angle omitted)."""
        return {"type": self.name, "G": self.G, "softening": self.softening} | self.summation()


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
