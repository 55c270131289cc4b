"""Speed distribution against the 2D Maxwell-Boltzmann law (seed 3.1.3)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Self

import numpy as np

from collidium.errors import InputError
from collidium.observers.base import Measurement, Trigger, new_axes
from collidium.state import FloatArray
from collidium.theory import MaxwellBoltzmann2D

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation


class SpeedHistogram(Measurement):
    """Histogram of the particles' speeds, one snapshot or accumulated over many.

    Parameters
    ----------
    bins : int
        Number of bins (default 30, the seed's).
    range : tuple of float
        Lowest and highest speed binned, m/s (default 0 to 30: bins of 1 m/s). Speeds outside
        still count in the total, so `density` estimates the true probability density.
    trigger : callable or int, optional
        When the run loop samples (default every step).

    Notes
    -----
    The temperature is the mean of ``KE / N`` over the samples (2 degrees of freedom, k = 1).
    `ks` tests the pooled speeds against the Maxwell-Boltzmann law at that temperature (when
    masses differ, a mixture weighted by the number of particles of each mass); speeds from
    snapshots close in time are correlated, so for a time average its p-value is only indicative.
    """

    #: Snapshots are taken when the trigger fires only (not when the run starts).
    baseline = False

    def __init__(
        self,
        bins: int = 30,
        range: tuple[float, float] = (0.0, 30.0),
        trigger: Trigger | int | None = None,
    ) -> None:
        super().__init__(trigger)
        if isinstance(bins, bool) or not isinstance(bins, int) or bins < 1:
            raise InputError("bins", f"must be a whole number >= 1, got {bins!r}")
        low, high = (float(x) for x in range)
        if not (math.isfinite(low) and math.isfinite(high) and 0 <= low < high):
            raise InputError("range", f"must be two finite speeds 0 <= low < high, got {range!r}")
        self.bin_edges = np.linspace(low, high, bins + 1)
        self.counts = np.zeros(bins, dtype=np.int64)
        self._speeds: list[FloatArray] = []
        self._masses: list[FloatArray] = []
        self._temperatures: list[float] = []

    def _start(self, sim: Simulation) -> None:
        self.counts[:] = 0
        self._speeds, self._masses, self._temperatures = [], [], []

    def _sample(self, sim: Simulation) -> None:
        p = sim.particles
        self._add(np.hypot(p.velocity[:, 0], p.velocity[:, 1]), p.mass, sim.temperature())

    def add(self, speed: FloatArray, mass: FloatArray, kT: float) -> Self:
        """Add one snapshot given as arrays: speeds (N,) in m/s, masses (N,) in kg and its
        temperature kT in J (for snapshots read from a file)."""
        self._add(speed, mass, kT)
        self.samples += 1
        return self

    def _add(self, speed: FloatArray, mass: FloatArray, kT: float) -> None:
        self.counts += np.histogram(speed, self.bin_edges)[0]
        self._speeds.append(np.asarray(speed, dtype=float))
        self._masses.append(np.array(mass, dtype=float))
        self._temperatures.append(float(kT))

    @property
    def frames(self) -> int:
        """Number of snapshots accumulated."""
        return len(self._speeds)

    @property
    def speeds(self) -> FloatArray:
        """All sampled speeds in m/s, pooled."""
        return np.concatenate(self._speeds) if self._speeds else np.empty(0)

    @property
    def bin_centers(self) -> FloatArray:
        """Middle of each bin in m/s."""
        return 0.5 * (self.bin_edges[1:] + self.bin_edges[:-1])

    @property
    def density(self) -> FloatArray:
        """Estimated probability density in s/m per bin (counts / (samples x bin width))."""
        total = max(self.speeds.size, 1)
        return self.counts / (total * np.diff(self.bin_edges))

    @property
    def temperature(self) -> float:
        """Mean kT = KE / N over the snapshots, in J."""
        return float(np.mean(self._temperatures)) if self._temperatures else float("nan")

    def maxwell_boltzmann(self, kT: float | None = None) -> MaxwellBoltzmann2D:
        """The 2D Maxwell-Boltzmann law for the sampled masses at ``kT`` (default: measured)."""
        masses = np.concatenate(self._masses) if self._masses else np.ones(1)
        return MaxwellBoltzmann2D(self.temperature if kT is None else kT, masses)

    def ks(self) -> tuple[float, float]:
        """Kolmogorov-Smirnov statistic and p-value of the speeds against `maxwell_boltzmann`."""
        from scipy import stats  # imported on first use: it is slow to load

        result = stats.kstest(self.speeds, self.maxwell_boltzmann().cdf)
        return float(result.statistic), float(result.pvalue)

    def fit_temperature(self) -> tuple[float, float]:
        """Temperature that best fits the histogram, and its standard error, in J.

        A least-squares fit of the expected bin counts ``n P_k(kT)`` to the counts, each weighted
        by its Poisson error. This uses the shape of the distribution only, so it checks the
        equilibrium independently of the kinetic energy.
        """
        from scipy import optimize

        total = self.speeds.size
        masses = np.concatenate(self._masses)

        def expected(_: FloatArray, kT: float) -> FloatArray:
            return total * MaxwellBoltzmann2D(kT, masses).bin_probabilities(self.bin_edges)

        sigma = np.sqrt(np.maximum(self.counts, 1.0))
        start = self.temperature
        (kT,), covariance = optimize.curve_fit(
            expected, self.bin_centers, self.counts, p0=[start], sigma=sigma,
            absolute_sigma=True, bounds=(1e-12 * start, np.inf),
        )  # fmt: skip
        return float(kT), float(np.sqrt(covariance[0, 0]))

    def plot(self, ax: Axes | None = None) -> Axes:
        """Bars of the measured density with the Maxwell-Boltzmann curve at the temperature."""
        ax = new_axes(ax)
        edges = self.bin_edges
        ax.bar(edges[:-1], self.density, width=np.diff(edges), align="edge", color="tab:gray",
               edgecolor="white", label="measured")  # fmt: skip
        if self.sampled and self.temperature > 0:
            v = np.linspace(edges[0], edges[-1], 300)
            ax.plot(v, self.maxwell_boltzmann().pdf(v), color="tab:red",
                    label=f"Maxwell-Boltzmann, kT = {self.temperature:.4g} J")  # fmt: skip
        ax.set_xlabel("speed (m/s)")
        ax.set_ylabel("probability density (s/m)")
        ax.legend(loc="upper right", fontsize="small")
        return ax

    def summary(self) -> dict[str, Any]:
        """Temperature, KS statistic and p-value."""
        if not self.sampled or not self.temperature > 0:
            return {"temperature": self.temperature, "ks_statistic": None, "ks_pvalue": None}
        statistic, pvalue = self.ks()
        return {"temperature": self.temperature, "ks_statistic": statistic, "ks_pvalue": pvalue}
