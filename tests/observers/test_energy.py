"""EnergyDrift: the largest relative change of the total energy during a run."""

from __future__ import annotations

import pytest

import collidium as cd
from collidium.observers import EnergyDrift, Every


def test_drift_is_zero_for_exact_force_free_run():
    sim = cd.load("head-on")
    drift = EnergyDrift()
    sim.observers.append(drift)
    sim.run(time=2.0)
    assert drift.initial_total == 25.0
    assert drift.max_rel_drift == 0.0


def test_drift_sees_the_largest_deviation_over_the_run():
    sim = cd.load("orbit", dt=0.05)
    every_step, sparse = EnergyDrift(), EnergyDrift(Every(50))
    sim.observers += [every_step, sparse]
    sim.run(time=10.0)
    final = abs(sim.energy().total - every_step.initial_total) / abs(every_step.initial_total)
    assert every_step.max_rel_drift >= final
    assert every_step.max_rel_drift >= sparse.max_rel_drift > 0.0
    assert every_step.initial_total == pytest.approx(-0.89, rel=1e-12)  # 0.36 J - 5/4 J
