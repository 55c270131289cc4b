"""Energy bookkeeping: the series the seed plots (Fig. 2) and the drift of the total."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from collidium.observers.base import Flown, Measurement, Trigger, new_axes
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Energy, Simulation

#: The seed's colours (Fig. 2): kinetic blue, total speed green, potential pink, total black.
SEED_COLOURS = {"kinetic": "tab:blue", "total_speed": "tab:green", "potential": "tab:pink",
                "total": "black"}  # fmt: skip

_COLUMNS = ("time", "kinetic", "potential", "total_speed", "px", "py")


class EnergySeries(Measurement):
    """Kinetic, potential and total energy, total speed and momentum over time.

    Parameters
    ----------
    trigger : callable or int, optional
        When to sample (default every step).

    Attributes
    ----------
    time, kinetic, potential, total, total_speed : ndarray, shape (K,)
        One value per sample: s, J, J, J, m/s.
    momentum : ndarray, shape (K, 2)
        Total momentum in kg m/s.
    """

    def __init__(self, trigger: Trigger | int | None = None) -> None:
        super().__init__(trigger)
        self._rows: list[tuple[float, ...]] = []

    def _start(self, sim: Simulation) -> None:
        self._rows = []

    def _sample(self, sim: Simulation) -> None:
        e = sim.energy()
        px, py = sim.momentum()
        self._rows.append((sim.time, e.kinetic, e.potential, sim.total_speed(), px, py))

    def take_flown(self, sim: Simulation, flown: Flown) -> None:
        """Samples of steps the run flew in one compiled call (`Flown`), as `update` after
        each."""
        columns = (flown.time, flown.kinetic, flown.potential, flown.total_speed, flown.px,
                   flown.py)  # fmt: skip
        self._rows += zip(*(column.tolist() for column in columns), strict=True)
        self.samples += flown.time.shape[0]

    def _column(self, name: str) -> FloatArray:
        table = np.asarray(self._rows, dtype=float).reshape(-1, len(_COLUMNS))
        return table[:, _COLUMNS.index(name)]

    @property
    def time(self) -> FloatArray:
        """Sample times in s."""
        return self._column("time")

    @property
    def kinetic(self) -> FloatArray:
        """Kinetic energy in J."""
        return self._column("kinetic")

    @property
    def potential(self) -> FloatArray:
        """Potential energy in J."""
        return self._column("potential")

    @property
    def total(self) -> FloatArray:
        """Kinetic plus potential energy in J."""
        return self.kinetic + self.potential

    @property
    def total_speed(self) -> FloatArray:
        """Sum of the speeds in m/s."""
        return self._column("total_speed")

    @property
    def momentum(self) -> FloatArray:
        """Total momentum (K, 2) in kg m/s."""
        return np.stack([self._column("px"), self._column("py")], axis=1)

    @property
    def max_rel_drift(self) -> float:
        """Largest ``|E(t) - E(t0)| / |E(t0)|`` over the samples (0 with fewer than two)."""
        total = self.total
        if total.size == 0:
            return 0.0
        return float(np.max(np.abs(total - total[0])) / max(abs(total[0]), 1e-300))

    def plot(self, ax: Axes | None = None) -> Axes:
        """Energies against time in the seed's colours; total speed on a second axis (green)."""
        return plot_energy(ax, self.time, self.kinetic, self.potential, self.total_speed)

    def summary(self) -> dict[str, Any]:
        """Last sample and the largest relative drift of the total energy."""
        if not self._rows:
            return {}
        last = dict(zip(_COLUMNS, self._rows[-1], strict=True))
        return {
            "kinetic": last["kinetic"],
            "potential": last["potential"],
            "total": last["kinetic"] + last["potential"],
            "initial_total": float(self.total[0]),
            "max_rel_drift": self.max_rel_drift,
        }


def plot_energy(
    ax: Axes | None,
    time: FloatArray,
    kinetic: FloatArray,
    potential: FloatArray,
    total_speed: FloatArray,
    speed_ax: Axes | None = None,
) -> Axes:
    """The seed's energy plot: kinetic (blue), potential (pink) and total (black) energy in J
    against time in s, and the total speed (green, m/s) on ``speed_ax`` (a small panel of its
    own), or on a second axis of ``ax`` without one. Returns ``ax``.

    The total is drawn first and wide, the others dashed over it, so that a kinetic energy equal
    to the total (a neutral gas) stays visible."""
    ax = new_axes(ax)
    ax.plot(time, kinetic + potential, color=SEED_COLOURS["total"], label="total", linewidth=3.0,
            alpha=0.6, zorder=1)  # fmt: skip
    for name, values in (("kinetic", kinetic), ("potential", potential)):
        ax.plot(time, values, color=SEED_COLOURS[name], label=name, linestyle="--", zorder=2)
    ax.set_ylabel("energy (J)")
    green = SEED_COLOURS["total_speed"]
    if speed_ax is None:
        ax.set_xlabel("time (s)")
        speed_axis = cast("Axes", ax.twinx())  # typed as a base class by Matplotlib 3.8
        speed_axis.plot(time, total_speed, color=green, label="total speed")
        speed_axis.set_ylabel("total speed (m/s)", color=green)
        lines = ax.get_lines() + speed_axis.get_lines()
    else:
        speed_ax.plot(time, total_speed, color=green, label="total speed")
        speed_ax.set_xlabel("time (s)")
        speed_ax.set_ylabel("total speed\n(m/s)", color=green, fontsize="small")
        lines = ax.get_lines()
    ax.legend(lines, [str(line.get_label()) for line in lines], loc="lower right", fontsize="small")
    return ax


