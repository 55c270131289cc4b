"""Forces between particles. `Coulomb`: seed eq. 9-10 with optional softening and the seed's
acceleration limiter."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from collidium.errors import InputError, SimulationError
from collidium.kernels import tree
from collidium.kernels.pairwise import coulomb_direct, coulomb_stiffness
from collidium.state import FloatArray, Particles
from collidium.vessels import Vessel

SumMethod = Literal["auto", "direct", "tree"]
SUM_METHODS: tuple[SumMethod, ...] = ("auto", "direct", "tree")

#: Charged particles from which ``method="auto"`` sums by tree. On 2 threads the two cost the same
#: near N = 200 (0.10 against 0.11 us per particle) and the tree is 1.5x faster at 500; from 500
#: on, so that the small seed scenes keep the exact direct sum.
TREE_CROSSOVER = 500

#: The tree's default opening angle.
DEFAULT_THETA = tree.THETA


@dataclass(frozen=True)
class Coulomb:
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
        "auto", the tree from `TREE_CROSSOVER` particles on in a walled vessel, else direct.
    theta : float
        The tree's opening angle (0 < theta < 1): smaller is more accurate and slower. The
        default keeps the RMS relative force error below 1e-3 (see `kernels/tree.py`).

    Notes
    -----
    In a periodic vessel the minimum image is used (an approximation until Ewald summation
    exists); the tree cannot follow it, so a periodic vessel always sums directly.
    """

    k: float = 5.0
    softening: float = 0.0
    max_acceleration: float | None = None
    method: SumMethod = "auto"
    theta: float = DEFAULT_THETA

    def __post_init__(self) -> None:
        if not math.isfinite(self.k):
            raise InputError("forces.coulomb.k", f"must be finite, got {self.k!r}")
        if not math.isfinite(self.softening) or self.softening < 0:
            raise InputError("forces.coulomb.softening", f"must be >= 0, got {self.softening!r}")
        cap = self.max_acceleration
        if cap is not None and (not math.isfinite(cap) or cap <= 0):
            raise InputError("forces.coulomb.max_acceleration", f"must be > 0, got {cap!r}")
        if self.method not in SUM_METHODS:
            raise InputError(
                "forces.coulomb.method", f"must be one of {SUM_METHODS}, got {self.method!r}"
            )
        if not (isinstance(self.theta, int | float) and 0.0 < self.theta < 1.0):
            raise InputError("forces.coulomb.theta", f"must be between 0 and 1, got {self.theta!r}")

    def check_box(self, vessel: Vessel) -> None:
        """Refuse the tree in a periodic vessel (it cannot follow the minimum image)."""
        if vessel.periodic and self.method == "tree":
            raise InputError(
                "forces.coulomb.method",
                "the tree cannot sum a periodic vessel (minimum image); use 'direct' or 'auto'",
            )

    def uses_tree(self, particles: Particles, vessel: Vessel) -> bool:
        """Whether `compute` sums by tree for these particles in this vessel."""
        if vessel.periodic or self.method == "direct":
            return False
        return self.method == "tree" or particles.n >= TREE_CROSSOVER

    def compute(
        self,
        particles: Particles,
        vessel: Vessel,
        force: FloatArray,
        energy: FloatArray,
        virial: FloatArray,
        work: dict[str, np.ndarray] | None = None,
    ) -> None:
        """Write this force on each particle into ``force`` (N, 2), in N, and each particle's share
        of the pair energy into ``energy`` (N,) and of the pair virial ``sum r_ij . F_ij`` into
        ``virial`` (N,), both in J (their sums are the totals).

        ``work`` holds the tree's buffers between calls (filled on first use; a fresh one is made
        for this call if None)."""
        if self.uses_tree(particles, vessel):
            work = {} if work is None else work
            if not work:
                work.update(tree.tree_buffers(particles.n))
            tree.coulomb_tree(
                particles.position, particles.charge, self.k, self.softening**2, force, energy,
                virial, work, theta=self.theta,
            )  # fmt: skip
            return
        width, height = (float(side) for side in vessel.size)  # the period, when periodic
        coulomb_direct(
            particles.position, particles.charge, self.k, self.softening**2,
            width, height, vessel.periodic, force, energy, virial,
        )  # fmt: skip

    def stiffness(self, particles: Particles, vessel: Vessel, acceleration: FloatArray) -> float:
        """How fast this force's energies change: ``S`` in J^2/s^4, such that a leapfrog step h
        errs on the energy of the pair that is hardest to follow by about ``sqrt(S) h^2``
        (`collidium.integrators`).

        Summed directly, the largest ``(|U_ij| rate_ij^2)^2`` over pairs
        (`collidium.kernels.pairwise.coulomb_stiffness`), O(N^2) like the sum itself. Summed by
        tree, which has no pair list, the same from each particle's acceleration ``|a_i|``
        (``acceleration`` (N, 2), m/s^2) and speed over ``l_i``, its diameter or the softening
        length, whichever is larger (the mean spacing for point particles without softening):
        ``|U_i| = m_i |a_i| l_i`` and ``rate_i^2 = (|v_i|^2 / l_i + |a_i|) / l_i``.
        """
        if not self.uses_tree(particles, vessel):
            width, height = (float(side) for side in vessel.size)
            return coulomb_stiffness(
                particles.position, particles.velocity, particles.charge, particles.mass, self.k,
                self.softening**2, width, height, vessel.periodic,
            )  # fmt: skip
        length = np.maximum(2.0 * particles.radius, self.softening)
        spacing = math.sqrt(vessel.area / max(particles.n, 1))
        length = np.where(length > 0.0, length, spacing)
        pull = np.hypot(acceleration[:, 0], acceleration[:, 1])
        speed2 = np.einsum("ij,ij->i", particles.velocity, particles.velocity)
        error = particles.mass * pull * (speed2 / length + pull)
        return float(np.max(error * error, initial=0.0))

    def limit(self, acceleration: FloatArray) -> None:
        """Apply the smooth acceleration cap in place (no-op without ``max_acceleration``)."""
        if self.max_acceleration is None:
            return
        magnitude = np.hypot(acceleration[:, 0], acceleration[:, 1])
        acceleration /= np.sqrt(1.0 + (magnitude / self.max_acceleration) ** 2)[:, None]

    def to_dict(self) -> dict[str, object]:
        """Parameters as in a scenario file (None omitted)."""
        out: dict[str, object] = {"type": "coulomb", "k": self.k, "softening": self.softening}
        if self.max_acceleration is not None:
            out["max_acceleration"] = self.max_acceleration
        if self.method != "auto":
            out["method"] = self.method
        if self.theta != DEFAULT_THETA:
            out["theta"] = self.theta
        return out


