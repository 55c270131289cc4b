"""Temperature and pressure: from the momentum the walls receive and from the virial.

Boltzmann's constant is 1, so temperatures are kT in J; in 2D pressure is a force per unit length
(N/m). With hard walls, a disk of radius r touches a wall when its centre is r away from it, so
the centres move in the vessel shrunk by the mean radius r: the wall pressure of a wall is the
normal force on it per unit length of its line of contact (`Vessel.contact_lengths`), and the
virial pressure uses the area that line encloses (`Vessel.available_area`; for a box
``A_c = (Lx - 2 r) (Ly - 2 r)``, ``Lx Ly`` when periodic; with a piston, both are taken where
it is at each sample),

    P_virial = (N kT + W / 2) / A_c,    W = <sum_{i<j} r_ij . F_ij> (collisions and forces).

With these definitions the two agree exactly on average in equilibrium (for equal radii: the
virial theorem with the walls' forces included), and an ideal gas has ``P A_c = N kT``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.observers.base import Flown, Measurement, Trigger, new_axes
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation

#: Most blocks the samples are grouped into for the statistical errors.
MAX_BLOCKS = 20


def _blocks(values: FloatArray, weights: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Weighted means of ``values`` over up to `MAX_BLOCKS` contiguous blocks, and the weights."""
    parts = np.array_split(np.arange(values.shape[0]), min(MAX_BLOCKS, values.shape[0]))
    sums = np.array([np.sum(values[p] * weights[p]) for p in parts])
    totals = np.array([np.sum(weights[p]) for p in parts])
    return sums / totals, totals


def _standard_error(block_values: FloatArray) -> float:
    if block_values.size < 2:
        return float("nan")
    return float(np.std(block_values, ddof=1) / np.sqrt(block_values.size))