#: Largest relative energy drift a run reports without a warning (the command line's
#: ``--max-drift`` sets another and makes passing it a failure; the viewer marks its readout).
#: The adaptive integrator keeps the seed scenes below 1e-5.
DRIFT_WARNING = 1e-3


def drift_warning(drift: float, limit: float = DRIFT_WARNING) -> str | None:
    """One line saying that the total energy drifted by ``drift`` (relative) past ``limit``, or
    None (also when the drift cannot be measured: NaN, a zero initial energy)."""
    if not (math.isfinite(drift) and abs(drift) > limit):
        return None
    return (
        f"the total energy drifted by {abs(drift):.3g} of its initial value (limit {limit:g}): "
        "try a smaller run.tolerance, or a smaller dt with the fixed integrator"
    )


class EnergyDrift(Measurement):
    """Largest relative change of the total energy during a run, without storing a series.

    What is conserved is the total energy less what the walls, collisions and velocity forces
    have given the disks (`conserved_energy`), so that is what is measured.

    Parameters
    ----------
    trigger : callable or int, optional
        When to sample (default every step).
    reference : float, optional
        Energy to measure the drift from, J (default: the first sample's); a resumed run passes
        the energy at the start of the whole run.

    Attributes
    ----------
    initial_total : float
        The reference energy in J (less the walls' heat until then).
    max_rel_drift : float
        ``max |E(t) - Q(t) - E_ref| / |E_ref|`` over the samples, Q the heat given.
    """

    def __init__(
        self, trigger: Trigger | int | None = None, reference: float | None = None
    ) -> None:
        super().__init__(trigger)
        self.reference = reference
        self.initial_total = float("nan")
        self.max_rel_drift = 0.0

    def _start(self, sim: Simulation) -> None:
        """Measure from the current energy (or the reference)."""
        self.initial_total = conserved_energy(sim) if self.reference is None else self.reference
        self.max_rel_drift = 0.0

    def _sample(self, sim: Simulation) -> None:
        self._take(conserved_energy(sim))

    def take_flown(self, sim: Simulation, flown: Flown) -> None:
        """Samples of steps the run flew in one compiled call (`Flown`): the same as `update`
        after each."""
        totals = (flown.kinetic + flown.potential).tolist()
        for total, heat, forces in zip(totals, flown.heat, flown.forces.tolist(), strict=True):
            self._take(total - given_energy(heat, forces))
        self.samples += flown.time.shape[0]

    def _take(self, conserved: float) -> None:
        scale = max(abs(self.initial_total), 1e-300)
        drift = abs(conserved - self.initial_total) / scale
        self.max_rel_drift = max(self.max_rel_drift, drift)

    def summary(self) -> dict[str, Any]:
        """Initial total energy and largest relative drift."""
        return {"initial_total": self.initial_total, "max_rel_drift": self.max_rel_drift}


def conserved_energy(sim: Simulation, energy: Energy | None = None) -> float:
    """The total energy less the energy the walls, inelastic collisions and velocity forces (drag,
    a thermostat) have given the disks since the start, J: what the dynamics conserve (the total
    energy itself with mirror walls, elastic disks and no velocity forces). ``energy``:
    `Simulation.energy` now, if the caller has it already (the pair sum is O(N^2))."""
    return (sim.energy() if energy is None else energy).total - _given(sim)


def _given(sim: Simulation) -> float:
    """The energy the walls, inelastic collisions and velocity forces have given the disks, J."""
    return given_energy(sim.tally.heat, sim.force_heat())


def given_energy(heat: FloatArray, forces: float) -> float:
    """The energy given to the disks, J, from a tally's ``heat`` (1 + W,) (the inelastic
    collisions', then each wall's) and the velocity forces' (``forces``), summed as
    `Simulation.wall_heat`, `Simulation.collision_heat` and `Simulation.force_heat` give them."""
    walls = sum(float(value) for value in heat[1:])
    return float(walls + float(heat[0]) + forces)
