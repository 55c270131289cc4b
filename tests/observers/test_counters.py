"""Collision rate and mean free time against equilibrium theory."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from test_thermo import hard_disk_fluid

import collidium as cd
from collidium.observers import CollisionRate, Thermo


@pytest.mark.parametrize("packing", [0.05, 0.3])
def test_collision_frequency_matches_the_contact_value_from_the_pressure(packing):
    """Per disk, nu = 2 n sigma sqrt(pi kT / m) g(sigma) (impact parameters span 2 sigma; the mean
    relative speed is sqrt(pi kT / m)); and Z = 1 + 2 eta g(sigma). Both are exact in equilibrium:
    the collision count and the virial measure the same contact value g(sigma) independently."""
    sim = hard_disk_fluid(packing)
    rate, thermo = CollisionRate(), Thermo()
    sim.observers += [rate, thermo]
    sim.run(time=500.0)
    n, sigma = sim.particles.n, 1.0
    density = n / thermo.area
    contact = (thermo.compressibility() - 1) / (2 * packing)
    nu = 2 * rate.rate / n
    expected = 2 * density * sigma * np.sqrt(np.pi * thermo.temperature) * contact
    collisions = rate.rate * thermo.duration
    z_error = thermo.virial_pressure_error() * thermo.area / (n * thermo.temperature)
    spread = np.hypot(1 / np.sqrt(collisions), z_error / (thermo.compressibility() - 1))
    assert abs(nu / expected - 1) < 4 * spread
    assert rate.mean_free_time == pytest.approx(1 / nu, rel=1e-12)
    assert rate.mean_free_path == pytest.approx(
        np.mean(np.hypot(*sim.particles.velocity.T)) / nu, rel=0.02
    )


def test_counts_follow_the_simulation_counters_per_wall():
    sim = cd.load("gas")
    rate = CollisionRate()
    sim.observers.append(rate)
    before = sim.counters
    sim.run(time=10.0)
    after = sim.counters
    assert rate.pair_collisions[-1] == after.pair_collisions - before.pair_collisions
    for wall, per_second in rate.wall_rates.items():
        assert per_second * 10.0 == pytest.approx(after.wall_hits[wall] - before.wall_hits[wall])
    assert np.all(np.diff(rate.pair_collisions) >= 0)
    ax = rate.plot(Figure().add_subplot())
    assert ax.get_ylabel() == "pair collisions"


def test_no_collisions_means_an_infinite_mean_free_time():
    rate = CollisionRate()
    sim = cd.load("charged-no-collisions")
    sim.observers.append(rate)
    sim.run(time=1.0)
    assert rate.rate == 0.0
    assert rate.mean_free_time == np.inf
