"""Partitions: straight walls inside any vessel, with their own name, response and an optional
hole. Disks never cross a closed one in any engine, they cross through a hole, the event sequence
equals the brute-force twin's, and bad partitions are one line naming the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium import Box, Circle, InputError, Particles, Partition, Polygon, Simulation
from collidium.initial import random_positions
from collidium.kernels import reference
from collidium.scenario import Scenario
from collidium.vessels import Thermal, vessel_from_dict

DIVIDER = Partition("divider", (0.0, -10.0), (0.0, 10.0))


def split_gas(vessel, n: int = 200, seed: int = 2, collisions: str = "exact") -> Simulation:
    rng = np.random.default_rng(seed)
    position = random_positions(n, 0.2, vessel, rng)
    velocity = rng.normal(0.0, 3.0, (n, 2))
    return Simulation(vessel, Particles(position, velocity, radius=0.2), dt=0.1,
                      collisions=collisions)  # fmt: skip


def test_a_partition_is_a_wall_of_the_vessel():
    box = Box(20.0, 20.0, partitions=[DIVIDER])
    assert box.wall_names == ("left", "right", "bottom", "top", "divider")
    # Its contact line: both sides and the half circles round its two ends.
    assert box.contact_lengths(0.5)[-1] == pytest.approx(2 * 20 + 2 * math.pi * 0.5)
    assert box.available_area(0.5) == pytest.approx(19**2 - (2 * 0.5 * 20 + math.pi * 0.25))
    np.testing.assert_array_equal(box.partition_lines(), [[[0, -10], [0, 10]]])
    assert box.outside(np.array([[0.3, 0.0], [0.6, 0.0]]), np.array([0.5, 0.5])).tolist() == [0]
    again = vessel_from_dict(box.to_dict())
    assert again.partitions == (DIVIDER,) and again.to_dict() == box.to_dict()


def test_a_hole_splits_a_partition_in_two_pieces():
    wall = Partition("wall", (0.0, -10.0), (0.0, 10.0), gap=2.0, gap_at=0.75)
    np.testing.assert_allclose(wall.pieces(), [[[0, -10], [0, 4]], [[0, 6], [0, 10]]])
    # Two flat pieces and the points at their four ends.
    assert len(Box(20.0, 20.0, partitions=[wall]).segments()) == 6


def test_disks_never_cross_a_closed_partition_in_any_engine():
    for collisions in ("exact", "step", "off"):
        sim = split_gas(Box(20.0, 20.0, partitions=[DIVIDER]), collisions=collisions)
        left = sim.particles.position[:, 0] < 0
        energy = sim.energy().total
        sim.run(time=30.0)
        assert sim.counters.wall_hits["divider"] > 300, collisions
        assert ((sim.particles.position[:, 0] < 0) == left).all(), collisions
        assert abs(sim.energy().total - energy) <= 1e-12 * energy
        assert sim.escaped() == 0


def test_disks_cross_through_the_hole():
    wall = Partition("wall", (0.0, -10.0), (0.0, 10.0), gap=3.0)
    sim = split_gas(Box(20.0, 20.0, partitions=[wall]))
    left = sim.particles.position[:, 0] < 0
    sim.run(time=30.0)
    crossed = (sim.particles.position[:, 0] < 0) != left
    assert crossed.sum() > 10 and sim.escaped() == 0


def test_the_engine_matches_the_brute_force_twin_with_a_partition_and_its_ends(rng):
    """A partition with a hole in a box: hits on its sides and, for a disk aimed at it, on the
    end of a piece. A short run (~50 events), so that round-off, which grows by a factor of
    order (free path / diameter) per collision, stays far below the tolerance."""
    wall = Partition("wall", (-2.0, -5.0), (-2.0, 3.0), gap=1.5)
    box = Box(10.0, 10.0, partitions=[wall])
    aimed = np.array([[2.0, -0.5]])  # straight at the top end (-2, -1.75) of the lower piece
    n = 20
    radius = np.full(n + 1, 0.3)
    position = np.vstack([aimed, random_positions(n, 0.3, box, rng, existing=aimed,
                                                  existing_radius=0.3)])  # fmt: skip
    velocity = np.vstack([[[-8.0, -2.5]], rng.uniform(-10, 10, (n, 2))])
    mass = rng.uniform(0.5, 2.0, n + 1)
    sim = Simulation(box, Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
                     dt=0.25)  # fmt: skip
    sim.run(steps=4)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, virial, impulse = reference.event_drift(
        twin_position, twin_velocity, mass, radius, np.array([5.0, 5.0]), 1.0,
        table=box.segments(),
    )  # fmt: skip
    assert pairs > 10 and impulse[4:6].sum() > 0 and impulse[6:].sum() > 0  # sides and an end
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    np.testing.assert_allclose(sim.tally.impulse, [virial, *impulse[:4], impulse[4:].sum()],
                               rtol=1e-9)  # fmt: skip
    np.testing.assert_allclose(sim.particles.position, twin_position, atol=1e-9)


def test_a_thermal_partition_in_a_circle_books_its_heat():
    hot = Partition("heater", (-3.0, 0.0), (3.0, 0.0))
    circle = Circle(10.0, partitions=[hot], walls={"heater": Thermal(20.0)})
    sim = split_gas(circle, n=100).run(time=20.0)
    assert sim.wall_heat()["heater"] > 0 and sim.wall_heat()["rim"] == 0
    total = sim.energy().total - sim.wall_heat()["heater"]
    assert total == pytest.approx(split_gas(circle, n=100).energy().total, rel=1e-12)


def test_a_partition_in_a_scenario_file():
    text = """
