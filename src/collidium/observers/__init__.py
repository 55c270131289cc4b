"""Observers: measurements taken during a run, each fired by a trigger."""

from collidium.observers.base import Every, Observer, Trigger
from collidium.observers.energy import EnergyDrift

__all__ = ["EnergyDrift", "Every", "Observer", "Trigger"]
