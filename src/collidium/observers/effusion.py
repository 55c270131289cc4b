"""Effusion: disks crossing a partition through its hole, counted per species (one species per
mass), and Graham's law: a species crosses at a rate that goes as ``1 / sqrt(m)``."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.errors import InputError
from collidium.observers.base import Measurement, Trigger, new_axes
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation


class Effusion(Measurement):
    """Crossings of a partition by the disks of each species, and the share of each species that
    has left the side it started on.

    A disk crossed between two samples when it is on the other side of the partition's line and
    its straight path from the first sample to the second meets the partition within its ends,
    that is, through the hole (the wall itself reflects). Sample every step (the default): a
    step is then far shorter than the time a disk takes to cross the hole and come back.

    Parameters
    ----------
    partition : str
        Name of the partition (`collidium.vessels.Partition`).
    trigger : callable or int, optional
        When to sample (default every step).

    Notes
    -----
    Through a hole of width ``w`` narrow against the mean free path, a species of number density
    ``n`` crosses in each direction at ``n <|v_n|> w / 2`` per second, ``v_n`` the velocity
    along the partition's normal (``n <v> w / pi`` for Maxwell-Boltzmann speeds, with
    ``<v> = sqrt(pi kT / (2 m))``). Counted both ways between chambers of equal area ``A``, the
    rate per disk is ``<|v_n|> w / (2 A)`` however the disks are shared between the chambers
    (`collidium.theory.effusion_rate`): two species at one temperature cross at rates in the
    ratio ``sqrt(m_2 / m_1)`` (Graham's law) from the first second, while the lighter one
    empties its chamber faster.
    """

    def __init__(self, partition: str, trigger: Trigger | int | None = None) -> None:
        super().__init__(trigger)
        if not isinstance(partition, str):
            raise InputError("partition", f"must be a partition's name, got {partition!r}")
        self.partition = partition
        #: The distinct masses in kg, ascending (one species each), and the disks of each.
        self.masses = np.empty(0)
        self.counts = np.empty(0, dtype=np.int64)
        self._species = np.empty(0, dtype=np.int64)
        self._time: list[float] = []
        self._escaped: list[FloatArray] = []
        self._crossings = np.empty(0, dtype=np.int64)

    def _start(self, sim: Simulation) -> None:
        line = sim.container.partition(self.partition)
        self._a = np.array(line.start)
        along = np.array(line.end) - self._a
        self._along = along / float(along @ along)  # projects onto [0, 1] along the partition
        self._normal = np.array([-along[1], along[0]])
        self.masses, self._species, self.counts = np.unique(
            sim.particles.mass, return_inverse=True, return_counts=True
        )
        self._crossings = np.zeros(self.masses.size, dtype=np.int64)
        self._position = sim.particles.position.copy()
        self._first_side = self._last_side = self._side(self._position)
        self._time, self._escaped = [], []

    def _side(self, position: FloatArray) -> np.ndarray:
        return (position - self._a) @ self._normal >= 0.0

    def _sample(self, sim: Simulation) -> None:
        before, now = self._position, sim.particles.position
        side = self._side(now)
        moved = np.flatnonzero(side != self._last_side)
        if moved.size:
            d0 = (before[moved] - self._a) @ self._normal
            d1 = (now[moved] - self._a) @ self._normal
            meet = before[moved] + (d0 / (d0 - d1))[:, None] * (now[moved] - before[moved])
            within = np.abs((meet - self._a) @ self._along - 0.5) <= 0.5
            self._crossings += np.bincount(self._species[moved[within]],
                                           minlength=self.masses.size)  # fmt: skip
        self._position, self._last_side = now.copy(), side
        self._time.append(sim.time)
        away = np.bincount(self._species, weights=side != self._first_side,
                           minlength=self.masses.size)  # fmt: skip
        self._escaped.append(away / self.counts)

    @property
    def time(self) -> FloatArray:
        """Sample times in s."""
        return np.asarray(self._time)

    @property
    def escaped(self) -> FloatArray:
        """Share of each species on the other side from where each disk was at the first sample,
        shape (samples, species)."""
        return np.asarray(self._escaped).reshape(-1, self.masses.size)

    @property
    def crossings(self) -> np.ndarray:
        """Crossings of each species (both ways) since the first sample."""
        return self._crossings.copy()

    def _duration(self) -> float:
        return self._time[-1] - self._time[0] if len(self._time) > 1 else math.nan

    @property
    def rates(self) -> FloatArray:
        """Crossings per disk per second of each species, 1/s."""
        return self._crossings / (self.counts * self._duration())

    @property
    def rate_errors(self) -> FloatArray:
        """Standard errors of `rates` (crossings counted as Poisson events), 1/s."""
        return np.sqrt(self._crossings) / (self.counts * self._duration())

    @property
    def ratio(self) -> float:
        """Rate per disk of the lightest species over that of the heaviest (Graham: `graham`)."""
        if self.masses.size < 2:
            return math.nan
        with np.errstate(divide="ignore", invalid="ignore"):  # inf while the heaviest stays put
            return float(self.rates[0] / self.rates[-1])

    @property
    def ratio_error(self) -> float:
        """Standard error of `ratio`."""
        c = self._crossings
        return (
            self.ratio * math.sqrt(1.0 / c[0] + 1.0 / c[-1]) if c.size > 1 and c.all() else math.nan
        )

    @property
    def graham(self) -> float:
        """Graham's law's ratio, ``sqrt(m_heaviest / m_lightest)``."""
        return math.sqrt(self.masses[-1] / self.masses[0]) if self.masses.size > 1 else math.nan

    def plot(self, ax: Axes | None = None) -> Axes:
        """The share of each species that has crossed over, against time."""
        ax = new_axes(ax)
        for k, mass in enumerate(self.masses):
            ax.plot(self.time, self.escaped[:, k], label=f"m = {mass:g} kg")
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"share across {self.partition}")
        ax.legend()
        return ax

    def summary(self) -> dict[str, Any]:
        """Per species (mass, disks, crossings, rate and error, share across at the end); the
        ratio of the lightest's rate to the heaviest's, its error, and Graham's ratio."""
        last = self.escaped[-1] if len(self._escaped) else np.full(self.masses.size, math.nan)
        return {
            "partition": self.partition,
            "masses": self.masses.tolist(),
            "counts": self.counts.tolist(),
            "crossings": self._crossings.tolist(),
            "rates": self.rates.tolist(),
            "rate_errors": self.rate_errors.tolist(),
            "escaped": last.tolist(),
            "ratio": self.ratio,
            "ratio_error": self.ratio_error,
            "graham": self.graham,
        }
