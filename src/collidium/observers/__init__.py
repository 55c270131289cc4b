"""Observers: measurements taken during a run, each fired by a trigger.

Attach one with ``sim.observers.append(obs)`` (or list it in a scenario file); the run loop calls
``obs.update(sim)`` after each step on which ``obs.trigger(sim)`` is true. Each measurement can
also be used on its own, freud-style: ``obs.compute(sim)`` returns the observer, ``reset=False``
accumulates, ``obs.plot(ax)`` draws it.
"""

from collidium.observers.base import (
    After,
    Every,
    Flown,
    Interval,
    Measurement,
    Observer,
    Trigger,
    foreseeable,
)
from collidium.observers.counters import CollisionRate
from collidium.observers.effusion import Effusion
from collidium.observers.energy import EnergyDrift, EnergySeries
from collidium.observers.paths import Tracer
from collidium.observers.profile import TemperatureProfile
from collidium.observers.speeds import SpeedHistogram
from collidium.observers.thermo import Thermo
from collidium.observers.virial import VirialRatio

__all__ = [
    "After",
    "CollisionRate",
    "Effusion",
    "EnergyDrift",
    "EnergySeries",
    "Every",
    "Flown",
    "Interval",
    "Measurement",
    "Observer",
    "SpeedHistogram",
    "TemperatureProfile",
    "Thermo",
    "Tracer",
    "Trigger",
    "VirialRatio",
    "foreseeable",
]