def _refuse_infinite(acceleration: FloatArray) -> None:
    """One line naming the first particle whose acceleration (N, 2) overflowed (a force on a
    mass too small to move by it)."""
    # A reduction on the hot path (any inf or NaN makes the sum one); the search only on failure.
    with np.errstate(invalid="ignore", over="ignore"):  # inf - inf is the NaN looked for
        total = float(acceleration.sum())
    if not math.isfinite(total):
        i = int(np.argmin(np.isfinite(acceleration).all(axis=1)))
        raise SimulationError(
            f"particle {i}: the force on it gives an infinite acceleration (its mass is too "
            "small for the force)"
        )


class ForceField:
    """All forces of a simulation: total acceleration and potential energy, with reused buffers.

    Parameters
    ----------
    forces : sequence of Coulomb
        The forces acting; empty for free flight.
    """

    def __init__(self, forces: tuple[Coulomb, ...]) -> None:
        self.forces = tuple(forces)
        self._work: list[dict[str, np.ndarray]] = [{} for _ in self.forces]  # tree buffers
        self._force = np.empty((0, 2))
        self._energy = np.empty(0)
        self._virial = np.empty(0)
        self._evaluated_at: FloatArray | None = None
        self._acceleration = np.empty((0, 2))
        self._potential = 0.0
        self._virial_sum = 0.0

    @property
    def acceleration(self) -> FloatArray:
        """Acceleration (N, 2) in m/s^2 from the last `evaluate`."""
        return self._acceleration

    @property
    def active(self) -> bool:
        """True when at least one force acts."""
        return bool(self.forces)

    def evaluate(self, particles: Particles, vessel: Vessel) -> FloatArray:
        """Total acceleration (N, 2) in m/s^2 at the current positions; also caches the potential
        and the virial.

        Each force's limiter (if any) applies to that force's own acceleration.
        """
        n = particles.n
        if self._force.shape[0] != n:
            self._force = np.empty((n, 2))
            self._energy = np.empty(n)
            self._virial = np.empty(n)
            self._acceleration = np.empty((n, 2))
        self._acceleration[...] = 0.0
        potential = virial = 0.0
        for force, work in zip(self.forces, self._work, strict=True):
            force.compute(particles, vessel, self._force, self._energy, self._virial, work)
            with np.errstate(over="ignore"):  # an infinite acceleration is refused just below
                np.divide(self._force, particles.mass[:, None], out=self._force)
            _refuse_infinite(self._force)
            force.limit(self._force)
            self._acceleration += self._force
            potential += float(np.sum(self._energy))
            virial += float(np.sum(self._virial))
        self._potential = potential
        self._virial_sum = virial
        self._evaluated_at = particles.position.copy()
        return self._acceleration

    def stiffness(self, particles: Particles, vessel: Vessel) -> float:
        """``S`` of all forces at the current state, in J^2/s^4: the largest of the forces'
        (`Coulomb.stiffness`; the acceleration of the last `evaluate` is used where one is
        needed)."""
        return max(
            (force.stiffness(particles, vessel, self._acceleration) for force in self.forces),
            default=0.0,
        )

    def potential(self, particles: Particles, vessel: Vessel) -> float:
        """Potential energy in J at the current positions (cached from the last evaluation)."""
        self._refresh(particles, vessel)
        return self._potential

    def virial(self, particles: Particles, vessel: Vessel) -> float:
        """Pair virial ``sum_{i<j} r_ij . F_ij`` in J at the current positions (of the forces
        before any acceleration cap; minimum image in a periodic vessel)."""
        self._refresh(particles, vessel)
        return self._virial_sum

    def _refresh(self, particles: Particles, vessel: Vessel) -> None:
        if not self.active:
            self._potential = self._virial_sum = 0.0
        elif self._evaluated_at is None or not np.array_equal(
            self._evaluated_at, particles.position
        ):
            self.evaluate(particles, vessel)
