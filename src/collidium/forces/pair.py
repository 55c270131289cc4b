"""What the inverse-distance pair forces share: ``U_ij = c s_i s_j / sqrt(r^2 + eps^2)``.

`Coulomb` (sources: the charges, ``c = k``) and `Newton` (the masses, ``c = -G``) are summed by the
same kernels, directly (`collidium.kernels.pairwise`) or by Barnes-Hut tree
(`collidium.kernels.tree`); this module chooses between them and checks the shared parameters.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np

from collidium.errors import InputError
from collidium.forces.base import check_at_least
from collidium.kernels import tree
from collidium.kernels.pairwise import inverse_distance_direct, inverse_distance_stiffness
from collidium.state import FloatArray, Particles, writable
from collidium.vessels import Vessel

SumMethod = Literal["auto", "direct", "tree"]
SUM_METHODS: tuple[SumMethod, ...] = ("auto", "direct", "tree")

#: Particles with a source from which ``method="auto"`` sums by tree. On 2 threads the direct
#: sum takes 0.8-1.3 times the tree's time at N = 500 and 1000, 1.6-2.0 times at 2000 and 4 times
#: at 8000 (`benchmarks/bench_core.py`, W2's costs): from 1000 on, so that up to there every
#: scene keeps the exact direct sum.
TREE_CROSSOVER = 1000

#: The tree's default opening angle.
DEFAULT_THETA = tree.THETA


#: Largest softening length, m: the kernels sum with its square, which must stay a float64.
MAX_SOFTENING = 1e150


def check_sum(name: str, softening: float, method: str, theta: float) -> None:
    """Refuse a bad softening, summation method or opening angle of the force ``name``."""
    check_at_least(name, "softening", softening)
    if softening > MAX_SOFTENING:
        raise InputError(
            f"forces.{name}.softening",
            f"must be at most {MAX_SOFTENING:g} m (its square must fit a float64), "
            f"got {softening!r}",
        )
    if method not in SUM_METHODS:
        raise InputError(f"forces.{name}.method", f"must be one of {SUM_METHODS}, got {method!r}")
    if not (isinstance(theta, int | float) and 0.0 < theta < 1.0):
        raise InputError(f"forces.{name}.theta", f"must be between 0 and 1, got {theta!r}")


def check_vessel(name: str, method: str, vessel: Vessel) -> None:
    """Refuse the tree in a periodic vessel (it cannot follow the minimum image)."""
    if vessel.periodic and method == "tree":
        raise InputError(
            f"forces.{name}.method",
            "the tree cannot sum a periodic vessel (minimum image); use 'direct' or 'auto'",
        )


def uses_tree(method: str, particles: Particles, vessel: Vessel) -> bool:
    """Whether a pair force with this ``method`` sums by tree here."""
    if vessel.periodic or method == "direct":
        return False
    return method == "tree" or particles.n >= TREE_CROSSOVER


def pair_sum(
    source: FloatArray,
    coupling: float,
    softening: float,
    method: str,
    theta: float,
    particles: Particles,
    vessel: Vessel,
    force: FloatArray,
    energies: tuple[FloatArray, FloatArray] | None,
    work: dict[str, np.ndarray],
) -> None:
    """Forces (N, 2) in N written into ``force``, and if ``energies`` is given half pair
    energies and half pair virials (N,) in J into its two arrays, of sources ``source`` (N,)
    with ``coupling`` (`collidium.kernels.pairwise`).

    ``work`` keeps the tree's buffers between calls (filled on first use). The tree sums the
    energies with the forces whatever is asked (into a work array when not wanted): its far
    field gives them for a few more terms of each expansion."""
    position = particles.position
    if uses_tree(method, particles, vessel):
        if not work:
            work.update(tree.tree_buffers(particles.n))
        if energies is None:
            unread = work.get("unread")
            if unread is None or unread.shape[0] != particles.n:
                unread = work["unread"] = np.empty(particles.n)
            energies = unread, unread
        energy, virial = energies
        tree.inverse_distance_tree(
            position, source, coupling, softening**2, force, energy, virial, work, theta=theta
        )
        return
    width, height = (float(side) for side in vessel.size)  # the period, when periodic
    inverse_distance_direct(
        position, source, coupling, softening**2, width, height, vessel.periodic, force,
        *(energies or ()),
    )  # fmt: skip


def pair_stiffness(
    source: FloatArray,
    coupling: float,
    softening: float,
    method: str,
    particles: Particles,
    vessel: Vessel,
    acceleration: FloatArray,
) -> float:
    """``S`` in J^2/s^4 (`collidium.forces.base.Force.stiffness`) of an inverse-distance force.

    Summed directly, the largest ``(|U_ij| rate_ij^2)^2`` over pairs
    (`collidium.kernels.pairwise.inverse_distance_stiffness`), O(N^2) like the sum itself.
    Summed by tree, which has no pair list, the same from each particle's acceleration
    (``acceleration`` (N, 2), m/s^2, of all forces): `tree.acceleration_stiffness`.
    """
    if not uses_tree(method, particles, vessel):
        width, height = (float(side) for side in vessel.size)
        return inverse_distance_stiffness(
            particles.position, particles.velocity, source, writable(particles.mass), coupling,
            softening**2, width, height, vessel.periodic,
        )  # fmt: skip
    spacing = math.sqrt(vessel.area / max(particles.n, 1))
    return tree.acceleration_stiffness(
        particles.velocity, acceleration, writable(particles.mass), writable(particles.radius),
        softening, spacing,
    )  # fmt: skip


class InverseDistanceForce:
    """The behaviour of an inverse-distance pair force, for a frozen dataclass with the fields
    ``softening``, ``method`` and ``theta``: its sources are the particles' `source` array
    ("charge" or "mass") and its coupling `coupling`."""

    name: ClassVar[str]
    source: ClassVar[str]
    #: Pair forces differ from particle to particle (`collidium.forces.base.PositionForce.fall`).
    fall: ClassVar[None] = None
    softening: float
    method: SumMethod
    theta: float

    @property
    def coupling(self) -> float:
        """``c`` in ``U_ij = c s_i s_j / sqrt(r^2 + eps^2)``."""
        raise NotImplementedError

    def __post_init__(self) -> None:
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
        energies: bool,
    ) -> None:
        """The pair sum of the sources (`collidium.forces.base.Force.compute`)."""
        pair_sum(
            writable(getattr(particles, self.source)), self.coupling, self.softening, self.method,
            self.theta, particles, vessel, force, (energy, virial) if energies else None, work,
        )  # fmt: skip

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """How fast the pair energies change (`pair_stiffness`)."""
        return pair_stiffness(
            writable(getattr(particles, self.source)), self.coupling, self.softening, self.method,
            particles, vessel, acceleration,
        )  # fmt: skip

    def pair_law(self, particles: Particles) -> tuple[FloatArray, float, float]:
        """The sources, coupling and squared softening of the law
        (`collidium.forces.base.PairLawForce`)."""
        return getattr(particles, self.source), self.coupling, self.softening**2

    def follows_law(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether the sum is the law's own gradient: direct, not by tree
        (`collidium.forces.base.PairLawForce`)."""
        return not uses_tree(self.method, particles, vessel)

    def direct_term(self, particles: Particles, vessel: Vessel) -> tuple[str, float, float] | None:
        """The sources' property, coupling and squared softening when the sum is direct and
        not periodic (`collidium.forces.base.DirectPairForce`)."""
        if vessel.periodic or uses_tree(self.method, particles, vessel):
            return None
        return self.source, self.coupling, self.softening**2

    def summation(self) -> dict[str, object]:
        """The summation settings as in a scenario file, those at their defaults left out."""
        out: dict[str, object] = {}
        if self.method != "auto":
            out["method"] = self.method
        if self.theta != DEFAULT_THETA:
            out["theta"] = self.theta
        return out
