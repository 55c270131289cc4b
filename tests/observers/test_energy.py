"""Energy series (the seed's Fig. 2 plot) and the drift of the total energy."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

import collidium as cd
from collidium.observers import EnergyDrift, EnergySeries, Every
from collidium.observers.energy import SEED_COLOURS

matplotlib.use("Agg")


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


@pytest.mark.slow
def test_series_records_the_orbit_exchanging_kinetic_and_potential_energy():
    sim = cd.load("orbit")
    series = EnergySeries(Every(10))
    sim.observers.append(series)
    sim.run(time=9.4)  # about one period
    assert series.time.shape == (95,)  # the start, then every 10 of 940 steps
    assert series.time[0] == 0.0 and series.time[-1] == pytest.approx(9.4)
    np.testing.assert_allclose(series.total, series.kinetic + series.potential)
    # Kinetic and potential energy swing by far more than the total moves.
    swing = np.ptp(series.kinetic)
    assert swing > 0.1 and np.ptp(series.total) < 1e-3 * swing
    assert series.max_rel_drift == pytest.approx(
        np.max(np.abs(series.total - series.total[0])) / abs(series.total[0])
    )
    # Opposite charges, equal masses, opposite velocities: the momentum stays zero.
    np.testing.assert_allclose(series.momentum, 0.0, atol=1e-12)
    speeds = np.hypot(*sim.particles.velocity.T).sum()
    assert series.total_speed[-1] == pytest.approx(speeds, rel=1e-15)


def test_compute_resets_unless_told_to_accumulate():
    sim = cd.load("head-on")
    series = EnergySeries().compute(sim)
    sim.run(steps=3)
    assert series.compute(sim, reset=False).time.shape == (2,)
    assert series.compute(sim).time.shape == (1,)
    assert series.summary()["initial_total"] == 25.0


def test_plot_uses_the_seed_colours():
    sim = cd.load("charged-like")
    series = EnergySeries(Every(5))
    sim.observers.append(series)
    sim.run(time=2.0)
    ax = Figure().add_subplot()
    series.plot(ax)
    colours = {line.get_label(): to_rgba(line.get_color()) for line in ax.get_lines()}
    for name in ("kinetic", "potential", "total"):
        assert colours[name] == to_rgba(SEED_COLOURS[name])
    assert ax.get_xlabel() == "time (s)"
    (speed_axis,) = [other for other in ax.figure.axes if other is not ax]
    (speed_line,) = speed_axis.get_lines()
    assert to_rgba(speed_line.get_color()) == to_rgba(SEED_COLOURS["total_speed"])
    np.testing.assert_array_equal(speed_line.get_ydata(), series.total_speed)