[vessel]
shape = "polygon"
vertices = [[-10, -5], [10, -5], [10, 5], [-10, 5]]

[[vessel.partitions]]
name = "middle"
start = [0, -5]
end = [0, 5]
gap = 1.0

[vessel.walls.middle]
response = "inelastic"
restitution = 0.5

[[particles]]
kind = "random"
n = 20
"""
    scenario = Scenario.from_toml_string(text)
    vessel = scenario.build().container
    assert isinstance(vessel, Polygon) and vessel.wall_names[-1] == "middle"
    assert vessel.partitions[0].gap == 1.0 and "middle" in vessel.walls
    assert Scenario.from_toml_string(scenario.to_toml()) == scenario


@pytest.mark.parametrize(
    ("vessel", "partition", "field", "reason"),
    [
        (dict(width=20, height=20), dict(name="p", start=[0, -12], end=[0, 5]),
         "vessel.partitions.p", "must lie inside the 20 x 20 box"),
        (dict(shape="polygon", vertices=[[0, 0], [10, 0], [10, 4], [4, 4], [4, 10], [0, 10]]),
         dict(name="p", start=[2, 2], end=[8, 8]), "vessel.partitions.p", "must lie inside"),
        (dict(width=20, height=20), dict(name="left", start=[0, 0], end=[1, 0]),
         "vessel.partitions.left", "already a wall's"),
        (dict(width=20, height=20), dict(name="p", start=[0, 0], end=[0, 0]),
         "vessel.partitions.p", "start and end must differ"),
        (dict(width=20, height=20), dict(name="p", start=[0, 0], end=[0, 2], gap=2.0),
         "vessel.partitions.p.gap", "shorter than the partition"),
        (dict(width=20, height=20), dict(name="p", start=[0, 0], end=[0, 2], gap=1.0, gap_at=0.1),
         "vessel.partitions.p.gap", "within the partition"),
        (dict(width=20, height=20, boundary="periodic"), dict(name="p", start=[0, 0], end=[0, 2]),
         "vessel.partitions", "periodic box has no walls"),
    ],
)  # fmt: skip
def test_a_bad_partition_names_the_field(vessel, partition, field, reason):
    data = {"vessel": vessel | {"partitions": [partition]},
            "particles": [{"kind": "random", "n": 2}]}  # fmt: skip
    with pytest.raises(InputError) as info:
        Scenario.from_dict(data).build()
    assert info.value.field == field and reason in info.value.reason
