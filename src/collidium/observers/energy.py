"""Energy bookkeeping during a run."""

from __future__ import annotations

from typing import TYPE_CHECKING

from collidium.observers.base import Every, Trigger

if TYPE_CHECKING:
    from collidium.simulation import Simulation


class EnergyDrift:
    """Largest relative change of the total energy seen during a run.

    Parameters
    ----------
    trigger : callable, optional
        When to sample (default every step).

    Attributes
    ----------
    initial_total : float
        Total energy in J when attached.
    max_rel_drift : float
        ``max |E(t) - E(0)| / |E(0)|`` over the samples (relative to ``max(|E(0)|, tiny)``).
    """

    def __init__(self, trigger: Trigger | None = None) -> None:
        self.trigger: Trigger = trigger or Every(1)
        self.initial_total = float("nan")
        self.max_rel_drift = 0.0

    def attach(self, sim: Simulation) -> None:
        """Record the starting total energy."""
        self.initial_total = sim.energy().total
        self.max_rel_drift = 0.0

    def update(self, sim: Simulation) -> None:
        """Fold the current total energy into the running maximum."""
        scale = max(abs(self.initial_total), 1e-300)
        drift = abs(sim.energy().total - self.initial_total) / scale
        self.max_rel_drift = max(self.max_rel_drift, drift)
