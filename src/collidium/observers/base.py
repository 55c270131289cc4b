"""Triggers and the observer base class (HOOMD-style: an operation fired by a trigger; freud-style:
``compute() -> self``, ``reset=False`` accumulates, ``.plot(ax)``)."""

from __future__ import annotations

import math
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, Self, runtime_checkable

import numpy as np

from collidium.errors import InputError
from collidium.state import BoolArray, FloatArray, IntArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from collidium.simulation import Simulation

#: A trigger is called with the simulation after each step and says whether to fire.
Trigger = Callable[["Simulation"], bool]


def _whole(value: object, field: str, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise InputError(field, f"must be a whole number >= {least}, got {value!r}")
    return value


def _duration(value: object, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(field, f"must be a finite number, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Every:
    """Fires every ``period`` steps (on steps ``period, 2 period, ...``).

    Parameters
    ----------
    period : int
        Steps between firings, >= 1.
    """

    period: int = 1

    def __post_init__(self) -> None:
        _whole(self.period, "trigger.period", 1)

    def __call__(self, sim: Simulation) -> bool:
        return sim.steps % self.period == 0


@dataclass(frozen=True)
class Interval:
    """Fires on the first step at or past each multiple of ``seconds`` of simulated time.

    Parameters
    ----------
    seconds : float
        Simulated time between firings in s, > 0.
    """

    seconds: float

    def __post_init__(self) -> None:
        if _duration(self.seconds, "trigger.interval") <= 0:
            raise InputError("trigger.interval", f"must be > 0, got {self.seconds!r}")

    def __call__(self, sim: Simulation) -> bool:
        # A relative slack keeps times that are multiples up to round-off on the right side.
        slack = 1e-9
        now = math.floor(sim.time / self.seconds + slack)
        before = math.floor((sim.time - sim.dt) / self.seconds + slack)
        return now > before


@dataclass(frozen=True)
class After:
    """Fires once the simulated time has reached ``time``, whenever ``then`` fires.

    Parameters
    ----------
    time : float
        Start time in s.
    then : callable, optional
        Trigger applied from then on (default: every step).
    """

    time: float
    then: Trigger = Every(1)

    def __post_init__(self) -> None:
        _duration(self.time, "trigger.after")

    def __call__(self, sim: Simulation) -> bool:
        return sim.time >= self.time * (1 - 1e-12) and self.then(sim)


@dataclass(frozen=True)
class _Ahead:
    """A run's clock at a step to come: all that `Every`, `Interval` and `After` read of it."""

    steps: int
    time: float
    dt: float


def foreseeable(trigger: Trigger) -> bool:
    """Whether when ``trigger`` fires depends on the run's clock alone (its steps, time and dt):
    `Every`, `Interval`, and `After` of such a trigger. A run then knows in advance the steps
    it fires on (`fires_at`), and flies the steps before them in one call."""
    if isinstance(trigger, After):
        return foreseeable(trigger.then)
    return isinstance(trigger, Every | Interval)


def fires_at(trigger: Trigger, steps: IntArray, times: FloatArray, dt: float) -> BoolArray:
    """Whether a `foreseeable` ``trigger`` fires after each of the ``steps`` (K,), which end at
    ``times`` (K,) in s (as `collidium.simulation.Simulation.time` counts them), ``dt`` s long."""
    if isinstance(trigger, Every):
        return np.asarray(steps % trigger.period == 0)
    ahead = typing.cast(Callable[[_Ahead], bool], trigger)
    clocks = zip(steps.tolist(), times.tolist(), strict=True)
    return np.array([ahead(_Ahead(step, time, dt)) for step, time in clocks], dtype=bool)


def as_trigger(trigger: Trigger | int | None) -> Trigger:
    """A trigger from a trigger, a whole number of steps (`Every`) or None (every step)."""
    if trigger is None:
        return Every(1)
    if isinstance(trigger, int) and not isinstance(trigger, bool):
        return Every(trigger)
    if not callable(trigger):
        raise InputError(
            "trigger", f"must be a whole number of steps or a callable, got {trigger!r}"
        )
    return trigger


@dataclass(frozen=True)
class Flown:
    """What a run records of the steps it flew in one compiled call (`Simulation.run`: exact
    collisions without forces or under a gravity alone, or a small charged scene), at those an
    observer's trigger fired on, as `Simulation` gives them at each. The vessel did not change in
    between (a flight with a piston has no steps an observer reads). Arrays of K rows, one per
    step.

    Attributes
    ----------
    time : ndarray, shape (K,)
        Simulated time in s.
    kinetic, potential, virial : ndarray, shape (K,)
        Kinetic and potential energy and pair virial in J (`Simulation.energy`,
        `Simulation.virial`).
    px, py : ndarray, shape (K,)
        Total momentum in kg m/s.
    total_speed : ndarray, shape (K,)
        Sum of the speeds in m/s.
    counts, impulse, heat : ndarray, shape (K, 1 + W)
        The tallies (`collidium.collisions.Tally`): collisions and wall hits, the collision
        virial and the walls' impulses, the heat given.
    forces : ndarray, shape (K,)
        The energy the velocity forces have given, J (`Simulation.force_heat`).
    """

    time: FloatArray
    kinetic: FloatArray
    potential: FloatArray
    virial: FloatArray
    px: FloatArray
    py: FloatArray
    total_speed: FloatArray
    counts: IntArray
    impulse: FloatArray
    heat: FloatArray
    forces: FloatArray


@runtime_checkable
class Observer(Protocol):
    """What the run loop calls: ``attach`` once before the first step, then ``update`` after each
    step on which ``trigger(sim)`` is true.

    An observer whose trigger is `foreseeable` and that reads no more than a `Flown` holds may
    also have ``take_flown(sim, flown)``: a run then flies the steps between the other
    observers' firings in one compiled call where it can and hands it what it would have read
    at each of its own (`EnergyDrift`, `EnergySeries`, `Thermo`, `CollisionRate` do). Such an
    observer only reads: the run may fly past it, and takes the particles after its ``update``
    to be as the step left them."""

    trigger: Trigger

    def attach(self, sim: Simulation) -> None:
        """Called when the observer first sees the simulation."""

    def update(self, sim: Simulation) -> None:
        """Called after a step on which the trigger fires."""


class Measurement:
    """Base of the measuring observers.

    A subclass implements `compute`; `update` (called by the run loop) is ``compute(sim,
    reset=False)``, so attached to a simulation a measurement accumulates over the run, while a
    direct ``compute(sim)`` measures the current state afresh. A measurement over a time window
    (``baseline = True``: series, averages, rates) takes its first sample when the run starts, or,
    under an `After` trigger, when that time comes.

    Parameters
    ----------
    trigger : callable or int, optional
        When the run loop samples: a trigger, a number of steps, or None for every step.
    """

    #: Whether the state when the run starts is the first sample (the start of the window).
    baseline = True

    def __init__(self, trigger: Trigger | int | None = None) -> None:
        self.trigger: Trigger = as_trigger(trigger)
        #: Samples taken since the last reset.
        self.samples = 0

    def attach(self, sim: Simulation) -> None:
        """Take the first sample when a run starts, unless samples were taken already or the
        trigger waits for a later time."""
        waiting = isinstance(self.trigger, After) and sim.time < self.trigger.time * (1 - 1e-12)
        if self.baseline and not self.sampled and not waiting:
            self.compute(sim)

    def update(self, sim: Simulation) -> None:
        """Add a sample (called by the run loop); the first one starts afresh."""
        self.compute(sim, reset=not self.sampled)

    @property
    def sampled(self) -> bool:
        """True once at least one sample was taken."""
        return self.samples > 0

    def compute(self, sim: Simulation, reset: bool = True) -> Self:
        """Sample the simulation; ``reset=False`` adds to the samples taken so far (the first
        sample always starts afresh)."""
        if reset or not self.sampled:
            self.samples = 0
            self._start(sim)
        self._sample(sim)
        self.samples += 1
        return self

    def _start(self, sim: Simulation) -> None:
        """Forget earlier samples; note what stays fixed over a window."""
        raise NotImplementedError

    def _sample(self, sim: Simulation) -> None:
        """Take one sample."""
        raise NotImplementedError

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the measurement on ``ax`` (a new figure if None) and return the axes."""
        raise NotImplementedError

    def summary(self) -> dict[str, Any]:
        """Plain numbers describing the measurement (for JSON)."""
        raise NotImplementedError


def new_axes(ax: Axes | None) -> Axes:
    """``ax``, or the axes of a new matplotlib figure."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, created = plt.subplots()
    return created
