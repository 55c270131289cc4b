"""Paths of chosen particles and their mean-square displacement (the seed's random walk)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.errors import InputError
from collidium.observers.base import Measurement, Trigger, new_axes
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation


class Tracer(Measurement):
    """Unwrapped positions of chosen particles over time.

    Parameters
    ----------
    particles : sequence of int, optional
        Indices of the particles to follow (default: all).
    trigger : callable or int, optional
        When to sample (default every step).

    Attributes
    ----------
    time : ndarray, shape (K,)
        Sample times in s.
    path : ndarray, shape (K, M, 2)
        Positions in m of the M followed particles, periodic wrapping undone.
    """

    def __init__(
        self, particles: Sequence[int] | None = None, trigger: Trigger | int | None = None
    ) -> None:
        super().__init__(trigger)
        self.indices = None if particles is None else np.asarray(particles, dtype=np.int64)
        self._time: list[float] = []
        self._path: list[FloatArray] = []

    def _start(self, sim: Simulation) -> None:
        if (
            self.indices is not None
            and self.indices.size
            and (self.indices.min() < 0 or self.indices.max() >= sim.particles.n)
        ):
            raise InputError("particles", f"indices must lie in [0, {sim.particles.n})")
        self._time, self._path = [], []

    def _sample(self, sim: Simulation) -> None:
        position = sim.unwrapped_position()
        self._time.append(sim.time)
        self._path.append(position if self.indices is None else position[self.indices])

    @property
    def time(self) -> FloatArray:
        """Sample times in s."""
        return np.asarray(self._time)

    @property
    def path(self) -> FloatArray:
        """Positions (K, M, 2) in m."""
        return np.asarray(self._path)

    def msd(self) -> FloatArray:
        """Mean over the followed particles of ``|r(t) - r(t0)|^2`` at each sample, m^2."""
        path = self.path
        if path.size == 0:
            return np.empty(0)
        return np.mean(np.sum((path - path[0]) ** 2, axis=2), axis=1)

    def diffusion_coefficient(self) -> float:
        """``D`` from a straight-line fit ``MSD = 4 D t + c`` over the later half of the samples,
        in m^2/s (meaningful in a periodic box once the motion is diffusive)."""
        time, msd = self.time, self.msd()
        half = time.size // 2
        if time.size - half < 2:
            return float("nan")
        slope = np.polyfit(time[half:] - time[0], msd[half:], 1)[0]
        return float(slope / 4.0)

    def plot(self, ax: Axes | None = None) -> Axes:
        """The followed particles' paths (up to 20 of them)."""
        ax = new_axes(ax)
        path = self.path
        for m in range(min(path.shape[1], 20) if path.ndim == 3 else 0):
            ax.plot(path[:, m, 0], path[:, m, 1], lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        return ax

    def summary(self) -> dict[str, Any]:
        """Final mean-square displacement and diffusion coefficient."""
        msd = self.msd()
        return {
            "msd": float(msd[-1]) if msd.size else None,
            "diffusion_coefficient": self.diffusion_coefficient(),
        }
