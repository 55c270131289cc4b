"""Effusion: crossings of a partition counted through its hole only, per species, the share
that has crossed, Graham's ratio; errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium import InputError, Particles, Simulation
from collidium.observers import Effusion
from collidium.vessels import Box, Partition


def divided(position, velocity, mass, radius=0.1, gap=2.0):
    """Disks in a 20 m x 10 m box cut at x = 0 by a partition with a hole about y = 0."""
    box = Box(20, 10, partitions=[Partition("divider", (0.0, -5.0), (0.0, 5.0), gap=gap)])
    particles = Particles(position=np.array(position, float), velocity=np.array(velocity, float),
                          mass=np.array(mass, float), radius=radius)  # fmt: skip
    sim = Simulation(box, particles, dt=0.01)
    effusion = Effusion("divider")
    sim.observers.append(effusion)
    return sim, effusion


def test_a_disk_through_the_hole_crosses_and_one_against_the_wall_does_not():
    # Disk 0 flies through the hole and back after the right wall (10 m away): two crossings
    # in 12 s. Disk 1 hits the partition's wall at y = 3 and bounces back: none.
    sim, effusion = divided([[-2.0, 0.0], [-2.0, 3.0]], [[2.0, 0.0], [2.0, 0.0]], [1.0, 4.0])
    sim.run(time=2.0)
    assert effusion.crossings.tolist() == [1, 0]
    np.testing.assert_array_equal(effusion.escaped[-1], [1.0, 0.0])
    sim.run(time=10.0)
    assert effusion.crossings.tolist() == [2, 0] and sim.counters.wall_hits["divider"] >= 2
    np.testing.assert_allclose(effusion.rates, [2 / 12.0, 0.0])
    assert effusion.graham == 2.0 and math.isinf(effusion.ratio)
    summary = effusion.summary()
    assert summary["masses"] == [1.0, 4.0] and summary["crossings"] == [2, 0]
    assert summary["counts"] == [1, 1] and effusion.plot() is not None


def test_species_are_the_distinct_masses_and_each_is_counted_apart():
    # Three light disks cross once each (the hole is 6 m wide), one heavy one twice.
    position = [[-1.0, -2.0], [-1.0, 0.0], [-1.0, 2.0], [-3.0, 1.0]]
    velocity = [[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [3.0, 0.0]]
    sim, effusion = divided(position, velocity, [1.0, 1.0, 1.0, 9.0], gap=6.0)
    sim.run(time=9.0)  # the heavy one comes back from the right wall at t = 19/3 s
    np.testing.assert_array_equal(effusion.masses, [1.0, 9.0])
    assert effusion.counts.tolist() == [3, 1] and effusion.crossings.tolist() == [3, 2]
    np.testing.assert_allclose(effusion.rates, [1 / 9.0, 2 / 9.0])
    assert effusion.ratio == pytest.approx(0.5) and effusion.graham == 3.0
    assert effusion.ratio_error == pytest.approx(0.5 * math.sqrt(1 / 3 + 1 / 2))
    np.testing.assert_array_equal(effusion.escaped[-1], [1.0, 0.0])


def test_a_single_species_has_no_ratio():
    sim, effusion = divided([[-2.0, 0.0]], [[2.0, 0.0]], [1.0])
    sim.run(time=2.0)
    assert math.isnan(effusion.ratio) and math.isnan(effusion.graham)
    assert effusion.summary()["crossings"] == [1]


def test_an_unknown_partition_is_refused_naming_it():
    sim, _ = divided([[-2.0, 0.0]], [[2.0, 0.0]], [1.0])
    with pytest.raises(InputError) as info:
        Effusion("door").compute(sim)
    assert info.value.field == "partition" and "'door' (it has: divider)" in info.value.reason
    with pytest.raises(InputError):
        Effusion(3)  # type: ignore[arg-type]
