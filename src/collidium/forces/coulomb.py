"""Coulomb's force between charges (seed eq. 9-10), softened, with the seed's optional limiter."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.forces.base import check_finite, register
from collidium.forces.pair import DEFAULT_THETA, InverseDistanceForce, SumMethod
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel


@register
@dataclass(frozen=True)
class Coulomb(InverseDistanceForce):
    """Coulomb interaction (seed eq. 9-10, softened).

    ``F = k q_i q_j r / (r^2 + eps^2)^(3/2)`` and ``U = k q_i q_j / sqrt(r^2 + eps^2)``.

    Parameters
    ----------
    k : float
        Coulomb constant in N m^2 / C^2 (the seed uses 5).
    softening : float
        Softening length eps in m (>= 0); keeps the force finite for point particles.
    max_acceleration : float or None
        The seed's limiter: accelerations are capped smoothly,
        ``a -> a / sqrt(1 + (|a| / a_max)^2)``. Not energy conserving (seed 4.2); None to disable.
    method : {"auto", "direct", "tree"}
        How the pair sum is done: "direct", every pair in a parallel numba kernel, O(N^2), exact;
        "tree", a Barnes-Hut quadtree with order-4 multipoles, O(N log N) (`kernels/tree.py`);
        "auto", the tree from `collidium.forces.pair.TREE_CROSSOVER` charges on in a walled
        vessel, else direct.
    theta : float
        The tree's opening angle (0 < theta < 1): smaller is more accurate and slower. The
        default keeps the RMS relative force error below 1e-3 (see `kernels/tree.py`).

    Notes
    -----
    In a periodic vessel the minimum image is used (an approximation until Ewald summation
    exists); the tree cannot follow it, so a periodic vessel always sums directly.
    """

    name: ClassVar[str] = "coulomb"
    source: ClassVar[str] = "charge"

    k: float = 5.0
    softening: float = 0.0
    max_acceleration: float | None = None
    method: SumMethod = "auto"
    theta: float = DEFAULT_THETA

    def __post_init__(self) -> None:
        check_finite(self.name, "k", self.k)
        super().__post_init__()
        cap = self.max_acceleration
        if cap is not None:
            check_finite(self.name, "max_acceleration", cap)
            if cap <= 0:
                raise InputError("forces.coulomb.max_acceleration", f"must be > 0, got {cap!r}")

    @property
    def coupling(self) -> float:
        """``k``."""
        return self.k

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
        """The pair sum of the charges (`collidium.forces.base.Force.compute`), then the
        limiter, if any, on each particle's force over its mass."""
        super().compute(particles, vessel, force, energy, virial, work, energies)
        if self.max_acceleration is not None:
            pull = np.hypot(force[:, 0], force[:, 1]) / particles.mass
            force /= np.sqrt(1.0 + (pull / self.max_acceleration) ** 2)[:, None]

    def follows_law(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether the force is the law's gradient: summed directly, without a limiter."""
        return self.max_acceleration is None and super().follows_law(particles, vessel)

    def direct_term(self, particles: Particles, vessel: Vessel) -> tuple[str, float, float] | None:
        """The direct sum's terms (`InverseDistanceForce.direct_term`), none with a limiter."""
        if self.max_acceleration is not None:
            return None
        return super().direct_term(particles, vessel)

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file (defaults of the optional ones omitted)."""
        out: dict[str, object] = {"type": self.name, "k": self.k, "softening": self.softening}
        if self.max_acceleration is not None:
            out["max_acceleration"] = self.max_acceleration
        return out | self.summation()
