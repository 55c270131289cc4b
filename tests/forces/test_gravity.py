"""Gravity: Newton's attraction (direct and tree, against the NumPy twin and a two-body orbit)
and uniform free fall (the parabola, bounces, a gas with collisions)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import Box, Gravity, Newton, Particles
from collidium.forces import ForceField
from collidium.integrators import DEFAULT_TOLERANCE
from collidium.kernels import reference


def _cluster(n: int, seed: int = 2) -> Particles:
    rng = np.random.default_rng(seed)
    return Particles(rng.uniform(-50, 50, (n, 2)), mass=rng.uniform(0.5, 2.0, n), radius=0.0)


def test_newton_is_the_twin_with_masses_and_minus_g():
    particles = _cluster(300)
    force = ForceField((Newton(G=3.0, softening=0.2, method="direct"),)).evaluate(
        particles, Box(200, 200)
    ) * particles.mass[:, None]  # fmt: skip
    want, _, _ = reference.inverse_distance_direct(particles.position, particles.mass, -3.0, 0.04)
    np.testing.assert_allclose(force, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


def test_newton_attracts():
    particles = Particles([[-1.0, 0.0], [1.0, 0.0]], mass=[2.0, 3.0])
    field = ForceField((Newton(G=0.5),))
    acceleration = field.evaluate(particles, Box(20, 20))
    # |F| = G m1 m2 / r^2 = 0.5 * 6 / 4 N, each towards the other.
    np.testing.assert_allclose(acceleration, [[0.75 / 2, 0.0], [-0.75 / 3, 0.0]], rtol=1e-15)
    assert field.potential(particles, Box(20, 20)) == pytest.approx(-1.5, rel=1e-15)


def test_newton_tree_agrees_with_the_direct_sum_to_the_tree_error():
    particles = _cluster(3000)
    box = Box(200, 200)
    direct = ForceField((Newton(method="direct", softening=0.05),)).evaluate(particles, box)
    by_tree = ForceField((Newton(method="tree", softening=0.05),)).evaluate(particles, box)
    error = np.linalg.norm(by_tree - direct, axis=1) / np.linalg.norm(direct, axis=1)
    assert np.sqrt(np.mean(error**2)) < 1e-3  # the tree's documented bound at theta = 0.3


def _binary(speed: float) -> cd.Simulation:
    """Two point masses of 4 kg, 2 m apart, G = 1, moving at ``speed`` times the circular speed
    ``v = sqrt(G m / (2 d)) = 1`` m/s, in opposite directions."""
    particles = Particles([[-1.0, 0.0], [1.0, 0.0]], velocity=[[0.0, -speed], [0.0, speed]],
                          mass=4.0, radius=0.0)  # fmt: skip
    return cd.Simulation(Box(20, 20), particles, forces=[Newton(G=1.0)], collisions="off")


@pytest.mark.slow
def test_an_eccentric_binary_holds_its_energy_as_the_time_stepping_targets():
    """An ellipse of eccentricity 0.36 (apocentre 2 m, pericentre 0.94 m), 20 s: within the
    1e-6 that the accurate time stepping holds for the seed's orbit."""
    sim = _binary(0.8)
    start = sim.energy().total
    worst = 0.0
    for _ in range(20):
        sim.run(time=1.0)
        worst = max(worst, abs(sim.energy().total / start - 1))
    assert worst <= 1e-6


@pytest.mark.slow
def test_a_circular_binary_keeps_its_period():
    """A circle, period ``T = pi d / v`` = 2 pi s: after 4 periods each mass is back where the
    period says, to the O(tolerance^2) phase error per period (2e-3^2 * 2 pi * 4 = 1e-4)."""
    sim = _binary(1.0)
    period = 2 * math.pi
    sim.run(time=round(4 * period, 2))
    phase = math.atan2(sim.particles.position[1, 1], sim.particles.position[1, 0])
    assert (
        abs(phase - 2 * math.pi * (sim.time / period - 4)) < DEFAULT_TOLERANCE**2 * 2 * math.pi * 4
    )


def test_free_fall_is_the_parabola_to_round_off():
    g = np.array([0.7, -9.81])
    x0, v0 = np.array([-5.0, 6.0]), np.array([2.0, 4.0])
    sim = cd.Simulation(Box(20, 20), Particles([x0], velocity=[v0]), forces=[Gravity(g=g)])
    for _ in range(10):
        sim.run(time=0.1)
        t = sim.time
        np.testing.assert_allclose(sim.particles.position[0], x0 + v0 * t + 0.5 * g * t**2,
                                   rtol=0, atol=1e-13)  # fmt: skip
        np.testing.assert_allclose(sim.particles.velocity[0], v0 + g * t, rtol=0, atol=1e-13)


def test_a_bouncing_disk_keeps_its_energy_to_round_off():
    """Elastic bounces on the floor and the walls under gravity: the exact engine flies the
    parabola and meets the floor at a root of its quadratic, so 20 s of bounces keep the
    energy to round-off, with no kicks and the event queue built once."""
    particles = Particles([[0.0, 5.0]], velocity=[[3.0, 0.0]], radius=0.25)
    sim = cd.Simulation(Box(20, 20), particles, forces=[Gravity()], dt=0.01)
    start = sim.energy().total
    sim.run(time=20.0)
    assert sim.counters.wall_hits["bottom"] >= 5  # a fall of 14.75 m: a bounce every 3.5 s
    assert sim.energy().total == pytest.approx(start, rel=1e-12)
    assert sim._drift.rebuilds == 1  # type: ignore[attr-defined]
    assert abs(sim.particles.position[0, 1]) <= 10 - 0.25  # never below the floor


def test_a_gas_under_gravity_with_collisions_keeps_its_energy_to_round_off():
    """Disks falling and colliding: pairs under the same g see no force in their relative
    motion, so collisions stay exact, and wall bounces are exact as above: the queue lives on
    from step to step."""
    rng = np.random.default_rng(1)
    grid = np.linspace(-9, 9, 10)
    position = np.column_stack([grid.repeat(10), np.tile(grid, 10)])
    particles = Particles(position, velocity=rng.normal(0, 3, (100, 2)), radius=0.25)
    sim = cd.Simulation(Box(20, 20), particles, forces=[Gravity()], dt=0.01)
    start = sim.energy().total
    sim.run(time=2.0)
    assert sim.counters.pair_collisions > 100
    assert sim.energy().total == pytest.approx(start, rel=1e-12)
    assert sim.escaped() == 0
    assert sim._drift.rebuilds == 1  # type: ignore[attr-defined]
