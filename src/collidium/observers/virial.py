"""The virial ratio of a self-bound cluster: `VirialRatio`."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.forces import PositionForce
from collidium.observers.base import Measurement, Trigger, new_axes
from collidium.state import FloatArray, Particles

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation
    from collidium.vessels import Vessel


class VirialRatio(Measurement):
    """``2 KE / |W|`` of the bound cluster over time: 1 in virial equilibrium under an
    inverse-distance pair force (the virial theorem, ``2 KE + W = 0`` with ``W = sum r_ij .
    F_ij``), below 1 while a cold cluster falls in, above while it bounces.

    The bound cluster is the particles whose kinetic energy is less than minus their energy in
    the field of all the others (twice their share of the pair energy): escapers, which the
    vessel's walls hold and send back, are left out, and ``W`` and ``KE`` are those of the
    cluster alone. Meant for a cluster held by its own pair forces (the ``galaxy`` preset).

    Parameters
    ----------
    trigger : callable or int, optional
        When to sample (default every step).

    Attributes
    ----------
    time, ratio, bound : ndarray, shape (K,)
        One value per sample: s, ``2 KE / |W|`` of the cluster, the fraction of particles in it.
    """

    def __init__(self, trigger: Trigger | int | None = None) -> None:
        super().__init__(trigger)
        self._rows: list[tuple[float, float, float]] = []

    def _start(self, sim: Simulation) -> None:
        self._rows = []

    def _sample(self, sim: Simulation) -> None:
        forces = [f for f in sim.forces if isinstance(f, PositionForce)]
        p = sim.particles
        speed2 = np.einsum("ij,ij->i", p.velocity, p.velocity)
        energy, _ = _pair_sums(forces, p, sim.container)
        bound = 0.5 * p.mass * speed2 + 2.0 * energy < 0.0
        cluster = Particles(p.position[bound], p.velocity[bound], mass=p.mass[bound],
                            radius=0.0, charge=p.charge[bound])  # fmt: skip
        _, virial = _pair_sums(forces, cluster, sim.container)
        kinetic = 0.5 * float(np.sum(cluster.mass * speed2[bound]))
        ratio = 2.0 * kinetic / abs(virial) if virial else float("nan")
        self._rows.append((sim.time, ratio, float(np.mean(bound)) if p.n else 0.0))

    def _column(self, k: int) -> FloatArray:
        return np.asarray(self._rows, dtype=float).reshape(-1, 3)[:, k]

    @property
    def time(self) -> FloatArray:
        """Sample times in s."""
        return self._column(0)

    @property
    def ratio(self) -> FloatArray:
        """``2 KE / |W|`` of the bound cluster."""
        return self._column(1)

    @property
    def bound(self) -> FloatArray:
        """Fraction of the particles in the bound cluster."""
        return self._column(2)

    def plot(self, ax: Axes | None = None) -> Axes:
        """The ratio against time, with equilibrium (1) dashed."""
        ax = new_axes(ax)
        ax.plot(self.time, self.ratio, color="tab:purple", label="2 KE / |W| (bound)")
        ax.axhline(1.0, color="grey", linestyle="--", label="virial equilibrium")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("virial ratio")
        ax.legend()
        return ax

    def summary(self) -> dict[str, Any]:
        """The last ratio and bound fraction, and the ratio's mean and spread over the samples."""
        if not self._rows:
            return {}
        ratio = self.ratio
        return {
            "virial_ratio": float(ratio[-1]),
            "bound_fraction": float(self.bound[-1]),
            "mean_virial_ratio": float(np.mean(ratio)),
            "virial_ratio_spread": float(np.std(ratio)),
        }


def _pair_sums(
    forces: list[PositionForce], particles: Particles, vessel: Vessel
) -> tuple[FloatArray, float]:
    """Each particle's share of the potential energy (N,), J, and the total virial, J."""
    n = particles.n
    force, share, virial = np.empty((n, 2)), np.empty(n), np.empty(n)
    energy, total = np.zeros(n), 0.0
    for f in forces:
        f.compute(particles, vessel, force, share, virial, {}, energies=True)
        energy += share
        total += float(np.sum(virial))
    return energy, total