class Thermo(Measurement):
    """Temperature, wall pressure (per wall and total) and virial pressure, averaged over a run.

    Parameters
    ----------
    trigger : callable or int, optional
        When to sample (default every step). The collision parts of the pressures are exact sums
        over every event whatever the trigger; the temperature and the force virial are averaged
        over the samples.

    Notes
    -----
    Statistical errors come from block averages: the sampled intervals are cut into up to 20
    contiguous blocks, and the error is the standard deviation of the block values over the square
    root of their number (reliable when a block is longer than the correlation time).
    """

    def __init__(self, trigger: Trigger | int | None = None) -> None:
        super().__init__(trigger)
        self._time: list[float] = []
        self._kT: list[float] = []
        self._impulse: list[FloatArray] = []
        self._force_virial: list[float] = []
        self._contact: list[FloatArray] = []
        self._area: list[float] = []

    def _start(self, sim: Simulation) -> None:
        self._time, self._kT, self._impulse, self._force_virial = [], [], [], []
        self._contact, self._area = [], []
        self.n = sim.particles.n
        self._radius = float(np.mean(sim.particles.radius)) if self.n > 0 else 0.0
        self.periodic = sim.container.periodic
        #: The vessel's walls, in the order of the wall counters.
        self.walls = sim.container.wall_names

    def _sample(self, sim: Simulation) -> None:
        self._time.append(sim.time)
        self._kT.append(sim.temperature())
        self._force_virial.append(sim.virial())
        self._take_walls(sim, sim.tally.impulse[None].copy())

    def take_flown(self, sim: Simulation, flown: Flown) -> None:
        """Samples of steps the run flew in one compiled call (`Flown`), as `update` after
        each: the vessel did not change in between."""
        n = sim.particles.n
        self._time += flown.time.tolist()
        self._kT += (flown.kinetic / n).tolist() if n else [float("nan")] * flown.time.shape[0]
        self._force_virial += flown.virial.tolist()
        self._take_walls(sim, flown.impulse)
        self.samples += flown.time.shape[0]

    def _take_walls(self, sim: Simulation, impulses: FloatArray) -> None:
        """The walls' ``impulses`` (K, 1 + W) of K samples, with the contact lengths and the
        area available now."""
        state = sim.piston()
        piston = None if state is None else state.position
        contact = sim.container.contact_lengths(self._radius, piston)
        area = sim.container.available_area(self._radius, piston)
        self._impulse += list(impulses)
        self._contact += [contact] * impulses.shape[0]
        self._area += [area] * impulses.shape[0]

    @property
    def contact(self) -> FloatArray:
        """Length (m) of each wall's line of contact for disks of the mean radius, averaged
        over the samples (it changes only with a piston)."""
        return np.mean(self._contact, axis=0)

    @property
    def area(self) -> float:
        """Area (m^2) the centres move in, averaged over the samples."""
        return float(np.mean(self._area))

    def _intervals(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Per sampled interval: duration, impulse sums gained, kT and force virial at its end."""
        time = np.asarray(self._time)
        impulse = np.asarray(self._impulse)
        return (
            np.diff(time),
            np.diff(impulse, axis=0),
            np.asarray(self._kT)[1:],
            np.asarray(self._force_virial)[1:],
        )

    @property
    def duration(self) -> float:
        """Time span of the samples in s."""
        return self._time[-1] - self._time[0] if self._time else 0.0

    @property
    def temperature(self) -> float:
        """kT = KE / N in J, averaged over the samples."""
        return float(np.mean(self._kT)) if self._kT else float("nan")

    def _wall_values(self) -> tuple[FloatArray, FloatArray]:
        """Wall pressure per interval (total) and the intervals' durations."""
        dt, impulse, _, _ = self._intervals()
        return impulse[:, 1:].sum(axis=1) / (dt * float(np.sum(self.contact))), dt

    def _virial_values(self) -> tuple[FloatArray, FloatArray]:
        """Virial pressure per interval and the intervals' durations."""
        dt, impulse, kT, force_virial = self._intervals()
        virial = impulse[:, 0] / dt + force_virial
        return (self.n * kT + 0.5 * virial) / self.area, dt

    def wall_pressure(self) -> dict[str, float]:
        """Force per unit length of contact line on each wall and on all together, N/m
        (NaN in a periodic box or without samples)."""
        if self.periodic or self.duration <= 0:
            return {name: float("nan") for name in (*self.walls, "total")}
        gained = self._impulse[-1] - self._impulse[0]
        out = {name: float(gained[1 + k] / (self.duration * self.contact[k]))
               for k, name in enumerate(self.walls)}  # fmt: skip
        out["total"] = float(gained[1:].sum() / (self.duration * float(np.sum(self.contact))))
        return out

    def wall_pressure_error(self) -> float:
        """Standard error of the total wall pressure in N/m (block averages)."""
        if self.periodic or len(self._time) < 3:
            return float("nan")
        return _standard_error(_blocks(*self._wall_values())[0])

    def virial_pressure(self) -> float:
        """``(N kT + W / 2) / A_c`` in N/m; W is the collision virial rate plus the mean force
        virial."""
        if self.duration <= 0:
            return float("nan")
        gained = self._impulse[-1][0] - self._impulse[0][0]
        virial = gained / self.duration + float(np.mean(self._force_virial[1:]))
        return float((self.n * self.temperature + 0.5 * virial) / self.area)

    def virial_pressure_error(self) -> float:
        """Standard error of the virial pressure in N/m (block averages)."""
        if len(self._time) < 3:
            return float("nan")
        return _standard_error(_blocks(*self._virial_values())[0])

    def compressibility(self) -> float:
        """``Z = P A_c / (N kT)`` from the virial pressure (1 for an ideal gas); NaN without
        particles or motion (N kT = 0)."""
        return self._per_ideal_gas(self.virial_pressure())

    def compressibility_error(self) -> float:
        """Standard error of `compressibility`, from that of the virial pressure."""
        return self._per_ideal_gas(self.virial_pressure_error())

    def _per_ideal_gas(self, pressure: float) -> float:
        """``pressure`` over the ideal gas's ``N kT / A_c``; NaN where that is not > 0."""
        ideal = self.n * self.temperature / self.area
        return pressure / ideal if ideal > 0 else math.nan

    def plot(self, ax: Axes | None = None) -> Axes:
        """Block averages of the wall and virial pressures over time, with the ideal-gas value."""
        ax = new_axes(ax)
        time = np.asarray(self._time)[1:]
        if time.size == 0:  # one sample: no interval to average over yet
            return ax
        middle, _ = _blocks(time, np.ones_like(time))
        if not self.periodic:
            ax.plot(middle, _blocks(*self._wall_values())[0], "o-", label="wall")
        ax.plot(middle, _blocks(*self._virial_values())[0], "s-", label="virial")
        ax.axhline(self.n * self.temperature / self.area, color="gray", ls="--",
                   label="ideal gas N kT / A")  # fmt: skip
        ax.set_xlabel("time (s)")
        ax.set_ylabel("pressure (N/m)")
        ax.legend(fontsize="small")
        return ax

    def summary(self) -> dict[str, Any]:
        """Temperature, pressures and the compressibility factor, with their errors."""
        wall = self.wall_pressure()
        return {
            "temperature": self.temperature,
            "pressure": {
                "wall": None if self.periodic else wall["total"],
                "wall_error": None if self.periodic else self.wall_pressure_error(),
                "walls": None if self.periodic else {k: wall[k] for k in self.walls},
                "virial": self.virial_pressure(),
                "virial_error": self.virial_pressure_error(),
            },
            "compressibility": self.compressibility(),
            "compressibility_error": self.compressibility_error(),
        }
