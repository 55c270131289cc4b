"""Speed distribution: histogram, the 2D Maxwell-Boltzmann law, KS test, fitted temperature."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from scipy import stats

import collidium as cd
from collidium.errors import InputError
from collidium.observers import Interval, SpeedHistogram


def test_default_bins_are_the_seeds_thirty_of_one_metre_per_second():
    histogram = SpeedHistogram()
    np.testing.assert_array_equal(histogram.bin_edges, np.arange(31.0))


def test_counts_and_density_of_a_snapshot():
    sim = cd.load("gas")
    histogram = SpeedHistogram(bins=10, range=(0.0, 5.0)).compute(sim)
    speed = np.hypot(*sim.particles.velocity.T)
    np.testing.assert_array_equal(histogram.counts, np.histogram(speed, np.linspace(0, 5, 11))[0])
    # Speeds above the range still count in the total: the density integrates to the share inside.
    inside = np.mean(speed < 5.0)
    assert np.sum(histogram.density * 0.5) == pytest.approx(inside, rel=1e-12)
    assert histogram.temperature == pytest.approx(sim.energy().kinetic / 200, rel=1e-15)


def test_gas_relaxes_to_maxwell_boltzmann():
    """The seed's 3.1.3: uniform velocity components relax to the 2D law within seconds."""
    sim = cd.load("gas")
    start = SpeedHistogram().compute(sim)
    sim.run(time=20.0)
    relaxed = SpeedHistogram().compute(sim)
    assert start.ks()[1] < 1e-3  # components uniform in [-10, 10]: far from the law
    _, pvalue = relaxed.ks()
    assert pvalue > 0.01
    # The fit uses the histogram's shape only; it must find KE / N within its standard error.
    kT, error = relaxed.fit_temperature()
    assert abs(kT - sim.temperature()) < 3 * error
    assert error < 0.15 * kT


@pytest.mark.slow
def test_time_averaged_histogram_pins_the_temperature():
    """50 snapshots 1 s apart (6 mean free times) of 1000 disks: a 0.5% fit. (The finite-N
    correction of the microcanonical speed law, 2/N = 0.2%, stays below it.)"""
    sim = cd.load("gas", n=1000)
    sim.run(time=10.0)
    histogram = SpeedHistogram(trigger=Interval(1.0))
    sim.observers.append(histogram)
    sim.run(time=50.0)
    assert histogram.frames == 50
    kT, error = histogram.fit_temperature()
    assert error < 0.006 * kT
    assert abs(kT - sim.temperature()) < 3 * error
    assert histogram.ks()[1] > 0.01


def test_pool_break_ends_with_the_gas_distribution():
    """The seed's 4.1.1: one cue ball at 100 m/s into a rack at rest ends in the same distribution
    as the gas, once speeds are scaled by sqrt(kT / m)."""

    def scaled_speeds(sim):
        return np.hypot(*sim.particles.velocity.T) / np.sqrt(sim.temperature() / sim.particles.mass)

    pool = cd.load("pool-break").run(time=40.0)
    gas = cd.load("gas").run(time=20.0)
    assert stats.ks_2samp(scaled_speeds(pool), scaled_speeds(gas)).pvalue > 0.01
    assert SpeedHistogram(range=(0.0, 100.0)).compute(pool).ks()[1] > 0.01


def test_mixture_for_two_masses():
    """Light and heavy disks share one temperature: the pooled speeds follow the mixture, and
    fail a single-mass law."""
    sim = cd.load("gas", n=400)
    sim.particles.mass = np.where(np.arange(400) % 2 == 0, 16.0, 1.0)
    sim.particles.velocity[::2] /= 4.0
    sim.run(time=30.0)
    histogram = SpeedHistogram().compute(sim)
    assert histogram.ks()[1] > 0.01
    single = stats.kstest(histogram.speeds, stats.rayleigh(scale=np.sqrt(sim.temperature())).cdf)
    assert single.pvalue < 1e-3


def test_plot_draws_the_bars_and_the_law():
    sim = cd.load("gas").run(time=5.0)
    ax = SpeedHistogram().compute(sim).plot(Figure().add_subplot())
    assert len(ax.patches) == 30
    (curve,) = ax.get_lines()
    assert "Maxwell-Boltzmann" in curve.get_label()


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"bins": 0}, "bins"), ({"range": (5.0, 1.0)}, "range"), ({"range": (0, np.inf)}, "range")],
)
def test_bad_settings_name_the_field(kwargs, field):
    with pytest.raises(InputError) as caught:
        SpeedHistogram(**kwargs)
    assert caught.value.field == field
