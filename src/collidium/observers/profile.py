"""Temperature and density profile: kT and disks per m^2 in slices of the vessel along an axis,
averaged over a run (heat flow between walls at different temperatures shows as a slope of kT,
gravity as a fall of the density)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from collidium.errors import InputError
from collidium.observers.base import Measurement, Trigger, new_axes
from collidium.observers.thermo import _blocks, _standard_error
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation

Axis = Literal["x", "y"]


class TemperatureProfile(Measurement):
    """kT = mean kinetic energy per disk (Boltzmann's constant 1, 2D) and the number density in
    ``bins`` equal slices of the vessel's bounding box along ``axis``, pooled over the samples.

    Parameters
    ----------
    bins : int
        Slices, >= 1.
    axis : {"x", "y"}
        The direction the slices cut across.
    trigger : callable or int, optional
        When to sample (default every step).

    Notes
    -----
    Statistical errors come from block averages of each slice, as in `Thermo`.
    """

    def __init__(self, bins: int = 10, axis: Axis = "x", trigger: Trigger | int | None = None):
        super().__init__(trigger)
        if isinstance(bins, bool) or not isinstance(bins, int) or bins < 1:
            raise InputError("bins", f"must be a whole number >= 1, got {bins!r}")
        if axis not in ("x", "y"):
            raise InputError("axis", f"must be 'x' or 'y', got {axis!r}")
        self.bins = bins
        self.axis: Axis = axis
        self._energy: list[np.ndarray] = []
        self._count: list[np.ndarray] = []
        self.edges = np.empty(0)
        self._slice_area = np.nan

    def _start(self, sim: Simulation) -> None:
        d = 0 if self.axis == "x" else 1
        low, high = sim.container.bounds[:, d]
        self.edges = np.linspace(low, high, self.bins + 1)
        self._slice_area = float(np.prod(sim.container.size)) / self.bins
        self._energy, self._count = [], []

    def _sample(self, sim: Simulation) -> None:
        p = sim.particles
        d = 0 if self.axis == "x" else 1
        slot = np.clip(np.searchsorted(self.edges, p.position[:, d], side="right") - 1, 0,
                       self.bins - 1)  # fmt: skip
        energy = 0.5 * p.mass * np.einsum("ij,ij->i", p.velocity, p.velocity)
        self._energy.append(np.bincount(slot, weights=energy, minlength=self.bins))
        self._count.append(np.bincount(slot, minlength=self.bins).astype(float))

    @property
    def centres(self) -> FloatArray:
        """Middle of each slice along the axis, m."""
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    @property
    def temperature(self) -> FloatArray:
        """kT in each slice, J (NaN where no disk was seen)."""
        count = np.sum(self._count, axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.sum(self._energy, axis=0) / count

    @property
    def density(self) -> FloatArray:
        """Mean number of disks per m^2 in each slice of the bounding box (a slice of a box is a
        strip of the box), 1/m^2."""
        return np.mean(self._count, axis=0) / self._slice_area

    def density_error(self) -> FloatArray:
        """Standard error of each slice's density, 1/m^2 (block averages; NaN with fewer than
        3 samples)."""
        if len(self._count) < 3:
            return np.full(self.bins, np.nan)
        count = np.asarray(self._count)
        weights = np.ones(len(count))
        errors = [_standard_error(_blocks(count[:, k], weights)[0]) for k in range(self.bins)]
        return np.array(errors) / self._slice_area

    def temperature_error(self) -> FloatArray:
        """Standard error of each slice's kT, J (block averages; NaN with fewer than 3
        samples)."""
        if len(self._energy) < 3:
            return np.full(self.bins, np.nan)
        energy, count = np.asarray(self._energy), np.asarray(self._count)
        errors = []
        for k in range(self.bins):
            seen = count[:, k] > 0
            if seen.sum() < 3:
                errors.append(np.nan)
                continue
            kT, _ = _blocks(energy[seen, k] / count[seen, k], count[seen, k])
            errors.append(_standard_error(kT))
        return np.array(errors)

    def plot(self, ax: Axes | None = None) -> Axes:
        """kT against position, with error bars."""
        ax = new_axes(ax)
        ax.errorbar(self.centres, self.temperature, yerr=self.temperature_error(), fmt="o-")
        ax.set_xlabel(f"{self.axis} (m)")
        ax.set_ylabel("kT (J)")
        return ax

    def summary(self) -> dict[str, Any]:
        """The profile: slice centres (m), kT and its error (J), density and its error
        (1/m^2)."""
        return {
            "axis": self.axis,
            "centres": self.centres.tolist(),
            "temperature": [float(t) for t in self.temperature],
            "temperature_error": [float(e) for e in self.temperature_error()],
            "density": [float(d) for d in self.density],
            "density_error": [float(e) for e in self.density_error()],
        }
