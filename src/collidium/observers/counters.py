"""Collision counts over time: collision rate, mean free time and mean free path."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.observers.base import Flown, Measurement, Trigger, new_axes
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation


class CollisionRate(Measurement):
    """Pair collisions and wall hits (per wall) counted between the first and the last sample.

    Parameters
    ----------
    trigger : callable or int, optional
        When to sample (default every step); the counts are exact whatever it is.
    """

    def __init__(self, trigger: Trigger | int | None = None) -> None:
        super().__init__(trigger)
        self._time: list[float] = []
        self._counts: list[np.ndarray] = []
        self._mean_speed: list[float] = []

    def _start(self, sim: Simulation) -> None:
        self._time, self._counts, self._mean_speed = [], [], []
        self.n = sim.particles.n
        #: The vessel's walls, in the order of the wall counters.
        self.walls = sim.container.wall_names

    def _sample(self, sim: Simulation) -> None:
        self._time.append(sim.time)
        self._counts.append(sim.tally.counts.copy())
        self._mean_speed.append(sim.total_speed() / max(sim.particles.n, 1))

    def take_flown(self, sim: Simulation, flown: Flown) -> None:
        """Samples of steps the run flew in one compiled call (`Flown`), as `update` after
        each."""
        self._time += flown.time.tolist()
        self._counts += list(flown.counts)
        self._mean_speed += (flown.total_speed / max(sim.particles.n, 1)).tolist()
        self.samples += flown.time.shape[0]

    @property
    def time(self) -> FloatArray:
        """Sample times in s."""
        return np.asarray(self._time)

    @property
    def pair_collisions(self) -> FloatArray:
        """Pair collisions counted since the first sample, at each sample."""
        counts = np.asarray(self._counts)
        return (counts[:, 0] - counts[0, 0]) if counts.size else np.empty(0)

    def _gained(self) -> tuple[np.ndarray, float]:
        if len(self._time) < 2:
            return np.zeros(1 + len(self.walls), dtype=np.int64), 0.0
        return self._counts[-1] - self._counts[0], self._time[-1] - self._time[0]

    @property
    def rate(self) -> float:
        """Pair collisions per second."""
        gained, duration = self._gained()
        return float(gained[0] / duration) if duration > 0 else float("nan")

    @property
    def wall_rates(self) -> dict[str, float]:
        """Hits per second on each wall."""
        gained, duration = self._gained()
        return {w: float(gained[1 + k] / duration) if duration > 0 else float("nan")
                for k, w in enumerate(self.walls)}  # fmt: skip

    @property
    def mean_free_time(self) -> float:
        """Mean time between a particle's collisions with others, ``N t / (2 collisions)``, in s."""
        gained, duration = self._gained()
        return float(self.n * duration / (2 * gained[0])) if gained[0] > 0 else float("inf")

    @property
    def mean_free_path(self) -> float:
        """Mean speed times mean free time, in m."""
        return float(np.mean(self._mean_speed)) * self.mean_free_time

    def plot(self, ax: Axes | None = None) -> Axes:
        """Cumulative pair collisions against time."""
        ax = new_axes(ax)
        ax.plot(self.time, self.pair_collisions, color="tab:purple")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("pair collisions")
        return ax

    def summary(self) -> dict[str, Any]:
        """Rates, mean free time and path."""
        return {
            "rate": self.rate,
            "wall_rates": self.wall_rates,
            "mean_free_time": self.mean_free_time,
            "mean_free_path": self.mean_free_path,
        }
