"""Never an escape: every shape (a polygon with reflex corners included), a dense gas (packing
0.6) started on a hexagonal lattice with one disk at 1000 m/s, ten million collisions."""

from __future__ import annotations

import math

import pytest

from collidium import Box, Circle, Particles, Polygon, Simulation
from collidium.initial import hexagonal_positions

RADIUS = 0.25
PACKING = 0.6


#: A five-pointed star: five reflex corners.
STAR = Polygon([
    [r * math.cos(math.pi / 2 + k * math.pi / 5), r * math.sin(math.pi / 2 + k * math.pi / 5)]
    for k, r in zip(range(10), [20.0, 9.0] * 5, strict=True)
])  # fmt: skip


@pytest.mark.parametrize(
    "vessel", [Box(24.0, 24.0), Circle(13.5), STAR], ids=["box", "circle", "star"]
)
@pytest.mark.slow
def test_ten_million_collisions_at_packing_0_6_with_a_disk_at_1000_m_per_s(vessel, rng):
    position = hexagonal_positions(vessel, RADIUS, PACKING)
    n = len(position)
    velocity = rng.normal(0.0, 1.0, (n, 2))
    velocity[n // 2] = [1000.0 * math.cos(0.3), 1000.0 * math.sin(0.3)]
    sim = Simulation(vessel, Particles(position, velocity, radius=RADIUS), dt=1.0)
    assert math.pi * RADIUS**2 * n / vessel.available_area(RADIUS) > 0.55  # dense
    energy = sim.energy().total
    while sim.counters.pair_collisions < 10_000_000:
        sim.run(steps=1)  # the audit checks after every step that nobody left
    assert sim.escaped() == 0
    assert sim.counters.wall_collisions > 10_000
    # Ten million roundings of ~1e-16 relative each, as a random walk.
    assert abs(sim.energy().total - energy) <= 1e-12 * energy
