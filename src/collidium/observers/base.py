"""Triggers and the observer protocol (HOOMD-style: an operation fired by a trigger)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from collidium.errors import InputError

if TYPE_CHECKING:
    from collidium.simulation import Simulation

Trigger = Callable[[int], bool]


@dataclass(frozen=True)
class Every:
    """Trigger that fires every ``period`` steps (step 0 excluded).

    Parameters
    ----------
    period : int
        Steps between firings, >= 1.
    """

    period: int = 1

    def __post_init__(self) -> None:
        if isinstance(self.period, bool) or not isinstance(self.period, int) or self.period < 1:
            raise InputError("trigger.period", f"must be a whole number >= 1, got {self.period!r}")

    def __call__(self, step: int) -> bool:
        return step % self.period == 0


@runtime_checkable
class Observer(Protocol):
    """What the run loop calls: ``attach`` once before the first step, then ``update`` whenever
    ``trigger(sim.steps)`` is true after a step."""

    trigger: Trigger

    def attach(self, sim: Simulation) -> None:
        """Called when the observer first sees the simulation."""

    def update(self, sim: Simulation) -> None:
        """Called after a step on which the trigger fires."""
